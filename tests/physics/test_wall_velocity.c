// SPDX-License-Identifier: MIT
// A wall's translational velocity (dem_world_set_wall_velocity) in the
// contact law, against mechanics worked out by hand:
//  - a sphere at rest on a floor that starts sliding along itself at V is
//    dragged by kinetic friction μ m g: its centre accelerates at μ g, its
//    spin at 5 μ g / (2R), so the slip at the contact point closes at
//    (7/2) μ g and sticks at t* = 2V / (7 μ g), after which the sphere rolls
//    on the moving floor at 2V/7 with spin 5V/(7R) (no force needed);
//  - a floor pushed up at constant speed U (moved every step and given that
//    velocity) carries a granule at U with the overlap of its weight, m g / k:
//    the dashpot acts on the relative normal velocity, which is zero (against
//    a still wall's surface the granule would be separating, and the dashpot
//    would pull it back with γ U, here 16 % of the weight: the overlap 16 %
//    deeper); with the implicit dashpot too;
//  - one evaluation apart from a twin at rest, a floor approaching at U puts
//    exactly γ U = 2ξ sqrt(m k) U more on the granule, along the normal only;
//  - a velocity set back to zero leaves a run the same bits as one never
//    given a velocity; a bad velocity or wall is refused.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dem_world.h"

static const double G = 9.81, RHO = 1800.0, R = 1e-3, K = 1000.0;

static dem_contact_params contact(double xi, double mu_s)
{
    return (dem_contact_params){.k_n = K, .k_s = K, .k_r = K, .xi = xi, .mu_s = mu_s, .damping = DEM_DAMPING_ALWAYS};
    // (μ_r = 0: no rolling resistance)
}

// One granule on the floor y = 0 (normal +y), settled at rest by the dashpot.
static dem_world *granule_on_floor(double mu_s, int implicit_damping)
{
    dem_world_def def = dem_default_world_def();
    def.granule = contact(0.7, mu_s);
    def.domain_lo = dem_v3(-0.2, -0.01, -0.05), def.domain_hi = dem_v3(0.2, 0.05, 0.05);
    def.threads = 1;
    def.implicit_damping = implicit_damping;
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    const dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 0, 1},
                                .contact = contact(0.7, mu_s), .name = "floor"};
    assert_int_equal(dem_world_add_wall(w, &floor), 0);
    assert_true(dem_world_add_granule(w, dem_v3(0, R, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO) >= 0);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    assert_int_equal(dem_world_step(w, (uint64_t)(0.3 / dem_world_dt(w))), DEM_OK);
    return w;
}

static double granule_mass(const dem_world *w) { return dem_world_granules(w).mass[0]; }

static void test_sliding_floor_drags_the_granule_until_it_rolls(void **state)
{
    (void)state;
    const double mu = 0.3, V = 0.2;
    dem_world *w = granule_on_floor(mu, 0);
    const double m = granule_mass(w), dt = dem_world_dt(w);
    assert_true(fabs(dem_world_granules(w).velocity[0].x) < 1e-9);
    assert_int_equal(dem_world_set_wall_velocity(w, 0, dem_v3(V, 0, 0)), DEM_OK);
    assert_true(dem_world_wall(w, 0)->velocity.x == V);
    char effects[512];
    dem_world_describe_features(w, effects, sizeof effects);
    assert_non_null(strstr(effects, "wall floor (plane, moving)"));

    // Sliding: half-way to t*, the centre's velocity is μ g t and the floor
    // feels the friction −μ m g along x (the granule pulls it back).
    const double t_stick = 2.0 * V / (7.0 * mu * G);
    const uint64_t half = (uint64_t)(0.5 * t_stick / dt);
    assert_int_equal(dem_world_step(w, half), DEM_OK);
    dem_granules_view g = dem_world_granules(w);
    const double t = (double)half * dt, v_slide = mu * G * t;
    const dem_vec3 f = dem_world_wall_force(w, 0);
    printf("sliding at t = %.4g s (t* = %.4g s): v = %.6g m/s (mu g t = %.6g), omega = %.6g rad/s "
           "(5 mu g t / 2R = %.6g), floor friction %.6g N (-mu m g = %.6g N)\n",
           t, t_stick, g.velocity[0].x, v_slide, g.omega[0].z, 2.5 * v_slide / R, f.x, -mu * m * G);
    assert_true(fabs(g.velocity[0].x - v_slide) < 0.01 * v_slide);
    assert_true(fabs(g.omega[0].z - 2.5 * v_slide / R) < 0.01 * 2.5 * v_slide / R);
    assert_true(fabs(f.x + mu * m * G) < 0.01 * mu * m * G);

    // Well after t*: rolling on the floor without slip, no force needed.
    assert_int_equal(dem_world_step(w, (uint64_t)(2.5 * t_stick / dt)), DEM_OK);
    g = dem_world_granules(w);
    const double v_roll = 2.0 * V / 7.0, w_roll = 5.0 * V / (7.0 * R);
    const double slip = g.velocity[0].x + R * g.omega[0].z - V;
    printf("rolling: v = %.6g m/s (2V/7 = %.6g), omega = %.6g rad/s (5V/7R = %.6g), slip %.3g m/s\n",
           g.velocity[0].x, v_roll, g.omega[0].z, w_roll, slip);
    assert_true(fabs(g.velocity[0].x - v_roll) < 0.02 * v_roll);
    assert_true(fabs(g.omega[0].z - w_roll) < 0.02 * w_roll);
    assert_true(fabs(slip) < 0.02 * V);
    dem_world_destroy(w);
}

