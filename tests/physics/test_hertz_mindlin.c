// SPDX-License-Identifier: MIT
// The Hertz–Mindlin contact law (DEM_LAW_HERTZ_MINDLIN, dem_contact.h)
// against analytic results, through the whole engine (the explicit
// integration runs pairs and wall contacts through the contact batch) and
// through the one-contact kernel:
//   1. two spheres, head-on, undamped: maximum overlap and contact duration
//      of Hertz's impact, restitution 1;
//   2. the same damped (Tsuji's dashpot, in both phases): restitution
//      exp(−πξ/sqrt(1−ξ²)) (Antypov & Elliott 2011), the same at two speeds;
//   3. a sphere on a plane wall: the same impact with m* = m, R* = R;
//   4. the kernel's forces: Hertz's normal force, Mindlin's tangential
//      stiffness, and the linear law still the default of a zeroed struct;
//   5. the coarse-graining rule keeps the relative overlap under one force;
//   6. a configured step above the Rayleigh limit is refused.
//
// Hertz's impact (Johnson 1985, ch. 11): m* ḧ = −(4/3) E* sqrt(R*) h^(3/2)
// from ḣ = v. Energy: ½ m* v² = (8/15) E* sqrt(R*) h_max^(5/2), so
//   h_max = (15 m* v² / (16 E* sqrt(R*)))^(2/5);
// and t_c = 2 (h_max/v) ∫₀¹ dx / sqrt(1 − x^(5/2)) = 2 (h_max/v) (2/5)
// B(2/5, 1/2) = 2.9432 h_max/v, i.e. 2.868 (m*²/(R* E*² v))^(1/5), the
// figure usually quoted (2.868 is this constant rounded).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>

#include "dem_scaling.h"
#include "dem_stability.h"
#include "dem_world.h"

static const double RHO = 2500.0; // glass-like, kg/m³
static const double R = 1e-3;     // radius, m
static const double E_STAR = 1e8; // effective modulus, Pa: soft, so that t_c is long against the step
// Steps per contact duration. Velocity Verlet's errors in the overlap and
// in the energy are O((ω dt)²) with ω ≈ π/t_c: (π/2000)² = 2.5e-6; the
// sampled maximum misses the true one by at most ½ ḧ (dt/2)², of relative
// size (π/2000)²/8 ≈ 3e-7; the crossings of h = 0, interpolated linearly,
// are exact to O(dt^(5/2)) (h ∝ t near them, the force ∝ h^(3/2)). A
// tolerance of 1e-4 leaves a margin of 40 over these, and is far inside
// what a wrong law gives: a factor 4/3 missing moves h_max by 12 %, a
// linear spring tuned to the same h_max moves t_c by 7 %.
#define STEPS_PER_CONTACT 2000
#define TIGHT 1e-4

static double sphere_mass(double r) { return RHO * 4.0 / 3.0 * DEM_PI * r * r * r; }

static void assert_rel(double got, double want, double tol, const char *what)
{
    const double err = fabs(got - want) / fabs(want);
    printf("    %-40s measured %.8g, analytic %.8g, relative error %.2e (tolerance %.0e)\n", what, got, want, err,
           tol);
    if (!(err <= tol))
        fail_msg("%s: measured %.9g, analytic %.9g, relative error %.3g > %.3g", what, got, want, err, tol);
}

// Hertz's impact at approach speed v (see the head of the file).
typedef struct hertz_impact {
    double h_max, t_c;
} hertz_impact;

static hertz_impact hertz_analytic(double m_star, double r_star, double e_star, double v)
{
    const double h_max = pow(15.0 * m_star * v * v / (16.0 * e_star * sqrt(r_star)), 0.4);
    const double integral = 0.4 * tgamma(0.4) * tgamma(0.5) / tgamma(0.9); // (2/5) B(2/5, 1/2)
    return (hertz_impact){h_max, 2.0 * integral * h_max / v};
}

static dem_contact_params hertz_params(double xi)
{
    return (dem_contact_params){.law = DEM_LAW_HERTZ_MINDLIN, .youngs_modulus = E_STAR, .xi = xi,
                                .damping = DEM_DAMPING_ALWAYS};
}

// What one impact measured: the largest sampled overlap, the contact
// duration (crossings of h = 0 interpolated within their step), and the
// restitution, −(normal relative velocity after)/(before).
typedef struct impact {
    double h_max, t_c, e;
} impact;

