// SPDX-License-Identifier: MIT
// The poured cylinder (section 4.1): pour, cut at the rim, settle, count.
#include "exp_cylinder.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_scaling.h"
#include "exp_contact_rules.h"
#include "exp_cost.h"
#include "exp_pour.h"

#define LAYER_KE_RATIO 1e-2
#define LAYER_MAX_TIME 0.6
#define SETTLE_KE_RATIO 1e-6
#define SETTLE_MAX_TIME 2.0
#define CHECK_EVERY 0.05 // s between rest checks

exp_cylinder_def exp_default_cylinder_def(void)
{
    exp_cylinder_def d;
    memset(&d, 0, sizeof d);
    d.diameter = 0.1;
    d.depth = 0.04;
    d.lambda = 4096;
    d.gsd = dem_default_gsd();
    d.density = 1800;
    d.granule = dem_default_world_def().granule;
    d.wall = d.granule; // a metallic container; its friction is the wall material's
    d.seed = 1;
    return d;
}

int exp_cylinder_check(const exp_cylinder_def *d, char *msg, size_t len)
{
    char sub[256];
    if (!(isfinite(d->diameter) && d->diameter > 0)) return exp_fail(msg, len, "diameter = %g: must be > 0", d->diameter);
    if (!(isfinite(d->depth) && d->depth > 0)) return exp_fail(msg, len, "depth = %g: must be > 0", d->depth);
    if (!(isfinite(d->density) && d->density > 0)) return exp_fail(msg, len, "density = %g: must be > 0", d->density);
    if (!(isfinite(d->lambda) && d->lambda >= 1) || dem_scale_check(d->lambda, sub, sizeof sub))
        return exp_fail(msg, len, "lambda = %g: must be finite and >= 1 (lambda = N_real/N_scaled, eq. 15)", d->lambda);
    if (dem_gsd_check(&d->gsd, sub, sizeof sub)) return exp_fail(msg, len, "%s", sub);
    if (dem_contact_params_check(&d->granule, sub, sizeof sub)) return exp_fail(msg, len, "granule_contact.%s", sub);
    if (dem_contact_params_check(&d->wall, sub, sizeof sub)) return exp_fail(msg, len, "wall_contact.%s", sub);
    // The pour's lattice pitch is 1.05 d_max and keeps 0.55 pitch off the wall
    // (exp_pour_to_rim): the container must hold a lattice point and a granule.
    double dmax = dem_gsd_max_diameter(&d->gsd) * cbrt(d->lambda);
    if (d->diameter < 2.2 * dmax || d->depth < dmax)
        return exp_fail(msg, len,
                        "lambda = %g: the largest scaled granule (%.3g m) does not fit the %.3g x %.3g m container",
                        d->lambda, dmax, d->diameter, d->depth);
    return 0;
}

exp_cylinder_cost exp_cylinder_predict_cost(const exp_cylinder_def *d)
{
    const double solid_fraction = 0.535, pour_time = 3.0;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    double r = 0.5 * d->diameter, volume = DEM_PI * r * r * d->depth;
    double n = (double)dem_gsd_count_for_volume(&gsd, solid_fraction * volume);
    double dt_crit = exp_lightest_dt_crit(&d->gsd, d->density, d->granule.k_n, d->lambda);
    return (exp_cylinder_cost){.granules = n,
                               .particle_steps = n * pour_time / (EXP_POUR_STEP_FRACTION * dt_crit),
                               .memory_mb = exp_predicted_peak_memory_mb(n)};
}

