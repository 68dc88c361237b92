// SPDX-License-Identifier: MIT
// Walls as the engine keeps them: the definition, the contact law's
// coefficients, each granule's springs against the wall, and the granules
// near enough to touch it before the next list rebuild.
#ifndef DEM_WALLS_INTERNAL_H
#define DEM_WALLS_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "dem_contact.h"
#include "dem_world.h" // dem_wall_def

#define DEM_MAX_WALLS 8

typedef struct dem_wall {
    dem_wall_def def;
    char name[32];
    dem_contact_coeffs coeffs;
    unsigned features;
    int translating; // def.velocity is nonzero: the contacts add it (dem_world_set_wall_velocity)
    int hist_len;
    double *hist; // hist_len doubles per granule
    // Granules within one skin of this wall at the last list rebuild, in
    // ascending order: the only ones that can touch it before the next (no
    // granule moves half a skin between rebuilds, nor does a wall a caller
    // moves: dem_lists_refresh).
    uint32_t *near;
    size_t near_count, near_cap;
    dem_vec3 point_at_build; // def.point when the near list was built: a caller may move the wall
    // force[k]: the force this wall put on granule near[k] at the last force
    // evaluation (0 where it did not touch), near_cap entries. Kept per entry,
    // not summed as the threads go, so that the total (dem_wall_force_total)
    // is added in one order, the same bits on any number of threads.
    dem_vec3 *force;
    // The total of force[] as it was when the near list was last rebuilt
    // (force[] is then zeroed: its entries named the old list's granules);
    // cleared by the next evaluation, which writes every entry.
    dem_vec3 force_carried;
} dem_wall;

// The force the granules put on the wall at the last force evaluation:
// minus the sum of what it put on them, in near-list order.
dem_vec3 dem_wall_force_total(const dem_wall *wall);

// How far the wall has moved since its near list was built, squared.
static inline double dem_wall_travel2(const dem_wall *wall)
{
    return dem_v3_norm2(dem_v3_sub(wall->def.point, wall->point_at_build));
}

// One step of the wall's prescribed motion (dem_wall_def.motion), at step
// `dt`; nothing for a wall that stands.
void dem_wall_advance(dem_wall *wall, double dt);

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

// The wall's near list for granules at pos with radii rad (n of them), and a
// skin: a granule is near if a sphere one skin larger would touch the wall.
// The springs of the others are cleared. 0, or 1 out of memory.
int dem_wall_near_rebuild(dem_wall *wall, size_t n, const dem_vec3 *pos, const double *rad, double skin);

#endif
