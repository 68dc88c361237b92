// SPDX-License-Identifier: MIT
// One granule–granule contact as the force loops compute it: what they read
// of the world (pair_ctx), a pair's geometry and kinematics, the law of
// dem_contact.h and the torques of eq. 9–10. Written once, for the pair loops
// (dem_pairs.c), the contact batch (dem_contact_batch_internal.h) and, for
// the torque on one side, the wall contacts (dem_wall_contacts.c).
#ifndef DEM_PAIR_CONTACT_INTERNAL_H
#define DEM_PAIR_CONTACT_INTERNAL_H

#include "dem_implicit_internal.h"
#include "dem_state_internal.h"

// Unit normal from a centre-to-centre vector; coincident centres get a fixed
// normal instead of a division by zero (the overlap then pushes them apart).
static inline dem_vec3 safe_normal(dem_vec3 d, double dist)
{
    return dist > 0.0 ? dem_v3_scale(d, 1.0 / dist) : dem_v3(0.0, 1.0, 0.0);
}

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

// Accumulate γ n nᵀ into a symmetric 3×3 stored as xx yy zz xy xz yz.
static inline void add_damping(double *d, double g, dem_vec3 n)
{
    d[0] += g * n.x * n.x, d[1] += g * n.y * n.y, d[2] += g * n.z * n.z;
    d[3] += g * n.x * n.y, d[4] += g * n.x * n.z, d[5] += g * n.y * n.z;
}

#endif
