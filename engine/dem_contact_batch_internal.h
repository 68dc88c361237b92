// SPDX-License-Identifier: MIT
// The contact batch: contacts gathered 32 at a time in structure-of-arrays
// form and run through the contact law in stages, each a loop the compiler
// vectorises. Used by the pair loops (dem_pairs.c) and the wall contacts
// (dem_wall_contacts.c), each of which instantiates the kernels it calls.
#ifndef DEM_CONTACT_BATCH_INTERNAL_H
#define DEM_CONTACT_BATCH_INTERNAL_H

#include "dem_pair_contact_internal.h"

// The explicit integration's pairs go through a batch: the touching pairs of
// a stretch of rows are gathered into structure-of-arrays form, the contact
// law runs over the batch in stages, each a loop the compiler vectorises
// (the law is branch-free; -fno-trapping-math lets it evaluate both sides of
// a select), and the results are added to the granules in the pairs' own
// order — the serial order, so the sums and the final state are bitwise
// those of the one-pair-at-a-time loop.
#define DEM_BATCH 32

typedef struct contact_batch {
    int count;
    uint32_t i[DEM_BATCH], j[DEM_BATCH];
    size_t k[DEM_BATCH];
    // 1: not a contact to compute but a pair crossing the thread's block,
    // whose slot (computed before the barrier) is added to i at this place
    // in the order. Its lane of the law runs on neutral data and is dropped.
    unsigned char slot[DEM_BATCH];
    double d[3][DEM_BATCH];
    double rad[2][DEM_BATCH], root_reduced_mass[DEM_BATCH], reduced_radius[DEM_BATCH];
    double vel[6][DEM_BATCH], omg[6][DEM_BATCH]; // x y z of i, then of j
    double hist[6][DEM_BATCH];
    double f[3][DEM_BATCH], ti[3][DEM_BATCH], tj[3][DEM_BATCH];
    // Between the stages of batch_compute: geometry, the springs' drive, and
    // the advanced springs (tangential x y z, then rolling) and their forces.
    double n[3][DEM_BATCH], overlap[DEM_BATCH], vrel[3][DEM_BATCH], wrel[3][DEM_BATCH], twist[DEM_BATCH];
    double lever[2][DEM_BATCH];
    double fn_abs[DEM_BATCH], vt[3][DEM_BATCH], vr[3][DEM_BATCH];
    double k_t[DEM_BATCH], inv_k_t[DEM_BATCH]; // Hertz–Mindlin: the tangential spring at this overlap
    double spring[6][DEM_BATCH], spring_force[6][DEM_BATCH];
} contact_batch;

static DEM_ALWAYS_INLINE void batch_put_side(contact_batch *restrict b, int e, int side, const pair_side *s)
{
    b->rad[side][e] = s->rad;
    const double v[3] = {s->vel.x, s->vel.y, s->vel.z}, o[3] = {s->omg.x, s->omg.y, s->omg.z};
    for (int q = 0; q < 3; ++q) b->vel[3 * side + q][e] = v[q], b->omg[3 * side + q][e] = o[q];
}

// A contact's hl doubles of history into lane e, and back out of it.
static DEM_ALWAYS_INLINE void batch_hist_in(contact_batch *restrict b, int e, const double *restrict hist, int hl)
{
    for (int q = 0; q < hl; ++q) b->hist[q][e] = hist[q];
}

static DEM_ALWAYS_INLINE void batch_hist_out(const contact_batch *restrict b, int e, double *restrict hist, int hl)
{
    for (int q = 0; q < hl; ++q) hist[q] = b->hist[q][e];
}

static DEM_ALWAYS_INLINE pair_side batch_side(const contact_batch *restrict b, int e, int side)
{
    const int o = 3 * side;
    return (pair_side){dem_v3(b->vel[o][e], b->vel[o + 1][e], b->vel[o + 2][e]),
                       dem_v3(b->omg[o][e], b->omg[o + 1][e], b->omg[o + 2][e]), b->rad[side][e]};
}

// No dependence between the iterations of the loop that follows: GCC needs
// it to vectorise the batch. (Clang, used only for the fuzz builds, does not
// vectorise this loop either way and would warn.)
#if defined(__GNUC__) && !defined(__clang__)
#define DEM_INDEPENDENT_ITERATIONS _Pragma("GCC ivdep")
#else
#define DEM_INDEPENDENT_ITERATIONS
#endif

// The vector in rows a[0], a[1], a[2] of the batch, lane e, and its store.
#define BATCH_V3(a, e) dem_v3((a)[0][e], (a)[1][e], (a)[2][e])
static DEM_ALWAYS_INLINE void batch_store_v3(double (*a)[DEM_BATCH], int e, dem_vec3 v)
{
    a[0][e] = v.x, a[1][e] = v.y, a[2][e] = v.z;
}

// A contact's geometry and kinematics into lane e (its sqrt(m*) and R* are
// there already).
static DEM_ALWAYS_INLINE void batch_put_state(contact_batch *restrict b, int e, const dem_contact_state *s,
                                              double lever_i, double lever_j)
{
    batch_store_v3(b->n, e, s->normal);
    batch_store_v3(b->vrel, e, s->vrel);
    batch_store_v3(b->wrel, e, s->wrel);
    b->overlap[e] = s->overlap, b->twist[e] = s->twist;
    b->lever[0][e] = lever_i, b->lever[1][e] = lever_j;
}

