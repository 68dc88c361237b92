// SPDX-License-Identifier: MIT
// The spin mode of the engine issue: equal granules in sticking contact
// (k_s = k_r = k_n, friction never reached), prestressed in a lattice that is
// periodic along x, perturbed. At the engine's default step the lattice
// returns to rest; run above the limit the engine computes, it blows up, so
// the limit is real and not just a safe-looking number; a configured step
// above it is refused before the run starts. Three integrations: explicit,
// implicit dashpot, implicit springs (limit √3/ω_n of the normal springs).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "dem_stability.h"
#include "dem_world.h"

#define R 1e-3
#define RHO 1800.0
#define CELLS 4
#define PRESTRESS 1e-3 // overlap / diameter of nearest neighbours

// The integration under test: 0 explicit, 1 implicit dashpot, 2 implicit
// springs (Newmark β = 1/4 on the sticking springs, network solve).
static int integration;

static dem_world_def lattice_def(double dt, int allow)
{
    dem_world_def def = dem_default_world_def();
    def.implicit_damping = integration == 1;
    def.implicit_springs = integration == 2;
    double a = 2 * R * (1 - PRESTRESS) * sqrt(2.0);
    def.gravity = dem_v3(0, 0, 0);
    def.granule.mu_s = def.granule.mu_r = 1e6; // sticking: springs never truncate
    def.periodic_axis = 0;
    def.domain_lo = dem_v3(0, -0.05, -0.05);
    def.domain_hi = dem_v3(CELLS * a, 0.05, 0.05);
    def.dt = dt;
    def.allow_unstable_dt = allow;
    return def;
}

// Plane walls hold the prestressed lattice on the four non-periodic sides.
static void add_confining_walls(dem_world *w, double a)
{
    dem_contact_params c = lattice_def(0, 0).granule;
    c.k_n = c.k_s = c.k_r = 400; // Table 3 granule–boundary
    double gap = R * (1 - 2 * PRESTRESS), top = a * (CELLS - 0.5) + gap;
    const double walls[4][6] = {{0, -gap, 0, 0, 1, 0}, {0, top, 0, 0, -1, 0}, {0, 0, -gap, 0, 0, 1},
                                {0, 0, top, 0, 0, -1}};
    for (int k = 0; k < 4; ++k) {
        dem_wall_def d = {.kind = DEM_WALL_PLANE, .contact = c, .name = "box"};
        d.point = dem_v3(walls[k][0], walls[k][1], walls[k][2]);
        d.normal = dem_v3(walls[k][3], walls[k][4], walls[k][5]);
        assert_true(dem_world_add_wall(w, &d) >= 0);
    }
}

static dem_world *make_lattice(double dt, int allow)
{
    dem_world_def def = lattice_def(dt, allow);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    double a = 2 * R * (1 - PRESTRESS) * sqrt(2.0);
    add_confining_walls(w, a);
    const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
    unsigned seed = 7;
    for (int x = 0; x < CELLS; ++x)
        for (int y = 0; y < CELLS; ++y)
            for (int z = 0; z < CELLS; ++z)
                for (int b = 0; b < 4; ++b) {
                    dem_vec3 p = dem_v3(a * (x + basis[b][0] + 0.25), a * (y + basis[b][1]), a * (z + basis[b][2]));
                    // Perturbation: small random velocity and spin.
                    seed = seed * 1103515245u + 12345u;
                    double r1 = (double)(seed >> 8) / 16777216.0 - 0.5;
                    seed = seed * 1103515245u + 12345u;
                    double r2 = (double)(seed >> 8) / 16777216.0 - 0.5;
                    dem_vec3 v = dem_v3(1e-4 * r1, 1e-4 * r2, 1e-4 * (r1 - r2));
                    dem_vec3 om = dem_v3(0.1 * r2, 0.1 * r1, 0.1 * (r1 + r2));
                    assert_true(dem_world_add_granule(w, p, v, om, R, RHO) >= 0);
                }
    return w;
}

static double energy(const dem_world *w)
{
    dem_diagnostics d = dem_world_diagnose(w);
    return d.ke_translational + d.ke_rotational + d.potential_elastic;
}

