// SPDX-License-Identifier: MIT
// Force and torque evaluation. Each granule–granule pair adds its force and
// two torques to both granules, rows in ascending order (the explicit
// integration computes the touching pairs 32 at a time in a vectorised
// batch, then adds them in that same order: "contact batches"); with threads, each
// owns a block of granules and only the pairs that cross a block's edge go
// through per-pair slots (pair_loop_threaded; the step team of dem_world.c
// runs the same block pieces, dem_forces_crossing and dem_forces_block, inside
// its one parallel region). No two threads write the same memory, and every
// granule sums its terms in the serial order, so results are bitwise
// identical for any thread count.
//
// The pair loop and the wall loop are instantiated once per feature mask
// (DEM_FEATURE_LOOP below): with the mask a constant, the inline kernel of
// dem_contact.h drops every effect the scene does not use.
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "dem_forces_internal.h"
#include "dem_implicit_internal.h"
#include "dem_threads_internal.h"

// Unit normal from a centre-to-centre vector; coincident centres get a fixed
// normal instead of a division by zero (the overlap then pushes them apart).
static inline dem_vec3 safe_normal(dem_vec3 d, double dist)
{
    return dist > 0.0 ? dem_v3_scale(d, 1.0 / dist) : dem_v3(0.0, 1.0, 0.0);
}

int dem_forces_threaded(const dem_world *w) { return w->n >= DEM_OMP_MIN_GRANULES && omp_get_max_threads() > 1; }

// A loop-level bit above the feature masks: the pair loop for a periodic
// scene whose centres one wrap may not do for (pair_separation_general).
#define DEM_GENERAL_IMAGE DEM_FEAT_COUNT_MASKS

// How a pair hands its forces on. DIRECT adds them straight to both granules;
// SLOTS writes them into the pair's slots, for a pair crossing a thread's
// block (pair_loop_threaded adds them in the serial order).
enum { DEM_SLOTS = 0, DEM_DIRECT = 1 };

// What the pair loop reads on every pair, copied out of the world once per
// force evaluation. The loop stores doubles (forces, springs) through
// pointers the compiler cannot tell apart from the world's own fields, so
// read from the world it would reload the coefficients and flags after every
// store; a local copy stays in registers.
typedef struct pair_ctx {
    const dem_vec3 *pos, *vel, *omg;
    const double *rad;
    const dem_pair_constants *constants;
    dem_vec3 *frc, *trq;
    const uint32_t *nbr, *row; // partner and row (granule i) of each pair
    double *hist;
    dem_vec3 *slot_f, *slot_ti, *slot_tj; // pairs crossing a thread's block: force, torques on i and j
    dem_contact_coeffs gg;
    double half_lever; // ½ lever_factor: lever arm R − ½h (or R)
    double hist_dt;
    double period;     // length along the periodic axis
    int axis;          // periodic axis, or −1
    int implicit_damping, implicit_springs;
} pair_ctx;

static inline pair_ctx pair_ctx_make(const dem_world *w)
{
    return (pair_ctx){w->pos, w->vel, w->omg, w->rad, w->nl.constants, w->frc, w->trq, w->nl.j, w->nl.row, w->nl.hist,
                      w->pair_f, w->pair_ti, w->pair_tj, w->gg, 0.5 * w->lever_factor, w->hist_dt, dem_world_period(w),
                      w->def.periodic_axis, w->def.implicit_damping, dem_implicit_on(w)};
}

// Whether contacts go through the contact batch: the implicit integrations
// keep per-pair and per-wall-contact data (pair_g, damp, the implicit solve's contacts and wall blocks)
// that only the one-at-a-time paths write. The one rule, for the pairs, the
// walls and the step team (dem_forces_blockwise) alike.
static inline int contacts_batched(int implicit_damping, int implicit_springs)
{
    return !implicit_damping && !implicit_springs;
}
static inline int uses_batch(const pair_ctx *c) { return contacts_batched(c->implicit_damping, c->implicit_springs); }

// Add the slot of pair k, which crosses a thread's block, to its granule i.
static DEM_ALWAYS_INLINE void add_slot(const pair_ctx *restrict c, size_t i, size_t k)
{
    c->frc[i] = dem_v3_add(c->frc[i], c->slot_f[k]);
    c->trq[i] = dem_v3_add(c->trq[i], c->slot_ti[k]);
}

// Minimum image of one component along a period of length len, for a
// separation shorter than one and a half periods. Branches, not a select:
// they are nearly always not taken and predicted so (measured, computing
// c − len·s with s = 1, −1 or 0 made the step 6 % slower at N = 20 000,
// 12 interleaved rounds).
static DEM_ALWAYS_INLINE double wrap_component(double c, double len)
{
    return c > 0.5 * len ? c - len : c < -0.5 * len ? c + len : c;
}

// Minimum image along the periodic axis by one wrap: right for every pair
// while all centres span less than DEM_ONE_WRAP_SPAN periods. A switch on
// named components, not a pointer to one, keeps the separation in registers.
static DEM_ALWAYS_INLINE dem_vec3 wrap_separation(dem_vec3 d, int axis, double len)
{
    dem_vec3 s = d;
    switch (axis) {
    case 0: s.x = wrap_component(d.x, len); break;
    case 1: s.y = wrap_component(d.y, len); break;
    default: s.z = wrap_component(d.z, len); break;
    }
    return s;
}

// One granule's side of a pair: what the contact law reads of it.
typedef struct pair_side {
    dem_vec3 vel, omg;
    double rad;
} pair_side;

// What a touching pair does: force on i (j gets −force), torques on i and j,
// and what the implicit integrations read.
typedef struct pair_result {
    dem_vec3 force, torque_i, torque_j, normal;
    double damping_coeff, k_tangential, k_rolling, lever_i, lever_j, reduced_radius;
} pair_result;

// Geometry and kinematics of a touching pair with separation d = r_j − r_i
// (minimum image), and its lever arms.
typedef struct pair_geometry {
    dem_contact_state s;
    double lever_i, lever_j;
} pair_geometry;

