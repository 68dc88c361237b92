// SPDX-License-Identifier: MIT
// The confined compression test (sections 3.2.1, 4.1): pour into the die,
// strike off, settle, cycle the piston between two pressures, E' (eq. 19).
// The physics only: its config is exp_compress_config.c, its runner (the
// files it writes) exp_compress_runner.c.
#include "exp_compress.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_scaling.h"
#include "exp_contact_rules.h"
#include "exp_pour.h"

#define FILL_GRAVITY 30.0 // pour and settle under 30 g (see exp_compress_run)
// exp_ke_ratio divides by (bed mass)·9.81·d50: the thresholds carry the
// factor FILL_GRAVITY, and a fall under it takes 1/sqrt(FILL_GRAVITY) as long.
#define LAYER_KE_RATIO (1e-2 * FILL_GRAVITY)
#define LAYER_MAX_TIME 0.1
#define SETTLE_KE_RATIO (1e-6 * FILL_GRAVITY)
#define SETTLE_MAX_TIME 0.1
#define RELAX_MAX_TIME 0.02
#define CHECK_EVERY 0.002 // s between rest checks: a layer lands in milliseconds under FILL_GRAVITY
#define APPROACH_FACTOR 10.0
#define WALL_SIDE 0
#define WALL_FLOOR 1
#define WALL_PISTON 2
#define SAMPLE_STRAIN 2e-5 // piston travel between samples, over the die depth

exp_compress_def exp_default_compress_def(void)
{
    exp_compress_def d;
    memset(&d, 0, sizeof d);
    d.diameter = 0.076, d.depth = 0.015; // section 3.2.1
    d.lambda = 4096;
    d.gsd = dem_default_gsd();
    d.density = 1800;
    d.granule = dem_default_world_def().granule;
    d.granule.mu_r = 0; // no rolling resistance in this scene
    d.wall = d.granule;
    d.wall.mu_s = 0.2; // section 4.1: granule–boundary friction 0.2
    d.sigma_min = 20, d.sigma_max = 60;
    d.piston_speed = 0.02;
    d.cycles = 4;
    d.max_time = 2.0;
    d.seed = 1;
    return d;
}

int exp_compress_check(const exp_compress_def *d, char *msg, size_t len)
{
    char sub[256];
    if (!(d->diameter > 0)) return exp_fail(msg, len, "diameter = %g: must be > 0", d->diameter);
    if (!(d->depth > 0)) return exp_fail(msg, len, "depth = %g: must be > 0", d->depth);
    if (!(d->density > 0)) return exp_fail(msg, len, "density = %g: must be > 0", d->density);
    if (!(d->sigma_min > 0)) return exp_fail(msg, len, "sigma_min = %g: must be > 0", d->sigma_min);
    if (!(d->sigma_max > d->sigma_min))
        return exp_fail(msg, len, "sigma_max = %g: must be > sigma_min (%g)", d->sigma_max, d->sigma_min);
    if (!(d->piston_speed > 0)) return exp_fail(msg, len, "piston_speed = %g: must be > 0", d->piston_speed);
    if (d->cycles < 2 || d->cycles > EXP_COMPRESS_MAX_CYCLES)
        return exp_fail(msg, len, "cycles = %d: must be in [2, %d]", d->cycles, EXP_COMPRESS_MAX_CYCLES);
    if (!(d->max_time > 0)) return exp_fail(msg, len, "max_time = %g: must be > 0", d->max_time);
    if (d->granule.mu_r != 0 || d->wall.mu_r != 0)
        return exp_fail(msg, len, "mu_r = %g: the compression test has no rolling resistance (must be 0)",
                        d->granule.mu_r != 0 ? d->granule.mu_r : d->wall.mu_r);
    if (dem_scale_check(d->lambda, sub, sizeof sub)) return exp_fail(msg, len, "%s", sub);
    if (dem_gsd_check(&d->gsd, sub, sizeof sub)) return exp_fail(msg, len, "%s", sub);
    if (dem_contact_params_check(&d->granule, sub, sizeof sub)) return exp_fail(msg, len, "granule_contact.%s", sub);
    if (dem_contact_params_check(&d->wall, sub, sizeof sub)) return exp_fail(msg, len, "wall_contact.%s", sub);
    double dmax = dem_gsd_max_diameter(&d->gsd) * cbrt(d->lambda);
    if (d->depth < 2 * dmax || d->diameter < 4 * dmax)
        return exp_fail(msg, len, "lambda = %g: the largest scaled granule (%.3g m) does not fit the die twice", d->lambda,
                        dmax);
    return 0;
}

