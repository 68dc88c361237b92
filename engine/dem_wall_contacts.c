// SPDX-License-Identifier: MIT
// Granule–wall contacts: each wall against the granules near it (its near
// list), through the contact batch in the explicit integration, one at a
// time (also handing the implicit integrations their part) otherwise. Each
// loop is instantiated once per wall feature mask.
#include <string.h>

#include <omp.h>

#include "dem_contact_batch_internal.h"
#include "dem_prefetch_internal.h"
#include "dem_threads_internal.h"
#include "dem_wall_contacts_internal.h"

// The wall batch kernels, one per wall feature mask (see DEM_WALL_KERNEL).
DEM_FOR_MASKS_16(DEM_WALL_KERNEL)
typedef void (*wall_kernel_fn)(const dem_contact_coeffs *restrict, double, contact_batch *restrict);
static const wall_kernel_fn wall_kernels[DEM_FEAT_KERNEL_MASKS] = DEM_BY_MASK_16(wall_batch_compute_);

// Geometry and kinematics of granule i against a wall (the wall a granule
// of infinite mass and radius: m* = m_i, R* = R_i), and its lever arm; 0 if
// it does not touch.
static DEM_ALWAYS_INLINE int wall_contact_of(const dem_world *restrict w, const dem_wall *wall, size_t i,
                                             dem_contact_state *s, double *lever)
{
    const double r = w->rad[i];
    const dem_wall_touch t = dem_wall_geometry(&wall->def, w->pos[i], r);
    if (!(t.overlap > 0.0)) return 0;
    const dem_vec3 n = t.normal, wi = w->omg[i];
    const dem_vec3 spin = dem_v3_scale(wall->def.axis, wall->def.spin);
    *lever = r - w->lever_factor * t.overlap;
    // The wall surface moves at Ω × (c − axis point) at the contact point c,
    // plus its translation where it has one (only then: a zero added could
    // turn a −0 into +0, and a wall at rest keeps its results bit for bit).
    dem_vec3 v_wall = dem_v3_cross(spin, dem_v3_sub(t.point, wall->def.point));
    if (wall->translating) v_wall = dem_v3_add(v_wall, wall->def.velocity);
    s->normal = n;
    s->overlap = t.overlap;
    s->vrel = dem_v3_sub(dem_v3_add(w->vel[i], dem_v3_cross(dem_v3_scale(wi, *lever), n)), v_wall);
    s->wrel = dem_v3_sub(wi, spin);
    s->twist = 0.5 * dem_v3_dot(dem_v3_add(wi, spin), n) * w->hist_dt;
    s->root_reduced_mass = sqrt(w->mass[i]);
    s->reduced_radius = r;
    s->dt = w->hist_dt;
    return 1;
}

// Granule i against a wall, one at a time: the implicit integrations, which
// also gather the contact's damping and stiffness, come this way. The force
// on i is also kept in *kept (its entry of dem_wall.force).
static DEM_ALWAYS_INLINE void wall_force(dem_world *restrict w, const dem_wall *wall, size_t i, dem_vec3 *kept,
                                         const unsigned mask)
{
    const int hl = dem_history_len(mask);
    double *hist = wall->hist + i * (size_t)hl;
    dem_contact_state s;
    double ai;
    if (!wall_contact_of(w, wall, i, &s, &ai)) {
        for (int h = 0; h < hl; ++h) hist[h] = 0.0;
        *kept = dem_v3(0, 0, 0);
        return;
    }
    const dem_vec3 n = s.normal;
    const double r = s.reduced_radius;
    dem_contact_out out;
    dem_contact_eval(&wall->coeffs, &s, hist, &out, mask);
    w->frc[i] = dem_v3_add(w->frc[i], out.force);
    *kept = out.force;
    if ((mask & DEM_FEAT_DAMPING) && w->def.implicit_damping) add_damping(w->damp + 6 * i, out.damping_coeff, n);
    if (dem_implicit_on(w))
        dem_imp_add_block(w->imp->wall + 36 * i, n, out.damping_coeff, out.k_tangential, out.k_rolling, ai, r, w->dt);
    w->trq[i] = dem_v3_add(w->trq[i], torque_on_i(n, out.f_tangential, out.f_rolling, r, ai));
}

