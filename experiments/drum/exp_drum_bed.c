// SPDX-License-Identifier: MIT
// The drum's poured bed as stage 1's scene (see exp_drum_bed.h).
#include "exp_drum_bed.h"

#include <math.h>
#include <string.h>

#include "dem_scaling.h"

// At least dmax inside the drum's wall (its axis is z through the origin),
// between the end plates of a full drum (a periodic slice has none), and
// below the free surface.
static int inside_drum_bed(dem_vec3 p, double top, double dmax, const void *ctx)
{
    const exp_drum_def *d = ctx;
    int between_plates = d->periodic || (p.z > dmax && p.z < d->depth - dmax);
    return sqrt(p.x * p.x + p.y * p.y) < 0.5 * d->diameter - dmax && p.y < top - dmax && between_plates;
}

dem_world *exp_drum_bed_run(const exp_drum_def *d, exp_progress_fn progress, void *ctx, exp_cylinder_result *out,
                            char *err, size_t len)
{
    memset(out, 0, sizeof *out);
    dem_world *w = exp_drum_fill(d, progress, ctx, err, len);
    if (!w) return NULL;
    dem_gsd gsd = dem_scale_gsd(&d->gsd, d->lambda);
    double solid, r = 0.5 * d->diameter;
    if (exp_count_bed_contacts(w, dem_gsd_max_diameter(&gsd), inside_drum_bed, d, out, &solid)) {
        exp_fail(err, len, "drum bed: out of memory counting contacts");
        dem_world_destroy(w);
        return NULL;
    }
    out->solid_fraction = solid / (d->fill * DEM_PI * r * r * d->depth);
    out->simulated_time_s = dem_world_time(w);
    out->particle_steps = (double)dem_world_particle_steps(w);
    return w;
}
