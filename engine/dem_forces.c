// SPDX-License-Identifier: MIT
// Force and torque evaluation. Each granule–granule pair writes its force and
// two torques into per-pair slots; each granule then gathers its own pairs in
// ascending pair order. No two threads write the same memory, and the sum
// order is fixed, so results are bitwise identical for any thread count.
//
// The pair loop and the wall loop are instantiated once per feature mask
// (DEM_FEATURE_LOOP below): with the mask a constant, the inline kernel of
// dem_contact.h drops every effect the scene does not use.
#include <string.h>

#include "dem_world_internal.h"

// Unit normal from a centre-to-centre vector; coincident centres get a fixed
// normal instead of a division by zero (the overlap then pushes them apart).
static inline dem_vec3 safe_normal(dem_vec3 d, double dist)
{
    return dist > 0.0 ? dem_v3_scale(d, 1.0 / dist) : dem_v3(0.0, 1.0, 0.0);
}

static inline void pair_force(dem_world *restrict w, size_t i, size_t k, const unsigned mask)
{
    const uint32_t j = w->nl.j[k];
    const int hl = dem_history_len(mask);
    double *hist = w->nl.hist + k * (size_t)hl;
    dem_vec3 d = dem_v3_sub(w->pos[j], w->pos[i]);
    if (mask & DEM_FEAT_PERIODIC) d = dem_world_min_image(w, d);
    const double ri = w->rad[i], rj = w->rad[j], rsum = ri + rj;
    const double dist2 = dem_v3_norm2(d);
    if (dist2 >= rsum * rsum) {
        // Open contact: springs forget (a new contact starts unloaded).
        for (int h = 0; h < hl; ++h) hist[h] = 0.0;
        w->pair_f[k] = w->pair_ti[k] = w->pair_tj[k] = dem_v3(0, 0, 0);
        if (w->def.implicit_damping) w->pair_g[k] = 0.0;
        return;
    }
    const double dist = sqrt(dist2);
    dem_contact_state s;
    s.normal = safe_normal(d, dist);
    s.overlap = rsum - dist;
    // Lever arms: centre to contact point (or R, see dem_lever_arm).
    const double ai = ri - 0.5 * w->lever_factor * s.overlap;
    const double aj = rj - 0.5 * w->lever_factor * s.overlap;
    const dem_vec3 n = s.normal, wi = w->omg[i], wj = w->omg[j];
    // Eq. 5 and 7: velocity of i's contact point relative to j's.
    s.vrel = dem_v3_sub(dem_v3_add(w->vel[i], dem_v3_cross(dem_v3_scale(wi, ai), n)),
                        dem_v3_sub(w->vel[j], dem_v3_cross(dem_v3_scale(wj, aj), n)));
    s.wrel = dem_v3_sub(wi, wj);
    s.twist = 0.5 * dem_v3_dot(dem_v3_add(wi, wj), n) * w->hist_dt;
    s.reduced_mass = 1.0 / (w->inv_mass[i] + w->inv_mass[j]);
    s.reduced_radius = ri * rj / rsum;
    s.dt = w->hist_dt;
    dem_contact_out out;
    dem_contact_eval(&w->gg, &s, hist, &out, mask);
    w->pair_f[k] = out.force;
    if (w->def.implicit_damping) { // read only by gather_damping
        w->pair_g[k] = out.damping_coeff;
        w->pair_n[k] = n;
    }
    // Eq. 9–10: torques on i and on j.
    const dem_vec3 ts = dem_v3_cross(n, out.f_tangential);
    const dem_vec3 tr = dem_v3_scale(dem_v3_cross(n, out.f_rolling), s.reduced_radius);
    w->pair_ti[k] = dem_v3_sub(dem_v3_scale(ts, ai), tr);
    w->pair_tj[k] = dem_v3_add(dem_v3_scale(ts, aj), tr);
}

static inline void pair_loop(dem_world *restrict w, const unsigned mask)
{
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES)
    for (size_t i = 0; i < n; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) pair_force(w, i, k, mask);
}

// Accumulate γ n nᵀ into a symmetric 3×3 stored as xx yy zz xy xz yz.
static inline void add_damping(double *d, double g, dem_vec3 n)
{
    d[0] += g * n.x * n.x, d[1] += g * n.y * n.y, d[2] += g * n.z * n.z;
    d[3] += g * n.x * n.y, d[4] += g * n.x * n.z, d[5] += g * n.y * n.z;
}

