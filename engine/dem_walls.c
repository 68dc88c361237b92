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
    if (wall->near_cap < n) {
        uint32_t *p = realloc(wall->near, (n ? n : 1) * sizeof *p);
        if (!p) return 1;
        wall->near = p;
        wall->near_cap = n;
    }
    const size_t hl = (size_t)wall->hist_len;
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) {
        if (dem_wall_geometry(&grown, pos[i], rad[i] + skin).overlap > 0.0) wall->near[count++] = (uint32_t)i;
        else if (hl) memset(wall->hist + i * hl, 0, hl * sizeof(double));
    }
    wall->near_count = count;
    wall->point_at_build = wall->def.point;
    return 0;
}
