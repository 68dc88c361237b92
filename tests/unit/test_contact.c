// SPDX-License-Identifier: MIT
// The stateless LSD contact kernel of engine/dem_contact.h, alone: eq. 3–4
// (normal spring and the four readings of the dashpot switch), eq. 6–8 and
// 11–13 (history springs and their Coulomb truncation), the carrying of a
// spring onto a new tangent plane, and the parameter registry and checks.
// Every expected value is written out from the paper's equations here, not
// taken from the engine.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "dem_contact.h"

// A few ulps: each expected value is a handful of roundings from the kernel's.
static const double ROUNDOFF = 64 * 2.220446049250313e-16;

static void assert_close(double got, double want, double tol, const char *what)
{
    double err = fabs(got - want);
    double scale = want != 0.0 ? fabs(want) : 1.0; // relative, absolute at zero
    if (!(err <= tol * scale)) {
        print_error("%s: got %.17g, want %.17g, error %.3g > %.3g\n", what, got, want, err, tol * scale);
        fail();
    }
}

static void assert_vec_close(dem_vec3 got, dem_vec3 want, double tol, const char *what)
{
    double err = dem_v3_norm(dem_v3_sub(got, want));
    double scale = dem_v3_norm(want) > 0.0 ? dem_v3_norm(want) : 1.0;
    if (!(err <= tol * scale)) {
        print_error("%s: got (%.17g, %.17g, %.17g), want (%.17g, %.17g, %.17g), error %.3g > %.3g\n", what,
                    got.x, got.y, got.z, want.x, want.y, want.z, err, tol * scale);
        fail();
    }
}

static dem_vec3 unit(dem_vec3 v) { return dem_v3_scale(v, 1.0 / dem_v3_norm(v)); }

// A contact in a general orientation, so that no component of any vector is
// zero by accident of the axes. Units are SI but the numbers are O(1) so that
// a tolerance of ROUNDOFF is meaningful.
static dem_contact_params base_params(void)
{
    return (dem_contact_params){.k_n = 300.0, .k_s = 250.0, .k_r = 120.0, .xi = 0.7, .mu_s = 0.5, .mu_r = 0.1,
                                .damping = DEM_DAMPING_APPROACHING};
}

#define M_STAR 0.25 // reduced mass of base_state, kg

static dem_contact_state base_state(void)
{
    dem_contact_state s;
    memset(&s, 0, sizeof s);
    s.normal = unit(dem_v3(1.0, 2.0, 2.0)); // (1, 2, 2)/3
    s.overlap = 0.01;
    s.vrel = dem_v3(0, 0, 0);
    s.wrel = dem_v3(0, 0, 0);
    s.twist = 0.0;
    s.root_reduced_mass = sqrt(M_STAR);
    s.reduced_radius = 0.5;
    s.dt = 1e-3;
    return s;
}

// Eq. 3 without a dashpot: F_n = −k_n h n, a repulsion along −n on granule i
// (n points from i to j).
static void test_normal_force_undamped(void **state)
{
    (void)state;
    dem_contact_params p = base_params();
    dem_contact_coeffs c = dem_contact_coeffs_make(&p);
    dem_contact_state s = base_state();
    s.vrel = dem_v3_scale(s.normal, 3.0); // approaching fast: must not matter without DEM_FEAT_DAMPING
    double hist[6] = {0};
    dem_contact_out out;
    dem_contact_eval(&c, &s, hist, &out, 0u);
    double want = p.k_n * s.overlap;
    printf("undamped normal force: %.17g N (k_n h = %.17g N)\n", out.normal_force, want);
    assert_close(out.normal_force, want, ROUNDOFF, "normal force magnitude");
    assert_vec_close(out.force, dem_v3_scale(s.normal, -want), ROUNDOFF, "force vector = -k_n h n");
    assert_vec_close(out.f_tangential, dem_v3(0, 0, 0), 0.0, "no tangential force without the feature");
    assert_vec_close(out.f_rolling, dem_v3(0, 0, 0), 0.0, "no rolling force without the feature");
}

