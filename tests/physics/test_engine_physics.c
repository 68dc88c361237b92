// SPDX-License-Identifier: MIT
// Whole-engine physics verification (dem_world_*), each test against an
// independent result derived in its comment:
//   1. binary collision: restitution and contact duration, four readings of eq. 4
//   2. undamped contacts conserve energy over 10^6 steps
//   3. sphere on an inclined plane: stick / roll / slide thresholds and accelerations
//   4. sphere launched on a flat plane: slip → roll → (rolling resistance) stop
//   5. objectivity of the history springs under rigid rotation of a pair;
//      the literal eq. 7 lever arm drifts by h·θ
//   6. Newton's third law: momentum (and angular momentum) of an isolated cluster
//   7. determinism: repeat runs and 1 vs 2 threads are bitwise identical
//   8. a pair within the skin but apart exerts nothing: free flight, exactly,
//      under each integration of the dashpots and springs
//   9. a pair across the periodic boundary pushes as the same pair inside,
//      also with a granule placed periods away (before its first drift)
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dem_world.h"

static const double G = 9.81;
static const double RHO = 1800.0; // granule density, kg/m³ (paper)

// ---------------------------------------------------------------- helpers ---

// Second pass of main(): every world with implicit springs forced on, at the
// tests' own steps (the default one being then the implicit springs' larger
// step): the condition that collisions, incline and rolling still pass.
static int force_implicit_springs;

static dem_world *world_new(const dem_world_def *def_in)
{
    char err[512] = "";
    dem_world_def def_copy = *def_in;
    if (force_implicit_springs) def_copy.implicit_springs = 1;
    const dem_world_def *def = &def_copy;
    dem_world *w = dem_world_create(def, err, sizeof err);
    if (!w) fail_msg("dem_world_create: %s", err);
    return w;
}

static void step_ok(dem_world *w, uint64_t n)
{
    dem_status st = dem_world_step(w, n);
    if (st != DEM_OK) fail_msg("dem_world_step: status %d: %s", (int)st, dem_world_error(w));
}

static void add_ok(dem_world *w, dem_vec3 p, dem_vec3 v, dem_vec3 o, double r, double rho)
{
    if (dem_world_add_granule(w, p, v, o, r, rho) < 0) fail_msg("add_granule: %s", dem_world_error(w));
}

static int wall_ok(dem_world *w, const dem_wall_def *d)
{
    int k = dem_world_add_wall(w, d);
    if (k < 0) fail_msg("add_wall: %s", dem_world_error(w));
    return k;
}

static uint64_t lcg_state;
static double urand(void) // uniform [0, 1), a fixed sequence
{
    lcg_state = lcg_state * 6364136223846793005ull + 1442695040888963407ull;
    return (double)(lcg_state >> 11) / 9007199254740992.0;
}

static double sphere_mass(double r) { return RHO * 4.0 / 3.0 * DEM_PI * r * r * r; }
static dem_vec3 unit(dem_vec3 v) { return dem_v3_scale(v, 1.0 / dem_v3_norm(v)); }

// Rotation of v about the unit axis a by θ (Rodrigues).
static dem_vec3 rotate(dem_vec3 v, dem_vec3 a, double th)
{
    dem_vec3 r = dem_v3_scale(v, cos(th));
    r = dem_v3_axpy(sin(th), dem_v3_cross(a, v), r);
    return dem_v3_axpy((1 - cos(th)) * dem_v3_dot(a, v), a, r);
}

static void assert_rel(double got, double want, double tol, const char *what)
{
    double err = fabs(got - want) / fabs(want);
    printf("    %-48s measured %.6g, expected %.6g, relative error %.2e (tolerance %.0e)\n", what, got, want, err,
           tol);
    if (!(err <= tol)) fail_msg("%s: measured %.9g, expected %.9g, relative error %.3g > %.3g", what, got, want,
                                err, tol);
}

// Least-squares slope of y(t).
static double slope(const double *t, const double *y, size_t n)
{
    double st = 0, sy = 0;
    for (size_t k = 0; k < n; ++k) st += t[k], sy += y[k];
    double mt = st / n, my = sy / n, num = 0, den = 0;
    for (size_t k = 0; k < n; ++k) num += (t[k] - mt) * (y[k] - my), den += (t[k] - mt) * (t[k] - mt);
    return num / den;
}

// A plane wall with the given contact law.
static dem_wall_def plane(dem_vec3 point, dem_vec3 normal, dem_contact_params c)
{
    dem_wall_def d;
    memset(&d, 0, sizeof d);
    d.kind = DEM_WALL_PLANE;
    d.point = point;
    d.normal = normal;
    d.axis = dem_v3(0, 0, 1);
    d.contact = c;
    d.name = "plane";
    return d;
}

// --------------------------------------------- 1. binary head-on collision ---
//
// Two equal granules, relative approach speed v0, no gravity, no friction.
// The overlap x obeys m* ẍ = −k x − on·γ ẋ with γ = 2ξ sqrt(m* k), m* = m/2.
// ω0 = sqrt(k/m*), ζ = ξ, β = sqrt(1 − ζ²), ω_d = β ω0, φ1 = atan2(β, ζ).
//
// Always damped: x = (v0/ω_d) e^{−ζω0 t} sin ω_d t ends at ω_d t = π:
//   t_c = π/ω_d,  e = exp(−ζπ/β) = 0.046.
// Approaching only: the damped half above until ẋ = 0, i.e. tan ω_d t1 = β/ζ,
// ω_d t1 = φ1, where x_max = (v0/ω_d) e^{−ζω0 t1} sin φ1 = (v0/ω0) e^{−ζφ1/β};
// then an undamped quarter period leaves at ω0 x_max:
//   t_c = φ1/ω_d + π/(2ω0),  e = exp(−ζφ1/β) = 0.459.
// Separating only: undamped quarter period to x_max = v0/ω0, then the damped
// release from rest x = x_max e^{−ζω0 t}(cos ω_d t + (ζ/β) sin ω_d t) reaches 0
// at ω_d t2 = π − φ1 with speed x_max ω0 e^{−ζω0 t2}:
//   t_c = π/(2ω0) + (π − φ1)/ω_d,  e = exp(−ζ(π − φ1)/β) = 0.100.
// No tension: damped both ways until the force k x + γ ẋ reaches 0 (x > 0):
// ω0² x + 2ζω0 ẋ = 0 gives tan ω_d t* = −2ζβ/(1 − 2ζ²), ω_d t* = φ* =
// atan2(2ζβ, 2ζ² − 1). There ẋ = v0 e^{−ζφ*/β}(cos φ* − (ζ/β) sin φ*) = −v0 e^{−ζφ*/β}
// (the bracket is exactly −1), and x = (v0/ω_d) e^{−ζφ*/β} sin φ* = 2ζ e v0/ω0.
// Afterwards the clamped force stays 0 (x falls, ẋ < 0), so the granules coast
// out of the overlap in x/|ẋ| = 2ζ/ω0:
//   t_c = φ*/ω_d + 2ζ/ω0,  e = exp(−ζφ*/β) = 0.210.
typedef struct collision_expect {
    double e, tc;
} collision_expect;

static collision_expect collision_analytic(dem_damping_mode mode, double xi, double w0)
{
    const double b = sqrt(1 - xi * xi), wd = b * w0, phi1 = atan2(b, xi);
    const double phis = atan2(2 * xi * b, 2 * xi * xi - 1);
    switch (mode) {
    case DEM_DAMPING_ALWAYS: return (collision_expect){exp(-xi * DEM_PI / b), DEM_PI / wd};
    case DEM_DAMPING_APPROACHING:
        return (collision_expect){exp(-xi * phi1 / b), phi1 / wd + 0.5 * DEM_PI / w0};
    case DEM_DAMPING_SEPARATING:
        return (collision_expect){exp(-xi * (DEM_PI - phi1) / b), 0.5 * DEM_PI / w0 + (DEM_PI - phi1) / wd};
    case DEM_DAMPING_NO_TENSION: return (collision_expect){exp(-xi * phis / b), phis / wd + 2 * xi / w0};
    default: return (collision_expect){NAN, NAN};
    }
}