static DEM_ALWAYS_INLINE pair_geometry pair_geometry_of(const pair_ctx *restrict c, dem_vec3 d, const pair_side *si,
                                                        const pair_side *sj, const dem_pair_constants *pk)
{
    const double ri = si->rad, rj = sj->rad, rsum = ri + rj;
    const double dist = sqrt(dem_v3_norm2(d));
    pair_geometry g;
    g.s.normal = safe_normal(d, dist);
    g.s.overlap = rsum - dist;
    // Lever arms: centre to contact point (or R, see dem_lever_arm).
    g.lever_i = ri - c->half_lever * g.s.overlap;
    g.lever_j = rj - c->half_lever * g.s.overlap;
    const dem_vec3 n = g.s.normal, wi = si->omg, wj = sj->omg;
    // Eq. 5 and 7: velocity of i's contact point relative to j's.
    g.s.vrel = dem_v3_sub(dem_v3_add(si->vel, dem_v3_cross(dem_v3_scale(wi, g.lever_i), n)),
                          dem_v3_sub(sj->vel, dem_v3_cross(dem_v3_scale(wj, g.lever_j), n)));
    g.s.wrel = dem_v3_sub(wi, wj);
    g.s.twist = 0.5 * dem_v3_dot(dem_v3_add(wi, wj), n) * c->hist_dt;
    g.s.root_reduced_mass = pk->root_reduced_mass;
    g.s.reduced_radius = pk->reduced_radius;
    g.s.dt = c->hist_dt;
    return g;
}

// Eq. 9–10: the torque on granule i (lever arm lever_i) of a contact's
// tangential force f_t and rolling quasi-force f_r; for a wall contact the
// only torque, with R* = R_i.
static DEM_ALWAYS_INLINE dem_vec3 torque_on_i(dem_vec3 n, dem_vec3 f_t, dem_vec3 f_r, double reduced_radius,
                                              double lever_i)
{
    const dem_vec3 ts = dem_v3_scale(dem_v3_cross(n, f_t), lever_i);
    const dem_vec3 tr = dem_v3_scale(dem_v3_cross(n, f_r), reduced_radius);
    return dem_v3_sub(ts, tr);
}

// Eq. 9–10: the torques on i and on j of a granule–granule contact.
static DEM_ALWAYS_INLINE void pair_torques(dem_vec3 n, dem_vec3 f_t, dem_vec3 f_r, double reduced_radius,
                                           double lever_i, double lever_j, dem_vec3 *ti, dem_vec3 *tj)
{
    *ti = torque_on_i(n, f_t, f_r, reduced_radius, lever_i);
    *tj = dem_v3_add(dem_v3_scale(dem_v3_cross(n, f_t), lever_j), dem_v3_scale(dem_v3_cross(n, f_r), reduced_radius));
}

// The contact of a touching pair, one pair at a time: geometry, the law
// (dem_contact_eval) and the torques. The batch runs the same functions in
// stages (batch_compute): the same arithmetic, bit for bit.
static DEM_ALWAYS_INLINE pair_result pair_contact(const pair_ctx *restrict c, dem_vec3 d, const pair_side *si,
                                                  const pair_side *sj, const dem_pair_constants *pk,
                                                  double *restrict hist, const unsigned mask)
{
    const pair_geometry g = pair_geometry_of(c, d, si, sj, pk);
    dem_contact_out out;
    dem_contact_eval(&c->gg, &g.s, hist, &out, mask);
    pair_result r = {out.force, {0, 0, 0}, {0, 0, 0}, g.s.normal, out.damping_coeff, out.k_tangential,
                     out.k_rolling, g.lever_i, g.lever_j, g.s.reduced_radius};
    pair_torques(g.s.normal, out.f_tangential, out.f_rolling, g.s.reduced_radius, g.lever_i, g.lever_j, &r.torque_i,
                 &r.torque_j);
    return r;
}

static DEM_ALWAYS_INLINE pair_side side_of(const pair_ctx *restrict c, size_t i)
{
    return (pair_side){c->vel[i], c->omg[i], c->rad[i]};
}

// Separation r_j − r_i of a listed pair while centres may lie more than
// DEM_ONE_WRAP_SPAN periods apart (a granule placed outside the domain,
// before its first drift): one wrap where it brings the pair within half a
// period, the general minimum image where not. Those evaluations have loops
// of their own (DEM_GENERAL_IMAGE): with this check and its call in the
// loops of every step, the compiler kept the loops' values on the stack
// around the call, and every pair paid (measured, the step 1.035x faster
// at N = 20 000 without it, median of 10 interleaved rounds).
static dem_vec3 pair_separation_general(const dem_world *w, const pair_ctx *restrict c, size_t i, uint32_t j)
{
    const dem_vec3 d = dem_v3_sub(c->pos[j], c->pos[i]), s = wrap_separation(d, c->axis, c->period);
    return fabs(dem_v3_comp(s, c->axis)) <= 0.5 * c->period ? s : dem_world_min_image(w, d);
}

// Separation r_j − r_i of a listed pair (minimum image).
static DEM_ALWAYS_INLINE dem_vec3 pair_separation(const dem_world *w, const pair_ctx *restrict c, size_t i,
                                                  uint32_t j, const unsigned mask)
{
    if (!(mask & DEM_FEAT_PERIODIC)) return dem_v3_sub(c->pos[j], c->pos[i]);
    if (mask & DEM_GENERAL_IMAGE) return pair_separation_general(w, c, i, j);
    return wrap_separation(dem_v3_sub(c->pos[j], c->pos[i]), c->axis, c->period);
}

// Separation r_j − r_i of a listed pair, and whether the granules touch.
static DEM_ALWAYS_INLINE int pair_touches(const dem_world *w, const pair_ctx *restrict c, size_t i, uint32_t j,
                                          const unsigned mask, dem_vec3 *d)
{
    *d = pair_separation(w, c, i, j, mask);
    const double rsum = c->rad[i] + c->rad[j];
    return dem_v3_norm2(*d) < rsum * rsum;
}

