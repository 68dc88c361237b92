// SPDX-License-Identifier: MIT
// Rigid motions of the whole granular state. A bed turned rigidly about the
// axis of a body of revolution that holds it (a drum turned before the clock
// starts) is the same mechanical state seen from a turned frame: positions,
// velocities, spins and every stored spring turn together, so each contact
// keeps its overlap, its spring and hence its force, only turned.
#include <math.h>

#include "dem_state_internal.h"

typedef struct rotation {
    dem_vec3 k; // unit axis
    double c, s;
} rotation;

// Rodrigues: R v = v cos θ + (k × v) sin θ + k (k · v)(1 − cos θ).
static dem_vec3 rotated(const rotation *r, dem_vec3 v)
{
    dem_vec3 out = dem_v3_axpy(r->s, dem_v3_cross(r->k, v), dem_v3_scale(v, r->c));
    return dem_v3_axpy(dem_v3_dot(r->k, v) * (1.0 - r->c), r->k, out);
}

// A point turned about the line through `point`.
static dem_vec3 turned_point(const rotation *r, dem_vec3 point, dem_vec3 p)
{
    return dem_v3_add(point, rotated(r, dem_v3_sub(p, point)));
}

// `count` consecutive 3-vectors stored as doubles (springs: every history
// slot is a vector, dem_history_len).
static void rotate_triples(const rotation *r, double *a, size_t count)
{
    for (size_t t = 0; t < count; ++t) {
        dem_vec3 v = rotated(r, dem_v3(a[3 * t], a[3 * t + 1], a[3 * t + 2]));
        a[3 * t] = v.x, a[3 * t + 1] = v.y, a[3 * t + 2] = v.z;
    }
}

// A symmetric tensor stored xx yy zz xy xz yz, turned: R D Rᵀ.
static void rotate_symmetric(const rotation *r, double *d)
{
    const dem_vec3 col[3] = {dem_v3(d[0], d[3], d[4]), dem_v3(d[3], d[1], d[5]), dem_v3(d[4], d[5], d[2])};
    dem_vec3 rd[3]; // columns of R D
    for (int c = 0; c < 3; ++c) rd[c] = rotated(r, col[c]);
    // (R D Rᵀ) rows are R applied to the rows of R D, i.e. to its columns' components.
    const dem_vec3 row_x = rotated(r, dem_v3(rd[0].x, rd[1].x, rd[2].x));
    const dem_vec3 row_y = rotated(r, dem_v3(rd[0].y, rd[1].y, rd[2].y));
    const dem_vec3 row_z = rotated(r, dem_v3(rd[0].z, rd[1].z, rd[2].z));
    d[0] = row_x.x, d[1] = row_y.y, d[2] = row_z.z, d[3] = row_x.y, d[4] = row_x.z, d[5] = row_y.z;
}

dem_status dem_world_rotate(dem_world *w, dem_vec3 point, dem_vec3 axis, double angle)
{
    const double len = dem_v3_norm(axis);
    if (!(len > 0) || !isfinite(len) || !isfinite(angle) || !dem_v3_isfinite(point)) {
        dem_world_set_error(w, "rotation: axis (%g, %g, %g) must be non-zero and finite, angle %g finite", axis.x, axis.y,
                            axis.z, angle);
        return DEM_ERR_INVALID;
    }
    rotation r = {dem_v3_scale(axis, 1.0 / len), cos(angle), sin(angle)};
    const int pa = w->def.periodic_axis;
    // Along a periodic axis the images would no longer tile the box.
    if (pa >= 0 && fabs(dem_v3_comp(r.k, pa)) < 1.0 - 1e-12) {
        dem_world_set_error(w, "rotation: the axis must be the periodic axis (%d) of this world", pa);
        return DEM_ERR_INVALID;
    }
    for (size_t i = 0; i < w->n; ++i) // first check, so that a refusal changes nothing
        if (!dem_v3_in_box(turned_point(&r, point, w->pos[i]), w->def.domain_lo, w->def.domain_hi)) {
            dem_world_set_error(w, "rotation: granule id %llu would leave the domain", (unsigned long long)w->id[i]);
            return DEM_ERR_INVALID;
        }
    for (size_t i = 0; i < w->n; ++i) {
        w->pos[i] = turned_point(&r, point, w->pos[i]);
        w->vel[i] = rotated(&r, w->vel[i]);
        w->omg[i] = rotated(&r, w->omg[i]);
        // The contact forces at the turned configuration are the old ones
        // turned (gravity is added at each kick, never stored here): keeping
        // them valid continues the step exactly instead of re-evaluating the
        // dashpots at full-step velocities where the step used half-step ones.
        w->frc[i] = rotated(&r, w->frc[i]);
        w->trq[i] = rotated(&r, w->trq[i]);
        if (w->damp) rotate_symmetric(&r, w->damp + 6 * i); // Σγ n nᵀ of the implicit dashpot
    }
    if (w->acc) rotate_triples(&r, w->acc, 2 * w->n); // implicit solve's rates: dv/dt and dω/dt
    // Springs of the pairs in the list: the next rebuild (every granule has
    // moved) carries them by pair, as it does after any step.
    if (w->list_valid) rotate_triples(&r, w->nl.hist, w->nl.count * (size_t)w->nl.hist_len / 3);
    for (int k = 0; k < w->n_walls; ++k)
        if (w->walls[k].hist) rotate_triples(&r, w->walls[k].hist, w->n * (size_t)w->walls[k].hist_len / 3);
    return DEM_OK;
}