typedef struct scene {
    dem_world *w;
    int wall; // 1: granule 0 against a plane y = 0; 0: granules 0 and 1
    double v; // approach speed
} scene;

static double overlap_of(const scene *s)
{
    const dem_granules_view g = dem_world_granules(s->w);
    if (s->wall) return R - g.position[0].y;
    return 2 * R - dem_v3_norm(dem_v3_sub(g.position[1], g.position[0]));
}

static double separation_speed(const scene *s)
{
    const dem_granules_view g = dem_world_granules(s->w);
    return s->wall ? g.velocity[0].y : g.velocity[1].x - g.velocity[0].x;
}

static void step_ok(dem_world *w, uint64_t n)
{
    const dem_status st = dem_world_step(w, n);
    if (st != DEM_OK) fail_msg("dem_world_step: status %d: %s", (int)st, dem_world_error(w));
}

static impact run_impact(const scene *s, double dt, double gap)
{
    double t_in = -1, t_out = -1, h_prev = -gap, t_prev = dem_world_time(s->w), h_max = 0;
    for (int k = 0; k < 20 * STEPS_PER_CONTACT && t_out < 0; ++k) {
        step_ok(s->w, 1);
        const double h = overlap_of(s), t = dem_world_time(s->w);
        if (h > h_max) h_max = h;
        if (t_in < 0 && h > 0) t_in = t_prev + dt * (-h_prev) / (h - h_prev);
        else if (t_in >= 0 && h <= 0) t_out = t_prev + dt * h_prev / (h_prev - h);
        h_prev = h, t_prev = t;
    }
    if (!(t_in >= 0 && t_out > t_in)) fail_msg("the impact did not end within %d steps", 20 * STEPS_PER_CONTACT);
    step_ok(s->w, 5); // free flight: the velocities are final
    return (impact){h_max, t_out - t_in, separation_speed(s) / s->v};
}

static dem_world *world_new(const dem_contact_params *granule, double dt)
{
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, 0);
    def.granule = *granule;
    def.dt = dt;
    char err[512] = "";
    dem_world *w = dem_world_create(&def, err, sizeof err);
    if (!w) fail_msg("dem_world_create: %s", err);
    return w;
}

static void add_ok(dem_world *w, dem_vec3 p, dem_vec3 v)
{
    if (dem_world_add_granule(w, p, v, dem_v3(0, 0, 0), R, RHO) < 0) fail_msg("add: %s", dem_world_error(w));
}

// Two equal spheres approaching at v (each at v/2): m* = m/2, R* = R/2.
static impact two_sphere_impact(double xi, double v, hertz_impact *expect)
{
    const double m = sphere_mass(R);
    *expect = hertz_analytic(0.5 * m, 0.5 * R, E_STAR, v);
    const double dt = expect->t_c / STEPS_PER_CONTACT, gap = 1e-3 * R;
    const dem_contact_params p = hertz_params(xi);
    dem_world *w = world_new(&p, dt);
    add_ok(w, dem_v3(-R - gap / 2, 0.01, 0.02), dem_v3(0.5 * v, 0, 0));
    add_ok(w, dem_v3(R + gap / 2, 0.01, 0.02), dem_v3(-0.5 * v, 0, 0));
    const scene s = {w, 0, v};
    const impact got = run_impact(&s, dt, gap);
    dem_world_destroy(w);
    return got;
}

// 1. Undamped: h_max and t_c within TIGHT, restitution 1 within TIGHT. Fails
// if the normal force is not (4/3) E* sqrt(R*) h^(3/2) (a linear spring, a
// missing factor, R instead of R*) or if the pair path drops the law's bit.
static void test_two_spheres_undamped(void **state)
{
    (void)state;
    hertz_impact ex;
    const impact got = two_sphere_impact(0.0, 0.2, &ex);
    printf("  two spheres, v = 0.2 m/s, E* = %g Pa, R = %g m, dt = t_c/%d:\n", E_STAR, R, STEPS_PER_CONTACT);
    assert_rel(got.h_max, ex.h_max, TIGHT, "maximum overlap h_max, m");
    assert_rel(got.t_c, ex.t_c, TIGHT, "contact duration t_c, s");
    const double m_star = 0.5 * sphere_mass(R), r_star = 0.5 * R;
    const double quoted = 2.868 * pow(m_star * m_star / (r_star * E_STAR * E_STAR * 0.2), 0.2);
    assert_rel(got.t_c, quoted, 2e-4, "t_c against 2.868 (m*^2/(R* E*^2 v))^(1/5)"); // 2.868 is rounded
    assert_rel(got.e, 1.0, TIGHT, "restitution (undamped)");
}

