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

// What a pair's contact law needs of its two granules' sizes and masses:
// sqrt(m*) for the dashpot of eq. 4, and R* for the rolling spring of eq. 12
// and the torque of eq. 10. They change only with the granules, so they are
// computed when the list is built, not at every contact and step: two
// divisions and a square root fewer per contact, in a batch kernel whose
// time goes mostly to waiting on its divider (measured, 1.034x the step at
// N = 20 000, median of 10 interleaved rounds, 16 bytes per listed pair).
typedef struct dem_pair_constants {
    double root_reduced_mass, reduced_radius;
} dem_pair_constants;

// Half neighbour list in CSR form: row i holds the j > i within
// R_i + R_j + skin, sorted by j, with each pair's history next to it.
typedef struct dem_neighbor_list {
    size_t *start;   // n + 1 row offsets
    uint32_t *j;     // partner of each pair
    uint32_t *row;   // row of each pair (its granule i): pair loops walk pieces of pairs across rows
    dem_pair_constants *constants; // of each pair
    double *hist;    // hist_len doubles per pair
    size_t count, cap;
    size_t hist_cap; // doubles allocated in hist
    size_t rows;     // granules the list was built for (start has rows + 1)
    int hist_len;
} dem_neighbor_list;

typedef struct dem_wall {
    dem_wall_def def;
    char name[32];
    dem_contact_coeffs coeffs;
    unsigned features;
    int hist_len;
    double *hist; // hist_len doubles per granule
    // Granules within one skin of this wall at the last list rebuild, in
    // ascending order: the only ones that can touch it before the next (walls
    // never move, and no granule moves half a skin between rebuilds).
    uint32_t *near;
    size_t near_count, near_cap;
} dem_wall;

// One contact as the implicit spring solve sees it (dem_forces.c): normal,
// dashpot γ applied, stiffness of the sticking tangential and rolling springs
// (0 while sliding), lever arms and R*. All zero for an open contact.
typedef struct dem_imp_contact {
    dem_vec3 n;
    double g, kt, kr, ai, aj, rs;
} dem_imp_contact;

// Scratch of the implicit spring solve, allocated on first use.
typedef struct dem_imp_scratch {
    dem_imp_contact *pair; // per neighbour-list pair
    dem_vec3 *pf, *pti, *ptj; // per pair: operator output (force on i, torques on i and j)
    double *wall;  // per granule, 36: walls' part of the diagonal block
    double *chol;  // per granule, 36: Cholesky factor of the diagonal block (preconditioner)
    double *b, *r, *z, *p, *q; // per granule, 6 each
    double *partial;           // per chunk, for reproducible dot products
    size_t pair_cap, cap, chunk_cap;
    int on; // implicit springs on and scratch in place for this force evaluation
} dem_imp_scratch;

// Statistics of the implicit spring solve (conjugate-gradient iterations).
typedef struct dem_imp_stats {
    uint64_t solves, iterations;
    int max_iterations, last_iterations, unconverged;
} dem_imp_stats;

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
    // outputs (force on i, torque on i, torque on j: written only for pairs
    // crossing a thread's block, dem_forces.c) and the reverse index (for
    // each granule, the pairs in which it is j, ascending).
    dem_neighbor_list nl, nl_old;
    dem_vec3 *pair_f, *pair_ti, *pair_tj;
    dem_vec3 *pair_n;  // contact normal, for the implicit dashpot
    double *pair_g;    // dashpot coefficient applied, for the implicit dashpot
    double *damp;      // per granule, 6 doubles: Σγ n nᵀ (xx yy zz xy xz yz)
    // Implicit springs: per granule, the velocity and spin rates the solve
    // found (6 doubles: dv/dt, dω/dt), used by both half kicks; and scratch.
    double *acc;
    int springs_requested; // dem_world_def.implicit_springs as given (may be auto)
    dem_imp_scratch imp;
    dem_imp_stats imp_stats;
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

// Geometry of a granule against a wall: overlap, unit normal from the granule
// towards the wall, and the contact point on the wall surface.
typedef struct dem_wall_touch {
    double overlap;
    dem_vec3 normal, point;
} dem_wall_touch;