static void test_binary_collision(void **state)
{
    (void)state;
    const double xi = 0.7, R = 1e-4, k = 200.0, v = 0.01; // each granule at v, v0 = 2v
    const double m = sphere_mass(R), w0 = sqrt(k / (0.5 * m));
    const dem_damping_mode modes[4] = {DEM_DAMPING_ALWAYS, DEM_DAMPING_SEPARATING, DEM_DAMPING_NO_TENSION,
                                       DEM_DAMPING_APPROACHING};
    const double quoted[4] = {0.046, 0.100, 0.210, 0.459}; // DESIGN.md
    for (int c = 0; c < 4; ++c) {
        collision_expect ex = collision_analytic(modes[c], xi, w0);
        assert_true(fabs(ex.e - quoted[c]) < 5e-4); // the derivation gives the quoted values
        dem_world_def def = dem_default_world_def();
        def.gravity = dem_v3(0, 0, 0);
        def.granule = (dem_contact_params){.k_n = k, .k_s = k, .k_r = k, .xi = xi, .mu_s = 0, .mu_r = 0,
                                           .damping = modes[c]};
        def.dt = ex.tc / 2000;
        dem_world *w = world_new(&def);
        const double gap = 2e-3 * R;
        add_ok(w, dem_v3(-R - gap / 2, 0.01, 0.02), dem_v3(v, 0, 0), dem_v3(0, 0, 0), R, RHO);
        add_ok(w, dem_v3(R + gap / 2, 0.01, 0.02), dem_v3(-v, 0, 0), dem_v3(0, 0, 0), R, RHO);
        const double dt = def.dt;
        double t_in = -1, t_out = -1, h_prev = -gap, t_prev = 0;
        for (int s = 0; s < 20000 && t_out < 0; ++s) {
            step_ok(w, 1);
            dem_granules_view g = dem_world_granules(w);
            double h = 2 * R - dem_v3_norm(dem_v3_sub(g.position[1], g.position[0]));
            double t = dem_world_time(w);
            // Crossings of h = 0, interpolated linearly within the step.
            if (t_in < 0 && h > 0) t_in = t_prev + dt * (-h_prev) / (h - h_prev);
            else if (t_in >= 0 && h <= 0) t_out = t_prev + dt * h_prev / (h_prev - h);
            h_prev = h, t_prev = t;
        }
        assert_true(t_in >= 0 && t_out > t_in);
        step_ok(w, 10); // free flight: velocities are final
        dem_granules_view g = dem_world_granules(w);
        double e = (g.velocity[1].x - g.velocity[0].x) / (2 * v);
        printf("  reading %-11s (dt = t_c/2000 = %.3g s):\n", dem_damping_mode_name(modes[c]), dt);
        assert_rel(e, ex.e, 1e-2, "restitution coefficient");
        assert_rel(t_out - t_in, ex.tc, 1e-2, "contact duration, s");
        dem_world_destroy(w);
    }
}

// -------------------------------------------- 2. energy without damping ---
//
// ξ = 0 and no friction: the only forces are gravity and the linear normal
// springs, all conservative, so E = Σ ½mv² + ½Iω² + m g y + Σ_contacts ½k h² is
// a constant of the motion. Velocity Verlet is symplectic: while the contact
// set does not change, its energy error is a bounded oscillation of relative
// size ~(ω Δt)², never a drift. Bound: the mean of E over the last 10% of
// 10^6 steps at the engine's default step differs from the mean over the
// first 10% by less than 1e-3 of the mechanical energy in play, E − E_static
// (the energy above the resting configuration; E itself is dominated by the
// constant m g y, against which any drift would be invisible).
//
// Why persistent contacts: where contacts open and close (a bouncing
// granule), the force has a kink inside a step and velocity Verlet loses its
// conserved shadow energy; each impact then changes E by a random amount that
// shrinks like Δt². At the default step (about 7.6 steps per wall contact at
// ξ = 0) that is ~2% rms per impact, the same in an independent 1-D velocity
// Verlet, so a bouncing granule's energy random-walks by ~20% over 10^6
// steps: an accuracy property of the integrator at that step, not a drift,
// and not testable against a 1e-3 bound.
static double energy_independent(const dem_world *w, double k_pair)
{
    dem_granules_view g = dem_world_granules(w);
    double e = 0;
    for (size_t i = 0; i < g.count; ++i) {
        e += 0.5 * g.mass[i] * dem_v3_norm2(g.velocity[i]) + 0.5 * g.inertia[i] * dem_v3_norm2(g.omega[i]);
        e += g.mass[i] * G * g.position[i].y; // gravity −y
        for (size_t j = i + 1; j < g.count; ++j) {
            double h = g.radius[i] + g.radius[j] - dem_v3_norm(dem_v3_sub(g.position[j], g.position[i]));
            if (h > 0) e += 0.5 * k_pair * h * h;
        }
    }
    return e;
}

// Elastic energy of the wall contacts, from the walls' definitions (planes:
// h = R − distance; cylinders, granules inside: h = R + ρ − radius).
static double wall_energy(const dem_world *w, const dem_wall_def *walls, int n_walls)
{
    dem_granules_view g = dem_world_granules(w);
    double e = 0;
    for (int k = 0; k < n_walls; ++k)
        for (size_t i = 0; i < g.count; ++i) {
            dem_vec3 d = dem_v3_sub(g.position[i], walls[k].point);
            double h = walls[k].kind == DEM_WALL_CYLINDER
                           ? g.radius[i] + dem_v3_norm(dem_v3_axpy(-dem_v3_dot(d, walls[k].axis), walls[k].axis, d)) -
                                 walls[k].radius
                           : g.radius[i] - dem_v3_dot(d, walls[k].normal);
            if (h > 0) e += 0.5 * walls[k].contact.k_n * h * h;
        }
    return e;
}

// Run 10^6 steps, sampling every 100; returns the relative drift.
static void energy_check(dem_world *w, const char *what, double k_pair, const dem_wall_def *walls, int n_walls,
                         double e_static)
{
    enum { STEPS = 1000000, EVERY = 100, SAMPLES = STEPS / EVERY };
    double *e = malloc(SAMPLES * sizeof *e);
    assert_non_null(e);
    dem_diagnostics d0 = dem_world_diagnose(w);
    double emin = INFINITY, emax = -INFINITY, worst_diag = 0;
    int contacts_changed = 0;
    for (int s = 0; s < SAMPLES; ++s) {
        step_ok(w, EVERY);
        e[s] = energy_independent(w, k_pair) + wall_energy(w, walls, n_walls);
        dem_diagnostics d = dem_world_diagnose(w);
        dem_granules_view g = dem_world_granules(w);
        double pot_g = 0;
        for (size_t i = 0; i < g.count; ++i) pot_g += g.mass[i] * G * g.position[i].y;
        double ed = d.ke_translational + d.ke_rotational + d.potential_elastic + pot_g;
        worst_diag = fmax(worst_diag, fabs(ed - e[s]) / (e[s] - e_static));
        contacts_changed |= d.contacts != d0.contacts || d.wall_contacts != d0.wall_contacts;
        emin = fmin(emin, e[s]), emax = fmax(emax, e[s]);
    }
    double first = 0, last = 0;
    for (int s = 0; s < SAMPLES / 10; ++s) first += e[s], last += e[SAMPLES - 1 - s];
    first /= SAMPLES / 10, last /= SAMPLES / 10;
    const double e_osc = first - e_static;
    const double drift = fabs(last - first) / e_osc;
    printf("  %s: dt = %.4g s (%s), %.4g s simulated, %zu granule and %zu wall contacts throughout\n", what,
           dem_world_dt(w), dem_world_dt_report(w), dem_world_time(w), d0.contacts, d0.wall_contacts);
    printf("    E - E_static: first-10%% mean %.6e J, last-10%% mean %.6e J (E = %.6e J): drift %.2e of E - E_static "
           "(bound 1e-3), %.1e of E; oscillation (max-min)/(E - E_static) %.2e; dem_world_diagnose vs the sum "
           "here %.1e\n",
           e_osc, last - e_static, first, drift, fabs(last - first) / first, (emax - emin) / e_osc, worst_diag);
    assert_false(contacts_changed);   // the premise: no contact opened or closed
    assert_true(e_osc > 0);
    assert_true(drift < 1e-3);
    assert_true(worst_diag < 1e-6);   // dem_world_diagnose agrees with the energy written here
    free(e);
}

static dem_contact_params frictionless(double k, double xi)
{
    return (dem_contact_params){.k_n = k, .k_s = k, .k_r = k, .xi = xi, .mu_s = 0, .mu_r = 0,
                                .damping = DEM_DAMPING_APPROACHING};
}