// 2. Tsuji's dashpot in both phases: e = exp(−πξ/sqrt(1−ξ²)) for every
// speed (Antypov & Elliott 2011; the Hertz spring's damped overlap maps onto
// a linear oscillator's of damping ratio ξ). The dashpot sees the velocity
// half a step late, an O(ξ ω dt) ≈ 0.3·π/2000 ≈ 5e-4 relative error: the
// tolerance is 2e-3. Fails if the dashpot's coefficient is off (a factor
// sqrt(5/6) missing: e = 0.41 instead of 0.37) or if it does not grow as
// h^(1/4) (a constant γ makes e depend on v: checked at 0.2 and 2 m/s).
static void test_two_spheres_damped(void **state)
{
    (void)state;
    const double xi = 0.3, e = exp(-DEM_PI * xi / sqrt(1 - xi * xi));
    const double speeds[2] = {0.2, 2.0};
    for (int k = 0; k < 2; ++k) {
        hertz_impact ex;
        const impact got = two_sphere_impact(xi, speeds[k], &ex);
        printf("  two spheres, xi = %g, v = %g m/s:\n", xi, speeds[k]);
        assert_rel(got.e, e, 2e-3, "restitution exp(-pi xi/sqrt(1-xi^2))");
    }
}

// 3. The wall path: a sphere on the plane y = 0 at v, m* = m, R* = R,
// undamped, with the same tolerances as 1. Fails if the wall contacts do not
// run the wall's law (its own mask bit).
static void test_sphere_on_wall(void **state)
{
    (void)state;
    const double v = 0.2, m = sphere_mass(R), gap = 1e-3 * R;
    const hertz_impact ex = hertz_analytic(m, R, E_STAR, v);
    const double dt = ex.t_c / STEPS_PER_CONTACT;
    const dem_contact_params p = hertz_params(0.0);
    dem_world *w = world_new(&p, dt);
    const dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = dem_v3(0, 0, 0), .normal = dem_v3(0, 1, 0),
                                .contact = p, .name = "floor"};
    if (dem_world_add_wall(w, &floor) < 0) fail_msg("add_wall: %s", dem_world_error(w));
    add_ok(w, dem_v3(0.01, R + gap, 0.02), dem_v3(0, -v, 0));
    const scene s = {w, 1, v};
    const impact got = run_impact(&s, dt, gap);
    printf("  sphere on a wall, v = %g m/s, dt = t_c/%d:\n", v, STEPS_PER_CONTACT);
    assert_rel(got.h_max, ex.h_max, TIGHT, "maximum overlap h_max, m");
    assert_rel(got.t_c, ex.t_c, TIGHT, "contact duration t_c, s");
    assert_rel(got.e, 1.0, TIGHT, "restitution (undamped)");
    dem_world_destroy(w);
}