// Stage 1: geometry and kinematics of each contact (pair_geometry_of).
static DEM_ALWAYS_INLINE void batch_geometry(const pair_ctx *restrict c, contact_batch *restrict b)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        const pair_side si = batch_side(b, e, 0), sj = batch_side(b, e, 1);
        const dem_pair_constants pk = {b->root_reduced_mass[e], b->reduced_radius[e]};
        const pair_geometry g = pair_geometry_of(c, BATCH_V3(b->d, e), &si, &sj, &pk);
        batch_put_state(b, e, &g.s, g.lever_i, g.lever_j);
    }
}

static DEM_ALWAYS_INLINE dem_contact_state batch_state(const contact_batch *restrict b, int e, double dt)
{
    return (dem_contact_state){BATCH_V3(b->n, e), b->overlap[e], BATCH_V3(b->vrel, e), BATCH_V3(b->wrel, e),
                               b->twist[e], b->root_reduced_mass[e], b->reduced_radius[e], dt};
}

// Stage 2: the normal force (into f) and what drives the springs.
static DEM_ALWAYS_INLINE void batch_normal(const dem_contact_coeffs *restrict cc, contact_batch *restrict b,
                                           double dt, const unsigned mask)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        const dem_contact_state s = batch_state(b, e, dt);
        dem_contact_out out;
        const dem_contact_drive drive = dem_contact_normal(cc, &s, &out, mask);
        batch_store_v3(b->f, e, out.force);
        b->fn_abs[e] = drive.fn_abs;
        batch_store_v3(b->vt, e, drive.vt);
        batch_store_v3(b->vr, e, drive.vr);
        if (mask & DEM_FEAT_HERTZ) b->k_t[e] = drive.k_t, b->inv_k_t[e] = drive.inv_k_t;
    }
}

// Stage 3: one spring carried and advanced (dem_spring_advance). `hist_row`:
// its first row in hist (0 tangential, dem_rolling_slot rolling); `row`: its
// first row in spring and spring_force (0 tangential, 3 rolling). The
// stiffness k, or each lane's own in b->k_t where `per_lane` (a constant:
// Mindlin's spring stiffens with the overlap).
static DEM_ALWAYS_INLINE void batch_advance(contact_batch *restrict b, int hist_row, int row,
                                            double (*vel)[DEM_BATCH], double k, double dt, const int per_lane)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        const double h[3] = {b->hist[hist_row][e], b->hist[hist_row + 1][e], b->hist[hist_row + 2][e]};
        dem_vec3 f;
        const dem_vec3 spring = dem_spring_advance(h, BATCH_V3(b->n, e), b->twist[e], BATCH_V3(vel, e), dt,
                                                   per_lane ? b->k_t[e] : k, &f);
        batch_store_v3(b->spring + row, e, spring);
        batch_store_v3(b->spring_force + row, e, f);
    }
}

// Stage 4: one spring's Coulomb limit (dem_spring_limit): its force in place
// in spring_force, the spring into hist. 1/k, or each lane's own in
// b->inv_k_t where `per_lane`, as batch_advance.
static DEM_ALWAYS_INLINE void batch_limit(contact_batch *restrict b, int hist_row, int row, double inv_k, double mu,
                                          const int per_lane)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        double h[3];
        int stick;
        const dem_vec3 f = dem_spring_limit(h, BATCH_V3(b->spring + row, e), BATCH_V3(b->spring_force + row, e),
                                            per_lane ? b->inv_k_t[e] : inv_k, mu * b->fn_abs[e], &stick);
        batch_store_v3(b->spring_force + row, e, f);
        for (int q = 0; q < 3; ++q) b->hist[hist_row + q][e] = h[q];
    }
}

// The stages of the law itself, with the coefficients cc and step dt.
static DEM_ALWAYS_INLINE void batch_law(const dem_contact_coeffs *restrict cc, contact_batch *restrict b, double dt,
                                        const unsigned mask)
{
    const int rolling = dem_rolling_slot(mask), mindlin = (mask & DEM_FEAT_HERTZ) != 0;
    batch_normal(cc, b, dt, mask);
    if (mask & DEM_FEAT_TANGENTIAL) batch_advance(b, 0, 0, b->vt, cc->k_s, dt, mindlin);
    if (mask & DEM_FEAT_ROLLING) batch_advance(b, rolling, 3, b->vr, cc->k_r, dt, 0);
    if (mask & DEM_FEAT_TANGENTIAL) batch_limit(b, 0, 0, cc->inv_k_s, cc->mu_s, mindlin);
    if (mask & DEM_FEAT_ROLLING) batch_limit(b, rolling, 3, cc->inv_k_r, cc->mu_r, 0);
}