// One granule on the floor, released from rest at 1.9× its static overlap
// h_s = m g/k_w: it oscillates between 1.9 h_s and 0.1 h_s, never leaving.
// E_static = m g (R − h_s) + ½ k_w h_s², E − E_static = ½ k_w (0.9 h_s)².
static void test_energy_conserved_granule_on_wall(void **state)
{
    (void)state;
    const double R = 1e-4, k = 200.0, kw = 400.0, m = sphere_mass(R), hs = m * G / kw;
    dem_world_def def = dem_default_world_def();
    def.granule = frictionless(k, 0);
    def.dt = 0; // the engine's own step
    def.threads = 1;
    dem_world *w = world_new(&def);
    dem_wall_def floor = plane(dem_v3(0, 0, 0), dem_v3(0, 1, 0), frictionless(kw, 0));
    wall_ok(w, &floor);
    add_ok(w, dem_v3(0.001, R - 1.9 * hs, -0.002), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    const double e_static = m * G * (R - hs) + 0.5 * kw * hs * hs;
    printf("    analytic E - E_static = 1/2 k_w (0.9 h_s)^2 = %.6e J\n", 0.5 * kw * 0.81 * hs * hs);
    energy_check(w, "granule oscillating on a plane", k, &floor, 1, e_static);
    dem_world_destroy(w);
}

// A 3-D cluster with persistent contacts: three granules on the floor inside
// a vertical cylinder wall, a fourth on top under a lid, every contact
// preloaded by ~1e-3 R (13 contacts with changing normals). It is settled with
// ξ = 0.7, frozen (E_static), switched to ξ = 0 and given random velocities
// small enough that no contact opens. (Three flat side walls instead of the
// cylinder would not do: the preloaded triangle is then unstable to turning
// about the vertical, and squeezes out.)
static void test_energy_conserved_cluster(void **state)
{
    (void)state;
    const double R = 1e-4, k = 200.0, kw = 400.0, pre = 1e-3 * R;
    dem_world_def def = dem_default_world_def();
    def.granule = frictionless(k, 0.7);
    def.dt = 0;
    def.threads = 1;
    dem_world *w = world_new(&def);
    const double rho = 2 * R / sqrt(3.0), ytop = R + R * sqrt(8.0 / 3.0);
    dem_wall_def walls[3];
    int nw = 0;
    walls[nw++] = plane(dem_v3(0, 0, 0), dem_v3(0, 1, 0), frictionless(kw, 0.7));
    walls[nw++] = plane(dem_v3(0, ytop + R - pre, 0), dem_v3(0, -1, 0), frictionless(kw, 0.7));
    walls[nw] = plane(dem_v3(0, 0, 0), dem_v3(0, 0, 0), frictionless(kw, 0.7));
    walls[nw].kind = DEM_WALL_CYLINDER;
    walls[nw].axis = dem_v3(0, 1, 0);
    walls[nw++].radius = rho + R - pre;
    for (int b = 0; b < 3; ++b) {
        double a = DEM_PI / 2 + 2 * DEM_PI * b / 3;
        add_ok(w, dem_v3(rho * cos(a), R, rho * sin(a)), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO);
    }
    add_ok(w, dem_v3(0, ytop, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO);
    for (int k2 = 0; k2 < nw; ++k2) wall_ok(w, &walls[k2]);
    step_ok(w, 20000); // settle
    dem_world_freeze(w);
    assert_int_equal(dem_world_set_granule_contact(w, &(dem_contact_params){.k_n = k, .k_s = k, .k_r = k}), 0);
    for (int k2 = 0; k2 < nw; ++k2) {
        walls[k2].contact.xi = 0;
        assert_int_equal(dem_world_set_wall_contact(w, k2, &walls[k2].contact), 0);
    }
    dem_diagnostics d = dem_world_diagnose(w);
    printf("    settled: %zu granule + %zu wall contacts, largest overlap %.3g R\n", d.contacts, d.wall_contacts,
           d.max_overlap_ratio);
    assert_int_equal(d.contacts + d.wall_contacts, 13);
    const double e_static = energy_independent(w, k) + wall_energy(w, walls, nw);
    lcg_state = 99;
    for (size_t i = 0; i < 4; ++i) {
        dem_vec3 v = dem_v3(urand() - 0.5, urand() - 0.5, urand() - 0.5);
        dem_world_set_granule_velocity(w, i, dem_v3_scale(v, 1e-3), dem_v3(0, 0, 0));
    }
    energy_check(w, "4-granule cluster in a cylinder under a lid", k, walls, nw, e_static);
    dem_world_destroy(w);
}

// ------------------------------------------------- 3. inclined plane ---
//
// Sphere (m, R, I = 2/5 mR²) on a plane whose normal is tilted by θ from +y;
// gravity −y; downslope unit s. Normal load F_n = m g cos θ; the tangential
// force acts at the lever a = R − h (contact point, h = F_n/k_n ≈ 2e-6 R, kept
// in the formulas), the rolling quasi-force at R* = R (a wall has infinite
// radius). With friction F (up the slope) and rolling torque T_r:
//   m v̇ = m g sin θ − F,   I ω̇ = F a − T_r,   rolling without slip: v = ω a.
// μ_r = 0 (T_r = 0): F = (I/a²) v̇, v̇ = g sin θ/(1 + I/(m a²)) ≈ 5/7 g sin θ, which
//   needs F = (2/7) m g sin θ ≤ μ_s m g cos θ, i.e. tan θ ≤ 7/2 μ_s; above it the
//   sphere slides: v̇ = g (sin θ − μ_s cos θ).
// μ_r > 0: at rest F = m g sin θ and the torque balance F a = T_r needs
//   T_r = m g sin θ a ≤ μ_r F_n R*, i.e. tan θ ≤ μ_r R*/a ≈ μ_r: it sticks. Above,
//   the rolling spring saturates, T_r = μ_r m g cos θ R*, and rolling gives
//   v̇ = g (sin θ − μ_r cos θ R*/a)/(1 + I/(m a²)) ≈ 5/7 g (sin θ − μ_r cos θ).
// With μ_r > μ_s (the rolling spring holds the spin) the sphere sticks up to
//   tan θ = μ_s and slides without turning above: v̇ = g (sin θ − μ_s cos θ).
// Measured: the least-squares slope of v·s over a window after the contact
// transients (the undamped tangential/rolling spring vibration averages out),
// and the contact-point slip speed at the end.
typedef struct incline_result {
    double accel, disp, slip, speed;
} incline_result;

static incline_result run_incline(double theta, double mu_s, double mu_r, double *expect_a)
{
    const double R = 1e-4, kw = 400.0, m = sphere_mass(R), I = 0.4 * m * R * R;
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, -G, 0);
    def.threads = 1;
    dem_world *w = world_new(&def);
    const dem_vec3 n = dem_v3(sin(theta), cos(theta), 0), s = dem_v3(cos(theta), -sin(theta), 0);
    dem_contact_params wc = {.k_n = kw, .k_s = kw, .k_r = kw, .xi = 0.7, .mu_s = mu_s, .mu_r = mu_r,
                             .damping = DEM_DAMPING_APPROACHING};
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = n, .axis = {0, 0, 1},
                               .contact = wc});
    const double h = m * G * cos(theta) / kw, a = R - h;
    add_ok(w, dem_v3_scale(n, R - h), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO); // at the static overlap
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    const double dt = dem_world_dt(w);
    const double t_settle = 0.004, t_window = 0.02;
    step_ok(w, (uint64_t)(t_settle / dt));
    enum { SAMPLES = 400 };
    double ts[SAMPLES], vs[SAMPLES];
    const uint64_t every = (uint64_t)(t_window / dt / SAMPLES);
    dem_vec3 p0 = dem_world_granules(w).position[0];
    for (int k = 0; k < SAMPLES; ++k) {
        step_ok(w, every);
        dem_granules_view g = dem_world_granules(w);
        ts[k] = dem_world_time(w);
        vs[k] = dem_v3_dot(g.velocity[0], s);
    }
    dem_granules_view g = dem_world_granules(w);
    incline_result r;
    r.accel = slope(ts, vs, SAMPLES);
    r.disp = dem_v3_norm(dem_v3_sub(g.position[0], p0));
    r.speed = dem_v3_norm(g.velocity[0]);
    // Velocity of the sphere's contact point: v + ω × (−a n).
    r.slip = dem_v3_norm(dem_v3_add(g.velocity[0], dem_v3_cross(g.omega[0], dem_v3_scale(n, -a))));
    const double roll = 1 + I / (m * a * a);
    const double st = sin(theta), ct = cos(theta);
    if (mu_r == 0) *expect_a = tan(theta) <= 3.5 * mu_s ? G * st / roll : G * (st - mu_s * ct);
    else if (mu_r > mu_s) *expect_a = tan(theta) <= mu_s ? 0 : G * (st - mu_s * ct);
    else *expect_a = tan(theta) <= mu_r * R / a ? 0 : G * (st - mu_r * ct * R / a) / roll;
    dem_world_destroy(w);
    return r;
}

