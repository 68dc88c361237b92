// SPDX-License-Identifier: MIT
// Private layout of dem_world, shared by the engine's own modules
// (world, neighbour list, forces, stability). Not installed, not for callers.
#ifndef DEM_WORLD_INTERNAL_H
#define DEM_WORLD_INTERNAL_H

#include "dem_world.h"

#define DEM_MAX_WALLS 8

// Below this many granules a step is a few microseconds of work and starting
// OpenMP threads would cost more than it saves.
#define DEM_OMP_MIN_GRANULES 512

// Half neighbour list in CSR form: row i holds the j > i within
// R_i + R_j + skin, sorted by j, with each pair's history next to it.
typedef struct dem_neighbor_list {
    size_t *start;   // n + 1 row offsets
    uint32_t *j;     // partner of each pair
    double *hist;    // hist_len doubles per pair
    size_t count, cap;
    size_t hist_cap; // doubles allocated in hist
    int hist_len;
} dem_neighbor_list;

typedef struct dem_wall {
    dem_wall_def def;
    char name[32];
    dem_contact_coeffs coeffs;
    unsigned features;
    int hist_len;
    double *hist; // hist_len doubles per granule
} dem_wall;

struct dem_world {
    dem_world_def def;

    // Hot granule data, structure of arrays.
    size_t n, cap;
    dem_vec3 *pos, *vel, *omg, *frc, *trq;
    double *rad, *mass, *inertia, *inv_mass, *inv_inertia;
    uint64_t *id;
    uint64_t next_id;

    // Walls: never written by the solver.
    int n_walls;
    dem_wall walls[DEM_MAX_WALLS];

    // Granule–granule contact law and the effects switched on.
    dem_contact_coeffs gg;
    unsigned features; // granule–granule mask | DEM_FEAT_PERIODIC

    // Neighbour list, its double buffer for carrying history, per-pair
    // outputs (force on i, torque on i, torque on j) and the reverse index
    // (for each granule, the pairs in which it is j, ascending).
    dem_neighbor_list nl, nl_old;
    dem_vec3 *pair_f, *pair_ti, *pair_tj;
    size_t pair_cap;
    size_t *rev_start, *rev_pair;
    dem_vec3 *pos_at_build;
    double skin;
    int list_valid;
    uint64_t rebuilds;

    double time, dt, dt_limit, lever_factor;
    double hist_dt; // dt when positions moved since the last force evaluation, else 0
    int moved;
    uint64_t step;
    int prepared, forces_valid;
    char err[512];
    char dt_report[512];
};

// dem_neighbor.c
int dem_nl_rebuild(dem_world *w);
void dem_nl_free(dem_neighbor_list *nl);
double dem_nl_max_displacement2(const dem_world *w);
dem_vec3 dem_world_min_image(const dem_world *w, dem_vec3 d);

// dem_forces.c
void dem_forces_compute(dem_world *w);

// dem_world.c
int dem_world_set_error(dem_world *w, const char *fmt, ...);

#endif