// Run a batch of wall contacts and add each to its granule; empties it.
// Each contact's force is also kept in kept[k], k its place in the near
// granules the batch was gathered from (b->k).
static DEM_ALWAYS_INLINE void wall_flush(dem_world *restrict w, const dem_wall *wall, contact_batch *restrict b,
                                         dem_vec3 *restrict kept, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    wall_kernels[mask & (DEM_FEAT_KERNEL_MASKS - 1)](&wall->coeffs, w->hist_dt, b);
    for (int e = 0; e < b->count; ++e) {
        const size_t i = b->i[e];
        batch_hist_out(b, e, wall->hist + i * (size_t)hl, hl);
        kept[b->k[e]] = BATCH_V3(b->f, e);
        w->frc[i] = dem_v3_add(w->frc[i], BATCH_V3(b->f, e));
        w->trq[i] = dem_v3_add(w->trq[i], BATCH_V3(b->ti, e));
    }
    b->count = 0;
}

// The data of near granule a that wall_contacts reads and adds to, asked
// for DEM_WALL_AHEAD near granules before the loop reaches it. The near
// granules are a thin layer spread through the whole ordering, so at
// N = 10^6 each came in as demand misses, the pair loop having evicted
// them. Measured at 10^6, 1 thread: the wall loop's perf samples 5 538 ->
// 3 891 (250 steps; 2 916 for the 5 000 bed in cache, same particle-steps),
// the step 1.06x (0.93-1.08, 4 rounds); 1.02x at 20 000 and 1.01x at 5 000
// (8 rounds each). A few hundred near granules stay in cache: at the
// calibration's scale (279 granules) the prefetches measured 0.98x (0.83-1.07,
// 3 rounds), so below DEM_WALL_PREFETCH_MIN_NEAR near granules none are issued.
#define DEM_WALL_AHEAD 16
#define DEM_WALL_PREFETCH_MIN_NEAR 2048
static DEM_ALWAYS_INLINE void prefetch_near_granule(const dem_world *restrict w, const dem_wall *wall, size_t a,
                                                    int hl)
{
    prefetch_vec3(w->pos + a);
    prefetch_vec3(w->vel + a);
    prefetch_vec3(w->omg + a);
    __builtin_prefetch(w->rad + a, 0, 2);
    __builtin_prefetch(w->mass + a, 0, 2);
    prefetch_vec3(w->frc + a);
    prefetch_vec3(w->trq + a);
    prefetch_springs_at(wall->hist + a * (size_t)hl, hl);
}

// The near granules near[0 … count−1] against a wall, each one's force kept
// in kept[0 … count−1] (zero where it does not touch). In the explicit
// integration the touching ones go through a contact batch, whose law runs
// in stages as the pairs' does: at the calibration's scale (279 granules)
// the walls took a fifth of the time one contact at a time (measured, the
// drum run 1.09x faster batched, 1.039x at N = 20 000). Each granule meets
// the wall once, so the additions are those of the one-at-a-time loop.
static DEM_ALWAYS_INLINE void wall_contacts(dem_world *restrict w, const dem_wall *wall, const uint32_t *near,
                                            dem_vec3 *restrict kept, size_t count, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    if (!contacts_batched(w->def.implicit_damping, dem_implicit_on(w))) {
        for (size_t k = 0; k < count; ++k) wall_force(w, wall, near[k], kept + k, mask);
        return;
    }
    contact_batch b;
    b.count = 0;
    const size_t prefetch_end = count >= DEM_WALL_PREFETCH_MIN_NEAR ? count - DEM_WALL_AHEAD : 0;
    for (size_t k = 0; k < count; ++k) {
        if (k < prefetch_end) prefetch_near_granule(w, wall, near[k + DEM_WALL_AHEAD], hl);
        const size_t i = near[k];
        double *restrict hist = wall->hist + i * (size_t)hl;
        dem_contact_state s;
        double lever;
        if (!wall_contact_of(w, wall, i, &s, &lever)) {
            for (int h = 0; h < hl; ++h) hist[h] = 0.0; // a new contact starts unloaded
            kept[k] = dem_v3(0, 0, 0);
            continue;
        }
        const int e = b.count++;
        b.i[e] = (uint32_t)i;
        b.k[e] = k;
        b.root_reduced_mass[e] = s.root_reduced_mass, b.reduced_radius[e] = s.reduced_radius;
        batch_put_state(&b, e, &s, lever, 0.0);
        batch_hist_in(&b, e, hist, hl);
        if (b.count == DEM_BATCH) wall_flush(w, wall, &b, kept, mask);
    }
    if (b.count) wall_flush(w, wall, &b, kept, mask);
}