static void test_incline_roll_slide(void **state)
{
    (void)state;
    const double mu_s = 0.3, tc = 3.5 * mu_s; // threshold tan θ = 7/2 μ_s
    const double tans[2] = {0.9 * tc, 1.1 * tc};
    for (int c = 0; c < 2; ++c) {
        double th = atan(tans[c]), want;
        incline_result r = run_incline(th, mu_s, 0.0, &want);
        printf("  mu_s = %.2f, mu_r = 0, tan(theta) = %.4f = %.1f x 7/2 mu_s: %s; slip %.3g m/s of speed %.3g m/s\n",
               mu_s, tans[c], tans[c] / tc, c == 0 ? "expect rolling" : "expect sliding", r.slip, r.speed);
        assert_rel(r.accel, want, 1e-2, c == 0 ? "rolling acceleration (5/7 g sin)" : "sliding acceleration");
        if (c == 0) {
            assert_true(r.slip < 1e-3 * r.speed); // rolls without slipping
        } else {
            // Slides: from rest, v = v̇ t and ω a = (μ_s g cos θ m a²/I) t, so the
            // contact point slips at the fraction 1 − μ_s g cos θ (5/2)/v̇ of v.
            double frac = 1 - mu_s * G * cos(th) * 2.5 / want;
            assert_rel(r.slip / r.speed, frac, 2e-2, "slip speed / speed while sliding");
        }
    }
}

static void test_incline_rolling_resistance(void **state)
{
    (void)state;
    const double mu_s = 0.8, mu_r = 0.2; // threshold tan θ = μ_r
    const double tans[2] = {0.9 * mu_r, 1.1 * mu_r};
    for (int c = 0; c < 2; ++c) {
        double th = atan(tans[c]), want;
        incline_result r = run_incline(th, mu_s, mu_r, &want);
        printf("  mu_s = %.2f, mu_r = %.2f, tan(theta) = %.4f = %.1f x mu_r: %s; displacement over 0.02 s %.3g m, "
               "slip %.3g m/s, speed %.3g m/s, acceleration %.4g m/s2\n",
               mu_s, mu_r, tans[c], tans[c] / mu_r, c == 0 ? "expect rest" : "expect rolling", r.disp, r.slip,
               r.speed, r.accel);
        if (c == 0) {
            // At rest: no more than the elastic creep of the springs (~1e-10 m)
            // against ~1e-5 m rolled just above the threshold.
            assert_true(r.disp < 1e-9);
            assert_true(fabs(r.accel) < 1e-4);
        } else {
            assert_rel(r.accel, want, 1e-2, "rolling acceleration 5/7 g (sin - mu_r cos)");
            assert_true(r.slip < 1e-2 * r.speed);
        }
    }
    // μ_r > μ_s: the rolling spring holds the spin; stick then slide at tan θ = μ_s.
    const double mu_s2 = 0.3, mu_r2 = 1.0;
    for (int c = 0; c < 2; ++c) {
        double tn = (c == 0 ? 0.9 : 1.1) * mu_s2, th = atan(tn), want;
        incline_result r = run_incline(th, mu_s2, mu_r2, &want);
        printf("  mu_s = %.2f, mu_r = %.2f, tan(theta) = %.3f = %.1f x mu_s: %s; displacement %.3g m, slip %.3g m/s, "
               "speed %.3g m/s\n",
               mu_s2, mu_r2, tn, tn / mu_s2, c == 0 ? "expect rest" : "expect sliding", r.disp, r.slip, r.speed);
        if (c == 0) {
            assert_true(r.disp < 1e-9);
        } else {
            assert_rel(r.accel, want, 1e-2, "sliding acceleration g (sin - mu_s cos)");
            assert_true(r.slip > 0.9 * r.speed);
        }
    }
}

// -------------------------------------- 4. launched on a flat plane ---
//
// Sphere on the floor (normal +y), launched at v0 along +x without spin.
// F_n = m g; levers a = R − h (tangential), R* = R (rolling).
// Sliding: kinetic friction μ_s m g backwards, v = v0 − μ_s g t; the spin grows
//   by I ω̇ = μ_s m g a − μ_r m g R (the rolling spring saturates at once), so the
//   contact point slips at u = v − ω a = v0 − g t [μ_s + m a (μ_s a − μ_r R)/I].
//   u = 0 at t_roll = v0 / (g [μ_s + m a (μ_s a − μ_r R)/I]), with a = R:
//   t_roll = v0/(g (7/2 μ_s − 5/2 μ_r)), = 2 v0/(7 μ_s g) for μ_r = 0, and then
//   v_roll = v0 − μ_s g t_roll (= 5/7 v0 for μ_r = 0).
// Rolling with the rolling quasi-force saturated at μ_r m g:
//   m v̇ = −F,  I ω̇ = F a − μ_r m g R,  v = ω a  ⇒  v̇ = −μ_r g (R/a)/(1 + I/(m a²))
//   ≈ −5/7 μ_r g (friction F = −m v̇ = 5/7 μ_r m g < μ_s m g: no slip), and it stops at
//   t_stop = t_roll + v_roll/|v̇|.
// Measured: t_roll where the slip speed first reaches zero, t_stop where v
// first reaches zero (both interpolated within a step), the rolling speed
// (μ_r = 0, mean over a window) or deceleration (μ_r > 0, least squares).
static void run_launch(double mu_s, double mu_r)
{
    const double R = 1e-4, kw = 400.0, v0 = 0.05, m = sphere_mass(R), I = 0.4 * m * R * R;
    dem_world_def def = dem_default_world_def();
    def.threads = 1;
    dem_world *w = world_new(&def);
    dem_contact_params wc = {.k_n = kw, .k_s = kw, .k_r = kw, .xi = 0.7, .mu_s = mu_s, .mu_r = mu_r,
                             .damping = DEM_DAMPING_APPROACHING};
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .normal = {0, 1, 0}, .axis = {0, 0, 1}, .contact = wc});
    const double h = m * G / kw, a = R - h;
    add_ok(w, dem_v3(-0.002, R - h, 0), dem_v3(v0, 0, 0), dem_v3(0, 0, 0), R, RHO);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    const double dt = dem_world_dt(w);
    const double t_roll = v0 / (G * (mu_s + m * a * (mu_s * a - mu_r * R) / I));
    const double v_roll = v0 - mu_s * G * t_roll;
    const double decel = mu_r * G * (R / a) / (1 + I / (m * a * a));
    const double t_stop = mu_r > 0 ? t_roll + v_roll / decel : INFINITY;
    const double t_end = mu_r > 0 ? 1.1 * t_stop : 3 * t_roll;
    printf("  mu_s = %.2f, mu_r = %.2f, v0 = %.3g m/s, dt = %.3g s: analytic t_roll = %.6g s (2v0/(7 mu_s g) = "
           "%.6g s), v_roll = %.6g m/s (5/7 v0 = %.6g)\n",
           mu_s, mu_r, v0, dt, t_roll, 2 * v0 / (7 * mu_s * G), v_roll, 5.0 / 7 * v0);
    double u_prev = v0, v_prev = v0, t_prev = 0, t_roll_m = -1, t_stop_m = -1;
    size_t cap = (size_t)(t_end / dt) + 16, n_fit = 0;
    double *tf = malloc(cap * sizeof *tf), *vf = malloc(cap * sizeof *vf);
    assert_true(tf && vf);
    double v_sum = 0;
    size_t v_cnt = 0;
    while (dem_world_time(w) < t_end) {
        step_ok(w, 1);
        dem_granules_view g = dem_world_granules(w);
        double t = dem_world_time(w), v = g.velocity[0].x;
        // Contact point (at −a ŷ from the centre) moves at v + ω × (−a ŷ).
        double u = dem_v3_add(g.velocity[0], dem_v3_cross(g.omega[0], dem_v3(0, -a, 0))).x;
        if (t_roll_m < 0 && u <= 0) t_roll_m = t_prev + dt * u_prev / (u_prev - u);
        if (t_stop_m < 0 && v <= 0) t_stop_m = t_prev + dt * v_prev / (v_prev - v);
        // Rolling window: from 1.2 t_roll to 0.9 t_stop (or to the end).
        if (t_roll_m > 0 && t > 1.2 * t_roll_m && (mu_r == 0 || t < 0.9 * t_stop) && n_fit < cap) {
            tf[n_fit] = t, vf[n_fit++] = v;
            v_sum += v, v_cnt++;
        }
        u_prev = u, v_prev = v, t_prev = t;
    }
    dem_granules_view g = dem_world_granules(w);
    assert_true(t_roll_m > 0);
    assert_rel(t_roll_m, t_roll, 1e-2, "time to rolling t_roll, s");
    if (mu_r == 0) {
        assert_rel(v_sum / v_cnt, v_roll, 1e-2, "rolling speed 5/7 v0, m/s");
        assert_rel(g.velocity[0].x, v_roll, 1e-2, "speed at the end, m/s");
        assert_true(fabs(slope(tf, vf, n_fit)) < 1e-3 * v0 / t_roll); // rolls on at constant speed
    } else {
        assert_rel(-slope(tf, vf, n_fit), decel, 1e-2, "rolling deceleration 5/7 mu_r g, m/s2");
        assert_true(t_stop_m > 0);
        assert_rel(t_stop_m, t_stop, 1e-2, "time to stop, s");
        // Stays stopped (the rolling spring holds it; no creep back).
        printf("    speed %.3g s after stopping: %.3g m/s\n", dem_world_time(w) - t_stop_m, g.velocity[0].x);
        assert_true(fabs(g.velocity[0].x) < 1e-3 * v0);
    }
    free(tf);
    free(vf);
    dem_world_destroy(w);
}

