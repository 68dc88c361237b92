// SPDX-License-Identifier: MIT
// The world's state: the private layout of struct dem_world, for the engine
// modules that work on a whole world (its lists, forces, integrators, step
// loop, network stability, diagnostics, ordering, checkpoints, and its
// lifetime in dem_world.c). The modules below it (domain, threads,
// neighbour list, walls, the contact law, the stability of a network) do not
// see it: they work on the arrays they are given. Not for callers.
#ifndef DEM_STATE_INTERNAL_H
#define DEM_STATE_INTERNAL_H

#include <float.h>
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>

#include "dem_domain_internal.h"
#include "dem_neighbor_internal.h"
#include "dem_walls_internal.h"
#include "dem_world.h"

// Scratch of the implicit spring solve (dem_implicit.c), its own.
typedef struct dem_implicit dem_implicit;

// Statistics of the implicit spring solve (conjugate-gradient iterations).
typedef struct dem_imp_stats {
    uint64_t solves, iterations;
    int max_iterations, last_iterations, unconverged;
} dem_imp_stats;

struct dem_world {
    dem_world_def def; // as given: never rewritten

    // Hot granule data, structure of arrays.
    size_t n, cap;
    dem_vec3 *pos, *vel, *omg, *frc, *trq;
    double *rad, *mass, *inertia, *inv_mass, *inv_inertia;
    uint64_t *id;
    uint64_t next_id;
    // Fixed granules (dem_world_set_granule_fixed): 1 where held still; the
    // kicks and the drift pass over them. Their mass stays theirs in every
    // contact (LIGGGHTS' fix freeze does the same).
    unsigned char *fixed;
    size_t n_fixed;

    // Walls: moved by the step only as their prescribed motion says
    // (dem_wall_def.motion).
    int n_walls;
    dem_wall walls[DEM_MAX_WALLS];

    // Granule–granule contact law and the effects switched on.
    dem_contact_coeffs gg;
    unsigned features; // granule–granule mask | DEM_FEAT_PERIODIC

    // Neighbour list, its double buffer for carrying history, per-pair
    // outputs (force on i, torque on i, torque on j: written only for pairs
    // crossing a thread's block, dem_pairs.c) and the reverse index (for
    // each granule, the pairs in which it is j, ascending).
    dem_neighbor_list nl, nl_old;
    dem_vec3 *pair_f, *pair_ti, *pair_tj;
    dem_vec3 *pair_n;  // contact normal, for the implicit dashpot
    double *pair_g;    // dashpot coefficient applied, for the implicit dashpot
    double *damp;      // per granule, 6 doubles: Σγ n nᵀ (xx yy zz xy xz yz)
    // Implicit springs: per granule, the velocity and spin rates the solve
    // found (6 doubles: dv/dt, dω/dt), used by both half kicks; and scratch.
    double *acc;
    int implicit_springs; // decided by dem_world_prepare from def.implicit_springs (which may be auto)
    dem_implicit *imp;
    dem_imp_stats imp_stats;
    size_t pair_cap;
    size_t *rev_start, *rev_pair;
    dem_vec3 *pos_at_build;
    double skin;
    int list_valid;
    uint64_t rebuilds;

    int threads; // of its parallel regions (dem_world_def.threads, dem_world_set_threads); 0: OpenMP's default

    double time, dt, dt_limit, lever_factor;
    double hist_dt; // dt when positions moved since the last force evaluation, else 0
    int moved;
    uint64_t step;
    uint64_t particle_steps; // Σ granules over the steps taken (dem_world_particle_steps)
    // The step's own network checks (def.network_check_interval, dem_step.c):
    // the steps since the last one, on which the next is scheduled (a resumed
    // run checks where the run that wrote the checkpoint would have), and
    // what they found.
    uint64_t steps_since_check;
    dem_network_checks checks;
    int prepared, forces_valid;
    char err[512];
    char dt_report[512];
};

// The team size of this world's parallel regions: its own thread count, or
// OpenMP's default for 0.
static inline int dem_world_team(const dem_world *w) { return w->threads > 0 ? w->threads : omp_get_max_threads(); }

static inline dem_domain dem_world_domain(const dem_world *w)
{
    return dem_domain_make(w->def.domain_lo, w->def.domain_hi, w->def.periodic_axis);
}

// Length of the domain along the periodic axis (0 if none).
static inline double dem_world_period(const dem_world *w)
{
    const int a = w->def.periodic_axis;
    return a < 0 ? 0.0 : dem_v3_comp(w->def.domain_hi, a) - dem_v3_comp(w->def.domain_lo, a);
}

static inline dem_vec3 dem_world_min_image(const dem_world *w, dem_vec3 d)
{
    const dem_domain dom = dem_world_domain(w);
    return dem_domain_min_image(&dom, d);
}

// The message of dem_world_error; returns 1, so `return dem_world_set_error(...)` fails.
static inline int dem_world_set_error(dem_world *w, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));
static inline int dem_world_set_error(dem_world *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(w->err, sizeof w->err, fmt, ap);
    va_end(ap);
    return 1;
}

// Lightest granule, smallest and largest radius (0 for none), over the arrays:
// the public dem_world_min_mass & co. and the modules below the world alike.
static inline double dem_granules_min_mass(const dem_world *w)
{
    double m = DBL_MAX;
    for (size_t i = 0; i < w->n; ++i) m = w->mass[i] < m ? w->mass[i] : m;
    return w->n ? m : 0.0;
}

static inline double dem_granules_min_radius(const dem_world *w)
{
    double r = DBL_MAX;
    for (size_t i = 0; i < w->n; ++i) r = w->rad[i] < r ? w->rad[i] : r;
    return w->n ? r : 0.0;
}

static inline double dem_granules_max_radius(const dem_world *w)
{
    double r = 0.0;
    for (size_t i = 0; i < w->n; ++i) r = w->rad[i] > r ? w->rad[i] : r;
    return r;
}

#endif