// Eq. 3–4 with a dashpot. The dashpot force along −n is γ_n v_n with
// γ_n = 2ξ sqrt(m* k_n) and v_n = v_rel·n (> 0 approaching, eq. 5). Which
// phase it acts in is the reading (dem_contact.h):
//   approaching: v_n > 0 only;  separating: v_n < 0 only;  always: both;
//   no_tension: both, and the total normal force is clamped at ≥ 0.
static double kernel_normal_force(dem_damping_mode mode, double vn, double overlap)
{
    dem_contact_params p = base_params();
    p.damping = mode;
    dem_contact_coeffs c = dem_contact_coeffs_make(&p);
    dem_contact_state s = base_state();
    s.overlap = overlap;
    // Add a tangential component too: the dashpot sees only the normal part.
    dem_vec3 t = unit(dem_v3_cross(s.normal, dem_v3(0, 0, 1)));
    s.vrel = dem_v3_add(dem_v3_scale(s.normal, vn), dem_v3_scale(t, 0.37));
    double hist[6] = {0};
    dem_contact_out out;
    dem_contact_eval(&c, &s, hist, &out, DEM_FEAT_DAMPING);
    assert_vec_close(out.force, dem_v3_scale(s.normal, -out.normal_force), ROUNDOFF, "force is along -n");
    return out.normal_force;
}

static void test_damping_readings(void **state)
{
    (void)state;
    const dem_contact_params p = base_params();
    const dem_contact_state s = base_state();
    const double gamma = 2.0 * p.xi * sqrt(M_STAR * p.k_n); // eq. 4
    const double spring = p.k_n * s.overlap;
    const double v_in = 0.02, v_out = -0.02; // |γ v| < k h: the force stays repulsive
    const double v_pull = -2.0;              // γ|v| > k h: an undamped-at-zero dashpot would pull
    printf("gamma_n = %.6g N s/m, k_n h = %.6g N, gamma v_in = %.6g N, gamma v_pull = %.6g N\n", gamma, spring,
           gamma * v_in, gamma * v_pull);
    assert_true(gamma * fabs(v_in) < spring);
    assert_true(spring + gamma * v_pull < 0.0);

    // Damped only while approaching (v_n > 0).
    assert_close(kernel_normal_force(DEM_DAMPING_APPROACHING, v_in, s.overlap), spring + gamma * v_in, ROUNDOFF,
                 "approaching reading, approaching");
    assert_close(kernel_normal_force(DEM_DAMPING_APPROACHING, v_out, s.overlap), spring, ROUNDOFF,
                 "approaching reading, separating");
    assert_close(kernel_normal_force(DEM_DAMPING_APPROACHING, v_pull, s.overlap), spring, ROUNDOFF,
                 "approaching reading never pulls");
    // Damped only while separating (v_n < 0): eq. 4 read literally.
    assert_close(kernel_normal_force(DEM_DAMPING_SEPARATING, v_in, s.overlap), spring, ROUNDOFF,
                 "separating reading, approaching");
    assert_close(kernel_normal_force(DEM_DAMPING_SEPARATING, v_out, s.overlap), spring + gamma * v_out, ROUNDOFF,
                 "separating reading, separating");
    assert_close(kernel_normal_force(DEM_DAMPING_SEPARATING, v_pull, s.overlap), spring + gamma * v_pull, ROUNDOFF,
                 "separating reading may pull");
    // Damped always.
    assert_close(kernel_normal_force(DEM_DAMPING_ALWAYS, v_in, s.overlap), spring + gamma * v_in, ROUNDOFF,
                 "always reading, approaching");
    assert_close(kernel_normal_force(DEM_DAMPING_ALWAYS, v_out, s.overlap), spring + gamma * v_out, ROUNDOFF,
                 "always reading, separating");
    assert_close(kernel_normal_force(DEM_DAMPING_ALWAYS, v_pull, s.overlap), spring + gamma * v_pull, ROUNDOFF,
                 "always reading may pull");
    // Damped always, clamped at zero.
    assert_close(kernel_normal_force(DEM_DAMPING_NO_TENSION, v_in, s.overlap), spring + gamma * v_in, ROUNDOFF,
                 "no-tension reading, approaching");
    assert_close(kernel_normal_force(DEM_DAMPING_NO_TENSION, v_out, s.overlap), spring + gamma * v_out, ROUNDOFF,
                 "no-tension reading, separating, still repulsive");
    assert_close(kernel_normal_force(DEM_DAMPING_NO_TENSION, v_pull, s.overlap), 0.0, 0.0,
                 "no-tension reading clamps at zero");
}

