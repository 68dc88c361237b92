// SPDX-License-Identifier: MIT
/// @file exp_compress_runner.h
/// The confined compression test's runner (exp_compress.h): run a
/// definition (exp_compress_config.h loads one) and write its files.
#ifndef EXP_COMPRESS_RUNNER_H
#define EXP_COMPRESS_RUNNER_H

#include <stddef.h>

#include "exp_compress.h"

/// Write the curve as CSV (t, cycle, branch, piston height, displacement,
/// strain, spring forces on piston, floor and side wall, sigma, KE/elastic,
/// then the engine's axial totals on the three walls) and, unless
/// `png_path` is NULL, the force–displacement PNG (one colour per cycle,
/// like Fig. 10). 0 or a message.
int exp_compress_write_curve(const exp_compress_result *r, const char *csv_path, const char *png_path, char *err,
                             size_t len);

/// `granucal simulate configs/compression.yaml [--set k=v ...] [--out DIR]`
/// once the config is loaded into `d`: run, print one JSON object on stdout
/// and write to `out_dir` (NULL: results/runs/compression) result.json,
/// result.h5, curve.csv and force_displacement.png. 0, or 1 when the run
/// failed or a file could not be written.
int exp_compress_simulate(const exp_compress_def *d, const char *out_dir);

#endif