static void test_launch_slip_roll(void **state)
{
    (void)state;
    run_launch(0.5, 0.0);
}

static void test_launch_slip_roll_stop(void **state)
{
    (void)state;
    run_launch(0.5, 0.1);
}

// ------------------------------------------------------ 5. objectivity ---
//
// Two equal overlapping granules, gravity off, friction coefficients high
// enough that both springs stick. The springs are loaded by a few steps of
// relative tangential velocity and relative spin, and are then read back from
// the forces and torques: F_s is the part of the force on i normal to n, and
// eq. 9–10 give τ_j − τ_i = 2R* n × F_r (equal radii: equal levers), so
// F_r = ((τ_j − τ_i)/(2R*)) × n.
// A rigid rotation of the pair must carry both springs with it unchanged:
// after a quarter turn Q, F_s → Q F_s and F_r → Q F_r.
//  • Ω along n: v = Ω × r = 0, ω_i = ω_j = Ω; this is a free motion (spring
//    torques are normal to n and cannot change ω·n), run at Ω ≫ the spring
//    frequencies so the springs' own vibration is negligible over the turn.
//  • Ω normal to n: repulsive contacts cannot supply the centripetal force, so
//    the pair is driven: before every step each granule gets the velocity that
//    carries it along the chord of the rotation by φ = Ω Δt about the pair's
//    centre, and spin Ω sin φ/φ, which makes the contact points' relative
//    tangential velocity zero with the contact-point lever a = R − h/2.
// Accuracy: the twist carry is exact to φ³/3 per step; the tangent-plane carry
// (project, rescale) turns the part of a spring in the rotation plane by
// cos φ relative to the part along Ω each step, a direction error up to
// θ φ/4 = 4e-4 for θ = π/2, φ = 1e-3. Tolerance: 2e-3 of |F|.
// With the lever R of eq. 7 as written, a rigidly rotating pair slides at h Ω
// at the contact: the spring gains h θ along the rotation (a documented
// property of DEM_LEVER_RADIUS).
// Driving through dem_world_set_granule_velocity makes the engine evaluate
// the forces once more at the same configuration before the step, and that
// evaluation currently advances the springs too (see
// test_set_velocity_keeps_history). With the contact-point lever and Ω normal
// to n it adds nothing (no twist, no relative tangential velocity); the spin-up
// about n adds one extra twist φ = 2.5e-4 (inside the tolerance); with lever R
// it adds a second h φ per step, so test_lever_radius_drift measures 2 h θ
// until the engine is fixed.
typedef struct pair_springs {
    dem_vec3 n, fs, fr;
    double h;
} pair_springs;

static pair_springs read_springs(const dem_world *w)
{
    dem_granules_view g = dem_world_granules(w);
    assert_int_equal(g.count, 2);
    assert_true(g.id[0] < g.id[1]);
    pair_springs p;
    dem_vec3 d = dem_v3_sub(g.position[1], g.position[0]);
    p.n = unit(d);
    p.h = g.radius[0] + g.radius[1] - dem_v3_norm(d);
    p.fs = dem_v3_axpy(-dem_v3_dot(g.force[0], p.n), p.n, g.force[0]);
    double rstar = g.radius[0] * g.radius[1] / (g.radius[0] + g.radius[1]);
    dem_vec3 nxfr = dem_v3_scale(dem_v3_sub(g.torque[1], g.torque[0]), 0.5 / rstar);
    p.fr = dem_v3_cross(nxfr, p.n);
    return p;
}

static const double OBJ_R = 1e-3, OBJ_K = 200.0, OBJ_DT = 1e-10;

// A loaded, sticking pair about n0 (a general direction).
static dem_world *loaded_pair(dem_lever_arm lever, dem_vec3 n0)
{
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, 0);
    def.granule = (dem_contact_params){.k_n = OBJ_K, .k_s = OBJ_K, .k_r = OBJ_K, .xi = 0, .mu_s = 10, .mu_r = 10};
    def.dt = OBJ_DT;
    def.lever_arm = lever;
    def.threads = 1;
    dem_world *w = world_new(&def);
    const double R = OBJ_R, h0 = 1e-3 * R, d = 2 * R - h0;
    const dem_vec3 c = dem_v3(0.1, 0.2, -0.1);
    // Tangent directions mixed, not aligned with any later rotation axis.
    dem_vec3 e1 = unit(dem_v3_cross(n0, dem_v3(0.3, 1, 0.5)));
    dem_vec3 e2 = unit(dem_v3_add(e1, dem_v3_scale(dem_v3_cross(n0, e1), 1.7)));
    // Load: 200 steps with relative tangential velocity 2u e1 and relative spin
    // 2w e2: δ_s = 2u·200Δt = 0.3 h0, |δ_r| = 2w R*·200Δt = 0.2 h0.
    const double tl = 200 * OBJ_DT, u = 0.3 * h0 / (2 * tl), wspin = 0.2 * h0 / (2 * 0.5 * R * tl);
    add_ok(w, dem_v3_axpy(-d / 2, n0, c), dem_v3_scale(e1, u), dem_v3_scale(e2, wspin), R, RHO);
    add_ok(w, dem_v3_axpy(d / 2, n0, c), dem_v3_scale(e1, -u), dem_v3_scale(e2, -wspin), R, RHO);
    step_ok(w, 200);
    return w;
}

static void report_springs(const char *what, pair_springs p, double k)
{
    printf("    %s: h = %.4g m, |F_s| = %.6g N (%.3f k h), |F_r| = %.6g N (%.3f k h)\n", what, p.h, dem_v3_norm(p.fs),
           dem_v3_norm(p.fs) / (k * p.h), dem_v3_norm(p.fr), dem_v3_norm(p.fr) / (k * p.h));
}

static double vec_rel_err(dem_vec3 got, dem_vec3 want)
{
    return dem_v3_norm(dem_v3_sub(got, want)) / dem_v3_norm(want);
}

// Drive a rigid rotation about `axis` (unit, normal to n) through the pair's
// centre for `steps` steps of angle φ each.
static void drive_rotation(dem_world *w, dem_vec3 axis, double phi, int steps)
{
    for (int s = 0; s < steps; ++s) {
        dem_granules_view g = dem_world_granules(w);
        dem_vec3 c = dem_v3_scale(dem_v3_add(g.position[0], g.position[1]), 0.5);
        for (size_t i = 0; i < 2; ++i) {
            dem_vec3 r = dem_v3_sub(g.position[i], c);
            dem_vec3 chord = dem_v3_sub(rotate(r, axis, phi), r);
            dem_world_set_granule_velocity(w, i, dem_v3_scale(chord, 1.0 / OBJ_DT),
                                           dem_v3_scale(axis, sin(phi) / OBJ_DT));
        }
        step_ok(w, 1);
    }
}

