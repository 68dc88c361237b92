// SPDX-License-Identifier: MIT
/// @file exp_incline_runner.h
/// The sphere on an inclined plane's runner (exp_incline.h): run a
/// definition (exp_incline_config.h loads one) and write its files.
#ifndef EXP_INCLINE_RUNNER_H
#define EXP_INCLINE_RUNNER_H

#include "exp_incline.h"

/// `granucal simulate configs/incline.yaml [--set k=v ...] [--out DIR]` once
/// the config is loaded into `d`: run, print one JSON object on stdout (the
/// measured and the analytic acceleration and regime); `out_dir` (NULL:
/// results/runs/incline) gets result.json and result.h5 (the sphere at the
/// end). 0, or 1 when the run failed or a file could not be written.
int exp_incline_simulate(const exp_incline_def *d, const char *out_dir);

#endif