static DEM_ALWAYS_INLINE void add_to_pair(const pair_ctx *restrict c, size_t i, size_t j, dem_vec3 f, dem_vec3 ti,
                                          dem_vec3 tj)
{
    dem_vec3 *restrict frc = c->frc, *restrict trq = c->trq;
    frc[i] = dem_v3_add(frc[i], f);
    frc[j] = dem_v3_sub(frc[j], f); // Newton's third law
    trq[i] = dem_v3_add(trq[i], ti);
    trq[j] = dem_v3_add(trq[j], tj);
}

// One pair, scalar: the implicit integrations (which keep per-pair data) and
// the pairs crossing a thread's block (SLOTS) come this way.
static DEM_ALWAYS_INLINE void pair_force(dem_world *restrict w, const pair_ctx *restrict c, size_t i, size_t k,
                                         const unsigned mask, const int direct)
{
    const uint32_t j = c->nbr[k];
    const int hl = dem_history_len(mask);
    double *restrict hist = c->hist + k * (size_t)hl;
    dem_vec3 d;
    if (!pair_touches(w, c, i, j, mask, &d)) {
        // Open contact: springs forget (a new contact starts unloaded).
        for (int h = 0; h < hl; ++h) hist[h] = 0.0;
        if (!direct) w->pair_f[k] = w->pair_ti[k] = w->pair_tj[k] = dem_v3(0, 0, 0);
        if (c->implicit_damping) w->pair_g[k] = 0.0, w->pair_n[k] = dem_v3(0, 0, 0); // gather_damping reads both
        if (c->implicit_springs) w->imp->pair[k] = (dem_imp_contact){{0, 0, 0}, 0, 0, 0, 0, 0, 0};
        return;
    }
    const pair_side si = side_of(c, i), sj = side_of(c, j);
    const pair_result r = pair_contact(c, d, &si, &sj, &c->constants[k], hist, mask);
    if (c->implicit_damping) { // read only by gather_damping
        w->pair_g[k] = r.damping_coeff;
        w->pair_n[k] = r.normal;
    }
    if (c->implicit_springs)
        w->imp->pair[k] = (dem_imp_contact){r.normal, r.damping_coeff, r.k_tangential, r.k_rolling,
                                           r.lever_i,  r.lever_j,     r.reduced_radius};
    if (direct) {
        add_to_pair(c, i, j, r.force, r.torque_i, r.torque_j);
    } else {
        w->pair_f[k] = r.force;
        w->pair_ti[k] = r.torque_i;
        w->pair_tj[k] = r.torque_j;
    }
}

// ------------------------------------------------------ contact batches ---
//
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
    }
}

// Stage 3: one spring carried and advanced (dem_spring_advance). `hist_row`:
// its first row in hist (0 tangential, dem_rolling_slot rolling); `row`: its
// first row in spring and spring_force (0 tangential, 3 rolling).
static DEM_ALWAYS_INLINE void batch_advance(contact_batch *restrict b, int hist_row, int row,
                                            double (*vel)[DEM_BATCH], double k, double dt)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        const double h[3] = {b->hist[hist_row][e], b->hist[hist_row + 1][e], b->hist[hist_row + 2][e]};
        dem_vec3 f;
        const dem_vec3 spring =
            dem_spring_advance(h, BATCH_V3(b->n, e), b->twist[e], BATCH_V3(vel, e), dt, k, &f);
        batch_store_v3(b->spring + row, e, spring);
        batch_store_v3(b->spring_force + row, e, f);
    }
}

// Stage 4: one spring's Coulomb limit (dem_spring_limit): its force in place
// in spring_force, the spring into hist.
static DEM_ALWAYS_INLINE void batch_limit(contact_batch *restrict b, int hist_row, int row, double inv_k, double mu)
{
    DEM_INDEPENDENT_ITERATIONS
    for (int e = 0; e < b->count; ++e) {
        double h[3];
        int stick;
        const dem_vec3 f = dem_spring_limit(h, BATCH_V3(b->spring + row, e), BATCH_V3(b->spring_force + row, e),
                                            inv_k, mu * b->fn_abs[e], &stick);
        batch_store_v3(b->spring_force + row, e, f);
        for (int q = 0; q < 3; ++q) b->hist[hist_row + q][e] = h[q];
    }
}

// The stages of the law itself, with the coefficients cc and step dt.
static DEM_ALWAYS_INLINE void batch_law(const dem_contact_coeffs *restrict cc, contact_batch *restrict b, double dt,
                                        const unsigned mask)
{
    const int rolling = dem_rolling_slot(mask);
    batch_normal(cc, b, dt, mask);
    if (mask & DEM_FEAT_TANGENTIAL) batch_advance(b, 0, 0, b->vt, cc->k_s, dt);
    if (mask & DEM_FEAT_ROLLING) batch_advance(b, rolling, 3, b->vr, cc->k_r, dt);
    if (mask & DEM_FEAT_TANGENTIAL) batch_limit(b, 0, 0, cc->inv_k_s, cc->mu_s);
    if (mask & DEM_FEAT_ROLLING) batch_limit(b, rolling, 3, cc->inv_k_r, cc->mu_r);
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
DEM_BATCH_KERNEL(0)
DEM_BATCH_KERNEL(1)
DEM_BATCH_KERNEL(2)
DEM_BATCH_KERNEL(3)
DEM_BATCH_KERNEL(4)
DEM_BATCH_KERNEL(5)
DEM_BATCH_KERNEL(6)
DEM_BATCH_KERNEL(7)
DEM_BATCH_KERNEL(8)
DEM_BATCH_KERNEL(9)
DEM_BATCH_KERNEL(10)
DEM_BATCH_KERNEL(11)
DEM_BATCH_KERNEL(12)
DEM_BATCH_KERNEL(13)
DEM_BATCH_KERNEL(14)
DEM_BATCH_KERNEL(15)
// The same for a batch of granule–wall contacts, per wall feature mask.
#define DEM_WALL_KERNEL(M)                                                                               \
    DEM_MULTIVERSION static void wall_batch_compute_##M(const dem_contact_coeffs *restrict cc, double dt, \
                                                        contact_batch *restrict b)                       \
    {                                                                                                    \
        wall_batch_compute(cc, dt, b, M);                                                                \
    }
