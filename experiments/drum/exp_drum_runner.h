// SPDX-License-Identifier: MIT
/// @file exp_drum_runner.h
/// The drum's runner for `granucal simulate`: fill a loaded drum config
/// (exp_drum_config.h), turn one copy of the settled bed at each speed asked
/// (exp_drum_turn_bed, the turn the calibration runs too), write the results.
#ifndef EXP_DRUM_RUNNER_H
#define EXP_DRUM_RUNNER_H

#include <stddef.h>

#include "exp_drum.h"
#include "exp_drum_config.h"

/// The text that defines one turn (the drum, its fill and the run at
/// run->rpm), the label of its checkpoint: a checkpoint with another label is
/// not resumed. Whose text it is is the caller's (`granucal simulate` labels
/// them with the calibration's record key, cal_drum_key).
typedef void (*exp_drum_key_fn)(const exp_drum_def *def, const exp_drum_run_opts *run, char *out, size_t len);

/// What `simulate` asks of a drum beyond its config.
typedef struct exp_drum_simulate_opts {
    const double *rpm;         ///< the speeds, one turn of a copy of the bed each; NULL or n_rpm 0: the config's rpm
    int n_rpm;                 ///< more than 1: results in DIR/rpm_<speed>/, one JSON with "runs" on stdout
    double checkpoint_every_s; ///< wall seconds between a turn's checkpoints; <= 0: none
    exp_drum_key_fn key;       ///< labels the checkpoints; NULL: no checkpoints
} exp_drum_simulate_opts;

/// `granucal simulate configs/drum.yaml [--rpm-list ...]` once the config is
/// loaded into `y`: fill the drum, turn a copy of the settled bed at each
/// speed, print one JSON object on stdout; `out_dir` (NULL:
/// results/runs/drum) gets result.json, result.h5 and drum_face.png (per
/// speed in rpm_<speed>/ for several), and each turn's checkpoint.h5 while it
/// runs (removed once its results are written; the same command after a kill
/// resumes there). 0, or 1 when a run failed or a file could not be written.
int exp_drum_simulate(const exp_drum_yaml *y, const char *out_dir, const exp_drum_simulate_opts *o);

#endif