// A lane's tangential and rolling forces (zero for a spring that is off),
// and the total force into f, as dem_contact_eval adds them.
static DEM_ALWAYS_INLINE void batch_total_force(contact_batch *restrict b, int e, dem_vec3 *f_t, dem_vec3 *f_r,
                                                const unsigned mask)
{
    const dem_vec3 zero = dem_v3(0, 0, 0);
    *f_t = mask & DEM_FEAT_TANGENTIAL ? BATCH_V3(b->spring_force, e) : zero;
    *f_r = mask & DEM_FEAT_ROLLING ? BATCH_V3(b->spring_force + 3, e) : zero;
    if (mask & DEM_FEAT_TANGENTIAL) batch_store_v3(b->f, e, dem_v3_add(BATCH_V3(b->f, e), *f_t));
}

// Stage 5: the total force and the torques.
static DEM_ALWAYS_INLINE void batch_torques(contact_batch *restrict b, const unsigned mask)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        dem_vec3 f_t, f_r, ti, tj;
        batch_total_force(b, e, &f_t, &f_r, mask);
        pair_torques(BATCH_V3(b->n, e), f_t, f_r, b->reduced_radius[e], b->lever[0][e], b->lever[1][e], &ti, &tj);
        batch_store_v3(b->ti, e, ti);
        batch_store_v3(b->tj, e, tj);
    }
}

// The law over the whole batch, in stages (see dem_contact.h): each a loop
// the compiler vectorises, with no branches and no dependence between its
// iterations. perf put the single loop's samples on the instructions
// waiting for its square roots and divisions, one chain after another;
// short stages let the processor overlap them across contacts (measured,
// 1.054x the step at N = 20 000, median of 10 interleaved rounds,
// 1.045-1.074; the kernel's share of the samples 27 % -> 22 %).
static DEM_ALWAYS_INLINE void batch_compute(const pair_ctx *restrict c, contact_batch *restrict b, const unsigned mask)
{
    batch_geometry(c, b);
    batch_law(&c->gg, b, c->hist_dt, mask);
    batch_torques(b, mask);
}

// The law over a batch of granule–wall contacts whose geometry the wall loop
// put in (wall_contacts): total force into f, torque into ti.
static DEM_ALWAYS_INLINE void wall_batch_compute(const dem_contact_coeffs *restrict cc, double dt,
                                                 contact_batch *restrict b, const unsigned mask)
{
    batch_law(cc, b, dt, mask);
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        dem_vec3 f_t, f_r;
        batch_total_force(b, e, &f_t, &f_r, mask);
        batch_store_v3(b->ti, e,
                       torque_on_i(BATCH_V3(b->n, e), f_t, f_r, b->reduced_radius[e], b->lever[0][e]));
    }
}

// The batch kernel is built twice, for the x86-64 baseline (two contacts per
// SSE instruction) and for x86-64-v3 (AVX2: four), and the loader picks the
// one this CPU runs (GCC function multi-versioning). The engine is built
// with -ffp-contract=off, so the v3 build uses no fused multiply-add: both
// are the same arithmetic and results do not depend on the machine.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define DEM_MULTIVERSION __attribute__((target_clones("arch=x86-64-v3", "default"), noinline))
#else
#define DEM_MULTIVERSION
#endif
#define DEM_BATCH_KERNEL(M)                                                                              \
    DEM_MULTIVERSION static void batch_compute_##M(const pair_ctx *restrict c, contact_batch *restrict b) \
    {                                                                                                    \
        batch_compute(c, b, M);                                                                          \
    }
// The same for a batch of granule–wall contacts, per wall feature mask.
#define DEM_WALL_KERNEL(M)                                                                               \
    DEM_MULTIVERSION static void wall_batch_compute_##M(const dem_contact_coeffs *restrict cc, double dt, \
                                                        contact_batch *restrict b)                       \
    {                                                                                                    \
        wall_batch_compute(cc, dt, b, M);                                                                \
    }
// The functions f0 … f31 instantiated for each feature mask, as a table.
#define DEM_BY_MASK_16(f) \
    {f##0, f##1, f##2, f##3, f##4, f##5, f##6, f##7, f##8, f##9, f##10, f##11, f##12, f##13, f##14, f##15}
#define DEM_BY_MASK_32(f)                                                                                           \
    {f##0,  f##1,  f##2,  f##3,  f##4,  f##5,  f##6,  f##7,  f##8,  f##9,  f##10, f##11, f##12, f##13, f##14, f##15, \
     f##16, f##17, f##18, f##19, f##20, f##21, f##22, f##23, f##24, f##25, f##26, f##27, f##28, f##29, f##30, f##31}
// Instantiate M(0) … M(15), or M(0) … M(31): one per kernel mask, or per mask.
#define DEM_FOR_MASKS_16(M) \
    M(0) M(1) M(2) M(3) M(4) M(5) M(6) M(7) M(8) M(9) M(10) M(11) M(12) M(13) M(14) M(15)
#define DEM_FOR_MASKS_32(M)                                                                                        \
    DEM_FOR_MASKS_16(M)                                                                                            \
    M(16) M(17) M(18) M(19) M(20) M(21) M(22) M(23) M(24) M(25) M(26) M(27) M(28) M(29) M(30) M(31)

#endif