DEM_WALL_KERNEL(0)
DEM_WALL_KERNEL(1)
DEM_WALL_KERNEL(2)
DEM_WALL_KERNEL(3)
DEM_WALL_KERNEL(4)
DEM_WALL_KERNEL(5)
DEM_WALL_KERNEL(6)
DEM_WALL_KERNEL(7)
// The functions f0 … f15 instantiated for each feature mask, as a table.
#define DEM_BY_MASK_8(f) {f##0, f##1, f##2, f##3, f##4, f##5, f##6, f##7}
#define DEM_BY_MASK_16(f) \
    {f##0, f##1, f##2, f##3, f##4, f##5, f##6, f##7, f##8, f##9, f##10, f##11, f##12, f##13, f##14, f##15}
typedef void (*batch_kernel_fn)(const pair_ctx *restrict, contact_batch *restrict);
static const batch_kernel_fn batch_kernels[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_16(batch_compute_);
typedef void (*wall_kernel_fn)(const dem_contact_coeffs *restrict, double, contact_batch *restrict);
static const wall_kernel_fn wall_kernels[8] = DEM_BY_MASK_8(wall_batch_compute_);

// Run the batch and add its results in the pairs' order; empties it.
static DEM_ALWAYS_INLINE void batch_flush(const pair_ctx *restrict c, contact_batch *restrict b, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    batch_kernels[mask & (DEM_FEAT_COUNT_MASKS - 1)](c, b);
    for (int e = 0; e < b->count; ++e) {
        if (b->slot[e]) {
            add_slot(c, b->i[e], b->k[e]);
            continue;
        }
        batch_hist_out(b, e, c->hist + b->k[e] * (size_t)hl, hl);
        add_to_pair(c, b->i[e], b->j[e], dem_v3(b->f[0][e], b->f[1][e], b->f[2][e]),
                    dem_v3(b->ti[0][e], b->ti[1][e], b->ti[2][e]), dem_v3(b->tj[0][e], b->tj[1][e], b->tj[2][e]));
    }
    b->count = 0;
}

// Run a batch of pairs crossing a thread's block and put each result in its
// pair's slot, for the threads to add in their turn; empties it.
static DEM_ALWAYS_INLINE void batch_flush_to_slots(const pair_ctx *restrict c, contact_batch *restrict b,
                                                   const unsigned mask)
{
    const int hl = dem_history_len(mask);
    batch_kernels[mask & (DEM_FEAT_COUNT_MASKS - 1)](c, b);
    for (int e = 0; e < b->count; ++e) {
        const size_t k = b->k[e];
        batch_hist_out(b, e, c->hist + k * (size_t)hl, hl);
        c->slot_f[k] = BATCH_V3(b->f, e);
        c->slot_ti[k] = BATCH_V3(b->ti, e);
        c->slot_tj[k] = BATCH_V3(b->tj, e);
    }
    b->count = 0;
}

// The slot of pair k, crossing the thread's block, added to row i in its
// turn. Not flushing the batch here keeps the batches full near a block's
// end, where most rows have such a pair.
static DEM_ALWAYS_INLINE void batch_slot(const pair_ctx *restrict c, contact_batch *restrict b, size_t i, size_t k,
                                         const unsigned mask)
{
    const int e = b->count++;
    b->slot[e] = 1;
    b->i[e] = b->j[e] = (uint32_t)i, b->k[e] = k;
    const pair_side neutral = {{0, 0, 0}, {0, 0, 0}, 1.0}; // any finite contact will do
    b->root_reduced_mass[e] = b->reduced_radius[e] = 1.0;
    b->d[0][e] = 1.0, b->d[1][e] = b->d[2][e] = 0.0;
    batch_put_side(b, e, 0, &neutral);
    batch_put_side(b, e, 1, &neutral);
    for (int q = 0; q < 6; ++q) b->hist[q][e] = 0.0;
    if (b->count == DEM_BATCH) batch_flush(c, b, mask);
}

// The partner data a pair reads and adds to, asked for DEM_PREFETCH_AHEAD
// pairs before the loop reaches it. Rows run in spatial order, so their own
// granules stream in sequence and the hardware prefetcher has them; a
// partner j > i lies ahead of that stream, often far ahead (a granule's
// neighbours in the next layer are a layer's worth of granules further on in
// Morton order), and its lines (pos, vel, omg, rad, frc, trq) came in one
// demand miss after another, each stalling the pair's chain of loads. Into
// L2 (locality 2), not L1: 96 pairs' partners would crowd L1 out.
// Read intent also for frc and trq: a line no other core holds comes in
// exclusive and takes the writes as well; write intent would take the lines
// of pairs crossing into another thread's block from that thread.
// Measured, interleaved A/B against no prefetch, 1 thread (commit d0b7a77):
// 1.28x at N = 1 000 000, 1.24x at 100 000, 0.97-1.09x at 20 000, none at
// 5 000 (in cache); 24, 48, 64 and 128 pairs ahead did less.
#define DEM_PREFETCH_AHEAD 96

// Both lines a 24-byte vector may lie on. Its start falls at a line offset
// of 0, 24, 48, 8, 32, 56, 16 or 40 bytes, and from 48 and 56 it runs into
// the next line: a prefetch of its first byte alone left a quarter of the
// partners' vectors to miss on their y or z. perf at N = 10^6 put the
// stalls of the pair loop on exactly those loads (pos[j].z, vel[j].z,
// omg[j].z, frc[j].z). Measured with the second line asked for as well,
// interleaved A/B, 1 thread, 4 rounds: 1.07x (1.04-1.10) at 10^6.
static DEM_ALWAYS_INLINE void prefetch_vec3(const dem_vec3 *v)
{
    __builtin_prefetch(v, 0, 2);
    __builtin_prefetch((const char *)(v + 1) - 1, 0, 2);
}

static DEM_ALWAYS_INLINE void prefetch_partner(const pair_ctx *restrict c, size_t k, size_t end)
{
    if (k + DEM_PREFETCH_AHEAD >= end) return;
    const uint32_t j = c->nbr[k + DEM_PREFETCH_AHEAD];
    prefetch_vec3(c->pos + j);
    prefetch_vec3(c->vel + j);
    prefetch_vec3(c->omg + j);
    __builtin_prefetch(c->rad + j, 0, 2);
    prefetch_vec3(c->frc + j);
    prefetch_vec3(c->trq + j);
}

// The hl doubles of springs at h, both their lines, for writing; none
// without springs (hl = 0, where the history array may not exist).
static DEM_ALWAYS_INLINE void prefetch_springs_at(const double *h, int hl)
{
    if (hl == 0) return;
    __builtin_prefetch(h, 1, 2);
    __builtin_prefetch(h + hl - 1, 1, 2);
}

// The springs (both their lines, for writing) and the constants of the pair
// DEM_PREFETCH_AHEAD on. Every listed pair writes its springs (a contact
// advances them, an open pair resets them), and stores to lines not yet held
// stalled the loop (perf at 10^6: the open pairs' reset and the batch's
// loads of the springs). The hardware prefetcher follows the stream, but not
// far enough ahead of a loop that only stores to most of it. Measured on top
// of the partners' second lines, interleaved A/B against neither, 1 thread:
// 1.16x (1.07-1.27, 4 rounds) at 10^6 against 1.07x for the second lines
// alone, 1.10x at 10^5, 1.04x at 20 000, 1.01x at 5 000; 2 threads at 10^5
// 1.21x (1.05-1.28, 6 rounds). The constants, read by touching pairs only,
// then still stalled the batch's gather at 10^6; asked for as well: 1.03x
// (1.02-1.03, 3 rounds) at 10^6, 1.04x (1.01-1.07, 6 rounds) at 10^5,
// 1.01x at 20 000 and 5 000 (8 rounds each). Bitwise the same results.
static DEM_ALWAYS_INLINE void prefetch_pair_state(const pair_ctx *restrict c, size_t k, size_t end, int hl)
{
    if (k + DEM_PREFETCH_AHEAD >= end) return;
    prefetch_springs_at(c->hist + (k + DEM_PREFETCH_AHEAD) * (size_t)hl, hl);
    __builtin_prefetch(c->constants + k + DEM_PREFETCH_AHEAD, 0, 2);
}

// Touching pair k (i, j, separation d) into the batch, flushing it when full
// into the granules, or with `to_slots` into the pairs' slots.
static DEM_ALWAYS_INLINE void batch_contact(const pair_ctx *restrict c, contact_batch *restrict b, size_t i,
                                            uint32_t j, size_t k, dem_vec3 d, const unsigned mask, const int to_slots)
{
    const int hl = dem_history_len(mask);
    const double *restrict hist = c->hist + k * (size_t)hl;
    const int e = b->count++;
    b->slot[e] = 0;
    b->i[e] = (uint32_t)i, b->j[e] = j, b->k[e] = k;
    b->d[0][e] = d.x, b->d[1][e] = d.y, b->d[2][e] = d.z;
    b->root_reduced_mass[e] = c->constants[k].root_reduced_mass;
    b->reduced_radius[e] = c->constants[k].reduced_radius;
    const pair_side si = side_of(c, i), sj = side_of(c, j);
    batch_put_side(b, e, 0, &si);
    batch_put_side(b, e, 1, &sj);
    batch_hist_in(b, e, hist, hl);
    if (b->count < DEM_BATCH) return;
    if (to_slots) batch_flush_to_slots(c, b, mask);
    else batch_flush(c, b, mask);
}

// Pair k of row i into the batch if it touches (flushing a full batch);
// an open pair's springs are reset here. A branch on the touch test: the
// small lists' loop (see DEM_BRANCH_FREE_MIN_PAIRS).
static DEM_ALWAYS_INLINE void batch_pair(dem_world *restrict w, const pair_ctx *restrict c, contact_batch *restrict b,
                                         size_t i, size_t k, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    dem_vec3 d;
    if (pair_touches(w, c, i, c->nbr[k], mask, &d)) batch_contact(c, b, i, c->nbr[k], k, d, mask, 0);
    else
        for (int h = 0; h < hl; ++h) c->hist[k * (size_t)hl + h] = 0.0; // a new contact starts unloaded
}

// Pairs k0 … k1−1 into the batch, in their order: the touching ones as
// contacts, those reaching past `hi` (the end of a thread's block) as slot
// entries; the others are open, and their springs are reset (a new contact
// starts unloaded). Contacts and near misses interleave in a bed, so a
// branch on the touch test is mispredicted about as often as not, and so is
// the end of a row's few pairs. Instead the pairs are walked in fixed pieces
// across rows (each pair knows its row), and each pair's index is written to
// both lists, of which only the one it belongs to advances.
// Below DEM_BRANCH_FREE_MIN_PAIRS listed pairs the loop with the branch is
// faster: the same few hundred granules' pattern of contacts and near misses
// comes round every step, and the branch predictor learns it. Measured, the
// branch-free loop's speed over the branching one's: 0.89x (median of 4
// rounds, 0.83-1.05) on the calibration's drum (279 granules, ~850 pairs),
// 0.91-0.94x at 1 148 granules; 1.08x and 1.27x at 2 233, 1.12x at 5 000
// (15 000 pairs). Both loops add the same pairs in the same order, so the
// choice changes no result.
#define DEM_BRANCH_FREE_MIN_PAIRS 4096
#define PAIR_PIECE 32
static DEM_ALWAYS_INLINE void batch_pairs(dem_world *restrict w, const pair_ctx *restrict c, contact_batch *restrict b,
                                          size_t k0, size_t k1, size_t hi, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    if (w->nl.count < DEM_BRANCH_FREE_MIN_PAIRS) {
        for (size_t k = k0; k < k1; ++k) {
            prefetch_partner(c, k, k1);
            if (c->nbr[k] >= hi) batch_slot(c, b, c->row[k], k, mask);
            else batch_pair(w, c, b, c->row[k], k, mask);
        }
        return;
    }
    const uint32_t *restrict row = c->row, *restrict nbr = c->nbr;
    for (size_t p0 = k0; p0 < k1; p0 += PAIR_PIECE) {
        const size_t p1 = p0 + PAIR_PIECE < k1 ? p0 + PAIR_PIECE : k1;
        size_t take[PAIR_PIECE], open[PAIR_PIECE];
        dem_vec3 sep[PAIR_PIECE];
        unsigned char crossing[PAIR_PIECE];
        int nt = 0, no = 0;
        for (size_t k = p0; k < p1; ++k) {
            prefetch_partner(c, k, k1);
            prefetch_pair_state(c, k, k1, hl);
            dem_vec3 d;
            const int x = nbr[k] >= hi, in = pair_touches(w, c, row[k], nbr[k], mask, &d) | x;
            take[nt] = k, sep[nt] = d, crossing[nt] = (unsigned char)x, open[no] = k;
            nt += in, no += !in;
        }
        for (int o = 0; o < no; ++o)
            for (int h = 0; h < hl; ++h) c->hist[open[o] * (size_t)hl + h] = 0.0;
        for (int t = 0; t < nt; ++t) {
            const size_t k = take[t];
            if (crossing[t]) batch_slot(c, b, row[k], k, mask);
            else batch_contact(c, b, row[k], nbr[k], k, sep[t], mask, 0);
        }
    }
}

// The serial order, the reference every thread count reproduces bit for bit:
// rows ascending, each pair added to i and to j as it comes.
static DEM_ALWAYS_INLINE void pair_loop_serial(dem_world *restrict w, const unsigned mask)
{
    const size_t n = w->n;
    const pair_ctx c = pair_ctx_make(w);
    const size_t *restrict start = w->nl.start;
    memset(w->frc, 0, n * sizeof *w->frc);
    memset(w->trq, 0, n * sizeof *w->trq);
    const size_t end = start[n];
    if (!uses_batch(&c)) {
        for (size_t i = 0; i < n; ++i)
            for (size_t k = start[i]; k < start[i + 1]; ++k) {
                prefetch_partner(&c, k, end);
                pair_force(w, &c, i, k, mask, DEM_DIRECT);
            }
        return;
    }
    contact_batch b;
    b.count = 0;
    batch_pairs(w, &c, &b, 0, end, n, mask);
    batch_flush(&c, &b, mask);
}

// Threads: each owns a block of granules and adds the pairs inside it
// directly. A pair reaching past the block's end (rows are sorted by
// partner, so these close each row) is computed first, into its slots
// (block_crossing_pairs); after a barrier each thread starts its granules
// from the slots of pairs coming in from lower blocks (the lowest pair
// indices, so first in the serial order), then walks its rows as the serial
// loop does, taking the outgoing crossing pairs' part from their slots at the
// end of each row (block_own_pairs). Every granule sums the same terms in the
// same order as pair_loop_serial.
//
// Each thread works from its own pair_ctx: read through the spawning
// thread's stack frame, which that thread keeps writing, every pair would
// share a cache line with those writes (measured: 2 threads 1.5x one at
// N = 100 000, against 1.95x for two separate processes).

// The pairs of row i (in a block ending at `end`) that reach past the
// block's end, into their slots: one at a time without a batch (the
// implicit integrations), or through the contact batch b, whose touching
// pairs are computed 32 at a time while an open pair's springs and slots are
// reset here. Each pair writes only its own slot and springs, so the order
// of the batch changes nothing. The crossing pairs are ~2 % of the pairs at
// N = 100 000 on 2 threads; one at a time they took 4.9 % of the samples,
// batched 3.6 % (commit fcd6044).
static DEM_ALWAYS_INLINE void row_crossing_pairs(dem_world *restrict w, const pair_ctx *restrict c,
                                                 contact_batch *b, size_t i, size_t end, const unsigned mask)
{
    const size_t *start = w->nl.start;
    const int hl = dem_history_len(mask);
    for (size_t k = start[i + 1]; k > start[i] && c->nbr[k - 1] >= end; --k) {
        const size_t p = k - 1;
        dem_vec3 d;
        if (!b) {
            pair_force(w, c, i, p, mask, DEM_SLOTS);
        } else if (pair_touches(w, c, i, c->nbr[p], mask, &d)) {
            batch_contact(c, b, i, c->nbr[p], p, d, mask, 1);
        } else {
            for (int h = 0; h < hl; ++h) c->hist[p * (size_t)hl + h] = 0.0; // a new contact starts unloaded
            c->slot_f[p] = c->slot_ti[p] = c->slot_tj[p] = dem_v3(0, 0, 0);
        }
    }
}

// Rows rows[0 … count−1] (or, without `rows`, every row of [first, end)) of
// a block ending at `end`: their pairs reaching past it, into their slots.
static DEM_ALWAYS_INLINE void crossing_pairs_of(dem_world *restrict w, const uint32_t *rows, size_t first,
                                                size_t count, size_t end, const unsigned mask)
{
    const pair_ctx c = pair_ctx_make(w);
    contact_batch b;
    b.count = 0;
    contact_batch *batch = uses_batch(&c) ? &b : NULL;
    for (size_t r = 0; r < count; ++r) row_crossing_pairs(w, &c, batch, rows ? rows[r] : first + r, end, mask);
    if (batch) batch_flush_to_slots(&c, batch, mask);
}

static DEM_ALWAYS_INLINE void block_crossing_pairs(dem_world *restrict w, size_t lo, size_t hi, const unsigned mask)
{
    crossing_pairs_of(w, NULL, lo, hi - lo, hi, mask);
}

static DEM_ALWAYS_INLINE void listed_crossing_pairs(dem_world *restrict w, const uint32_t *rows, size_t count,
                                                    size_t end, const unsigned mask)
{
    crossing_pairs_of(w, rows, 0, count, end, mask);
}

static DEM_ALWAYS_INLINE void block_own_pairs(dem_world *restrict w, size_t lo, size_t hi, const unsigned mask)
{
    const pair_ctx c = pair_ctx_make(w);
    const size_t *start = w->nl.start;
    const uint32_t *nbr = w->nl.j;
    const size_t first_own_pair = start[lo];
    for (size_t i = lo; i < hi; ++i) { // incoming crossing pairs: partner rows below lo
        dem_vec3 f = dem_v3(0, 0, 0), t = dem_v3(0, 0, 0);
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1] && w->rev_pair[r] < first_own_pair; ++r) {
            const size_t k = w->rev_pair[r];
            f = dem_v3_sub(f, w->pair_f[k]); // Newton's third law
            t = dem_v3_add(t, w->pair_tj[k]);
        }
        w->frc[i] = f;
        w->trq[i] = t;
    }
    const size_t end = start[hi];
    if (!uses_batch(&c)) {
        for (size_t i = lo; i < hi; ++i)
            for (size_t k = start[i]; k < start[i + 1]; ++k) {
                prefetch_partner(&c, k, end);
                if (nbr[k] < hi) pair_force(w, &c, i, k, mask, DEM_DIRECT);
                else add_slot(&c, i, k);
            }
        return;
    }
    contact_batch b;
    b.count = 0;
    batch_pairs(w, &c, &b, start[lo], end, hi, mask);
    batch_flush(&c, &b, mask);
}

