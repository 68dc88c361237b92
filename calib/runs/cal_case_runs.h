// SPDX-License-Identifier: MIT
/// @file cal_case_runs.h
/// The simulations a calibration asks for, through the result store: a
/// drum candidate (one settled bed turned at each speed) and a poured
/// cylinder. What is stored is never run again; what is missing is dealt
/// out over MPI ranks and, on each machine, over worker processes.
#ifndef CAL_CASE_RUNS_H
#define CAL_CASE_RUNS_H

#include <stdint.h>

#include "cal_config.h"
#include "cal_progress.h"
#include "cal_store.h"
#include "exp_cylinder.h"
#include "exp_drum.h"

/// How simulations are run and reported.
typedef struct cal_env {
    char store[1100];   ///< record directory
    int workers;        ///< processes per machine
    int use_fork;
    int tty;            ///< progress on a terminal
    char stage[64];     ///< label of the current stage, for progress lines
    double started;     ///< wall clock at the start of the calibration
    /// Wall seconds between a drum run's checkpoints in the store (0: none):
    /// a killed run, run again, resumes its turn from the last one.
    double checkpoint_every_s;
    unsigned long long simulations_run; ///< by this process (the rest came from the store)
    cal_progress *progress;             ///< the whole calibration's, or NULL (a study, a single run)
    /// Read the store, run nothing (a plan replaying a resumed run): the first
    /// batch with a record missing ends the evaluation with an error, and
    /// `store_missing` says how many of its runs were missing. Nothing is
    /// written: not a failed record, and a damaged one (missing: it will run
    /// again) is not moved aside.
    int store_only;
    int store_missing;
    int mapping;                        ///< the level running in a two-tier stage: 0 the tier's own, 1
                                        ///< its map tier, 2 that tier's map tier...: its drum runs are
                                        ///< counted by level (cal_progress_drum_kind), its stage named
                                        ///< "NAME (map)", "NAME (map 2)"... (cal_progress_level_name)
    /// The last settled bed and the text that defined it: the wall stage's
    /// candidates all turn the same one (cal_drum_case_wall), so it is
    /// settled once per process. Freed by cal_sim_release.
    dem_world *kept_bed;
    char kept_text[1024];
    /// Turned beds (cal_drum_case.start turned at a speed), by the hash of
    /// their text, kept for this process's later candidates; wall_s: what
    /// making one cost this process, charged to the first run that starts
    /// from it. Freed by cal_sim_release.
    struct cal_turned_bed {
        dem_world *bed;
        char hash[17];
        double wall_s;
    } *turned;
    int n_turned;
} cal_env;

/// Name the stage that progress lines are labelled with.
void cal_env_set_stage(cal_env *env, const char *stage);

/// Default wall seconds between a drum run's checkpoints: a kill costs at
/// most this much turning, and a save (a few MB at λ 1000) is a small share.
#define CAL_CHECKPOINT_EVERY_S 120.0

/// A drum candidate: the drum and powder, how its bed is settled, and how
/// each speed is run.
enum { CAL_CASE_MAX_RPM = 32 };

typedef struct cal_drum_case {
    exp_drum_def def;  ///< turned with these pairs
    exp_drum_def fill; ///< settled with these (the same drum; only the wall pair may differ)
    exp_drum_run_opts run;
    /// Speeds averaged for another time than run.average_time (a tier's
    /// average_time_per_rpm); read through cal_drum_run_opts.
    int n_average;
    double average_rpm[CAL_CASE_MAX_RPM], average_time[CAL_CASE_MAX_RPM];
    /// Speeds whose runs start from a turned bed (a tier's turned_start_rpm;
    /// 0: none): the fill's drum and seed poured and turned turned_time s at
    /// that speed with the start pairs, once for every candidate that shares
    /// them; the run then goes on from there with its own pairs, without the
    /// start tilt, stopped by MSER (cal_drum_run_opts).
    int n_turned;
    double turned_rpm[CAL_CASE_MAX_RPM], turned_time;
    exp_drum_def start; ///< the turned bed's drum (the fill's) and pairs
} cal_drum_case;

/// Every bed of case d (its turn, fill and turned start) on `seed`.
void cal_drum_case_set_seed(cal_drum_case *d, uint64_t seed);

/// 1 if case c's runs at `rpm` start from its turned bed.
int cal_drum_case_turned(const cal_drum_case *c, double rpm);

