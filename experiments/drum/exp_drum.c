// SPDX-License-Identifier: MIT
// The rotating drum: build, pour, settle, measure.
#include "exp_drum.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_checkpoint.h"
#include "dem_scaling.h"
#include "exp_contact_rules.h"
#include "exp_cost.h"
#include "exp_pour.h"
#include "exp_series.h"

#define LAYER_MAX_TIME 0.6     // s a poured layer may take to land
#define LAYER_KE_RATIO 1e-2    // a layer has landed below this KE over (bed mass)·g·d50
#define SETTLE_MAX_TIME 2.0    // s
#define SETTLE_KE_RATIO 1e-4   // KE over (bed mass)·g·d50 at rest (see exp_drum_fill)
#define CHECK_EVERY 0.05       // s between rest checks

exp_drum_cost exp_drum_predict_cost(const exp_drum_def *d, double max_time)
{
    const double poured_fraction = 0.6, fill_time = 1.25, turn_fraction = 0.30;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    double r = 0.5 * d->diameter, bed_volume = d->fill * DEM_PI * r * r * d->depth;
    double n = (double)dem_gsd_count_for_volume(&gsd, poured_fraction * bed_volume);
    double dt_crit = exp_lightest_dt_crit(&d->gsd, d->density, d->granule.k_n, d->lambda);
    return (exp_drum_cost){.granules = n,
                           .fill_particle_steps = n * fill_time / (EXP_POUR_STEP_FRACTION * dt_crit),
                           .turn_particle_steps = n * max_time / (turn_fraction * dt_crit),
                           .memory_mb = exp_predicted_peak_memory_mb(n)};
}

exp_drum_def exp_default_drum_def(void)
{
    exp_drum_def d;
    memset(&d, 0, sizeof d);
    d.diameter = 0.1;
    d.depth = 0.044;
    d.fill = 0.43;
    d.periodic = 0;
    d.lambda = 64;
    d.gsd = dem_default_gsd();
    d.density = 1800;
    d.granule = dem_default_world_def().granule;
    d.wall = exp_boundary_pair(&d.granule, d.granule.mu_s, d.granule.mu_r);
    d.end_plate = d.wall;
    d.pixel = 0;
    d.closing_px = 2;
    d.seed = 1;
    return d;
}

exp_drum_def exp_drum_def_from_physics(const exp_drum_physics *p)
{
    exp_drum_def d = exp_default_drum_def();
    d.diameter = p->diameter, d.fill = p->fill, d.periodic = p->periodic;
    d.depth = p->periodic ? p->slice_depth : p->depth;
    d.lambda = p->lambda, d.density = p->density, d.seed = p->seed;
    d.gsd = p->gsd;
    d.granule = exp_granule_pair(p->k_n, p->xi, p->mu_s, p->mu_r, p->damping);
    d.wall = exp_boundary_pair(&d.granule, p->wall_mu_s, p->wall_mu_r);
    d.end_plate = d.wall;
    d.fill_method = p->fill_method;
    return d;
}

int exp_drum_check(const exp_drum_def *d, char *msg, size_t len)
{
    char sub[256];
    if (!(d->diameter > 0)) return snprintf(msg, len, "drum.diameter = %g: must be > 0", d->diameter), 1;
    if (!(d->depth > 0)) return snprintf(msg, len, "drum.depth = %g: must be > 0", d->depth), 1;
    if (!(d->fill > 0 && d->fill < 1)) return snprintf(msg, len, "drum.fill = %g: must be in (0, 1)", d->fill), 1;
    if (!(d->pixel >= 0)) return snprintf(msg, len, "drum.pixel = %g: must be >= 0", d->pixel), 1;
    if (d->closing_px < 0 || d->closing_px > 50)
        return snprintf(msg, len, "drum.closing_px = %d: must be in [0, 50]", d->closing_px), 1;
    if (!(d->density > 0)) return snprintf(msg, len, "density = %g: must be > 0", d->density), 1;
    if (dem_scale_check(d->lambda, sub, sizeof sub)) return snprintf(msg, len, "%s", sub), 1;
    if (dem_gsd_check(&d->gsd, sub, sizeof sub)) return snprintf(msg, len, "%s", sub), 1;
    if (dem_contact_params_check(&d->granule, sub, sizeof sub))
        return snprintf(msg, len, "granule_contact.%s", sub), 1;
    if (dem_contact_params_check(&d->wall, sub, sizeof sub)) return snprintf(msg, len, "wall_contact.%s", sub), 1;
    return 0;
}

