// SPDX-License-Identifier: MIT
// The walls' near lists; see dem_walls_internal.h.
#include <stdlib.h>
#include <string.h>

#include "dem_walls_internal.h"

// A granule is near a wall if a sphere one skin larger would touch it (for a
// disc, one skin wider too: a granule may slide in over its rim). The others
// cannot reach the wall before the next rebuild; their springs are open, and
// are cleared here so the wall loop need not visit them.
int dem_wall_near_rebuild(dem_wall *wall, size_t n, const dem_vec3 *pos, const double *rad, double skin)
{
    dem_wall_def grown = wall->def;
    if (grown.kind == DEM_WALL_DISC) grown.radius += skin;
    // The last evaluation's total outlives its entries, which name the old list.
    wall->force_carried = dem_v3_neg(dem_wall_force_total(wall));
    if (wall->near_cap < n || !wall->force) {
        const size_t cap = n > wall->near_cap ? n : wall->near_cap;
        uint32_t *p = realloc(wall->near, (cap ? cap : 1) * sizeof *p);
        if (!p) return 1;
        wall->near = p;
        dem_vec3 *f = realloc(wall->force, (cap ? cap : 1) * sizeof *f);
        if (!f) return 1;
        wall->force = f;
        wall->near_cap = cap;
    }
    const size_t hl = (size_t)wall->hist_len;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        if (dem_wall_geometry(&grown, pos[i], rad[i] + skin).overlap > 0.0) wall->near[count++] = (uint32_t)i;
        else if (hl) memset(wall->hist + i * hl, 0, hl * sizeof(double));
    }
    wall->near_count = count;
    memset(wall->force, 0, count * sizeof *wall->force);
    wall->point_at_build = wall->def.point;
    return 0;
}

dem_vec3 dem_wall_force_total(const dem_wall *wall)
{
    dem_vec3 sum = wall->force_carried;
    for (size_t k = 0; k < wall->near_count; ++k) sum = dem_v3_add(sum, wall->force[k]);
    return dem_v3_neg(sum);
}

void dem_wall_advance(dem_wall *wall, double dt)
{
    if (wall->def.motion != DEM_WALL_TRANSLATES) return;
    const dem_vec3 s = wall->def.step_displacement;
    const dem_vec3 d = s.x != 0.0 || s.y != 0.0 || s.z != 0.0 ? s : dem_v3_scale(wall->def.velocity, dt);
    // Only the components that move: adding +0 turns a −0 coordinate into +0,
    // and a caller who moved the wall along one axis changed only that one.
    if (d.x != 0.0) wall->def.point.x += d.x;
    if (d.y != 0.0) wall->def.point.y += d.y;
    if (d.z != 0.0) wall->def.point.z += d.z;
}