// The floor moves up at U, moved before every step and given its velocity.
static void carried_up(int implicit_damping)
{
    const double U = 1e-4;
    dem_world *w = granule_on_floor(0.3, implicit_damping);
    const double m = granule_mass(w), dt = dem_world_dt(w);
    const double gamma = 2.0 * 0.7 * sqrt(m * K);
    assert_int_equal(dem_world_set_wall_velocity(w, 0, dem_v3(0, U, 0)), DEM_OK);
    dem_vec3 p = dem_world_wall(w, 0)->point;
    const uint64_t steps = (uint64_t)(0.3 / dt);
    for (uint64_t s = 0; s < steps; ++s) {
        p.y += U * dt;
        assert_int_equal(dem_world_set_wall_point(w, 0, p), DEM_OK);
        assert_int_equal(dem_world_step(w, 1), DEM_OK);
    }
    dem_granules_view g = dem_world_granules(w);
    const double h = R - (g.position[0].y - p.y), h_weight = m * G / K;
    const dem_vec3 f = dem_world_wall_force(w, 0);
    printf("floor moving up at %g m/s (implicit dashpot %d): granule at %.6g m/s, overlap %.6g m (m g / k = %.6g; "
           "a still wall's dashpot would leave %.6g), floor force %.6g N (weight %.6g N)\n",
           U, implicit_damping, g.velocity[0].y, h, h_weight, (m * G + gamma * U) / K, f.y, m * G);
    assert_true(fabs(g.velocity[0].y - U) < 1e-3 * U);
    assert_true(fabs(h - h_weight) < 1e-3 * h_weight);
    assert_true(fabs(f.y + m * G) < 1e-3 * m * G);
    dem_world_destroy(w);
}

static void test_floor_pushed_up_carries_the_granule_at_its_weight(void **state)
{
    (void)state;
    carried_up(0);
    carried_up(1);
}

// One force evaluation from the same state, the floor at rest in one twin and
// approaching at U in the other (the velocity set after the forces the step
// starts from, so both kick and drift the same): the dashpot's γ U apart.
static void test_approaching_floor_adds_its_dashpot(void **state)
{
    (void)state;
    const double U = 1e-3;
    dem_world *a = granule_on_floor(0.3, 0);
    dem_world *b = dem_world_clone(a);
    assert_non_null(b);
    const double m = granule_mass(a), gamma = 2.0 * 0.7 * sqrt(m * K);
    assert_int_equal(dem_world_set_wall_velocity(a, 0, dem_v3(0, U, 0)), DEM_OK);
    assert_int_equal(dem_world_step(a, 1), DEM_OK);
    assert_int_equal(dem_world_step(b, 1), DEM_OK);
    const dem_vec3 fa = dem_world_wall_force(a, 0), fb = dem_world_wall_force(b, 0);
    printf("floor approaching at %g m/s: floor force %.9g N, at rest %.9g N, difference %.9g N (-gamma U = %.9g N)\n",
           U, fa.y, fb.y, fa.y - fb.y, -gamma * U);
    assert_true(fabs((fa.y - fb.y) + gamma * U) < 1e-9 * gamma * U);
    assert_true(fa.x == fb.x && fa.z == fb.z);
    dem_world_destroy(a);
    dem_world_destroy(b);
}

// A velocity set and cleared again is no velocity: the same bits as a twin
// never given one (a zero is not added to the relative velocity).
static void test_cleared_velocity_changes_nothing(void **state)
{
    (void)state;
    dem_world *a = granule_on_floor(0.3, 0);
    dem_world *b = dem_world_clone(a);
    assert_non_null(b);
    assert_int_equal(dem_world_set_wall_velocity(a, 0, dem_v3(0.1, -0.0, 0.2)), DEM_OK);
    assert_int_equal(dem_world_set_wall_velocity(a, 0, dem_v3(0, -0.0, 0)), DEM_OK);
    assert_int_equal(dem_world_step(a, 500), DEM_OK);
    assert_int_equal(dem_world_step(b, 500), DEM_OK);
    dem_granules_view ga = dem_world_granules(a), gb = dem_world_granules(b);
    assert_memory_equal(ga.position, gb.position, sizeof *ga.position);
    assert_memory_equal(ga.velocity, gb.velocity, sizeof *ga.velocity);
    assert_memory_equal(ga.omega, gb.omega, sizeof *ga.omega);
    const dem_vec3 fa = dem_world_wall_force(a, 0), fb = dem_world_wall_force(b, 0);
    assert_memory_equal(&fa, &fb, sizeof fa);
    char effects[512];
    dem_world_describe_features(a, effects, sizeof effects);
    assert_non_null(strstr(effects, "wall floor (plane)"));

    assert_int_equal(dem_world_set_wall_velocity(a, 0, dem_v3(NAN, 0, 0)), DEM_ERR_INVALID);
    assert_non_null(strstr(dem_world_error(a), "velocity must be finite"));
    assert_int_equal(dem_world_set_wall_velocity(a, 1, dem_v3(0, 0, 0)), DEM_ERR_INVALID);
    dem_wall_def bad = *dem_world_wall(a, 0);
    bad.velocity = dem_v3(0, INFINITY, 0);
    assert_int_equal(dem_world_add_wall(a, &bad), -1);
    dem_world_destroy(a);
    dem_world_destroy(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sliding_floor_drags_the_granule_until_it_rolls),
        cmocka_unit_test(test_floor_pushed_up_carries_the_granule_at_its_weight),
        cmocka_unit_test(test_approaching_floor_adds_its_dashpot),
        cmocka_unit_test(test_cleared_velocity_changes_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
