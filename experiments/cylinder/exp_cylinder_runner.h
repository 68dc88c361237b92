// SPDX-License-Identifier: MIT
/// @file exp_cylinder_runner.h
/// The poured cylinder's runner (section 4.1, exp_cylinder.h): pour a
/// definition (exp_cylinder_config.h loads one), report, write the results.
#ifndef EXP_CYLINDER_RUNNER_H
#define EXP_CYLINDER_RUNNER_H

#include <stdio.h>

#include "exp_cylinder.h"

/// What a run adds to exp_cylinder_result for its report.
typedef struct exp_cylinder_report {
    double wall_time_s;
    double ke_ratio;            ///< kinetic energy over (bed mass)·g·d50 at the end (at rest: < 1e-6)
    double bed_surface_m;       ///< height below which 98 % of the granule tops lie
    double bed_top_m;           ///< highest granule top
} exp_cylinder_report;

/// Write DIR/result.json (exp_result_write_json: atomically) and
/// DIR/result.h5 (the bed at rest, one frame) for a finished run, creating
/// DIR. 0, or 1 with a message.
int exp_cylinder_write_outputs(const char *dir, const exp_cylinder_def *d, const exp_cylinder_result *r,
                               const exp_cylinder_report *rep, const dem_world *w, char *err, size_t len);

/// The result as one line of JSON (what result.json holds).
void exp_cylinder_write_json(FILE *f, const exp_cylinder_def *d, const exp_cylinder_result *r,
                             const exp_cylinder_report *rep, const dem_world *w);

/// Pour `d` (exp_cylinder_run) and fill `rep`; progress on stderr every 10 s
/// when `verbose`. NULL world with a message on error.
dem_world *exp_cylinder_pour_and_report(const exp_cylinder_def *d, int verbose, exp_cylinder_result *r,
                                        exp_cylinder_report *rep, char *err, size_t len);

/// `granucal simulate configs/cylinder.yaml [--set k=v ...] [--out DIR]`
/// once the config is loaded into `d`: one JSON object on stdout; `out_dir`
/// (NULL: results/runs/cylinder) gets result.json and result.h5. 0 when the run finished and its files were
/// written; a bed still creeping when the settle's time limit (2 s) ended it
/// is reported as status "not at rest", with its kinetic energy ratio.
int exp_cylinder_simulate(const exp_cylinder_def *d, const char *out_dir);

#endif