static inline void wall_force(dem_world *restrict w, const dem_wall *wall, size_t i, const unsigned mask)
{
    const int hl = dem_history_len(mask);
    double *hist = wall->hist + i * (size_t)hl;
    const double r = w->rad[i];
    dem_wall_touch t = dem_wall_geometry(&wall->def, w->pos[i], r);
    if (!(t.overlap > 0.0)) {
        for (int h = 0; h < hl; ++h) hist[h] = 0.0;
        return;
    }
    const dem_vec3 n = t.normal, wi = w->omg[i];
    const dem_vec3 spin = dem_v3_scale(wall->def.axis, wall->def.spin);
    const double ai = r - w->lever_factor * t.overlap;
    // The wall surface moves at Ω × (c − axis point) at the contact point c.
    const dem_vec3 v_wall = dem_v3_cross(spin, dem_v3_sub(t.point, wall->def.point));
    dem_contact_state s;
    s.normal = n;
    s.overlap = t.overlap;
    s.vrel = dem_v3_sub(dem_v3_add(w->vel[i], dem_v3_cross(dem_v3_scale(wi, ai), n)), v_wall);
    s.wrel = dem_v3_sub(wi, spin);
    s.twist = 0.5 * dem_v3_dot(dem_v3_add(wi, spin), n) * w->hist_dt;
    s.reduced_mass = w->mass[i]; // infinite wall mass: m* = m_i
    s.reduced_radius = r;        // infinite wall radius: R* = R_i
    s.dt = w->hist_dt;
    dem_contact_out out;
    dem_contact_eval(&wall->coeffs, &s, hist, &out, mask);
    w->frc[i] = dem_v3_add(w->frc[i], out.force);
    if ((mask & DEM_FEAT_DAMPING) && w->def.implicit_damping) add_damping(w->damp + 6 * i, out.damping_coeff, n);
    const dem_vec3 ts = dem_v3_scale(dem_v3_cross(n, out.f_tangential), ai);
    const dem_vec3 tr = dem_v3_scale(dem_v3_cross(n, out.f_rolling), r);
    w->trq[i] = dem_v3_add(w->trq[i], dem_v3_sub(ts, tr));
}

static inline void wall_loop(dem_world *restrict w, const dem_wall *wall, const unsigned mask)
{
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES)
    for (size_t i = 0; i < n; ++i) wall_force(w, wall, i, mask);
}

// One specialised function per feature mask; the switch picks it per scene.
#define DEM_PAIR_LOOP(M) \
    static void pair_loop_##M(dem_world *w) { pair_loop(w, M); }
#define DEM_WALL_LOOP(M) \
    static void wall_loop_##M(dem_world *w, const dem_wall *wall) { wall_loop(w, wall, M); }
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

typedef void (*pair_loop_fn)(dem_world *);
typedef void (*wall_loop_fn)(dem_world *, const dem_wall *);
static const pair_loop_fn pair_loops[DEM_FEAT_COUNT_MASKS] = {
    pair_loop_0, pair_loop_1, pair_loop_2,  pair_loop_3,  pair_loop_4,  pair_loop_5,  pair_loop_6,  pair_loop_7,
    pair_loop_8, pair_loop_9, pair_loop_10, pair_loop_11, pair_loop_12, pair_loop_13, pair_loop_14, pair_loop_15};
static const wall_loop_fn wall_loops[8] = {wall_loop_0, wall_loop_1, wall_loop_2, wall_loop_3,
                                           wall_loop_4, wall_loop_5, wall_loop_6, wall_loop_7};

static void gather(dem_world *restrict w)
{
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES)
    for (size_t i = 0; i < n; ++i) {
        dem_vec3 f = dem_v3(0, 0, 0), t = dem_v3(0, 0, 0);
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) {
            f = dem_v3_add(f, w->pair_f[k]);
            t = dem_v3_add(t, w->pair_ti[k]);
        }
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1]; ++r) {
            size_t k = w->rev_pair[r];
            f = dem_v3_sub(f, w->pair_f[k]); // Newton's third law
            t = dem_v3_add(t, w->pair_tj[k]);
        }
        w->frc[i] = f;
        w->trq[i] = t;
    }
}

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

void dem_forces_compute(dem_world *w)
{
    pair_loops[w->features & (DEM_FEAT_COUNT_MASKS - 1)](w);
    gather(w);
    if (w->def.implicit_damping) gather_damping(w);
    for (int k = 0; k < w->n_walls; ++k) wall_loops[w->walls[k].features & 7u](w, &w->walls[k]);
}