static void test_objectivity_rotation_about_normal(void **state)
{
    (void)state;
    const dem_vec3 n0 = unit(dem_v3(1, 2, -2));
    dem_world *w = loaded_pair(DEM_LEVER_CONTACT_POINT, n0);
    pair_springs p0 = read_springs(w);
    report_springs("loaded", p0, OBJ_K);
    // Ω along n, φ = Ω Δt = 2.5e-4 per step; a quarter turn in N steps.
    const double phi = 2.5e-4, omega = phi / OBJ_DT;
    const int steps = (int)lround(DEM_PI / 2 / phi);
    const double theta = steps * phi;
    for (size_t i = 0; i < 2; ++i) dem_world_set_granule_velocity(w, i, dem_v3(0, 0, 0), dem_v3_scale(p0.n, omega));
    step_ok(w, (uint64_t)steps);
    pair_springs p1 = read_springs(w);
    report_springs("after a quarter turn about n", p1, OBJ_K);
    double en = acos(fmin(1.0, dem_v3_dot(p0.n, p1.n)));
    double es = vec_rel_err(p1.fs, rotate(p0.fs, p0.n, theta));
    double er = vec_rel_err(p1.fr, rotate(p0.fr, p0.n, theta));
    printf("    turned %.6f rad about n in %d steps: normal moved %.2e rad; |F_s - Q F_s0|/|F_s0| = %.2e, "
           "|F_r - Q F_r0|/|F_r0| = %.2e (tolerance 2e-3)\n",
           theta, steps, en, es, er);
    // Unrotated, the springs would be off by sqrt(2) · |F|: the test can fail.
    assert_true(vec_rel_err(rotate(p0.fs, p0.n, theta), p0.fs) > 1.0);
    assert_true(es < 2e-3);
    assert_true(er < 2e-3);
    assert_rel(dem_v3_norm(p1.fs), dem_v3_norm(p0.fs), 2e-3, "|F_s| kept");
    assert_rel(dem_v3_norm(p1.fr), dem_v3_norm(p0.fr), 2e-3, "|F_r| kept");
    dem_world_destroy(w);
}

static void test_objectivity_rotation_normal_to_n(void **state)
{
    (void)state;
    const dem_vec3 n0 = unit(dem_v3(1, 2, -2));
    dem_world *w = loaded_pair(DEM_LEVER_CONTACT_POINT, n0);
    pair_springs p0 = read_springs(w);
    report_springs("loaded", p0, OBJ_K);
    // Axis in the tangent plane at 45° to F_s: half the spring lies in the
    // rotation plane, half along the axis (the worst case of the carry).
    const dem_vec3 fs_dir = unit(p0.fs);
    const dem_vec3 axis = unit(dem_v3_add(fs_dir, dem_v3_cross(p0.n, fs_dir)));
    const double phi = 1e-3;
    const int steps = (int)lround(DEM_PI / 2 / phi);
    drive_rotation(w, axis, phi, steps);
    pair_springs p1 = read_springs(w);
    report_springs("after a quarter turn about an axis normal to n", p1, OBJ_K);
    // The rotation actually made, from the positions.
    double theta = atan2(dem_v3_dot(dem_v3_cross(p0.n, p1.n), axis), dem_v3_dot(p0.n, p1.n));
    double es = vec_rel_err(p1.fs, rotate(p0.fs, axis, theta));
    double er = vec_rel_err(p1.fr, rotate(p0.fr, axis, theta));
    printf("    turned %.6f rad (%d steps of %.0e), overlap %.4g -> %.4g m; |F_s - Q F_s0|/|F_s0| = %.2e, "
           "|F_r - Q F_r0|/|F_r0| = %.2e (tolerance 2e-3)\n",
           theta, steps, phi, p0.h, p1.h, es, er);
    assert_true(fabs(theta - steps * phi) < 1e-6);
    assert_true(fabs(p1.h - p0.h) < 1e-3 * p0.h);
    assert_true(vec_rel_err(rotate(p0.fs, axis, theta), p0.fs) > 0.5); // a wrong carry would show
    assert_true(es < 2e-3);
    assert_true(er < 2e-3);
    dem_world_destroy(w);
}

// Eq. 7 as written (lever R): a pair turning rigidly by θ about an axis
// normal to n slides at the contact at (2R − d) Ω = h Ω, so the tangential
// spring gains h θ along the direction of motion (the rolling spring is
// unaffected: ω_i − ω_j = 0). Expected: |δ_s − Q δ_s0| = h θ within 5%, and
// the same run with the contact-point lever gains < 1% of that.
static double lever_drift(dem_lever_arm lever, double *h_out, double *theta_out)
{
    const dem_vec3 n0 = unit(dem_v3(1, 2, -2));
    dem_world *w = loaded_pair(lever, n0);
    pair_springs p0 = read_springs(w);
    const dem_vec3 axis = unit(dem_v3_cross(p0.n, dem_v3(0, 0, 1)));
    const double phi = 1e-3;
    const int steps = (int)lround(DEM_PI / 2 / phi);
    drive_rotation(w, axis, phi, steps);
    pair_springs p1 = read_springs(w);
    double theta = atan2(dem_v3_dot(dem_v3_cross(p0.n, p1.n), axis), dem_v3_dot(p0.n, p1.n));
    // Spring displacement δ = −F_s/k_s.
    dem_vec3 drift = dem_v3_scale(dem_v3_sub(p1.fs, rotate(p0.fs, axis, theta)), -1.0 / OBJ_K);
    // i's contact point slips relative to j's at (2R − d) Ω × n = h Ω × n
    // (eq. 7 with lever R), so the drift points along Ω × n.
    dem_vec3 t_dir = unit(dem_v3_cross(axis, p1.n));
    double along = dem_v3_dot(drift, t_dir) / fmax(dem_v3_norm(drift), 1e-300);
    printf("    lever %s: drift |delta_s - Q delta_s0| = %.4g m, h theta = %.4g m, ratio %.4f, cosine with "
           "Omega x n %.4f\n",
           lever == DEM_LEVER_RADIUS ? "R (eq. 7)" : "R - h/2", dem_v3_norm(drift), 0.5 * (p0.h + p1.h) * theta,
           dem_v3_norm(drift) / (0.5 * (p0.h + p1.h) * theta), along);
    if (lever == DEM_LEVER_RADIUS) assert_true(along > 0.99);
    *h_out = 0.5 * (p0.h + p1.h);
    *theta_out = theta;
    dem_world_destroy(w);
    return dem_v3_norm(drift);
}

static void test_lever_radius_drift(void **state)
{
    (void)state;
    double h, th, h2, th2;
    double d_radius = lever_drift(DEM_LEVER_RADIUS, &h, &th);
    double d_contact = lever_drift(DEM_LEVER_CONTACT_POINT, &h2, &th2);
    assert_rel(d_radius, h * th, 5e-2, "eq. 7 lever R: spring drift = h theta");
    assert_true(d_contact < 1e-2 * h2 * th2);
}

// Setting a granule's velocity to the value it already has must not change
// the simulation: it only invalidates velocity-dependent forces. The pair
// spinning about n (as above) is run twice, once straight and once with
// dem_world_set_granule_velocity(current v, current ω) before every step; the
// springs must agree to round-off. (Engine bug at the time of writing:
// dem_world_step re-evaluates invalidated forces with the full Δt, so every
// such call advances the history springs by one extra step, here one extra
// twist: the spring turns twice as fast as the pair. The same extra increment
// follows dem_world_prepare, dem_world_set_wall_spin and the set_*_contact
// calls.)
static void test_set_velocity_keeps_history(void **state)
{
    (void)state;
    const dem_vec3 n0 = unit(dem_v3(1, 2, -2));
    const double phi = 2.5e-4, omega = phi / OBJ_DT;
    const int steps = 2000;
    pair_springs res[2];
    for (int c = 0; c < 2; ++c) {
        dem_world *w = loaded_pair(DEM_LEVER_CONTACT_POINT, n0);
        pair_springs p0 = read_springs(w);
        for (size_t i = 0; i < 2; ++i)
            dem_world_set_granule_velocity(w, i, dem_v3(0, 0, 0), dem_v3_scale(p0.n, omega));
        for (int s = 0; s < steps; ++s) {
            if (c == 1) {
                dem_granules_view g = dem_world_granules(w);
                for (size_t i = 0; i < 2; ++i) dem_world_set_granule_velocity(w, i, g.velocity[i], g.omega[i]);
            }
            step_ok(w, 1);
        }
        res[c] = read_springs(w);
        dem_world_destroy(w);
    }
    double turn = acos(fmax(-1.0, fmin(1.0, dem_v3_dot(unit(res[0].fs), unit(res[1].fs)))));
    double err = vec_rel_err(res[1].fs, res[0].fs);
    printf("    after %d steps spinning at %.3g rad/s about n: F_s with a velocity re-set each step differs by "
           "%.3e relative, turned %.4f rad further (the pair turned %.4f rad)\n",
           steps, omega, err, turn, steps * phi);
    assert_true(err < 1e-9);
}