static inline dem_wall_touch dem_wall_geometry(const dem_wall_def *wd, dem_vec3 p, double r)
{
    dem_wall_touch t = {-1.0, {0, 0, 0}, {0, 0, 0}};
    if (wd->kind == DEM_WALL_CYLINDER) {
        dem_vec3 d = dem_v3_sub(p, wd->point);
        dem_vec3 radial = dem_v3_axpy(-dem_v3_dot(d, wd->axis), wd->axis, d);
        double rho = dem_v3_norm(radial);
        if (rho <= 0.0) return t;
        t.normal = dem_v3_scale(radial, 1.0 / rho);
        t.overlap = r + rho - wd->radius;
        t.point = dem_v3_axpy(wd->radius - rho, t.normal, p);
        return t;
    }
    double dist = dem_v3_dot(dem_v3_sub(p, wd->point), wd->normal);
    t.normal = dem_v3_neg(wd->normal);
    t.overlap = r - dist;
    t.point = dem_v3_axpy(-dist, wd->normal, p);
    if (wd->kind == DEM_WALL_DISC && dem_v3_norm(dem_v3_sub(t.point, wd->point)) > wd->radius) t.overlap = -1.0;
    return t;
}

// Length of the domain along the periodic axis (0 if none).
static inline double dem_world_period(const dem_world *w)
{
    const int a = w->def.periodic_axis;
    return a < 0 ? 0.0 : dem_v3_comp(w->def.domain_hi, a) - dem_v3_comp(w->def.domain_lo, a);
}

// dem_neighbor.c
int dem_nl_rebuild(dem_world *w);
void dem_nl_free(dem_neighbor_list *nl);
double dem_nl_max_displacement2(const dem_world *w);
// The same over granules [lo, hi) only, for a caller already on a thread.
double dem_nl_max_displacement2_range(const dem_world *w, size_t lo, size_t hi);
dem_vec3 dem_world_min_image(const dem_world *w, dem_vec3 d);

// dem_forces.c
void dem_forces_compute(dem_world *w);
// Granules [lo, hi) of thread t of nt: contiguous blocks, so with the
// granules sorted along a space-filling curve few pairs cross a block's edge.
void dem_thread_block(size_t n, int t, int nt, size_t *lo, size_t *hi);
// Whether the force evaluation and the step run on several threads.
int dem_forces_threaded(const dem_world *w);
// The force evaluation split by thread blocks, for the step loop that runs
// on a team of threads in one parallel region (dem_world_step): whether this
// world can be evaluated that way (the explicit integration); the rows of
// block [lo, hi) with a pair reaching past hi, into `rows` (their count); on
// any threads, dem_forces_crossing for such rows of a block ending at `end`
// (each row on one thread), computing those pairs into their slots; then a
// barrier, and on each thread dem_forces_block (the block's other pairs and
// its walls). Bitwise the same forces as dem_forces_compute.
int dem_forces_blockwise(const dem_world *w);
size_t dem_forces_crossing_rows(const dem_world *w, size_t lo, size_t hi, uint32_t *rows);
void dem_forces_crossing(dem_world *w, const uint32_t *rows, size_t count, size_t end);
void dem_forces_block(dem_world *w, size_t lo, size_t hi);
// The lowest and highest centre of granules [lo, hi) along the periodic
// axis (+inf and −inf for none, or without the axis), and whether centres
// spanning [lowest, highest] there are near enough for one wrap to give
// every pair's minimum image.
// dem_forces_crossing and dem_forces_block take that as given: their caller
// checks it after each drift (dem_forces_compute checks it itself).
void dem_forces_axis_extent(const dem_world *w, size_t lo, size_t hi, double *lowest, double *highest);
int dem_forces_one_wrap(const dem_world *w, double lowest, double highest);
// Implicit springs: solve (M + Δt C + Δt²/4 K_t) a = F + M g for every
// granule's rates a (into w->acc); 0 on success, 1 out of memory.
int dem_implicit_solve(dem_world *w);
void dem_imp_scratch_free(dem_imp_scratch *s);

// dem_world.c
int dem_world_set_error(dem_world *w, const char *fmt, ...);

#endif