// 4. The one-contact kernel: Hertz's force at an overlap h, and Mindlin's
// spring after one step of tangential slip u = v_t dt: F_t = −8 G* sqrt(R* h) u
// (below the Coulomb limit). A zeroed parameter struct is the linear law.
static void test_kernel_forces(void **state)
{
    (void)state;
    const double h = 1e-6, r_star = 5e-4, g_star = 4e7, vt = 1e-3, dt = 1e-6;
    dem_contact_params p = hertz_params(0.0);
    p.shear_modulus = g_star;
    p.mu_s = 1.0;
    char msg[200];
    assert_int_equal(dem_contact_params_check(&p, msg, sizeof msg), 0);
    const unsigned mask = dem_contact_features(&p);
    assert_int_equal(mask, DEM_FEAT_HERTZ | DEM_FEAT_TANGENTIAL);
    const dem_contact_coeffs c = dem_contact_coeffs_make(&p);
    const dem_contact_state s = {dem_v3(1, 0, 0), h, dem_v3(0, vt, 0), dem_v3(0, 0, 0), 0.0, 1.0, r_star, dt};
    double hist[3] = {0, 0, 0};
    dem_contact_out out;
    dem_contact_eval(&c, &s, hist, &out, DEM_FEAT_HERTZ | DEM_FEAT_TANGENTIAL);
    const double a = sqrt(r_star * h);
    printf("  kernel at h = %g m, R* = %g m:\n", h, r_star);
    assert_rel(out.normal_force, 4.0 / 3.0 * E_STAR * sqrt(r_star) * pow(h, 1.5), 1e-14, "normal force, N");
    assert_rel(out.f_tangential.y, -8.0 * g_star * a * vt * dt, 1e-14, "tangential force, N");
    assert_rel(out.k_tangential, 8.0 * g_star * a, 1e-14, "tangential stiffness (sticking), N/m");
    // The linear law's fields are refused under Hertz–Mindlin, and a zeroed
    // struct is the linear law.
    p.k_n = 200;
    assert_int_not_equal(dem_contact_params_check(&p, msg, sizeof msg), 0);
    const dem_contact_params zero = {0};
    assert_int_equal(zero.law, DEM_LAW_LINEAR);
    assert_int_equal(dem_contact_features(&zero) & DEM_FEAT_HERTZ, 0);
    assert_string_equal(dem_contact_law_name(DEM_LAW_HERTZ_MINDLIN), "hertz_mindlin");
    assert_int_equal(dem_contact_law_from_name("hertz_mindlin"), DEM_LAW_HERTZ_MINDLIN);
}

// 5. Coarse graining keeps eq. 18's relative overlap: the same force on the
// scaled granule (R·λ^(1/3), E* and G* by λ^(−2/3)) gives the same h/R.
// Fails if the moduli were scaled as the linear springs (λ^(−1/3)).
static void test_scaling_keeps_relative_overlap(void **state)
{
    (void)state;
    const double lambda = 216, force = 1e-3;
    dem_contact_params p = hertz_params(0.3);
    p.shear_modulus = 3e7;
    const dem_contact_params s = dem_scale_contact(&p, lambda);
    const double rs = dem_scale_radius(R, lambda);
    // h under force F: (3F / (4 E* sqrt R))^(2/3).
    const double h_r = pow(3 * force / (4 * p.youngs_modulus * sqrt(R)), 2.0 / 3.0);
    const double h_s = pow(3 * force / (4 * s.youngs_modulus * sqrt(rs)), 2.0 / 3.0);
    printf("  coarse graining, lambda = %g:\n", lambda);
    assert_rel(h_s / rs, h_r / R, 1e-12, "relative overlap h/R under one force");
    assert_rel(s.shear_modulus / s.youngs_modulus, p.shear_modulus / p.youngs_modulus, 1e-15, "G*/E* kept");
    assert_true(s.xi == p.xi && s.law == DEM_LAW_HERTZ_MINDLIN);
}

// 6. The Hertz limit: a configured step above 0.2 of the Rayleigh time is
// refused (DEM_ERR_UNSTABLE), one below it accepted. Fails if the linear
// law's eq. 14 (k_n = 0 here: an infinite step) were applied instead.
static void test_rayleigh_limit(void **state)
{
    (void)state;
    const dem_contact_params p = hertz_params(0.0);
    const double t_r = dem_rayleigh_time(&p, sphere_mass(R), R);
    // ν = 0 (no G*), G = E*: t_R = π R sqrt(ρ/E*) / 0.8766.
    printf("  Rayleigh time:\n");
    assert_rel(t_r, DEM_PI * R * sqrt(RHO / E_STAR) / 0.8766, 1e-14, "t_R, s");
    for (int k = 0; k < 2; ++k) {
        const double dt = (k ? 1.01 : 0.99) * DEM_RAYLEIGH_FRACTION * t_r;
        dem_world *w = world_new(&p, dt);
        add_ok(w, dem_v3(0, 0, 0), dem_v3(0, 0, 0));
        const dem_status st = dem_world_prepare(w);
        printf("    dt = %.3g s: %s\n", dt, st == DEM_OK ? "accepted" : dem_world_error(w));
        assert_int_equal(st, k ? DEM_ERR_UNSTABLE : DEM_OK);
        dem_world_destroy(w);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_spheres_undamped),
        cmocka_unit_test(test_two_spheres_damped),
        cmocka_unit_test(test_sphere_on_wall),
        cmocka_unit_test(test_kernel_forces),
        cmocka_unit_test(test_scaling_keeps_relative_overlap),
        cmocka_unit_test(test_rayleigh_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