// --------------------------------------------- 6. Newton's third law ---
//
// Every pair force enters i and j with opposite signs, and the torques
// a_i n × F_s and a_j n × F_s (a_i + a_j = d) with ±R* n × F_r balance the moment
// of the pair force, so an isolated cluster keeps its total linear momentum
// Σ m v and its total angular momentum Σ (r × m v + I ω) (velocity Verlet
// with forces evaluated at one configuration preserves both exactly in exact
// arithmetic). Bound: round-off, 1e-12 of Σ|p_i| (and of Σ|L_i|).
static void momenta(const dem_world *w, dem_vec3 *p, dem_vec3 *l, double *sum_p, double *sum_l)
{
    dem_granules_view g = dem_world_granules(w);
    *p = *l = dem_v3(0, 0, 0);
    *sum_p = *sum_l = 0;
    for (size_t i = 0; i < g.count; ++i) {
        dem_vec3 pi = dem_v3_scale(g.velocity[i], g.mass[i]);
        dem_vec3 li = dem_v3_axpy(g.inertia[i], g.omega[i], dem_v3_cross(g.position[i], pi));
        *p = dem_v3_add(*p, pi), *l = dem_v3_add(*l, li);
        *sum_p += dem_v3_norm(pi), *sum_l += dem_v3_norm(li);
    }
}

static void momentum_run(int implicit_springs)
{
    const double R = 1e-4;
    dem_world_def def = dem_default_world_def(); // Table 3: damping, friction, rolling all on
    // Both integrations: the implicit springs' solve stops at a tolerance and
    // restores the momenta of an isolated world (dem_implicit.c).
    def.implicit_springs = implicit_springs;
    def.gravity = dem_v3(0, 0, 0);
    def.threads = 2;
    // A fixed step, about the explicit integration's own (0.165 dt_crit): the
    // run then has thousands of contact-steps whatever the default step is
    // (the implicit springs' default, 0.57 dt_crit, gives 3.5x fewer).
    def.dt = 8.7e-7;
    dem_world *w = world_new(&def);
    lcg_state = 12345;
    // 48 granules (radii 0.9–1.1 R) placed at random, without overlap, in a
    // ball of radius 7R, all moving towards its centre at 0.2 m/s plus ±0.01
    // m/s noise, with random spins (±200 rad/s): the cloud collapses into a
    // dense, dissipative granular gas and re-expands, through thousands of
    // short contacts with sliding, sticking and rolling springs.
    const dem_vec3 c = dem_v3(0.001, -0.002, 0.0005);
    const double VIN = 0.2;
    dem_vec3 pos[48];
    double rad[48];
    int n = 0;
    while (n < 48) {
        dem_vec3 p = dem_v3(2 * urand() - 1, 2 * urand() - 1, 2 * urand() - 1);
        double r = R * (0.9 + 0.2 * urand());
        if (dem_v3_norm(p) > 1) continue;
        p = dem_v3_axpy(7 * R, p, c);
        int ok = 1;
        for (int j = 0; j < n && ok; ++j) ok = dem_v3_norm(dem_v3_sub(p, pos[j])) > 1.02 * (r + rad[j]);
        if (!ok) continue;
        pos[n] = p, rad[n++] = r;
    }
    for (int i = 0; i < n; ++i) {
        dem_vec3 v = dem_v3_scale(unit(dem_v3_sub(c, pos[i])), VIN);
        v = dem_v3_add(v, dem_v3(0.02 * (urand() - 0.5), 0.02 * (urand() - 0.5), 0.02 * (urand() - 0.5)));
        dem_vec3 o = dem_v3(400 * (urand() - 0.5), 400 * (urand() - 0.5), 400 * (urand() - 0.5));
        add_ok(w, pos[i], v, o, rad[i], RHO);
    }
    dem_vec3 p0, l0, p1, l1;
    double sp, sl, sp_max = 0, sl_max = 0, dp = 0, dl = 0;
    momenta(w, &p0, &l0, &sp, &sl);
    sp_max = sp, sl_max = sl;
    size_t max_contacts = 0, contacts_total = 0;
    enum { SAMPLES = 1000, EVERY = 10 };
    for (int k = 0; k < SAMPLES; ++k) {
        step_ok(w, EVERY);
        dem_diagnostics d = dem_world_diagnose(w);
        contacts_total += d.contacts;
        if (d.contacts > max_contacts) max_contacts = d.contacts;
        momenta(w, &p1, &l1, &sp, &sl);
        sp_max = fmax(sp_max, sp), sl_max = fmax(sl_max, sl);
        dp = fmax(dp, dem_v3_norm(dem_v3_sub(p1, p0))), dl = fmax(dl, dem_v3_norm(dem_v3_sub(l1, l0)));
    }
    printf("  %s: 48 granules, %d steps of %.3g s: up to %zu contacts at once, ~%zu contact-steps; max sum|p_i| = %.4g kg m/s, "
           "max |P - P0|/sum|p_i| = %.2e; max sum|L_i| = %.4g kg m2/s, max |L - L0|/sum|L_i| = %.2e (bound 1e-12)\n",
           implicit_springs ? "implicit springs" : "explicit", SAMPLES * EVERY, dem_world_dt(w), max_contacts, contacts_total * EVERY, sp_max, dp / sp_max,
           sl_max, dl / sl_max);
    assert_true(max_contacts >= 5);
    assert_true(contacts_total * EVERY >= 2000); // contact-steps
    assert_true(dp / sp_max < 1e-12);
    assert_true(dl / sl_max < 1e-12);
    dem_world_destroy(w);
}

static void test_momentum_conserved(void **state)
{
    (void)state;
    momentum_run(0);
    momentum_run(1);
}

// -------------------------------------------------- 7. determinism ---
//
// The engine gathers per-pair forces in a fixed order, so runs must be bitwise
// identical: twice with the same settings, and with 1 and 2 threads. The bed
// has 640 granules, above the engine's threshold for starting OpenMP threads
// (DEM_OMP_MIN_GRANULES = 512 in dem_threads_internal.h), so the 2-thread runs
// really split the loops.
static dem_world *small_bed(int threads)
{
    const double R = 1e-4;
    dem_world_def def = dem_default_world_def();
    def.threads = threads;
    def.domain_lo = dem_v3(-0.005, -0.001, -0.005);
    def.domain_hi = dem_v3(0.005, 0.01, 0.005);
    dem_world *w = world_new(&def);
    dem_contact_params wc = def.granule;
    wc.k_n = wc.k_s = wc.k_r = 400;
    const double half = 9 * R;
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .normal = {0, 1, 0}, .axis = {0, 0, 1}, .contact = wc});
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .point = {-half, 0, 0}, .normal = {1, 0, 0},
                               .axis = {0, 0, 1}, .contact = wc});
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .point = {half, 0, 0}, .normal = {-1, 0, 0},
                               .axis = {0, 0, 1}, .contact = wc});
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .point = {0, 0, -half}, .normal = {0, 0, 1},
                               .axis = {0, 0, 1}, .contact = wc});
    wall_ok(w, &(dem_wall_def){.kind = DEM_WALL_PLANE, .point = {0, 0, half}, .normal = {0, 0, -1},
                               .axis = {0, 0, 1}, .contact = wc});
    lcg_state = 777;
    for (int y = 0; y < 10; ++y)
        for (int x = 0; x < 8; ++x)
            for (int z = 0; z < 8; ++z) {
                dem_vec3 p = dem_v3((x - 3.5) * 2.2 * R + 0.1 * R * urand(), (1.2 + 2.2 * y) * R,
                                    (z - 3.5) * 2.2 * R + 0.1 * R * urand());
                dem_vec3 v = dem_v3(0.05 * (urand() - 0.5), -0.1 - 0.05 * urand(), 0.05 * (urand() - 0.5));
                add_ok(w, p, v, dem_v3(0, 0, 0), R * (0.8 + 0.25 * urand()), RHO);
            }
    return w;
}

static void test_determinism(void **state)
{
    (void)state;
    enum { STEPS = 30000 };
    const int threads[3] = {2, 2, 1};
    dem_vec3 *snap[3][3];
    size_t n = 0;
    dem_diagnostics d = {0};
    for (int r = 0; r < 3; ++r) {
        dem_world *w = small_bed(threads[r]);
        int got_threads = dem_world_threads(w);
        step_ok(w, STEPS);
        dem_granules_view g = dem_world_granules(w);
        n = g.count;
        d = dem_world_diagnose(w);
        const dem_vec3 *src[3] = {g.position, g.velocity, g.omega};
        for (int a = 0; a < 3; ++a) {
            snap[r][a] = malloc(n * sizeof(dem_vec3));
            assert_non_null(snap[r][a]);
            memcpy(snap[r][a], src[a], n * sizeof(dem_vec3));
        }
        printf("  run %d: %d thread(s) (the world reports %d), %zu granules, %d steps, t = %.4g s, %zu contacts, "
               "%zu wall contacts\n",
               r + 1, threads[r], got_threads, n, STEPS, dem_world_time(w), d.contacts, d.wall_contacts);
        assert_int_equal(got_threads, threads[r]);
        dem_world_destroy(w);
    }
    assert_true(n > 512);
    assert_true(d.contacts + d.wall_contacts > 300); // a bed, not a gas
    for (int r = 1; r < 3; ++r)
        for (int a = 0; a < 3; ++a) {
            int same = memcmp(snap[0][a], snap[r][a], n * sizeof(dem_vec3)) == 0;
            printf("  run %d vs run 1, %s: %s\n", r + 1, (const char *[]){"positions", "velocities", "spins"}[a],
                   same ? "bitwise identical" : "DIFFERENT");
            assert_true(same);
        }
    for (int r = 0; r < 3; ++r)
        for (int a = 0; a < 3; ++a) free(snap[r][a]);
}