void exp_compress_result_free(exp_compress_result *r)
{
    if (r) free(r->curve), r->curve = NULL, r->n_curve = 0;
}

// ----------------------------------------------------------------- the die

static dem_world *create_die(const exp_compress_def *d, double gravity, char *err, size_t len)
{
    double r = 0.5 * d->diameter;
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, -gravity, 0);
    def.granule = dem_scale_contact(&d->granule, d->lambda);
    def.domain_lo = dem_v3(-1.2 * r, -0.01, -1.2 * r);
    def.domain_hi = dem_v3(1.2 * r, 4 * d->depth, 1.2 * r);
    dem_world *w = dem_world_create(&def, err, len);
    if (!w) return NULL;
    dem_contact_params wall = d->wall; // the die's friction and dashpot, as given
    wall.k_n = wall.k_s = wall.k_r = exp_boundary_stiffness(d->granule.k_n);
    wall = dem_scale_contact(&wall, d->lambda);
    dem_wall_def side = {.kind = DEM_WALL_CYLINDER, .point = {0, 0, 0}, .axis = {0, 1, 0}, .radius = r,
                         .contact = wall, .name = "die"};
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .contact = wall, .name = "floor"};
    // The piston waits above the pour, facing down.
    dem_wall_def piston = {.kind = DEM_WALL_PLANE, .point = {0, 3.5 * d->depth, 0}, .normal = {0, -1, 0},
                           .axis = {0, 1, 0}, .contact = wall, .name = "piston"};
    if (dem_world_add_wall(w, &side) != WALL_SIDE || dem_world_add_wall(w, &floor) != WALL_FLOOR ||
        dem_world_add_wall(w, &piston) != WALL_PISTON) {
        exp_fail(err, len, "%s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    return w;
}

// The piston's height: its prescribed position, moved by the engine before
// every step (drive_piston).
static double piston_y(const dem_world *w) { return dem_world_wall(w, WALL_PISTON)->point.y; }

// Place the piston at height y, its surface moving at vy (m/s, along the
// die's axis): 0, where it is placed rather than driven (drive_piston).
static dem_status move_piston(dem_world *w, double y, double vy)
{
    dem_vec3 p = dem_world_wall(w, WALL_PISTON)->point;
    p.y = y;
    dem_status st = dem_world_set_wall_point(w, WALL_PISTON, p);
    return st != DEM_OK ? st : dem_world_set_wall_velocity(w, WALL_PISTON, dem_v3(0, vy, 0));
}

// Drive the piston from where it stands, down while loading: the engine
// moves it by `travel` before every step (the wall's prescribed motion,
// dem_world_set_wall_translation), its surface at `speed`, so that its
// contacts' dashpots and friction see the relative velocity of granule and
// piston (a move alone is not seen by the contact law). `travel` is this
// file's own product (speed × dt, times the approach factor), handed over as
// it is, and the engine adds it as this loop once did step by step
// (y += ±travel): the piston's heights are the same bits.
static dem_status drive_piston(dem_world *w, int loading, double travel, double speed)
{
    return dem_world_set_wall_translation(w, WALL_PISTON, dem_v3(0, loading ? -speed : speed, 0),
                                          dem_v3(0, loading ? -travel : travel, 0));
}

// Spring forces on the piston, the floor and the side wall: the normal
// springs k_n·h of eq. 3. The dashpot is left out on purpose: at the
// quasi-static rate it is a small, rate-dependent part (docs/experiments.md),
// and σ = f_top / area (eq. 19's pressure, the reversal points and E') has
// been this sum in every result published. The engine's own totals, dashpot
// and friction included (dem_world_wall_force), are kept beside it
// (wall_totals): they are not a sum of magnitudes, so the side wall's
// normal load, which cancels as a vector around the die, is only here.
static void wall_forces(const dem_world *w, const exp_compress_def *d, double piston_y, double *top, double *bottom,
                        double *side)
{
    dem_granules_view g = dem_world_granules(w);
    double k = dem_scale_stiffness(exp_boundary_stiffness(d->granule.k_n), d->lambda), r_die = 0.5 * d->diameter;
    double ft = 0, fb = 0, fs = 0;
    for (size_t i = 0; i < g.count; ++i) {
        double ri = g.radius[i], y = g.position[i].y;
        double ht = ri - (piston_y - y), hb = ri - y;
        double rho = sqrt(g.position[i].x * g.position[i].x + g.position[i].z * g.position[i].z);
        double hs = ri + rho - r_die;
        if (ht > 0) ft += k * ht;
        if (hb > 0) fb += k * hb;
        if (hs > 0) fs += k * hs;
    }
    *top = ft, *bottom = fb, *side = fs;
}

// The engine's totals along the die's axis (see exp_compress_sample).
static void wall_totals(const dem_world *w, exp_compress_sample *s)
{
    s->f_piston_axial = dem_world_wall_force(w, WALL_PISTON).y;
    s->f_floor_axial = dem_world_wall_force(w, WALL_FLOOR).y;
    s->f_side_axial = dem_world_wall_force(w, WALL_SIDE).y;
}

static double bed_top(const dem_world *w)
{
    dem_granules_view g = dem_world_granules(w);
    double top = 0;
    for (size_t i = 0; i < g.count; ++i) top = fmax(top, g.position[i].y + g.radius[i]);
    return top;
}

typedef struct curve_buf {
    exp_compress_sample *s;
    size_t n, cap;
} curve_buf;

static int push(curve_buf *c, const exp_compress_sample *s)
{
    if (c->n == c->cap) {
        size_t cap = c->cap ? 2 * c->cap : 4096;
        exp_compress_sample *p = realloc(c->s, cap * sizeof *p);
        if (!p) return 1;
        c->s = p, c->cap = cap;
    }
    c->s[c->n++] = *s;
    return 0;
}

// Work of the piston on the bed over samples [from, to] (trapezoids of
// F_top over the piston travel), J; positive when the piston moves down.
static double piston_work(const exp_compress_sample *s, size_t from, size_t to)
{
    double wk = 0;
    for (size_t k = from; k < to; ++k) wk += 0.5 * (s[k].f_top + s[k + 1].f_top) * (s[k].piston_y - s[k + 1].piston_y);
    return wk;
}

// Stable cycle: the permanent strain of the last cycle is below 5 % of its
// elastic (unloading) strain and its E' is within 5 % of the previous one's.
static int is_stable(const exp_compress_result *r)
{
    if (r->n_cycles < 2) return 0;
    const exp_compress_cycle *a = &r->cycle[r->n_cycles - 2], *b = &r->cycle[r->n_cycles - 1];
    double elastic = b->strain_turn - b->strain_end;
    return fabs(b->permanent_strain) < 0.05 * elastic && fabs(b->e_unloading - a->e_unloading) < 0.05 * b->e_unloading;
}

// Drive the piston: down until σ ≥ σ_max, up until σ ≤ σ_min, `cycles` times.
static int cycle_piston(dem_world *w, const exp_compress_def *d, exp_progress_fn progress, void *ctx,
                        exp_compress_result *out, char *err, size_t len)
{
    double area = DEM_PI * 0.25 * d->diameter * d->diameter, dt = dem_world_dt(w);
    double step_travel = d->piston_speed * dt;
    uint64_t per_sample = (uint64_t)(SAMPLE_STRAIN * d->depth / step_travel) + 1;
    double y = fmin(piston_y(w), bed_top(w) + 0.02 * dem_gsd_max_diameter(&d->gsd) * cbrt(d->lambda));
    move_piston(w, y, 0.0);
    curve_buf c = {0};
    int loading = 1, cycle = 1, touched = 0, approaching = 1;
    double h0 = NAN, t0 = dem_world_time(w);
    size_t turn_at = 0, start_at = 0;
    unsigned long long steps = 0;
    exp_compress_cycle *cy = &out->cycle[0];
    while (1) {
        // Approach: the struck-off surface is as rough as the largest granule,
        // and the piston meets it across the die only millimetres down; it
        // travels at APPROACH_FACTOR × the test speed until σ reaches a
        // quarter of σ_min (the Instron's approach), then at the test speed.
        double travel = approaching ? APPROACH_FACTOR * step_travel : step_travel;
        const double speed = (approaching ? APPROACH_FACTOR : 1.0) * d->piston_speed;
        // One sample's steps in one call: the engine moves the piston and
        // steps on its threads.
        if (drive_piston(w, loading, travel, speed) != DEM_OK || dem_world_step(w, per_sample) != DEM_OK)
            return free(c.s), exp_fail(err, len, "%s", dem_world_error(w));
        y = piston_y(w);
        steps += per_sample;
        exp_compress_sample sm = {0};
        sm.t = dem_world_time(w) - t0;
        sm.piston_y = y;
        wall_forces(w, d, y, &sm.f_top, &sm.f_bottom, &sm.f_side);
        wall_totals(w, &sm);
        sm.sigma = sm.f_top / area;
        dem_diagnostics dg = dem_world_diagnose(w);
        sm.ke_over_elastic = dg.potential_elastic > 0 ? (dg.ke_translational + dg.ke_rotational) / dg.potential_elastic : 0;
        sm.cycle = cycle, sm.loading = loading;
        if (sm.sigma >= 0.25 * d->sigma_min) approaching = 0;
        if (isnan(h0) && sm.sigma >= d->sigma_min) {
            h0 = y; // the bed's height at σ_min: the strain reference (eq. 19)
            start_at = c.n;
            touched = 1;
        }
        sm.displacement = isnan(h0) ? 0 : h0 - y;
        sm.strain = isnan(h0) ? 0 : sm.displacement / h0;
        if (touched) out->max_ke_over_elastic = fmax(out->max_ke_over_elastic, sm.ke_over_elastic);
        if (push(&c, &sm)) return free(c.s), exp_fail(err, len, "out of memory");
        if (isnan(h0) && y < 0.3 * d->depth)
            return free(c.s), exp_fail(err, len, "compression: the piston reached 0.3 of the die depth below sigma_min");
        if (loading && !isnan(h0) && sm.sigma >= d->sigma_max) {
            cy->sigma_start = c.s[start_at].sigma, cy->strain_start = c.s[start_at].strain;
            cy->sigma_turn = sm.sigma, cy->strain_turn = sm.strain;
            cy->work_in = piston_work(c.s, start_at, c.n - 1);
            out->coordination_turn = dg.coordination;
            turn_at = c.n - 1;
            loading = 0;
            if (d->stop_at_last_turn && cycle == d->cycles) break;
        } else if (!loading && sm.sigma <= d->sigma_min) {
            cy->sigma_end = sm.sigma, cy->strain_end = sm.strain;
            cy->work_out = -piston_work(c.s, turn_at, c.n - 1);
            cy->e_loading = (cy->sigma_turn - cy->sigma_start) / (cy->strain_turn - cy->strain_start); // eq. 19
            cy->e_unloading = (cy->sigma_turn - cy->sigma_end) / (cy->strain_turn - cy->strain_end);   // eq. 19
            cy->permanent_strain = cy->strain_end - cy->strain_start;
            out->n_cycles = cycle;
            if (cycle == d->cycles) break;
            cy = &out->cycle[cycle++];
            start_at = c.n - 1;
            loading = 1;
        }
        if (progress) progress(loading ? "load" : "unload", sm.t, dem_world_granules(w).count, ctx);
        if (sm.t > d->max_time) break;
    }
    dem_world_stop_wall(w, WALL_PISTON); // the test is over: the piston stops where it is
    out->curve = c.s, out->n_curve = c.n;
    out->bed_height = h0;
    out->particle_steps = steps * dem_world_granules(w).count;
    out->simulated_time_s = dem_world_time(w) - t0;
    if (out->n_cycles > 0) {
        out->e_confined = out->cycle[out->n_cycles - 1].e_unloading;
        out->e_confined_loading = out->cycle[out->n_cycles - 1].e_loading;
    }
    out->stable = is_stable(out);
    return 0;
}

dem_world *exp_compress_run(const exp_compress_def *d, exp_progress_fn progress, void *ctx, exp_compress_result *out,
                            char *err, size_t len)
{
    memset(out, 0, sizeof *out);
    if (len) err[0] = '\0';
    if (exp_compress_check(d, err, len)) return NULL;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    // Pour and settle under FILL_GRAVITY·g: a free fall takes as long as in
    // the lab, while the step, set by sqrt(m/k) (eq. 14) with a coarse granule
    // keeping a real granule's mass (eq. 16–17), is microseconds: the pour
    // would be most of the cost. The bed's own weight is then moved into a world with g, where it
    // is negligible against σ_min (ρ_bulk·g·H ≈ 0.03 Pa at λ = 4096).
    dem_world *f = create_die(d, FILL_GRAVITY * 9.81, err, len);
    if (!f) return NULL;
    exp_rim_pour pour = {"compression", 0.5 * d->diameter, d->depth, 2.0, &gsd, d->seed,
                         dem_scale_density(d->density, d->lambda), LAYER_KE_RATIO, LAYER_MAX_TIME, CHECK_EVERY};
    if (exp_pour_to_rim(f, &pour, progress, ctx, err, len) ||
        exp_run_until_rest(f, gsd.median_diameter, SETTLE_KE_RATIO, SETTLE_MAX_TIME, CHECK_EVERY, progress, ctx,
                           "settle")) {
        if (!err[0]) exp_fail(err, len, "%s", dem_world_error(f));
        dem_world_destroy(f);
        return NULL;
    }
    out->fill_time_s = dem_world_time(f);
    dem_world *w = create_die(d, 9.81, err, len);
    dem_granules_view fg = dem_world_granules(f);
    for (size_t i = 0; w && i < fg.count; ++i)
        if (dem_world_add_granule(w, fg.position[i], dem_v3(0, 0, 0), dem_v3(0, 0, 0), fg.radius[i],
                                  dem_scale_density(d->density, d->lambda)) < 0) {
            exp_fail(err, len, "%s", dem_world_error(w));
            dem_world_destroy(w), w = NULL;
        }
    dem_world_destroy(f);
    if (!w) return NULL;
    // The bed carries the overlaps of FILL_GRAVITY·g; released under g they
    // would launch granules (the default dashpot acts only on approach), so
    // the piston is lowered onto the bed first and the bed relaxes under it.
    move_piston(w, bed_top(w) + 0.02 * dem_gsd_max_diameter(&gsd), 0.0);
    if (dem_world_prepare(w) != DEM_OK ||
        exp_run_until_rest(w, gsd.median_diameter, 1e-6, RELAX_MAX_TIME, CHECK_EVERY, progress, ctx, "relax")) {
        exp_fail(err, len, "%s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    out->fill_time_s = dem_world_time(w) + out->fill_time_s;
    out->granules = dem_world_granules(w).count;
    if (cycle_piston(w, d, progress, ctx, out, err, len)) {
        dem_world_destroy(w);
        return NULL;
    }
    dem_granules_view g = dem_world_granules(w);
    double solid = 0, r = 0.5 * d->diameter;
    for (size_t i = 0; i < g.count; ++i) solid += 4.0 / 3.0 * DEM_PI * g.radius[i] * g.radius[i] * g.radius[i];
    out->solid_fraction = solid / (DEM_PI * r * r * out->bed_height);
    return w;
}
