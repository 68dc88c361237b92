// SPDX-License-Identifier: MIT
/// @file exp_drum_bed.h
/// Stage 1 on the drum's own bed: the bed exp_drum_fill builds (poured in
/// layers, cut to the fill degree, settled), its coordination number counted
/// as the poured cylinder's is (exp_count_bed_contacts). A calibration tier
/// with `stiffness_scene: drum` sweeps the stiffness on it, at the drum's own
/// λ and slice, instead of on the cylinder (results/stiffness_drum_L1000/).
#ifndef EXP_DRUM_BED_H
#define EXP_DRUM_BED_H

#include "exp_cylinder.h"
#include "exp_drum.h"

/// Fill the drum of `d` and count the settled bed's contacts into *out:
/// interior granules at least d_max from the drum's wall (and end plates, in
/// a full drum) and below the free surface; solid_fraction over the bed
/// volume of the fill degree (fill · π r² · depth). NULL world on error.
dem_world *exp_drum_bed_run(const exp_drum_def *d, exp_progress_fn progress, void *ctx, exp_cylinder_result *out,
                            char *err, size_t len);

#endif