// ------------------------------------ 8. open pairs in the skin, free flight ---
//
// Two granules 0.05 R apart, inside the Verlet skin (0.2 R), separating at
// 1 mm/s with gravity off: the list holds the pair, the force loop visits it
// every step, and it must add nothing. Velocities stay bitwise what they
// were (the kick adds 0 · Δt/m) and centres follow x0 + v t. Run under the
// explicit law, the implicit dashpot and the implicit springs: each keeps its
// own per-pair data. In the sanitizer build (GRANUCAL_POISON_SCRATCH) the
// engine fills fresh per-pair storage with NaN, so an integration that reads
// an open pair's entry before writing it fails here at once, not by chance
// (the implicit dashpot once left an open pair's normal unwritten; found
// when a pour turned non-finite).
static void free_flight_run(int implicit_damping, int implicit_springs, const char *label)
{
    const double R = 5e-4, gap = 0.05 * R, v = 1e-3;
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, 0);
    def.domain_lo = dem_v3(-0.01, -0.01, -0.01), def.domain_hi = dem_v3(0.01, 0.01, 0.01);
    def.implicit_damping = implicit_damping, def.implicit_springs = implicit_springs;
    dem_world *w = world_new(&def); // run in the default group only: the integration is the one set here
    const dem_vec3 x0[2] = {dem_v3(-R - 0.5 * gap, 0, 0), dem_v3(R + 0.5 * gap, 0, 0)};
    const dem_vec3 v0[2] = {dem_v3(-v, 0, 0), dem_v3(v, 0, 0)};
    for (int i = 0; i < 2; ++i) add_ok(w, x0[i], v0[i], dem_v3(0, 0, 0), R, RHO);
    const uint64_t steps = 200;
    step_ok(w, steps);
    dem_diagnostics d = dem_world_diagnose(w);
    dem_granules_view g = dem_world_granules(w);
    const double t = dem_world_time(w);
    double worst = 0;
    for (size_t i = 0; i < 2; ++i) {
        assert_memory_equal(&g.velocity[i], &v0[i], sizeof(dem_vec3));
        worst = fmax(worst, dem_v3_norm(dem_v3_sub(g.position[i], dem_v3_add(x0[i], dem_v3_scale(v0[i], t)))));
    }
    printf("  %s: %zu pair(s) in the list, %zu contacts; after %llu steps velocities unchanged, "
           "centres %.2e m from x0 + v t\n", label, d.list_pairs, d.contacts, (unsigned long long)steps, worst);
    assert_int_equal(d.list_pairs, 1); // the pair is visited: the test can fail
    assert_int_equal(d.contacts, 0);
    assert_true(worst < 1e-15);
    dem_world_destroy(w);
}

static void test_open_pairs_free_flight(void **state)
{
    (void)state;
    free_flight_run(0, 0, "explicit");
    free_flight_run(1, 0, "implicit dashpot");
    free_flight_run(0, 1, "implicit springs");
}

// The initial forces (no step taken) of two granules touching with overlap
// 0.1 R along the periodic axis z (period 0.02 m), granule 0 at z0 and
// granule 1 at z1.
static dem_vec3 periodic_pair_force(double z0, double z1, double *force_on_1)
{
    const double R = 5e-4;
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, 0);
    def.periodic_axis = 2;
    def.domain_lo = dem_v3(-0.01, -0.01, -0.01), def.domain_hi = dem_v3(0.01, 0.01, 0.01);
    dem_world *w = world_new(&def);
    const int64_t id0 = dem_world_add_granule(w, dem_v3(0, 0, z0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO);
    add_ok(w, dem_v3(0, 0, z1), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO);
    assert_true(id0 >= 0);
    step_ok(w, 0);
    const dem_granules_view g = dem_world_granules(w);
    const size_t first = g.id[0] == (uint64_t)id0 ? 0 : 1; // the engine may have re-sorted them
    const dem_vec3 f = g.force[first];
    *force_on_1 = g.force[1 - first].z;
    dem_world_destroy(w);
    return f;
}

// A pair across the boundary of the periodic axis is the same pair as one
// inside (minimum image), and the normal force of eq. 3 on each is k_n h.
// The pair loops take the minimum image by one wrap while all centres lie
// within 1.25 periods; a granule placed further out, before its first
// drift, goes through the general minimum image: placed three periods over,
// one wrap would leave the pair a period apart, and it would not push.
static void test_periodic_pair_across_boundary(void **state)
{
    (void)state;
    const double R = 5e-4, h = 0.1 * R, a = R - 0.5 * h, L = 0.02;
    const double k_n = dem_default_world_def().granule.k_n;
    const struct {
        double z0, z1;
        const char *label;
    } cases[] = {
        {-a, a, "inside"},
        {0.01 - a, -0.01 + a, "across the boundary"},
        {0.01 - a, -0.01 + a + 3 * L, "granule 1 three periods over"},
        {0.01 - a - 2 * L, -0.01 + a, "granule 0 two periods under"},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; ++c) {
        double f1;
        const dem_vec3 f0 = periodic_pair_force(cases[c].z0, cases[c].z1, &f1);
        printf("  %s: force on 0 (%.3g, %.3g, %.10g) N, on 1 %.10g N; k_n h = %.10g N\n", cases[c].label, f0.x,
               f0.y, f0.z, f1, k_n * h);
        assert_true(f0.x == 0.0 && f0.y == 0.0);
        assert_rel(-f0.z, k_n * h, 1e-9, cases[c].label); // granule 1 is above granule 0 (minimum image)
        assert_rel(f1, k_n * h, 1e-9, cases[c].label);
    }
}

static struct timespec t_start;
static int timer_start(void **state)
{
    (void)state;
    clock_gettime(CLOCK_MONOTONIC, &t_start);
    return 0;
}
static int timer_report(void **state)
{
    (void)state;
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    printf("  (%.1f s)\n", (double)(t.tv_sec - t_start.tv_sec) + 1e-9 * (double)(t.tv_nsec - t_start.tv_nsec));
    return 0;
}
#define TEST(f) cmocka_unit_test_setup_teardown(f, timer_start, timer_report)

int main(void)
{
    const struct CMUnitTest tests[] = {
        TEST(test_binary_collision),
        TEST(test_energy_conserved_granule_on_wall),
        TEST(test_energy_conserved_cluster),
        TEST(test_incline_roll_slide),
        TEST(test_incline_rolling_resistance),
        TEST(test_launch_slip_roll),
        TEST(test_launch_slip_roll_stop),
        TEST(test_objectivity_rotation_about_normal),
        TEST(test_objectivity_rotation_normal_to_n),
        TEST(test_lever_radius_drift),
        TEST(test_set_velocity_keeps_history),
        TEST(test_momentum_conserved),
        TEST(test_determinism),
        TEST(test_open_pairs_free_flight),
        TEST(test_periodic_pair_across_boundary),
    };
    int failed = cmocka_run_group_tests_name("default integration", tests, NULL, NULL);
    // Determinism, momentum and free flight run their own integrations;
    // the rest again with implicit springs.
    force_implicit_springs = 1;
    const struct CMUnitTest forced[] = {
        TEST(test_binary_collision),          TEST(test_energy_conserved_granule_on_wall),
        TEST(test_energy_conserved_cluster),  TEST(test_incline_roll_slide),
        TEST(test_incline_rolling_resistance), TEST(test_launch_slip_roll),
        TEST(test_launch_slip_roll_stop),     TEST(test_objectivity_rotation_about_normal),
        TEST(test_objectivity_rotation_normal_to_n), TEST(test_lever_radius_drift),
        TEST(test_set_velocity_keeps_history),  TEST(test_periodic_pair_across_boundary),
    };
    return failed + cmocka_run_group_tests_name("implicit springs forced", forced, NULL, NULL);
}