// Eq. 6–8: below the Coulomb limit the tangential spring grows by v_t Δt
// (v_t the tangential part of v_rel, eq. 7) and F_s = −k_s δ_s exactly.
static void test_tangential_spring_sticks(void **state)
{
    (void)state;
    dem_contact_params p = base_params();
    dem_contact_coeffs c = dem_contact_coeffs_make(&p);
    dem_contact_state s = base_state();
    dem_vec3 t = unit(dem_v3_cross(s.normal, dem_v3(1, 0, 0)));
    dem_vec3 vt = dem_v3_scale(t, 0.004);
    s.vrel = dem_v3_add(vt, dem_v3_scale(s.normal, 0.3)); // normal part must not enter the spring
    double hist[3] = {0};
    dem_contact_out out;
    dem_contact_eval(&c, &s, hist, &out, DEM_FEAT_TANGENTIAL);
    dem_vec3 delta = dem_v3_scale(vt, s.dt);
    double limit = p.mu_s * p.k_n * s.overlap;
    printf("sticking: k_s |delta| = %.6g N < mu_s |F_n| = %.6g N\n", p.k_s * dem_v3_norm(delta), limit);
    assert_true(p.k_s * dem_v3_norm(delta) < limit);
    assert_vec_close(dem_v3(hist[0], hist[1], hist[2]), delta, ROUNDOFF, "spring = v_t dt");
    assert_vec_close(out.f_tangential, dem_v3_scale(delta, -p.k_s), ROUNDOFF, "F_s = -k_s delta");
    assert_vec_close(out.force, dem_v3_add(dem_v3_scale(s.normal, -p.k_n * s.overlap), out.f_tangential), ROUNDOFF,
                     "force = F_n + F_s");
    // A second step with the same velocity doubles it (eq. 6 is incremental).
    dem_contact_eval(&c, &s, hist, &out, DEM_FEAT_TANGENTIAL);
    assert_vec_close(dem_v3(hist[0], hist[1], hist[2]), dem_v3_scale(delta, 2.0), ROUNDOFF, "spring after 2 steps");
}

// Eq. 8 and 13: past the limit, |F| = μ|F_n| along the trial force, and the
// stored spring is reset so that k|δ| = μ|F_n| (Luding 2008). |F_n| is the
// whole normal force, dashpot included.
static void check_truncation(dem_damping_mode mode, double vn)
{
    dem_contact_params p = base_params();
    p.damping = mode;
    dem_contact_coeffs c = dem_contact_coeffs_make(&p);
    dem_contact_state s = base_state();
    dem_vec3 t1 = unit(dem_v3_cross(s.normal, dem_v3(1, 0, 0)));
    dem_vec3 t2 = dem_v3_cross(s.normal, t1);
    dem_vec3 vt = dem_v3_add(dem_v3_scale(t1, 30.0), dem_v3_scale(t2, -20.0)); // k_s |v_t| dt ≫ μ k_n h
    s.vrel = dem_v3_add(vt, dem_v3_scale(s.normal, vn));
    dem_vec3 w = dem_v3_add(dem_v3_scale(t1, -40.0), dem_v3_scale(t2, 10.0));
    s.wrel = dem_v3_add(w, dem_v3_scale(s.normal, 5.0)); // spin about n: no rolling
    double hist[6] = {0};
    dem_contact_out out;
    const unsigned mask = DEM_FEAT_DAMPING | DEM_FEAT_TANGENTIAL | DEM_FEAT_ROLLING;
    dem_contact_eval(&c, &s, hist, &out, mask);

    // Independent normal force: k h + γ v_n if the reading damps this phase.
    double gamma = 2.0 * p.xi * sqrt(M_STAR * p.k_n);
    int damped = mode == DEM_DAMPING_ALWAYS || mode == DEM_DAMPING_NO_TENSION ||
                 (mode == DEM_DAMPING_APPROACHING && vn > 0) || (mode == DEM_DAMPING_SEPARATING && vn < 0);
    double fn = p.k_n * s.overlap + (damped ? gamma * vn : 0.0);
    if (mode == DEM_DAMPING_NO_TENSION && fn < 0) fn = 0;
    assert_close(out.normal_force, fn, ROUNDOFF, "normal force");

    // Sliding: direction of the trial force −k_s v_t Δt, magnitude μ_s|F_n|.
    double ls = p.mu_s * fabs(fn);
    dem_vec3 fs_want = dem_v3_scale(unit(vt), -ls);
    dem_vec3 ds = dem_v3(hist[0], hist[1], hist[2]);
    printf("reading %-11s v_n %+5.2f: |F_n| = %.6g N, |F_s| = %.17g N (mu_s|F_n| = %.17g), k_s|delta_s| = %.17g N\n",
           dem_damping_mode_name(mode), vn, fabs(fn), dem_v3_norm(out.f_tangential), ls, p.k_s * dem_v3_norm(ds));
    assert_close(dem_v3_norm(out.f_tangential), ls, ROUNDOFF, "|F_s| = mu_s |F_n|");
    assert_vec_close(out.f_tangential, fs_want, ROUNDOFF, "F_s along the trial force");
    assert_close(p.k_s * dem_v3_norm(ds), ls, ROUNDOFF, "k_s |delta_s| = mu_s |F_n|");
    assert_vec_close(dem_v3_scale(ds, -p.k_s), out.f_tangential, ROUNDOFF, "stored spring gives the force");

    // Rolling, eq. 12: v_r = −R* (ω_i − ω_j) × n; magnitude μ_r|F_n|.
    dem_vec3 vr = dem_v3_scale(dem_v3_cross(s.wrel, s.normal), -s.reduced_radius);
    double lr = p.mu_r * fabs(fn);
    dem_vec3 dr = dem_v3(hist[3], hist[4], hist[5]);
    assert_close(dem_v3_norm(out.f_rolling), lr, ROUNDOFF, "|F_r| = mu_r |F_n|");
    assert_vec_close(out.f_rolling, dem_v3_scale(unit(vr), -lr), ROUNDOFF, "F_r along the trial force");
    assert_close(p.k_r * dem_v3_norm(dr), lr, ROUNDOFF, "k_r |delta_r| = mu_r |F_n|");
    // The rolling quasi-force is not a force on the granule (only a torque).
    assert_vec_close(out.force, dem_v3_add(dem_v3_scale(s.normal, -fn), out.f_tangential), ROUNDOFF,
                     "force = F_n + F_s");
}