// Runs `steps` and returns max over the run of (KE now / KE at start).
static double run_growth(dem_world *w, int steps, double *final_ratio)
{
    dem_diagnostics d0 = dem_world_diagnose(w);
    double ke0 = d0.ke_translational + d0.ke_rotational, worst = 1;
    for (int s = 0; s < steps; s += 100) {
        if (dem_world_step(w, 100) != DEM_OK) return INFINITY;
        dem_diagnostics d = dem_world_diagnose(w);
        double ke = d.ke_translational + d.ke_rotational;
        worst = fmax(worst, ke / ke0);
        *final_ratio = ke / ke0;
    }
    return worst;
}

static void test_default_step_returns_to_rest(void **state)
{
    (void)state;
    dem_world *w = make_lattice(0.0, 0);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    printf("%s\n", dem_world_dt_report(w));
    double e0 = energy(w), fin = 0;
    double worst = run_growth(w, 20000, &fin);
    printf("default step: KE max %.3g x start, final %.3g x start; energy %.4g -> %.4g J\n", worst, fin, e0, energy(w));
    assert_true(fin < 1e-2);        // damped back towards rest
    assert_true(energy(w) <= e0);   // nothing pumped in
    dem_world_destroy(w);
}

// The stability limit the engine computes for this lattice.
static double engine_limit(void)
{
    dem_world *probe = make_lattice(0.0, 0);
    assert_int_equal(dem_world_prepare(probe), DEM_OK);
    double limit = dem_world_dt_limit(probe);
    dem_world_destroy(probe);
    return limit;
}

static void test_limit_is_real(void **state)
{
    (void)state;
    double limit = engine_limit();
    // Explicit dashpot: the limit is a bound (highest frequency and strongest
    // dashpot taken as if in one mode), so steps somewhat above it may still
    // be stable; far above it the spin mode must blow up, or the bound is
    // meaningless. Implicit dashpot: the limit is the spring modes' own,
    // ω·dt = 2, so it is sharp: stable just below, blowing up just above.
    // Implicit springs: the limit is the normal springs' ω_n·dt = √3 (the
    // switched dashpot of eq. 4 pumps a mode turning > 120° a step): stable
    // at 0.95 of it, blowing up at 1.3 (0.82 dt_crit).
    const double explicit_factors[] = {1.0, 1.6, 2.5}, implicit_factors[] = {0.95, 1.0, 1.1};
    const double spring_factors[] = {0.95, 1.1, 1.3};
    const double *factors = integration == 2 ? spring_factors : integration ? implicit_factors : explicit_factors;
    double worst[3];
    for (size_t k = 0; k < 3; ++k) {
        dem_world *w = make_lattice(factors[k] * limit, 1);
        double fin = 0;
        worst[k] = run_growth(w, 20000, &fin);
        printf("dt = %.2f x limit: KE max %.3g x start, final %.3g x start\n", factors[k], worst[k], fin);
        dem_world_destroy(w);
    }
    assert_true(worst[0] <= 1.0 + 1e-9);
    assert_true(worst[2] > 1e3 || isinf(worst[2]));
}

static void test_step_above_limit_refused(void **state)
{
    (void)state;
    double limit = engine_limit();
    dem_world *w = make_lattice(1.01 * limit, 0);
    assert_int_equal(dem_world_prepare(w), DEM_ERR_UNSTABLE);
    printf("refused: %s\n", dem_world_error(w));
    dem_world_destroy(w);
}

static int explicit_dashpot(void **state)
{
    (void)state;
    integration = 0;
    printf("-- explicit dashpot\n");
    return 0;
}

static int implicit_dashpot(void **state)
{
    (void)state;
    integration = 1;
    printf("-- implicit dashpot\n");
    return 0;
}

static int implicit_springs(void **state)
{
    (void)state;
    integration = 2;
    printf("-- implicit springs\n");
    return 0;
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_default_step_returns_to_rest),
                                       cmocka_unit_test(test_limit_is_real),
                                       cmocka_unit_test(test_step_above_limit_refused)};
    int failed = cmocka_run_group_tests_name("explicit dashpot", tests, explicit_dashpot, NULL);
    failed += cmocka_run_group_tests_name("implicit dashpot", tests, implicit_dashpot, NULL);
    return failed + cmocka_run_group_tests_name("implicit springs", tests, implicit_springs, NULL);
}
