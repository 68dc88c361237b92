// SPDX-License-Identifier: MIT
#include "exp_pour.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include <gsl/gsl_rng.h>

#include "dem_vec.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

double exp_bed_surface(const dem_world *w, double floor_y)
{
    dem_granules_view g = dem_world_granules(w);
    if (g.count == 0) return floor_y;
    double *tops = malloc(g.count * sizeof *tops);
    if (!tops) return INFINITY;
    for (size_t i = 0; i < g.count; ++i) tops[i] = g.position[i].y + g.radius[i];
    qsort(tops, g.count, sizeof *tops, cmp_double);
    double top = tops[(size_t)(0.98 * (double)(g.count - 1))];
    free(tops);
    return top;
}

// Does a granule of radius r at p overlap any granule reaching above `above`?
static int overlaps(const dem_world *w, dem_vec3 p, double r, double above)
{
    dem_granules_view g = dem_world_granules(w);
    for (size_t i = 0; i < g.count; ++i) {
        if (g.position[i].y + g.radius[i] < above) continue;
        double reach = r + g.radius[i];
        if (dem_v3_norm2(dem_v3_sub(g.position[i], p)) < reach * reach) return 1;
    }
    return 0;
}

size_t exp_pour_layer(dem_world *w, const exp_pour_region *region, double floor_y, const double *diam, size_t next,
                      size_t n, double pitch, double density)
{
    double y0 = exp_bed_surface(w, floor_y) + 0.5 * pitch;
    size_t placed = 0;
    for (double y = y0; y < region->hi.y && next + placed < n; y += pitch)
        for (double x = region->lo.x; x <= region->hi.x && next + placed < n; x += pitch)
            for (double z = region->lo.z; z <= region->hi.z && next + placed < n; z += pitch) {
                size_t k = next + placed;
                dem_vec3 p = dem_v3(x, y, z);
                if (!region->inside(p, region->ctx) || overlaps(w, p, 0.5 * diam[k], y0 - pitch)) continue;
                // A small sideways velocity so layers do not stack in columns, with
                // a component along z too: without it a drum bed poured on lattice
                // planes z = const stays in them (every contact normal lies in the
                // plane), a stack of uncoupled 2D monolayers (results/drum_geometry).
                dem_vec3 v = dem_v3(0.05 * sin(1.3 * (double)k), -0.1, 0.05 * cos(1.7 * (double)k));
                if (dem_world_add_granule(w, p, v, dem_v3(0, 0, 0), 0.5 * diam[k], density) < 0) return placed;
                placed++;
            }
    return placed;
}

// Spheres already in a band, in a uniform grid of cells one largest
// diameter wide, for the overlap test of random sequential addition.
typedef struct band_grid {
    dem_vec3 lo;
    double cell;
    int nx, ny, nz;
    int *head, *next; // per cell: first sphere; per sphere: the next in its cell (-1 ends)
    dem_vec3 *p;
    double *r;
    size_t count, cap;
} band_grid;

static int cell_of(const band_grid *g, dem_vec3 p, int *ix, int *iy, int *iz)
{
    *ix = (int)floor((p.x - g->lo.x) / g->cell), *iy = (int)floor((p.y - g->lo.y) / g->cell);
    *iz = (int)floor((p.z - g->lo.z) / g->cell);
    return *ix >= 0 && *ix < g->nx && *iy >= 0 && *iy < g->ny && *iz >= 0 && *iz < g->nz;
}

static size_t cell_index(const band_grid *g, int ix, int iy, int iz)
{
    return ((size_t)iz * (size_t)g->ny + (size_t)iy) * (size_t)g->nx + (size_t)ix;
}

static void grid_insert(band_grid *g, dem_vec3 p, double r)
{
    int ix, iy, iz;
    if (g->count == g->cap || !cell_of(g, p, &ix, &iy, &iz)) return; // outside the band: cannot touch it
    size_t c = cell_index(g, ix, iy, iz);
    g->p[g->count] = p, g->r[g->count] = r, g->next[g->count] = g->head[c];
    g->head[c] = (int)g->count++;
}

static int grid_overlaps(const band_grid *g, dem_vec3 p, double r)
{
    int cx, cy, cz;
    cell_of(g, p, &cx, &cy, &cz);
    for (int iz = cz - 1; iz <= cz + 1; ++iz)
        for (int iy = cy - 1; iy <= cy + 1; ++iy)
            for (int ix = cx - 1; ix <= cx + 1; ++ix) {
                if (ix < 0 || iy < 0 || iz < 0 || ix >= g->nx || iy >= g->ny || iz >= g->nz) continue;
                for (int k = g->head[cell_index(g, ix, iy, iz)]; k >= 0; k = g->next[k]) {
                    double reach = r + g->r[k];
                    if (dem_v3_norm2(dem_v3_sub(g->p[k], p)) < reach * reach) return 1;
                }
            }
    return 0;
}

static void grid_free(band_grid *g) { free(g->head), free(g->next), free(g->p), free(g->r); }