static dem_world *create_container(const exp_cylinder_def *d, char *err, size_t len)
{
    double r = 0.5 * d->diameter;
    dem_world_def def = dem_default_world_def();
    def.granule = dem_scale_contact(&d->granule, d->lambda);
    def.domain_lo = dem_v3(-1.2 * r, -0.01, -1.2 * r);
    def.domain_hi = dem_v3(1.2 * r, 4 * d->depth, 1.2 * r);
    dem_world *w = dem_world_create(&def, err, len);
    if (!w) return NULL;
    dem_contact_params wall = d->wall; // the container's friction and dashpot, as given
    wall.k_n = wall.k_s = wall.k_r = exp_boundary_stiffness(d->granule.k_n);
    wall = dem_scale_contact(&wall, d->lambda);
    dem_wall_def side = {.kind = DEM_WALL_CYLINDER, .point = {0, 0, 0}, .axis = {0, 1, 0}, .radius = r,
                         .contact = wall, .name = "container"};
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .contact = wall, .name = "floor"};
    if (dem_world_add_wall(w, &side) < 0 || dem_world_add_wall(w, &floor) < 0) {
        exp_fail(err, len, "%s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    return w;
}

int exp_count_bed_contacts(const dem_world *w, double dmax, exp_interior_fn interior, const void *ctx,
                           exp_cylinder_result *out, double *solid_volume)
{
    dem_diagnostics diag = dem_world_diagnose(w);
    out->granules = diag.granules;
    out->coordination = diag.coordination;
    out->wall_contacts_per_granule = diag.granules ? (double)diag.wall_contacts / (double)diag.granules : 0;
    dem_granules_view g = dem_world_granules(w);
    unsigned *z = malloc((g.count + 1) * sizeof *z);
    if (!z) return 1;
    dem_world_contact_counts(w, z);
    double top = -INFINITY, sum_in = 0, solid = 0;
    size_t n_in = 0;
    for (size_t i = 0; i < g.count; ++i) top = fmax(top, g.position[i].y);
    for (size_t i = 0; i < g.count; ++i) {
        solid += 4.0 / 3.0 * DEM_PI * g.radius[i] * g.radius[i] * g.radius[i];
        if (interior(g.position[i], top, dmax, ctx)) sum_in += z[i], n_in++;
    }
    free(z);
    out->coordination_interior = n_in ? sum_in / (double)n_in : NAN;
    *solid_volume = solid;
    return 0;
}

// At least d_max from the container's side and floor (y = 0) and below the free surface.
static int inside_cylinder(dem_vec3 p, double top, double dmax, const void *ctx)
{
    double r = 0.5 * ((const exp_cylinder_def *)ctx)->diameter;
    return sqrt(p.x * p.x + p.z * p.z) < r - dmax && p.y > dmax && p.y < top - dmax;
}

dem_world *exp_cylinder_run(const exp_cylinder_def *d, exp_progress_fn progress, void *ctx, exp_cylinder_result *out,
                            char *err, size_t len)
{
    char sub[256];
    memset(out, 0, sizeof *out);
    if (len) err[0] = '\0';
    if (dem_scale_check(d->lambda, sub, sizeof sub) || dem_gsd_check(&d->gsd, sub, sizeof sub) ||
        dem_contact_params_check(&d->granule, sub, sizeof sub)) {
        exp_fail(err, len, "poured cylinder: %s", sub);
        return NULL;
    }
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    dem_world *w = create_container(d, err, len);
    if (!w) return NULL;
    exp_rim_pour pour = {"poured cylinder", 0.5 * d->diameter, d->depth, 3.0, &gsd, d->seed,
                         dem_scale_density(d->density, d->lambda), LAYER_KE_RATIO, LAYER_MAX_TIME, CHECK_EVERY};
    if (exp_pour_to_rim(w, &pour, progress, ctx, err, len) ||
        exp_run_until_rest(w, gsd.median_diameter, SETTLE_KE_RATIO, SETTLE_MAX_TIME, CHECK_EVERY, progress, ctx,
                           "settle")) {
        if (!err[0]) exp_fail(err, len, "%s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    double solid, r = 0.5 * d->diameter;
    if (exp_count_bed_contacts(w, dem_gsd_max_diameter(&gsd), inside_cylinder, d, out, &solid)) {
        exp_fail(err, len, "poured cylinder: out of memory counting contacts");
        dem_world_destroy(w);
        return NULL;
    }
    out->solid_fraction = solid / (DEM_PI * r * r * d->depth);
    out->simulated_time_s = dem_world_time(w);
    out->particle_steps = (double)dem_world_particle_steps(w);
    return w;
}
