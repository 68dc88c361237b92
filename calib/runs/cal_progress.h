// SPDX-License-Identifier: MIT
/// @file cal_progress.h
/// A whole calibration's progress: its stages, the simulations each may run
/// (an upper bound: the search can stop early), how many are done, and the
/// time left at the measured cost of a simulation of each kind.
///
/// The cost of a kind is the mean wall time of the records seen so far,
/// stored ones included (each record keeps what its run cost, settling
/// included): a resumed calibration knows its cost from the first batch.
/// The time left is the simulations left times their cost, shared by the
/// simulations run at once; it is an upper bound, like the counts.
#ifndef CAL_PROGRESS_H
#define CAL_PROGRESS_H

#include <stddef.h>

#include "cal_config.h"

/// Kinds of simulation, each with its own cost: a two-tier stage's map-tier
/// drum runs cost a small part of the tier's own, and each level further down
/// (a map tier's own map tier) a part of the level above's.
typedef enum cal_run_kind {
    CAL_RUN_CYLINDER = 0,
    CAL_RUN_DRUM = 1,
    CAL_RUN_MAP_DRUM = 2, ///< level 1 (the map tier); level d is CAL_RUN_MAP_DRUM + d - 1
    CAL_RUN_KINDS = CAL_RUN_MAP_DRUM + CAL_MAX_MAP_DEPTH
} cal_run_kind;

/// The drum runs' kind at a level of a multilevel stage (0: the tier's own).
cal_run_kind cal_progress_drum_kind(int level);

/// A stage's name at a level: "granule" at 0, "granule (map)" at its map
/// tier, "granule (map 2)" a level further down, and so on.
void cal_progress_level_name(const char *stage, int level, char *out, size_t len);

/// Stage 1, then each friction stage (the granule's and 16 materials') at
/// each level.
enum { CAL_PROGRESS_MAX_STAGES = 1 + 17 * (CAL_MAX_MAP_DEPTH + 1) };

typedef struct cal_progress_stage {
    char name[64]; ///< a material's name (< 32), with its level (cal_progress_level_name)
    cal_run_kind kind;
    int planned;  ///< at most this many simulations
    int expected; ///< as many as a typical run takes (the plan's expected figure; `planned` until told)
    int done;     ///< run now or found in the store
} cal_progress_stage;

typedef struct cal_progress {
    cal_progress_stage stage[CAL_PROGRESS_MAX_STAGES];
    int n_stages;
    int current;  ///< the stage running, -1 before the first
    int parallel; ///< simulations run at once (workers × ranks)
    double cost_sum[CAL_RUN_KINDS];
    int cost_n[CAL_RUN_KINDS];
} cal_progress;

/// An empty plan: `parallel` simulations at once (at least 1).
void cal_progress_init(cal_progress *p, int parallel);

/// Add a stage that runs at most `planned` simulations of `kind`; 0, or 1
/// if the plan is full.
int cal_progress_plan(cal_progress *p, const char *name, cal_run_kind kind, int planned);

/// The stage called `name` is expected to run `expected` simulations (the
/// plan's expected figure, at most its `planned`); 0, or 1 if it was not
/// planned.
int cal_progress_expect(cal_progress *p, const char *name, int expected);

/// The stage called `name` is running now (later counts go to it); 0, or 1
/// if it was not planned. Every function takes p == NULL and does nothing.
int cal_progress_enter(cal_progress *p, const char *name);

/// One simulation of the current stage done; wall_s: what it cost to run
/// (its record's wall time with its settling), NAN if unknown.
void cal_progress_count(cal_progress *p, cal_run_kind kind, double wall_s);

/// Wall seconds left at most, NAN while a kind still to run has no cost.
double cal_progress_eta_s(const cal_progress *p);

/// Wall seconds left if each stage runs its expected count (a stage past it
/// has none left), NAN while a kind still to run has no cost.
double cal_progress_expected_eta_s(const cal_progress *p);

/// A duration as progress lines print it: "45 s", "12 min", "3.4 h".
void cal_progress_format_duration(double s, char *out, size_t len);

/// "step 2 of 5 (granule), 14 of ≤ 86 simulations, ≤ 1.2 h left" (or
/// "time left after the first drum run"); empty when p is NULL or unplanned.
void cal_progress_describe(const cal_progress *p, char *out, size_t len);

#endif