dem_world *exp_drum_create_empty(const exp_drum_def *d, char *err, size_t len)
{
    double r = 0.5 * d->diameter;
    dem_world_def def = dem_default_world_def();
    def.granule = dem_scale_contact(&d->granule, d->lambda);
    def.domain_lo = dem_v3(-1.2 * r, -1.2 * r, d->periodic ? 0 : -0.1 * d->depth);
    def.domain_hi = dem_v3(1.2 * r, 1.2 * r, d->periodic ? d->depth : 1.1 * d->depth);
    def.periodic_axis = d->periodic ? 2 : -1;
    dem_world *w = dem_world_create(&def, err, len);
    if (!w) return NULL;
    dem_wall_def cyl = {.kind = DEM_WALL_CYLINDER, .point = {0, 0, 0}, .axis = {0, 0, 1}, .radius = r,
                        .contact = dem_scale_contact(&d->wall, d->lambda), .name = "drum"};
    int ok = dem_world_add_wall(w, &cyl) >= 0;
    if (!d->periodic) {
        dem_contact_params plate = dem_scale_contact(&d->end_plate, d->lambda);
        dem_wall_def front = {.kind = DEM_WALL_DISC, .point = {0, 0, 0}, .normal = {0, 0, 1}, .axis = {0, 0, 1},
                              .radius = r, .contact = plate, .name = "front plate"};
        dem_wall_def back = front;
        back.point = dem_v3(0, 0, d->depth), back.normal = dem_v3(0, 0, -1), back.name = "back plate";
        ok = ok && dem_world_add_wall(w, &front) >= 0 && dem_world_add_wall(w, &back) >= 0;
    }
    if (!ok) {
        snprintf(err, len, "%s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    return w;
}

// The drum's cross-section, less half a pitch, is where a layer may go.
static int inside_drum(dem_vec3 p, const void *ctx)
{
    double inner = *(const double *)ctx;
    return p.x * p.x + p.y * p.y <= inner * inner;
}

int exp_drum_fill_method_from_name(const char *name, exp_drum_fill_method *out)
{
    if (strcmp(name, "pour") == 0) return *out = EXP_FILL_POUR, 0;
    if (strcmp(name, "pack") == 0) return *out = EXP_FILL_PACK, 0;
    return 1;
}

const char *exp_drum_fill_method_name(exp_drum_fill_method m) { return m == EXP_FILL_PACK ? "pack" : "pour"; }

int exp_drum_steady_rule_from_name(const char *name, int *out)
{
    if (strcmp(name, "windows") == 0) return *out = EXP_STEADY_WINDOWS, 0;
    if (strcmp(name, "mser") == 0) return *out = EXP_STEADY_MSER, 0;
    return 1;
}

double exp_drum_fill_level(double r, double fill)
{
    double lo = -r, hi = r;
    for (int it = 0; it < 60; ++it) {
        double y = 0.5 * (lo + hi), above = r * r * acos(y / r) - y * sqrt(r * r - y * y);
        if (1.0 - above / (DEM_PI * r * r) < fill) lo = y;
        else hi = y;
    }
    return 0.5 * (lo + hi);
}

// A random packing band reaches this far above the fill level, as a share
// of the height still to fill: at a solid fraction of ~0.3 it settles to
// about half its height, so a band 1.6 times the height left lands a little
// short of the level and the next band tops it up.
#define PACK_BAND_FACTOR 1.6
#define PACK_TRIES 200 // random points a granule may try before the band counts as full

static size_t place_layer(dem_world *w, const exp_drum_def *d, const double *diam, size_t next, size_t n, double pitch,
                          int layer)
{
    double r = 0.5 * d->diameter, inner = r - 0.55 * pitch;
    double margin = d->periodic ? 0.5 * pitch : 0.6 * pitch, density = dem_scale_density(d->density, d->lambda);
    exp_pour_region region = {dem_v3(-inner, -r, margin), dem_v3(inner, inner, d->depth - margin + 1e-12), inside_drum,
                              &inner};
    if (d->fill_method == EXP_FILL_POUR) return exp_pour_layer(w, &region, -r, diam, next, n, pitch, density);
    double level = exp_drum_fill_level(r, d->fill), surface = exp_bed_surface(w, -r);
    double top = fmin(level + PACK_BAND_FACTOR * fmax(level - surface, pitch), inner);
    return exp_pack_band(w, &region, -r, top, diam, next, n, density, d->seed * 1000003ULL + (unsigned long long)layer,
                         PACK_TRIES);
}

// Raster resolution of the drum face: a quarter of the median diameter, and
// a closing of half a median diameter, which fills the pores between
// granules (as a photograph of a powder shows none) but not the surface.
static double face_pixel(const exp_drum_def *d) { return d->pixel > 0 ? d->pixel : 0.25 * d->gsd.median_diameter * cbrt(d->lambda); }

// The drum face with the granules whose centres lie at or below y_cut
// projected onto it and closed; NULL on out-of-memory or a failed closing.
static exp_raster *face_raster(const dem_world *w, const exp_drum_def *d, double pixel, int closing_px, double y_cut)
{
    dem_granules_view g = dem_world_granules(w);
    double *x = malloc((g.count + 1) * sizeof *x), *y = malloc((g.count + 1) * sizeof *y), *r = malloc((g.count + 1) * sizeof *r);
    exp_raster *img = exp_raster_create(0.5 * d->diameter, pixel);
    int ok = x && y && r && img;
    if (ok) {
        size_t m = 0;
        for (size_t i = 0; i < g.count; ++i)
            if (g.position[i].y <= y_cut) x[m] = g.position[i].x, y[m] = g.position[i].y, r[m++] = g.radius[i];
        exp_raster_paint_discs(img, m, x, y, r);
        ok = exp_raster_close(img, closing_px) == 0;
    }
    free(x), free(y), free(r);
    if (!ok) exp_raster_free(img);
    return ok ? img : NULL;
}

// CSA (eq. 20) of the granules whose centres lie at or below y_cut.
static double csa_below(const dem_world *w, const exp_drum_def *d, double y_cut)
{
    exp_raster *img = face_raster(w, d, face_pixel(d), d->closing_px, y_cut);
    double csa = img ? exp_raster_csa_percent(img, 0.5 * d->diameter) : NAN;
    exp_raster_free(img);
    return csa;
}

// Remove the granules above the height at which the bed's CSA is the fill
// degree (bisection on the cut height).
static void cut_to_fill(dem_world *w, const exp_drum_def *d)
{
    double lo = -0.5 * d->diameter, hi = 0.5 * d->diameter, target = 100.0 * d->fill;
    for (int it = 0; it < 40; ++it) {
        double mid = 0.5 * (lo + hi);
        if (csa_below(w, d, mid) < target) lo = mid;
        else hi = mid;
    }
    exp_remove_above(w, hi);
}

static dem_world *fill_failed(dem_world *w, double *diam, char *err, size_t len, const char *why)
{
    snprintf(err, len, "drum fill: %s", why ? why : dem_world_error(w));
    free(diam);
    dem_world_destroy(w);
    return NULL;
}

dem_world *exp_drum_fill(const exp_drum_def *d, exp_progress_fn progress, void *ctx, char *err, size_t len)
{
    if (exp_drum_check(d, err, len)) return NULL;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    double r = 0.5 * d->diameter, bed_volume = d->fill * DEM_PI * r * r * d->depth;
    // Enough sizes for a bed three times looser than a dense one; the pour
    // stops when the bed's CSA reaches the fill degree.
    size_t cap = 3 * dem_gsd_count_for_volume(&gsd, 0.6 * bed_volume) + 16;
    double *diam = malloc(cap * sizeof *diam);
    if (!diam) return fill_failed(NULL, diam, err, len, "out of memory");
    dem_world *w = exp_drum_create_empty(d, err, len);
    if (!w) return free(diam), NULL; // it wrote the message
    if (dem_gsd_sample(&gsd, d->seed, cap, diam)) return fill_failed(w, diam, err, len, "cannot sample sizes");
    double pitch = 1.05 * dem_gsd_max_diameter(&gsd), target = 100.0 * d->fill;
    for (size_t next = 0, layer = 0; csa_below(w, d, r) < target; ++layer) {
        size_t placed = next < cap ? place_layer(w, d, diam, next, cap, pitch, (int)layer) : 0;
        if (placed == 0) return fill_failed(w, diam, err, len, "no room left to pour: the fill degree is too high");
        if (dem_world_prepare(w) != DEM_OK ||
            exp_run_until_rest(w, gsd.median_diameter, LAYER_KE_RATIO, LAYER_MAX_TIME, CHECK_EVERY, progress, ctx, "pour"))
            return fill_failed(w, diam, err, len, NULL);
        next += placed;
    }
    free(diam);
    cut_to_fill(w, d);
    // Layers were poured in placement order; in curve order the force loop
    // finds each granule's partners in cache for the rest of the run.
    if (dem_world_sort_spatially(w) != DEM_OK) return fill_failed(w, NULL, err, len, dem_world_error(w));
    // At rest means far below the kinetic energy the drum will give the bed:
    // turning rigidly at 4 rpm (the slowest lab speed, wall speed v = 21 mm/s)
    // it has v^2 / (2 g d50) >= 3.5e-3 of (bed mass)·g·d50 for any d50 up to the
    // 6.4 mm of lambda 32768, 35x above SETTLE_KE_RATIO. A stricter 1e-6 was
    // never reached by a granule-lined bed (mu_r 0.2 creeps) before
    // SETTLE_MAX_TIME, and cost 80% of the fill: 2.0 s against 0.3 s now.
    if (exp_run_until_rest(w, gsd.median_diameter, SETTLE_KE_RATIO, SETTLE_MAX_TIME, CHECK_EVERY, progress, ctx,
                           "settle"))
        return fill_failed(w, NULL, err, len, NULL);
    return w;
}

int exp_drum_measure_now(const dem_world *w, const exp_drum_def *d, double pixel, int closing_px,
                         exp_drum_measure *out)
{
    exp_raster *img = face_raster(w, d, pixel, closing_px, INFINITY);
    if (!img) return 1;
    double r = 0.5 * d->diameter;
    out->csa_percent = exp_raster_csa_percent(img, r);
    exp_angle a;
    int rc = exp_raster_surface_angle(img, r, 0.6, &a);
    out->angle_deg = fabs(a.angle_deg);
    out->angle_signed_deg = a.angle_deg;
    out->angle_fit_sd_m = a.residual_sd;
    exp_raster_free(img);
    return rc;
}

exp_drum_run_opts exp_default_drum_run_opts(void)
{
    return (exp_drum_run_opts){.rpm = 4, .max_time = 6, .sample_interval = 0.05, .window = 1.0,
                               .angle_tol_deg = 1.0, .csa_tol_percent = 0.5, .adopt_network_dt = 1,
                               .start_tilt_deg = 20.0, .average_time = 0, .network_check_interval = 0.5};
}

dem_status exp_drum_tilt(dem_world *w, double degrees)
{
    // The drum's axis is z through the origin (exp_drum_create_empty); a positive spin
    // about +z turns it counter-clockwise seen from +z, as this does.
    return dem_world_rotate(w, dem_v3(0, 0, 0), dem_v3(0, 0, 1), degrees * DEM_PI / 180.0);
}

typedef struct window_stats {
    double mean_angle, sd_angle, mean_csa, sd_csa, mean_fit;
} window_stats;

static window_stats stats_of(const exp_drum_measure *m, int from, int to)
{
    window_stats s = {0};
    int n = to - from;
    for (int k = from; k < to; ++k) s.mean_angle += m[k].angle_deg, s.mean_csa += m[k].csa_percent, s.mean_fit += m[k].angle_fit_sd_m;
    s.mean_angle /= n, s.mean_csa /= n, s.mean_fit /= n;
    for (int k = from; k < to; ++k) {
        s.sd_angle += (m[k].angle_deg - s.mean_angle) * (m[k].angle_deg - s.mean_angle);
        s.sd_csa += (m[k].csa_percent - s.mean_csa) * (m[k].csa_percent - s.mean_csa);
    }
    s.sd_angle = n > 1 ? sqrt(s.sd_angle / (n - 1)) : 0, s.sd_csa = n > 1 ? sqrt(s.sd_csa / (n - 1)) : 0;
    return s;
}

// Statistically steady: the means of the last two windows agree within the
// tolerance plus half their mean spread. A bed that slumps in avalanches
// saw-tooths by many degrees; its window means then differ by sampling
// noise of that order, and the criterion must not wait for less. While the
// bed still turns with the drum the means differ by the turned angle.
static int is_steady(const exp_drum_measure *m, int count, int per_window, const exp_drum_run_opts *o)
{
    if (count < 2 * per_window) return 0;
    window_stats a = stats_of(m, count - 2 * per_window, count - per_window), b = stats_of(m, count - per_window, count);
    double angle_tol = o->angle_tol_deg + 0.25 * (a.sd_angle + b.sd_angle);
    double csa_tol = o->csa_tol_percent + 0.25 * (a.sd_csa + b.sd_csa);
    return fabs(a.mean_angle - b.mean_angle) <= angle_tol && fabs(a.mean_csa - b.mean_csa) <= csa_tol;
}

// MSER's batch (samples) and the batches of the standard error: a batch of
// 10 % of the span kept, ~1 s at 4 rpm for a 10 s mean, an avalanche cycle.
enum { MSER_BATCH = 5, SE_BATCHES = 10 };

// The MSER rule (EXP_STEADY_MSER): whether the run may stop, and then where
// its mean starts (*from, untouched otherwise). `scratch`: 2 * count doubles.
static int mser_steady(const exp_drum_measure *m, int count, int per_window, const exp_drum_run_opts *o,
                       double *scratch, int *from)
{
    if (count < 2 * per_window) return 0;
    double *angle = scratch, *csa = scratch + count;
    for (int k = 0; k < count; ++k) angle[k] = m[k].angle_deg, csa[k] = m[k].csa_percent;
    int angle_at_limit, csa_at_limit;
    const int angle_from = exp_series_mser_start(angle, count, MSER_BATCH, &angle_at_limit);
    const int csa_from = exp_series_mser_start(csa, count, MSER_BATCH, &csa_at_limit);
    if (angle_from < 0 || csa_from < 0 || angle_at_limit || csa_at_limit) return 0;
    const int start = angle_from > csa_from ? angle_from : csa_from;
    if (count - start < 2 * per_window) return 0; // at least the windows' test's span averaged
    if (exp_series_batch_se(angle + start, count - start, SE_BATCHES) > o->se_angle_deg ||
        exp_series_batch_se(csa + start, count - start, SE_BATCHES) > o->se_csa_percent)
        return 0;
    *from = start;
    return 1;
}

// Everything of a rotation run that is not the world: what a checkpoint
// saves beside it.
typedef struct turn_state {
    exp_drum_measure *m; // one per sample
    int count, cap;
    int steady_from; // first sample of the averaged span once steady, else -1
    int steady_at;   // samples there were when the steady test first held
    uint64_t steps;
    double t0, earlier_wall_s;
} turn_state;

enum { MEASURE_DOUBLES = 4 };
// The slots of the checkpoint's "turn" array, one home for save and resume.
enum {
    TURN_T0,
    TURN_STEPS,
    TURN_WALL_S,
    TURN_START_TILT,
    TURN_STEADY_FROM,
    TURN_STEADY_AT,
    TURN_DOUBLES // (the network checks so far are the world's: dem_world_network_checks)
};
_Static_assert(sizeof(exp_drum_measure) == MEASURE_DOUBLES * sizeof(double), "a measurement is saved as 4 doubles");

static int save_turn(const dem_world *w, const exp_drum_run_opts *o, const turn_state *s, const exp_drum_result *out,
                     double wall_s, char *err, size_t len)
{
    double turn[TURN_DOUBLES];
    turn[TURN_T0] = s->t0, turn[TURN_STEPS] = (double)s->steps, turn[TURN_WALL_S] = s->earlier_wall_s + wall_s;
    turn[TURN_START_TILT] = o->start_tilt_deg;
    turn[TURN_STEADY_FROM] = s->steady_from, turn[TURN_STEADY_AT] = s->steady_at;
    dem_checkpoint_array extra[2] = {{"turn", turn, TURN_DOUBLES},
                                     {"measurements", (double *)s->m, (size_t)s->count * MEASURE_DOUBLES}};
    return dem_checkpoint_write(w, o->checkpoint->path, o->checkpoint->key, extra, 2, err, len);
}

// 1 if the run's checkpoint was there and now holds w and s; else 0, with
// a note if a checkpoint was there but could not be resumed.
static int resume_turn(dem_world *w, const exp_drum_run_opts *o, turn_state *s, exp_drum_result *out)
{
    dem_checkpoint_array extra[2] = {{"turn", NULL, 0}, {"measurements", NULL, 0}};
    char err[400];
    int rc = dem_checkpoint_read(w, o->checkpoint->path, o->checkpoint->key, extra, 2, err, sizeof err);
    int ok = rc == 0 && extra[0].count == TURN_DOUBLES && extra[1].count % MEASURE_DOUBLES == 0 &&
             extra[1].count / MEASURE_DOUBLES <= (size_t)s->cap;
    if (ok) {
        const double *turn = extra[0].data;
        s->t0 = turn[TURN_T0], s->steps = (uint64_t)turn[TURN_STEPS], s->earlier_wall_s = turn[TURN_WALL_S];
        out->start_tilt_deg = turn[TURN_START_TILT];
        s->steady_from = (int)turn[TURN_STEADY_FROM], s->steady_at = (int)turn[TURN_STEADY_AT];
        s->count = (int)(extra[1].count / MEASURE_DOUBLES);
        memcpy(s->m, extra[1].data, extra[1].count * sizeof(double));
    } else if (rc != 1)
        snprintf(out->checkpoint_note, sizeof out->checkpoint_note, "%s; the run starts afresh",
                 rc == 0 ? "checkpoint of another length of run" : err);
    free(extra[0].data), free(extra[1].data);
    return ok;
}

// A run not resumed: the turn's own contacts, the start tilt, the step the
// bed allows, and the drum set turning.
static dem_status start_turn(dem_world *w, const exp_drum_def *d, const exp_drum_run_opts *o, turn_state *s,
                             exp_drum_result *out)
{
    // The turn's own friction: a bed may have been settled with another pair
    // (a calibration's wall stage settles one bed for all its candidates).
    dem_contact_params granule = dem_scale_contact(&d->granule, d->lambda), wall = dem_scale_contact(&d->wall, d->lambda),
                       plate = dem_scale_contact(&d->end_plate, d->lambda);
    int bad = dem_world_set_granule_contact(w, &granule) || dem_world_set_wall_contact(w, 0, &wall);
    for (int k = 1; k < (d->periodic ? 1 : 3) && !bad; ++k) bad = dem_world_set_wall_contact(w, k, &plate);
    if (bad) return DEM_ERR_INVALID;
    dem_status st = o->start_tilt_deg != 0 ? exp_drum_tilt(w, o->start_tilt_deg) : DEM_OK;
    if (st != DEM_OK) return st;
    out->start_tilt_deg = o->start_tilt_deg;
    st = o->adopt_network_dt ? dem_world_adopt_network_dt(w) : dem_world_prepare(w);
    if (st != DEM_OK) return st;
    // The engine re-checks the step itself, counted in samples (the chunks
    // exp_drum_rotate steps in): each check at the end of a sample, every
    // network_check_interval of turning, also after a lowered step. The
    // schedule is the world's, so a resumed run (its checkpoint) checks on
    // where it would have.
    st = dem_world_set_network_check(w, o->network_check_interval > 0 ? o->network_check_interval : 0,
                                     o->sample_interval);
    if (st != DEM_OK) return st;
    // The end plates are part of the drum and turn with it (walls 1 and 2
    // of a full drum; they stood still before, dragging the bed's faces).
    for (int k = 0; k < (d->periodic ? 1 : 3); ++k) dem_world_set_wall_spin(w, k, o->rpm * 2.0 * DEM_PI / 60.0);
    s->t0 = dem_world_time(w);
    return DEM_OK;
}

// What the world's network checks found (dem_world_network_checks: the whole
// run's, a resumed one's included), and the wall time of this call's own.
static void report_checks(const dem_world *w, double wall_before, exp_drum_result *out)
{
    const dem_network_checks c = dem_world_network_checks(w);
    out->dt_margin_min = c.margin_min, out->dt_lowered = (int)c.lowered;
    out->network_check_wall_s = c.wall_s - wall_before;
}

dem_status exp_drum_rotate(dem_world *w, const exp_drum_def *d, const exp_drum_run_opts *o, exp_progress_fn progress,
                           void *ctx, exp_drum_result *out)
{
    memset(out, 0, sizeof *out);
    out->dt_margin_min = NAN; // no check yet (a resumed run takes its checkpoint's)
    int per_window = (int)(o->window / o->sample_interval + 0.5);
    int avg_samples = (int)(o->average_time / o->sample_interval + 0.5);
    turn_state s = {.cap = (int)(o->max_time / o->sample_interval) + 2, .steady_from = -1};
    const int mser = o->steady_rule == EXP_STEADY_MSER;
    if (mser) avg_samples = 0; // the rule stops the run itself
    s.m = malloc((size_t)s.cap * sizeof *s.m);
    double *scratch = mser ? malloc(2 * (size_t)s.cap * sizeof *scratch) : NULL;
    if (!s.m || (mser && !scratch)) return free(s.m), free(scratch), DEM_ERR_NOMEM;
    out->resumed = o->checkpoint && resume_turn(w, o, &s, out);
    dem_status st = out->resumed ? DEM_OK : start_turn(w, d, o, &s, out);
    if (st != DEM_OK) return free(s.m), free(scratch), st;
    out->earlier_wall_s = s.earlier_wall_s;
    const uint64_t steps_before = s.steps; // a resumed turn already done steps none here
    const double check_wall_before = dem_world_network_checks(w).wall_s;
    double pixel = face_pixel(d), started = exp_wall_seconds(), saved = started;
    while (s.count < s.cap && dem_world_time(w) - s.t0 < o->max_time - 0.5 * o->sample_interval &&
           !(s.steady_from >= 0 && s.count - s.steady_at >= avg_samples)) {
        // One sample's steps at the step now in use: a network check (the
        // engine's, at the end of a sample) may have lowered it.
        const uint64_t chunk = (uint64_t)(o->sample_interval / dem_world_dt(w) + 0.5);
        st = dem_world_step(w, chunk);
        s.steps += chunk;
        // DEM_ERR_UNSTABLE: the check at the sample's end refused a
        // configured step, after the steps; the sample is still measured.
        if (st != DEM_OK && st != DEM_ERR_UNSTABLE) break;
        double measure_start = exp_wall_seconds();
        int unmeasured = exp_drum_measure_now(w, d, pixel, d->closing_px, &s.m[s.count]);
        out->measure_wall_s += exp_wall_seconds() - measure_start;
        if (unmeasured) break;
        if (o->on_sample) o->on_sample(s.count, &s.m[s.count], o->sample_ctx);
        s.count++;
        if (st != DEM_OK) break;
        if (mser && s.steady_from < 0 && mser_steady(s.m, s.count, per_window, o, scratch, &s.steady_from))
            s.steady_at = s.count;
        else if (!mser && s.steady_from < 0 && is_steady(s.m, s.count, per_window, o))
            s.steady_from = s.count - 2 * per_window, s.steady_at = s.count;
        if (progress) progress("turn", dem_world_time(w) - s.t0, dem_world_granules(w).count, ctx);
        double now = exp_wall_seconds();
        if (o->checkpoint && now - saved >= o->checkpoint->every_s) {
            // A checkpoint that cannot be written costs the resume, not the run.
            if (save_turn(w, o, &s, out, now - started, out->checkpoint_note, sizeof out->checkpoint_note) == 0)
                out->checkpoint_note[0] = '\0';
            saved = now;
        }
    }
    // The two windows the steady test compared are one state: both are
    // averaged (a slumping bed's saw-tooth makes one window's mean depend on
    // where in an avalanche cycle it starts), and so is every sample after
    // them (average_time); under the MSER rule, every sample from its start.
    // Not steady: the last two windows.
    report_checks(w, check_wall_before, out);
    if (o->checkpoint && o->checkpoint->at_end && st == DEM_OK && s.steps != steps_before &&
        save_turn(w, o, &s, out, exp_wall_seconds() - started, out->checkpoint_note, sizeof out->checkpoint_note) == 0)
        out->checkpoint_note[0] = '\0';
    out->steady = s.steady_from >= 0;
    int from = out->steady ? s.steady_from : s.count > 2 * per_window ? s.count - 2 * per_window : 0;
    out->averaged_time_s = (s.count - from) * o->sample_interval;
    window_stats ws = s.count ? stats_of(s.m, from, s.count) : (window_stats){NAN, NAN, NAN, NAN, NAN};
    free(s.m), free(scratch);
    out->angle_deg = ws.mean_angle, out->angle_sd_deg = ws.sd_angle;
    out->csa_percent = ws.mean_csa, out->csa_sd_percent = ws.sd_csa, out->fit_sd_m = ws.mean_fit;
    out->simulated_time_s = dem_world_time(w) - s.t0;
    out->granules = dem_world_granules(w).count;
    out->particle_steps = (unsigned long long)s.steps * out->granules;
    if (st != DEM_OK) out->steady = 0;
    return st;
}
