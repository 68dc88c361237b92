// SPDX-License-Identifier: MIT
/// @file exp_drum_turn.h
/// Turn a settled drum bed with a checkpoint: the one turn that `granucal
/// simulate` (calib/cli/cal_simulate_drum.c) and the calibration
/// (calib/runs/cal_case_runs.c) both run. What defines the run (its key) is
/// the caller's: this layer only labels the checkpoint with it.
#ifndef EXP_DRUM_TURN_H
#define EXP_DRUM_TURN_H

#include "dem_world.h"
#include "exp_common.h"
#include "exp_drum.h"

/// One turn of a settled bed, resumable from its checkpoint.
typedef struct exp_drum_turn {
    const exp_drum_def *def;
    exp_drum_run_opts run;       ///< its `checkpoint` is set by exp_drum_turn_bed
    const char *checkpoint_path; ///< where the turn saves its state
    const char *key;             ///< the text that defines the run: another run's checkpoint is not resumed
    double checkpoint_every_s;   ///< wall seconds between saves; <= 0: no checkpoint
    /// 1: the checkpoint is also saved when the turn ends, and kept: the file
    /// is then the turned bed, for runs that start from it (needs
    /// checkpoint_every_s > 0).
    int checkpoint_at_end;
    exp_progress_fn progress;    ///< may be NULL
    void *progress_ctx;
    /// 1: the progress leaves its last line open (a terminal's \r line),
    /// ended before the turn's messages.
    int progress_line_open;
    const char *log_prefix;      ///< starts each message on stderr ("granucal simulate:", "[stage]")
} exp_drum_turn;

/// Turn `bed` as `t` says (exp_drum_rotate). The world turned is `bed`
/// itself when `own`, else a clone of it (the caller destroys it when it is
/// not `bed`); NULL when the clone failed (out of memory). On stderr: why a
/// checkpoint found was not resumed, or that the turn resumed. *status: the
/// turn's engine status. out->wall_time_s: the turn's wall time, with the
/// part spent before the checkpoint it resumed from.
dem_world *exp_drum_turn_bed(dem_world *bed, int own, const exp_drum_turn *t, exp_drum_result *out,
                             dem_status *status);

#endif