static void test_coulomb_truncation(void **state)
{
    (void)state;
    check_truncation(DEM_DAMPING_APPROACHING, 0.0);
    check_truncation(DEM_DAMPING_APPROACHING, 0.05);  // dashpot raises |F_n| and the limit
    check_truncation(DEM_DAMPING_SEPARATING, -0.05);  // dashpot lowers it
    check_truncation(DEM_DAMPING_ALWAYS, -0.05);
    check_truncation(DEM_DAMPING_NO_TENSION, -5.0);   // clamped: limit 0, spring reset to 0
}

// With both springs on, the history holds δ_s in slots 0–2 and δ_r in 3–5,
// and each grows by its own relative velocity while sticking.
static void test_history_layout(void **state)
{
    (void)state;
    assert_int_equal(dem_history_len(0u), 0);
    assert_int_equal(dem_history_len(DEM_FEAT_DAMPING), 0);
    assert_int_equal(dem_history_len(DEM_FEAT_TANGENTIAL), 3);
    assert_int_equal(dem_history_len(DEM_FEAT_ROLLING), 3);
    assert_int_equal(dem_history_len(DEM_FEAT_TANGENTIAL | DEM_FEAT_ROLLING | DEM_FEAT_DAMPING), 6);
    dem_contact_params p = base_params();
    dem_contact_coeffs c = dem_contact_coeffs_make(&p);
    dem_contact_state s = base_state();
    dem_vec3 t = unit(dem_v3_cross(s.normal, dem_v3(0, 1, 0)));
    s.vrel = dem_v3_scale(t, 0.001);
    s.wrel = dem_v3_scale(dem_v3_cross(s.normal, t), 0.002);
    double hist[6] = {0};
    dem_contact_out out;
    dem_contact_eval(&c, &s, hist, &out, DEM_FEAT_TANGENTIAL | DEM_FEAT_ROLLING);
    dem_vec3 ds = dem_v3_scale(s.vrel, s.dt);
    dem_vec3 dr = dem_v3_scale(dem_v3_cross(s.wrel, s.normal), -s.reduced_radius * s.dt);
    assert_vec_close(dem_v3(hist[0], hist[1], hist[2]), ds, ROUNDOFF, "slot 0-2: tangential spring");
    assert_vec_close(dem_v3(hist[3], hist[4], hist[5]), dr, ROUNDOFF, "slot 3-5: rolling spring");
    assert_vec_close(out.f_rolling, dem_v3_scale(dr, -p.k_r), ROUNDOFF, "F_r = -k_r delta_r");
}