/// The run options of case c turned at `rpm`: its speed, and its averaging
/// time at that speed.
exp_drum_run_opts cal_drum_run_opts(const cal_drum_case *c, double rpm);

/// Stage 2: the drum lined with granules (wall pair = granule pair) at
/// granule stiffness k_n, settled and turned with that pair. The bed's
/// packing, hence its CSA, depends on the granule pair, so each candidate
/// settles its own bed (same seed: the same granules at the same places).
/// A turned start's bed is the stage's own, poured and turned with the
/// config's prior pair (pour_mu_s, pour_mu_r), shared by every candidate.
cal_drum_case cal_drum_case_granule(const cal_config *c, const cal_tier *t, double k_n, double mu_s, double mu_r);

/// Stage 3: the granule pair frozen, a wall material's pair (wall_mu_s,
/// wall_mu_r). Every candidate turns the same bed, settled in the drum lined
/// with granules: the wall changes only the boundary layer of a poured bed, so
/// one fill serves the whole stage (a fill costs about as much as a turn).
/// A turned start's bed is that fill turned in the granule-lined drum.
cal_drum_case cal_drum_case_wall(const cal_config *c, const cal_tier *t, double k_n, double gg_mu_s, double gg_mu_r,
                                 double wall_mu_s, double wall_mu_r);

/// Free the settled bed kept between candidates (at the end of a run).
void cal_sim_release(cal_env *env);

/// The poured cylinder of stage 1 at stiffness k_n and seed.
exp_cylinder_def cal_cylinder_case_make(const cal_config *c, const cal_tier *t, double k_n, uint64_t seed);

/// A stage-1 bed: the poured cylinder, or the tier's drum's own poured bed
/// (its tier's stiffness_scene), both poured with the config's prior friction.
typedef struct cal_bed_case {
    int on_drum;               ///< 1: drum_bed (exp_drum_bed_run), 0: cylinder (exp_cylinder_run)
    exp_cylinder_def cylinder;
    exp_drum_def drum_bed;     ///< the tier's drum, granule and wall pairs at pour_mu_s, pour_mu_r
} cal_bed_case;

/// Stage 1's bed at tier t, stiffness k_n and seed, in the tier's scene.
cal_bed_case cal_bed_case_make(const cal_config *c, const cal_tier *t, double k_n, uint64_t seed);
/// Its record's key: the cylinder's key (cal_cylinder_key), or "drum_bed "
/// and the drum definition's text (all that defines the settled bed).
void cal_bed_key(const cal_bed_case *b, char *out, size_t len);

/// The text that defines a simulation (hashed into its record's name).
void cal_drum_key(const cal_drum_case *c, double rpm, char *out, size_t len);
void cal_cylinder_key(const exp_cylinder_def *c, char *out, size_t len);
/// The kind of run a drum record's key names: the key with every friction
/// pair and the seed masked ("mu=*", "seed=*"). Runs of one kind differ only
/// by pairs and bed: the same drum, tier, speed and stopping rule. With
/// any_scale, the coarse-graining λ, the slice depth and the stiffnesses
/// are masked too ("lambda=*", "depth=*", "k=*"): the same drum, speed, start
/// and stopping rule at any λ and k_n.
void cal_drum_key_kind(const char *key, int any_scale, char *out, size_t len);

/// Records of the drum candidate at each speed, running the missing ones.
/// 0 when every record is in hand (failed simulations included), else 1
/// with a message (the store could not be read or written).
int cal_drum_evaluate(cal_env *env, const cal_drum_case *c, const double *rpm, int n, cal_record *out, char *err,
                      size_t len);
/// The same for several candidates at once (out: n_cases × n records, by
/// candidate): their missing runs share the workers, so one candidate's long
/// speed does not leave the others idle.
int cal_drum_evaluate_many(cal_env *env, const cal_drum_case *cases, int n_cases, const double *rpm, int n,
                           cal_record *out, char *err, size_t len);

/// What one stage-1 bed is expected to cost before it runs, in particle-steps,
/// and its peak memory (MB): the cylinder's exp_cylinder_predict_cost, or the
/// drum fill's (exp_drum_predict_cost).
double cal_bed_predict_particle_steps(const cal_bed_case *b, double *memory_mb);

/// Records of stage-1 beds, running the missing ones side by side.
int cal_bed_evaluate(cal_env *env, const cal_bed_case *cases, int n, cal_record *out, char *err, size_t len);

#endif