static DEM_ALWAYS_INLINE void pair_loop_threaded(dem_world *restrict w, const unsigned mask)
{
#pragma omp parallel
    {
        size_t lo, hi;
        dem_thread_block(w->n, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        block_crossing_pairs(w, lo, hi, mask);
#pragma omp barrier
        block_own_pairs(w, lo, hi, mask);
    }
}

static DEM_ALWAYS_INLINE void pair_loop(dem_world *restrict w, const unsigned mask)
{
    if (dem_forces_threaded(w)) pair_loop_threaded(w, mask);
    else pair_loop_serial(w, mask);
}

// Accumulate γ n nᵀ into a symmetric 3×3 stored as xx yy zz xy xz yz.
static inline void add_damping(double *d, double g, dem_vec3 n)
{
    d[0] += g * n.x * n.x, d[1] += g * n.y * n.y, d[2] += g * n.z * n.z;
    d[3] += g * n.x * n.y, d[4] += g * n.x * n.z, d[5] += g * n.y * n.z;
}

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
    // The wall surface moves at Ω × (c − axis point) at the contact point c.
    const dem_vec3 v_wall = dem_v3_cross(spin, dem_v3_sub(t.point, wall->def.point));
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
// also gather the contact's damping and stiffness, come this way.
static DEM_ALWAYS_INLINE void wall_force(dem_world *restrict w, const dem_wall *wall, size_t i, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    double *hist = wall->hist + i * (size_t)hl;
    dem_contact_state s;
    double ai;
    if (!wall_contact_of(w, wall, i, &s, &ai)) {
        for (int h = 0; h < hl; ++h) hist[h] = 0.0;
        return;
    }
    const dem_vec3 n = s.normal;
    const double r = s.reduced_radius;
    dem_contact_out out;
    dem_contact_eval(&wall->coeffs, &s, hist, &out, mask);
    w->frc[i] = dem_v3_add(w->frc[i], out.force);
    if ((mask & DEM_FEAT_DAMPING) && w->def.implicit_damping) add_damping(w->damp + 6 * i, out.damping_coeff, n);
    if (dem_implicit_on(w))
        dem_imp_add_block(w->imp->wall + 36 * i, n, out.damping_coeff, out.k_tangential, out.k_rolling, ai, r, w->dt);
    w->trq[i] = dem_v3_add(w->trq[i], torque_on_i(n, out.f_tangential, out.f_rolling, r, ai));
}

// Run a batch of wall contacts and add each to its granule; empties it.
static DEM_ALWAYS_INLINE void wall_flush(dem_world *restrict w, const dem_wall *wall, contact_batch *restrict b,
                                         const unsigned mask)
{
    const int hl = dem_history_len(mask);
    wall_kernels[mask & 7u](&wall->coeffs, w->hist_dt, b);
    for (int e = 0; e < b->count; ++e) {
        const size_t i = b->i[e];
        batch_hist_out(b, e, wall->hist + i * (size_t)hl, hl);
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

// The near granules near[0 … count−1] against a wall. In the explicit
// integration the touching ones go through a contact batch, whose law runs
// in stages as the pairs' does: at the calibration's scale (279 granules)
// the walls took a fifth of the time one contact at a time (measured, the
// drum run 1.09x faster batched, 1.039x at N = 20 000). Each granule meets
// the wall once, so the additions are those of the one-at-a-time loop.
static DEM_ALWAYS_INLINE void wall_contacts(dem_world *restrict w, const dem_wall *wall, const uint32_t *near,
                                            size_t count, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    if (!contacts_batched(w->def.implicit_damping, dem_implicit_on(w))) {
        for (size_t k = 0; k < count; ++k) wall_force(w, wall, near[k], mask);
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
            continue;
        }
        const int e = b.count++;
        b.i[e] = (uint32_t)i;
        b.root_reduced_mass[e] = s.root_reduced_mass, b.reduced_radius[e] = s.reduced_radius;
        batch_put_state(&b, e, &s, lever, 0.0);
        batch_hist_in(&b, e, hist, hl);
        if (b.count == DEM_BATCH) wall_flush(w, wall, &b, mask);
    }
    if (b.count) wall_flush(w, wall, &b, mask);
}

// Only the granules near the wall (dem_wall.near): the others are out of reach.
static DEM_ALWAYS_INLINE void wall_loop(dem_world *restrict w, const dem_wall *wall, const unsigned mask)
{
#pragma omp parallel if (w->n >= DEM_OMP_MIN_GRANULES)
    {
        size_t lo, hi;
        dem_thread_block(wall->near_count, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        wall_contacts(w, wall, wall->near + lo, hi - lo, mask);
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
    wall_contacts(w, wall, near + a, end - a, mask);
}

// One specialised function per feature mask; the table picks it per scene.
#define DEM_PAIR_LOOP(M)                                                                                \
    static void pair_loop_##M(dem_world *w) { pair_loop(w, M); }                                        \
    static void crossing_pairs_##M(dem_world *w, const uint32_t *rows, size_t count, size_t end)         \
    {                                                                                                   \
        listed_crossing_pairs(w, rows, count, end, M);                                                  \
    }                                                                                                   \
    static void own_pairs_##M(dem_world *w, size_t lo, size_t hi) { block_own_pairs(w, lo, hi, M); }
#define DEM_WALL_LOOP(M)                                                                                \
    static void wall_loop_##M(dem_world *w, const dem_wall *wall) { wall_loop(w, wall, M); }            \
    static void wall_block_##M(dem_world *w, const dem_wall *wall, size_t lo, size_t hi)                \
    {                                                                                                   \
        wall_block(w, wall, lo, hi, M);                                                                 \
    }
#define DEM_FEATURE_LOOP(M) DEM_PAIR_LOOP(M) DEM_WALL_LOOP(M)
DEM_FEATURE_LOOP(0)
DEM_FEATURE_LOOP(1)
DEM_FEATURE_LOOP(2)
DEM_FEATURE_LOOP(3)
DEM_FEATURE_LOOP(4)
DEM_FEATURE_LOOP(5)
DEM_FEATURE_LOOP(6)
DEM_FEATURE_LOOP(7)
DEM_PAIR_LOOP(8)
DEM_PAIR_LOOP(9)
DEM_PAIR_LOOP(10)
DEM_PAIR_LOOP(11)
DEM_PAIR_LOOP(12)
DEM_PAIR_LOOP(13)
DEM_PAIR_LOOP(14)
DEM_PAIR_LOOP(15)
#define DEM_GENERAL_IMAGE_LOOP(M) \
    static void general_image_pair_loop_##M(dem_world *w) { pair_loop(w, DEM_FEAT_PERIODIC | DEM_GENERAL_IMAGE | M); }
DEM_GENERAL_IMAGE_LOOP(0)
DEM_GENERAL_IMAGE_LOOP(1)
DEM_GENERAL_IMAGE_LOOP(2)
DEM_GENERAL_IMAGE_LOOP(3)
DEM_GENERAL_IMAGE_LOOP(4)
DEM_GENERAL_IMAGE_LOOP(5)
DEM_GENERAL_IMAGE_LOOP(6)
DEM_GENERAL_IMAGE_LOOP(7)

typedef void (*pair_loop_fn)(dem_world *);
typedef void (*crossing_pairs_fn)(dem_world *, const uint32_t *, size_t, size_t);
typedef void (*block_pairs_fn)(dem_world *, size_t, size_t);
typedef void (*wall_loop_fn)(dem_world *, const dem_wall *);
typedef void (*wall_block_fn)(dem_world *, const dem_wall *, size_t, size_t);
static const pair_loop_fn pair_loops[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_16(pair_loop_);
static const crossing_pairs_fn crossing_pair_loops[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_16(crossing_pairs_);
static const block_pairs_fn own_pair_loops[DEM_FEAT_COUNT_MASKS] = DEM_BY_MASK_16(own_pairs_);
static const pair_loop_fn general_image_pair_loops[8] = DEM_BY_MASK_8(general_image_pair_loop_);
static const wall_loop_fn wall_loops[8] = DEM_BY_MASK_8(wall_loop_);
static const wall_block_fn wall_blocks[8] = DEM_BY_MASK_8(wall_block_);

// Each granule's own dashpots, Σγ n nᵀ over its contacts (implicit dashpot).
static void gather_damping(dem_world *restrict w)
{
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES)
    for (size_t i = 0; i < n; ++i) {
        double d[6] = {0, 0, 0, 0, 0, 0};
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) add_damping(d, w->pair_g[k], w->pair_n[k]);
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1]; ++r)
            add_damping(d, w->pair_g[w->rev_pair[r]], w->pair_n[w->rev_pair[r]]);
        for (int c = 0; c < 6; ++c) w->damp[6 * i + c] = d[c];
    }
}

int dem_forces_blockwise(const dem_world *w)
{
    return contacts_batched(w->def.implicit_damping, w->implicit_springs);
}

size_t dem_forces_crossing_rows(const dem_world *w, size_t lo, size_t hi, uint32_t *rows)
{
    size_t count = 0;
    for (size_t i = lo; i < hi; ++i)
        if (w->nl.start[i + 1] > w->nl.start[i] && w->nl.j[w->nl.start[i + 1] - 1] >= hi) rows[count++] = (uint32_t)i;
    return count;
}

void dem_forces_crossing(dem_world *w, const uint32_t *rows, size_t count, size_t end)
{
    crossing_pair_loops[w->features & (DEM_FEAT_COUNT_MASKS - 1)](w, rows, count, end);
}

void dem_forces_block(dem_world *w, size_t lo, size_t hi)
{
    own_pair_loops[w->features & (DEM_FEAT_COUNT_MASKS - 1)](w, lo, hi);
    for (int k = 0; k < w->n_walls; ++k) wall_blocks[w->walls[k].features & 7u](w, &w->walls[k], lo, hi);
}

// One wrap gives a pair's minimum image if its separation along the
// periodic axis is shorter than one and a half periods; centres spanning at
// most 1.25 periods leave a margin no rounding can take away. A drift wraps
// every centre into the domain, one period.
#define DEM_ONE_WRAP_SPAN 1.25

void dem_forces_axis_extent(const dem_world *w, size_t lo, size_t hi, double *lowest, double *highest)
{
    const int a = w->def.periodic_axis;
    double low = INFINITY, high = -INFINITY; // no centre: spans nothing
    if (a >= 0)
        for (size_t i = lo; i < hi; ++i) {
            const double x = dem_v3_comp(w->pos[i], a);
            low = x < low ? x : low;
            high = x > high ? x : high;
        }
    *lowest = low;
    *highest = high;
}

int dem_forces_one_wrap(const dem_world *w, double lowest, double highest)
{
    return highest - lowest <= DEM_ONE_WRAP_SPAN * dem_world_period(w);
}

void dem_forces_compute(dem_world *w)
{
    const unsigned mask = w->features & (DEM_FEAT_COUNT_MASKS - 1);
    double lowest, highest;
    dem_forces_axis_extent(w, 0, w->n, &lowest, &highest);
    dem_implicit_begin(w);
    if ((mask & DEM_FEAT_PERIODIC) && !dem_forces_one_wrap(w, lowest, highest))
        general_image_pair_loops[mask & (DEM_FEAT_PERIODIC - 1)](w);
    else
        pair_loops[mask](w);
    if (w->def.implicit_damping) gather_damping(w);
    for (int k = 0; k < w->n_walls; ++k) wall_loops[w->walls[k].features & 7u](w, &w->walls[k]);
}