// Rotation of v about unit axis a by angle θ (Rodrigues).
static dem_vec3 rotate(dem_vec3 v, dem_vec3 a, double th)
{
    dem_vec3 r = dem_v3_scale(v, cos(th));
    r = dem_v3_axpy(sin(th), dem_v3_cross(a, v), r);
    return dem_v3_axpy((1 - cos(th)) * dem_v3_dot(a, v), a, r);
}

// Carrying a spring onto a new tangent plane (Luding 2008): its length is
// kept and it ends perpendicular to the new normal.
static void test_spring_carry_new_normal(void **state)
{
    (void)state;
    dem_vec3 n0 = unit(dem_v3(1, 2, 2));
    dem_vec3 spring = dem_v3_scale(unit(dem_v3_cross(n0, dem_v3(0.3, -1, 0.2))), 2.5e-6);
    dem_vec3 n1 = unit(dem_v3_add(n0, dem_v3(0.05, -0.02, 0.01)));
    dem_vec3 out = dem_spring_carry(spring, n1, 0.0);
    printf("carry to a normal turned by %.4g rad: |s| %.17g -> %.17g, s.n1 = %.3g\n",
           acos(dem_v3_dot(n0, n1)), dem_v3_norm(spring), dem_v3_norm(out), dem_v3_dot(out, n1));
    assert_close(dem_v3_norm(out) / dem_v3_norm(spring), 1.0, ROUNDOFF, "length kept");
    assert_true(fabs(dem_v3_dot(out, n1)) <= ROUNDOFF * dem_v3_norm(spring));
    // The plain projection would lose length: the carry must not be it.
    dem_vec3 proj = dem_v3_axpy(-dem_v3_dot(spring, n1), n1, spring);
    assert_true(dem_v3_norm(proj) < dem_v3_norm(spring) * (1 - 1e-6));
    // It stays in the plane spanned by the old spring and the normals: the
    // carried spring is the projection, rescaled.
    assert_vec_close(out, dem_v3_scale(unit(proj), dem_v3_norm(spring)), ROUNDOFF, "carry = projection rescaled");
    // Carrying onto the same plane changes nothing.
    assert_vec_close(dem_spring_carry(spring, n0, 0.0), spring, ROUNDOFF, "same plane: unchanged");
}

// Twist θ about n turns the spring by θ about n. The carry is first order in
// θ (turn by θ n × s, then rescale), which is a turn by atan θ: exact to
// θ³/3 per call. The step twist is ω Δt ≪ 1, so check single small twists to
// that bound and a quarter turn made of many steps to N (θ/N)³/3.
static void test_spring_carry_twist(void **state)
{
    (void)state;
    dem_vec3 n = unit(dem_v3(-2, 1, 2));
    dem_vec3 spring = dem_v3_scale(unit(dem_v3_cross(n, dem_v3(1, 1, 0))), 3e-6);
    const double small[] = {1e-4, -3e-3, 2e-2};
    for (size_t k = 0; k < sizeof small / sizeof *small; ++k) {
        double th = small[k];
        dem_vec3 out = dem_spring_carry(spring, n, th);
        dem_vec3 want = rotate(spring, n, th);
        double err = dem_v3_norm(dem_v3_sub(out, want)) / dem_v3_norm(spring);
        printf("twist %+.0e rad: direction error %.3g (bound theta^3/3 = %.3g)\n", th, err, fabs(th * th * th) / 3);
        assert_true(err <= fabs(th * th * th) / 3 * 1.01 + ROUNDOFF);
        assert_close(dem_v3_norm(out) / dem_v3_norm(spring), 1.0, ROUNDOFF, "length kept by a twist");
    }
    const int steps = 1000;
    const double total = DEM_PI / 2, th = total / steps;
    dem_vec3 s = spring;
    for (int k = 0; k < steps; ++k) s = dem_spring_carry(s, n, th);
    dem_vec3 want = rotate(spring, n, total);
    double err = dem_v3_norm(dem_v3_sub(s, want)) / dem_v3_norm(spring);
    printf("quarter turn in %d twists: error %.3g (bound %.3g)\n", steps, err, steps * th * th * th / 3);
    assert_true(err <= steps * th * th * th / 3 * 1.01 + 1e-12);
    assert_true(fabs(dem_v3_dot(s, n)) <= 1e-12 * dem_v3_norm(spring));
}

