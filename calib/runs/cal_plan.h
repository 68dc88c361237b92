// SPDX-License-Identifier: MIT
/// @file cal_plan.h
/// The cost model behind every `--plan` (calibrate, synthesize, study): what
/// a simulation costs in core-seconds, predicted from its particle-steps, and
/// what a batch of them takes in wall time on the workers. Each plan gives two
/// figures: the EXPECTED cost (a drum run ends at the steady test's first
/// chance, the searches run their typical counts) and the WORST case (every
/// run turns for max_time, every search runs its every evaluation).
#ifndef CAL_PLAN_H
#define CAL_PLAN_H

#include "cal_case_runs.h"

/// Particle-steps a core does per second in a whole drum run (turning,
/// measuring, checks): measured on this project's 2-core machine at 4d0268d
/// (results/benchmarks/drum_end_to_end.md, "The stiffness stage 1 chooses":
/// 1.46e7 at k_n 50 N/m and 1.52e7 at 200 N/m on the λ 1000 drum; the kernel
/// 1.45-1.60e7 at d07c877). Another machine scales every figure of a plan.
#define CAL_PLAN_RATE 1.5e7

/// What a plan adds up.
typedef struct cal_plan_cost {
    int runs;           ///< simulations
    double core_s;      ///< their single-core seconds
    double wall_s;      ///< on the workers, batch after batch
    double memory_mb;   ///< the largest simulation's peak memory
    int mser_runs;      ///< drum runs stopped by the MSER rule
    int mser_from_store; ///< of those, how many a store's runs of their own kind predict (cal_plan_history)
    int mser_from_other_scale; ///< how many runs of their kind at another λ or k_n predict
} cal_plan_cost;

/// What a store's runs say of when the MSER rule stops a run: each stored
/// drum run under that rule (steady or not, failed ones left out), its kind
/// and its kind at any scale (cal_drum_key_kind) and the simulated time it
/// turned.
typedef struct cal_plan_history {
    int n, cap;
    char **kind, **any_scale;
    double *turn_s;
} cal_plan_history;

/// The fewest stored runs of a kind whose mean stop a plan takes for that
/// kind: below it, the plan keeps max_time.
#define CAL_PLAN_HISTORY_MIN 3

/// Read the MSER runs of store folder `store` (none where it does not exist
/// yet). 0, or 1 with a message.
int cal_plan_history_read(cal_plan_history *h, const char *store, char *err, size_t len);
void cal_plan_history_free(cal_plan_history *h);

/// The mean simulated time of h's runs of `kind` (any_scale: of that kind at
/// any scale), and their count in *n (the mean is the cost to expect: an MSER
/// run either stops early or turns to max_time, so its stops have two modes).
double cal_plan_history_mean(const cal_plan_history *h, const char *kind, int any_scale, int *n);

/// The figures of a plan: expected, and worst case.
typedef struct cal_plan {
    cal_plan_cost expected, worst;
} cal_plan;

/// What a drum run's expected and worst-case figures assume (cal_plan_turn_time), as a plan prints it.
#define CAL_PLAN_RUN_ASSUMPTION \
    "expected: each run ends at the steady test's first chance (two windows, then its averaging; under the MSER " \
    "rule the mean stop of the store's runs of its kind where it holds at least 3, of its kind at another λ or " \
    "k_n where those are 3, else max_time); worst case: " \
    "max_time."

/// Add plan p to a total, expected and worst case alike (runs, seconds; the
/// largest memory).
void cal_plan_add(cal_plan *total, const cal_plan *p);

/// Add `runs` of c's runs to a total at c's cost per run: what is left of a
/// step whose other runs a store holds. Nothing if runs or c's runs are 0.
void cal_plan_add_runs(cal_plan_cost *total, const cal_plan_cost *c, int runs);

/// Simulated seconds a drum run of case d turns at rpm: the worst case
/// max_time; expected, the steady test's first chance (its two windows, then
/// the averaging time), at most max_time. Every λ 1000 run of the committed
/// standard calibration ended within 0.75 s of that (results/calibration-standard/
/// simulations.csv: 10.05-10.75 s at 4 rpm, 4.0-4.1 s at 40 and 116).
/// Under the MSER rule the run's own series decides its stop, which nothing
/// but runs of its kind predicts: expected, the mean stop of history's runs
/// of its kind where there are CAL_PLAN_HISTORY_MIN (*from_store = 1); else
/// of its kind at another λ or k_n (*from_store = 2: a finer λ's series is
/// smoother, so it should reach its standard error no later); else max_time
/// (*from_store = 0; history may be NULL).
double cal_plan_turn_time(const cal_drum_case *d, double rpm, int worst, const cal_plan_history *history,
                          int *from_store);

/// The turned beds of a stage whose tier starts some speeds turned
/// (cal_drum_case.n_turned): one per bed (seed) and turned speed, each
/// poured and turned turned_time s before the first run starts from it,
/// side by side. Added to *cost once for the beds a process keeps.
void cal_plan_turned_beds(cal_plan_cost *cost, const cal_drum_case *d, int beds, int parallel);

/// m drum candidates like d, each on `beds` beds (seeds), turned at the n
/// speeds rpm[], run together as one batch the way cal_drum_evaluate_many
/// runs them: where every run settles the same bed (one candidate on one
/// bed, or a wall stage on one bed) the bed is settled first, unless
/// `bed_kept` (a wall stage's bed settled earlier in the process), and each
/// run is a task; otherwise each candidate's bed is a task that settles it
/// and turns its speeds in turn. Added to *cost.
/// `history` (may be NULL) as in cal_plan_turn_time.
void cal_plan_drum_batch(cal_plan_cost *cost, const cal_drum_case *d, const double *rpm, int n, int m, int beds,
                         int wall_stage, int bed_kept, int parallel, int worst, const cal_plan_history *history);

/// A batch of n independent tasks of task_s core-seconds each on `parallel`
/// workers: the longest task or the total shared out, whichever is longer.
double cal_plan_makespan(const double *task_s, int n, int parallel);

/// "4.2 core-hours, 2.4 h on 2 worker(s)" and the like: hours with two
/// significant figures.
void cal_plan_describe(const cal_plan_cost *c, int parallel, char *out, size_t len);

/// How c's MSER runs were predicted (cal_plan_turn_time), as every plan
/// prints it: "4 of 16 MSER runs from OUT/store, 4 more from runs of their
/// kind at another λ or k_n".
void cal_plan_describe_mser(const cal_plan_cost *c, const char *store, char *out, size_t len);

#endif
