// SPDX-License-Identifier: MIT
// The linearised contact: one contact's force and torques as a linear
// function of the relative motion of its two granules, the one home of the
// linearisation of eq. 3–4 (normal spring or dashpot along n), 6–7 and 9
// (tangential spring on the contact-point slip) and 10–12 (rolling spring on
// −R*(ω_i − ω_j) × n). Two users read it:
//  - the stability limit (dem_stability.c): the stiffness operator K of a
//    contact network, its springs as they are (kn = k_n, c = 1);
//  - the implicit-spring solve (dem_implicit.c): its operator Δt·C + Δt²/4·K_t
//    (kn = Δt·γ, the dashpot applied; c = Δt²/4 on the sticking springs), and
//    each granule's diagonal block of it, the solve's preconditioner.
// The operator and its block are written side by side so that they stay the
// same linearisation. Only dem_vec.h below: the stability analysis stays a
// pure function of its contact network.
#ifndef DEM_LINEAR_CONTACT_INTERNAL_H
#define DEM_LINEAR_CONTACT_INTERNAL_H

#include "dem_vec.h"

// One contact of the linearised operator: unit normal n from i towards j,
// lever arms a_i and a_j (contact point from each centre along ±n), R*, the
// normal coefficient kn (a spring's k_n, or Δt·γ for the dashpot), the
// tangential and rolling stiffnesses kt and kr (0 for a spring that slides or
// is off) and a common factor c of those two springs.
typedef struct dem_linear_contact {
    dem_vec3 n;
    double ai, aj, rs;
    double kn, kt, kr, c;
} dem_linear_contact;

// What the contact puts on i for a relative motion (translation du = u_i −
// u_j, rotations ti and tj): force f on i (−f on j), torques on i and j.
typedef struct dem_linear_response {
    dem_vec3 f, torque_i, torque_j;
} dem_linear_response;

// The operator applied: the normal part kn (du·n) n; the contact-point slip,
// du's tangential part plus (a_i ti + a_j tj) × n, through c·kt; the rolling
// displacement R* n × (ti − tj) through c·kr; each spring's torque about
// either centre (the tangential force at the lever arm, the rolling
// quasi-force at R*). A wall is a partner with tj = 0.
static inline dem_linear_response dem_linear_contact_apply(const dem_linear_contact *l, dem_vec3 du, dem_vec3 ti,
                                                           dem_vec3 tj)
{
    const dem_vec3 n = l->n;
    const double dn = dem_v3_dot(du, n);
    dem_vec3 slip = dem_v3_axpy(-dn, n, du);
    slip = dem_v3_add(slip, dem_v3_cross(dem_v3_axpy(l->aj, tj, dem_v3_scale(ti, l->ai)), n));
    const dem_vec3 roll = dem_v3_scale(dem_v3_cross(n, dem_v3_sub(ti, tj)), l->rs);
    const dem_vec3 fs = dem_v3_scale(slip, l->c * l->kt), fr = dem_v3_scale(roll, l->c * l->kr);
    const dem_vec3 ns = dem_v3_cross(n, fs), nr = dem_v3_scale(dem_v3_cross(n, fr), l->rs);
    dem_linear_response r;
    r.f = dem_v3_axpy(l->kn * dn, n, fs);
    r.torque_i = dem_v3_sub(dem_v3_scale(ns, l->ai), nr);
    r.torque_j = dem_v3_add(dem_v3_scale(ns, l->aj), nr);
    return r;
}

// The contact's part of granule i's own 6×6 block (v, ω) of that operator,
// added to b (row-major, full 6×6):
//   vv: kn n nᵀ + c kt T              vω: −c kt a_i [n]×
//   ωv: c kt a_i [n]×                  ωω: c (kt a_i² + kr R*²) T
// with T = I − n nᵀ and [n]× the cross-product matrix. The partner's block
// is the same with −n and a_j.
static inline void dem_linear_contact_add_block(double *b, const dem_linear_contact *l)
{
    const dem_vec3 n = l->n;
    const double c = l->c, kt = l->kt, a = l->ai, nv[3] = {n.x, n.y, n.z};
    const double cross[3][3] = {{0, -n.z, n.y}, {n.z, 0, -n.x}, {-n.y, n.x, 0}};
    const double rot = c * (kt * a * a + l->kr * l->rs * l->rs);
    for (int r = 0; r < 3; ++r)
        for (int q = 0; q < 3; ++q) {
            double t = (r == q) - nv[r] * nv[q];
            b[6 * r + q] += l->kn * nv[r] * nv[q] + c * kt * t;
            b[6 * r + q + 3] -= c * kt * a * cross[r][q];
            b[6 * (r + 3) + q] += c * kt * a * cross[r][q];
            b[6 * (r + 3) + q + 3] += rot * t;
        }
}

#endif