// A zero spring stays exactly zero under any carry; a spring that ends up
// along the new normal has no tangential part and becomes zero, not NaN.
static void test_spring_carry_degenerate(void **state)
{
    (void)state;
    dem_vec3 zero = dem_v3(0, 0, 0);
    dem_vec3 out = dem_spring_carry(zero, unit(dem_v3(0.2, 1, -0.3)), 0.7);
    assert_true(out.x == 0.0 && out.y == 0.0 && out.z == 0.0);
    dem_vec3 n = dem_v3(0, 0, 1);
    out = dem_spring_carry(dem_v3(0, 0, 1e-6), n, 0.0);
    assert_true(dem_v3_isfinite(out));
    assert_true(out.x == 0.0 && out.y == 0.0 && out.z == 0.0);
}

static void test_damping_names(void **state)
{
    (void)state;
    assert_int_equal(dem_damping_mode_from_name("approaching"), DEM_DAMPING_APPROACHING);
    assert_int_equal(dem_damping_mode_from_name("always"), DEM_DAMPING_ALWAYS);
    assert_int_equal(dem_damping_mode_from_name("separating"), DEM_DAMPING_SEPARATING);
    assert_int_equal(dem_damping_mode_from_name("no_tension"), DEM_DAMPING_NO_TENSION);
    assert_int_equal(dem_damping_mode_from_name("approach"), -1);
    assert_int_equal(dem_damping_mode_from_name("Always"), -1);
    assert_int_equal(dem_damping_mode_from_name(""), -1);
    assert_int_equal(dem_damping_mode_from_name(NULL), -1);
    for (int m = 0; m < DEM_DAMPING_MODE_COUNT; ++m)
        assert_int_equal(dem_damping_mode_from_name(dem_damping_mode_name((dem_damping_mode)m)), m);
}

static void expect_rejected(dem_contact_params p, const char *field)
{
    char msg[256] = "";
    int rc = dem_contact_params_check(&p, msg, sizeof msg);
    printf("rejected (%s): %s\n", field, msg);
    assert_int_not_equal(rc, 0);
    assert_non_null(strstr(msg, field));
}

static void test_params_check(void **state)
{
    (void)state;
    char msg[256] = "";
    dem_contact_params ok = base_params();
    assert_int_equal(dem_contact_params_check(&ok, msg, sizeof msg), 0);
    ok.mu_s = ok.mu_r = 0.0; // frictionless is valid
    ok.xi = 0.0;
    assert_int_equal(dem_contact_params_check(&ok, msg, sizeof msg), 0);

    dem_contact_params p = base_params();
    p.mu_s = -0.1;
    expect_rejected(p, "mu_s");
    p = base_params();
    p.mu_r = -1e-9;
    expect_rejected(p, "mu_r");
    p = base_params();
    p.k_n = NAN;
    expect_rejected(p, "k_n");
    p = base_params();
    p.k_s = NAN;
    expect_rejected(p, "k_s");
    p = base_params();
    p.k_n = 0.0;
    expect_rejected(p, "k_n");
    p = base_params();
    p.xi = 1.0;
    expect_rejected(p, "xi");
    p = base_params();
    p.xi = 1.5;
    expect_rejected(p, "xi");
    p = base_params();
    p.damping = (dem_damping_mode)7;
    expect_rejected(p, "damping");
}

// A friction coefficient of zero switches its spring off (it could never
// carry force); ξ = 0 switches the dashpot off.
static void test_features_from_params(void **state)
{
    (void)state;
    dem_contact_params p = base_params();
    assert_int_equal(dem_contact_features(&p), DEM_FEAT_DAMPING | DEM_FEAT_TANGENTIAL | DEM_FEAT_ROLLING);
    p.mu_r = 0;
    assert_int_equal(dem_contact_features(&p), DEM_FEAT_DAMPING | DEM_FEAT_TANGENTIAL);
    p.mu_s = 0;
    p.xi = 0;
    assert_int_equal(dem_contact_features(&p), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_normal_force_undamped),   cmocka_unit_test(test_damping_readings),
        cmocka_unit_test(test_tangential_spring_sticks), cmocka_unit_test(test_coulomb_truncation),
        cmocka_unit_test(test_history_layout),          cmocka_unit_test(test_spring_carry_new_normal),
        cmocka_unit_test(test_spring_carry_twist),      cmocka_unit_test(test_spring_carry_degenerate),
        cmocka_unit_test(test_damping_names),           cmocka_unit_test(test_params_check),
        cmocka_unit_test(test_features_from_params),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