// Only the granules near the wall (dem_wall.near): the others are out of reach.
static DEM_ALWAYS_INLINE void wall_loop(dem_world *restrict w, const dem_wall *wall, const unsigned mask)
{
#pragma omp parallel if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    {
        size_t lo, hi;
        dem_thread_block(wall->near_count, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        wall_contacts(w, wall, wall->near + lo, wall->force + lo, hi - lo, mask);
    }
}

// Granules [lo, hi) of one thread's block that are near the wall (the near
// list is in ascending order).
static DEM_ALWAYS_INLINE void wall_block(dem_world *restrict w, const dem_wall *wall, size_t lo, size_t hi,
                                         const unsigned mask)
{
    const uint32_t *near = wall->near;
    size_t a = 0, b = wall->near_count;
    while (a < b) { // first near granule at or above lo
        const size_t m = a + (b - a) / 2;
        if (near[m] < lo) a = m + 1;
        else b = m;
    }
    size_t end = a;
    while (end < wall->near_count && near[end] < hi) ++end;
    wall_contacts(w, wall, near + a, wall->force + a, end - a, mask);
}

// One specialised function per wall feature mask; the table picks it per wall.
#define DEM_WALL_LOOP(M)                                                                                \
    static void wall_loop_##M(dem_world *w, const dem_wall *wall) { wall_loop(w, wall, M); }            \
    static void wall_block_##M(dem_world *w, const dem_wall *wall, size_t lo, size_t hi)                \
    {                                                                                                   \
        wall_block(w, wall, lo, hi, M);                                                                 \
    }
DEM_FOR_MASKS_16(DEM_WALL_LOOP)

typedef void (*wall_loop_fn)(dem_world *, const dem_wall *);
typedef void (*wall_block_fn)(dem_world *, const dem_wall *, size_t, size_t);
static const wall_loop_fn wall_loops[DEM_FEAT_KERNEL_MASKS] = DEM_BY_MASK_16(wall_loop_);
static const wall_block_fn wall_blocks[DEM_FEAT_KERNEL_MASKS] = DEM_BY_MASK_16(wall_block_);

void dem_wall_contacts_begin(dem_world *w)
{
    for (int k = 0; k < w->n_walls; ++k) w->walls[k].force_carried = dem_v3(0, 0, 0);
}

void dem_wall_contacts_compute(dem_world *w)
{
    dem_wall_contacts_begin(w);
    for (int k = 0; k < w->n_walls; ++k) wall_loops[w->walls[k].features & (DEM_FEAT_KERNEL_MASKS - 1)](w, &w->walls[k]);
}

void dem_wall_contacts_block(dem_world *w, size_t lo, size_t hi)
{
    for (int k = 0; k < w->n_walls; ++k) wall_blocks[w->walls[k].features & (DEM_FEAT_KERNEL_MASKS - 1)](w, &w->walls[k], lo, hi);
}