// The band [y0, top] of the region, one cell more all round, holding the
// granules already there and room for `more`.
static int grid_make(band_grid *g, const dem_world *w, const exp_pour_region *region, double y0, double top,
                     double cell, size_t more)
{
    dem_granules_view v = dem_world_granules(w);
    *g = (band_grid){.lo = dem_v3(region->lo.x - cell, y0 - cell, region->lo.z - cell), .cell = cell};
    g->nx = (int)((region->hi.x - region->lo.x) / cell) + 3, g->ny = (int)((top - y0) / cell) + 3;
    g->nz = (int)((region->hi.z - region->lo.z) / cell) + 3;
    size_t cells = (size_t)g->nx * (size_t)g->ny * (size_t)g->nz;
    g->cap = v.count + more;
    g->head = malloc(cells * sizeof *g->head), g->next = malloc(g->cap * sizeof *g->next);
    g->p = malloc(g->cap * sizeof *g->p), g->r = malloc(g->cap * sizeof *g->r);
    if (!g->head || !g->next || !g->p || !g->r) return grid_free(g), 1;
    for (size_t c = 0; c < cells; ++c) g->head[c] = -1;
    for (size_t i = 0; i < v.count; ++i) grid_insert(g, v.position[i], v.radius[i]);
    return 0;
}

size_t exp_pack_band(dem_world *w, const exp_pour_region *region, double floor_y, double top, const double *diam,
                     size_t next, size_t n, double density, unsigned long long seed, int tries)
{
    double y0 = exp_bed_surface(w, floor_y), largest = 0;
    for (size_t k = next; k < n; ++k) largest = fmax(largest, diam[k]);
    dem_granules_view v = dem_world_granules(w);
    for (size_t i = 0; i < v.count; ++i) largest = fmax(largest, 2 * v.radius[i]);
    if (!(top > y0) || next >= n) return 0;
    band_grid g;
    if (grid_make(&g, w, region, y0, top, largest, n - next)) return 0;
    gsl_rng *rng = gsl_rng_alloc(gsl_rng_mt19937);
    if (!rng) return grid_free(&g), 0;
    gsl_rng_set(rng, (unsigned long)seed);
    size_t placed = 0;
    for (size_t k = next; k < n; ++k) {
        double r = 0.5 * diam[k];
        int found = 0;
        dem_vec3 p;
        for (int t = 0; t < tries && !found; ++t) {
            p = dem_v3(region->lo.x + (region->hi.x - region->lo.x) * gsl_rng_uniform(rng),
                       y0 + r + (top - y0 - r) * gsl_rng_uniform(rng),
                       region->lo.z + (region->hi.z - region->lo.z) * gsl_rng_uniform(rng));
            found = region->inside(p, region->ctx) && !grid_overlaps(&g, p, r);
        }
        if (!found || dem_world_add_granule(w, p, dem_v3(0, 0, 0), dem_v3(0, 0, 0), r, density) < 0) break;
        grid_insert(&g, p, r);
        placed++;
    }
    gsl_rng_free(rng);
    grid_free(&g);
    return placed;
}

static int keep_below(const dem_granules_view *g, size_t i, void *ctx) { return g->position[i].y <= *(double *)ctx; }

void exp_remove_above(dem_world *w, double y) { dem_world_remove_granules(w, keep_below, &y); }

double exp_ke_ratio(const dem_world *w, double d50)
{
    dem_diagnostics d = dem_world_diagnose(w);
    return d.granules ? (d.ke_translational + d.ke_rotational) / (d.mass * 9.81 * d50) : 0.0;
}

int exp_run_for(dem_world *w, double seconds, exp_progress_fn progress, void *ctx, const char *phase)
{
    uint64_t chunk = (uint64_t)(fmin(0.01, seconds) / dem_world_dt(w)) + 1;
    double t_end = dem_world_time(w) + seconds;
    while (dem_world_time(w) < t_end) {
        if (dem_world_step(w, chunk) != DEM_OK) return 1;
        if (progress) progress(phase, dem_world_time(w), dem_world_granules(w).count, ctx);
    }
    return 0;
}

int exp_run_until_rest(dem_world *w, double d50, double ratio, double max_time, double check_every,
                       exp_progress_fn progress, void *ctx, const char *phase)
{
    for (double t = 0; t < max_time; t += check_every) {
        if (exp_run_for(w, check_every, progress, ctx, phase)) return 1;
        if (exp_ke_ratio(w, d50) < ratio) break;
    }
    return 0;
}

static int inside_cylinder(dem_vec3 p, const void *ctx)
{
    double inner = *(const double *)ctx;
    return p.x * p.x + p.z * p.z <= inner * inner;
}

int exp_pour_to_rim(dem_world *w, const exp_rim_pour *p, exp_progress_fn progress, void *ctx, char *err, size_t len)
{
    double pitch = 1.05 * dem_gsd_max_diameter(p->gsd), inner = p->radius - 0.55 * pitch;
    size_t cap = 3 * dem_gsd_count_for_volume(p->gsd, 0.6 * DEM_PI * p->radius * p->radius * p->depth) + 16, next = 0;
    double *diam = malloc(cap * sizeof *diam);
    if (!diam || dem_gsd_sample(p->gsd, p->seed, cap, diam))
        return free(diam), exp_fail(err, len, "%s: cannot sample sizes", p->what);
    exp_pour_region region = {dem_v3(-inner, 0, -inner), dem_v3(inner, p->headroom * p->depth, inner), inside_cylinder,
                              &inner};
    while (exp_bed_surface(w, 0) < p->depth) {
        size_t placed = next < cap ? exp_pour_layer(w, &region, 0, diam, next, cap, pitch, p->density) : 0;
        if (placed == 0) return free(diam), exp_fail(err, len, "%s: ran out of room or sizes while pouring", p->what);
        if (dem_world_prepare(w) != DEM_OK || exp_run_until_rest(w, p->gsd->median_diameter, p->layer_ke_ratio,
                                                                 p->layer_max_time, p->check_every, progress, ctx, "pour"))
            return free(diam), exp_fail(err, len, "%s", dem_world_error(w));
        next += placed;
    }
    free(diam);
    exp_remove_above(w, p->depth);
    return 0;
}
