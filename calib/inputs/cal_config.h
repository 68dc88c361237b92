// SPDX-License-Identifier: MIT
/// @file cal_config.h
/// A calibration config (configs/calibration.yaml): the powder, the drum,
/// the lab data files, the stiffness candidates, the friction bounds, the
/// wall materials to fit and the fidelity tiers. Loaded with libcyaml and
/// validated field by field before any simulation starts.
#ifndef CAL_CONFIG_H
#define CAL_CONFIG_H

#include <stddef.h>
#include "cal_multifidelity.h"
#include "dem_gsd.h"

/// A wall material to fit: its name in the table and its drum lining's name
/// in the lab data files.
typedef struct cal_material {
    char *name;    ///< "aluminium"
    char *surface; ///< "Aluminium"
} cal_material;

/// Bounds of a (μs, μr) search; μr is searched on a log scale.
typedef struct cal_bounds {
    double mu_s_min, mu_s_max, mu_r_min, mu_r_max;
} cal_bounds;

/// Tiers that may map below one tier (its map_tier, that tier's map_tier...):
/// each level is a whole search run before the one above it, so a chain
/// deeper than this is a mistake rather than a plan (checked on loading).
enum { CAL_MAX_MAP_DEPTH = 3 };

/// A fidelity tier: every accuracy knob of the virtual experiments, and
/// the search budget that goes with it. A rung of the fidelity study is the
/// same struct, read by the same schema, with the drum's knobs alone (name
/// to average_time below, cal_tier_calibration_key says which others a rung
/// may not give): the study runs a rung's drum as the calibration runs a
/// tier's, through the same drum case and so the same store keys.
typedef struct cal_tier {
    // The drum's knobs, a tier's and a rung's:
    char *name;
    double lambda;          ///< drum coarse-graining factor (eq. 15)
    double slice_depth;     ///< periodic slice depth, m; 0 = the full drum with end plates
    double max_time;        ///< s of turning at most per speed
    double window;          ///< s, steady-state averaging window
    double sample_interval; ///< s between drum-face measurements (optional; 0: the drum's default)
    double steady_angle_tol_deg, steady_csa_tol_percent; ///< optional; 0: the drum's defaults
    char *fill_method;      ///< how the drum's bed is built: "pour" (absent) or "pack" (exp_drum_fill_method)
    double average_time;    ///< s averaged on after the steady test holds (exp_drum_run_opts; 0: none)
    /// How a run decides it is steady and stops: "windows" (absent: the two
    /// windows' test, then the averaging) or "mser" (exp_drum_run_opts.
    /// steady_rule: MSER's cut and a standard error of at most
    /// steady_se_angle_deg and steady_se_csa_percent, both then required).
    char *steady_rule;
    double steady_se_angle_deg, steady_se_csa_percent;
    // A calibration tier's alone (optional in the schema, so that a rung
    // reads without them; check_tier requires cylinder_lambda and seeds):
    /// The same, one per entry of rpm (replaces average_time): a slow drum
    /// avalanches and needs seconds of averaging for its angle, a fast one
    /// flows steadily and needs far less for its CSA.
    double *average_time_per_rpm;
    unsigned average_time_per_rpm_count;
    /// Speeds whose runs start from a turned bed instead of a level one
    /// (absent: none). Per seed, the stage's bed, poured with its fill pair
    /// (the granule stage: pour_mu_s, pour_mu_r; the wall stage: the frozen
    /// granule pair), is turned turned_start_time s at that speed once, and
    /// every candidate's run at it starts from there without the start tilt;
    /// MSER (steady_se_angle_deg, steady_se_csa_percent) cuts the transient
    /// of the change of pair and stops the run. Why: from a level bed a 4 rpm
    /// run still compacts for ~8 s, and the windows' test then reads its
    /// angle ~1.4° high at λ 1000 (results/steady_rule/turned_start/).
    double *turned_start_rpm;
    unsigned turned_start_rpm_count;
    double turned_start_time;
    double *rpm;            ///< speeds simulated; empty = every speed in the data
    unsigned rpm_count;
    double cylinder_lambda; ///< coarse-graining factor of the poured cylinder (stage 1)
    /// Stage 1's candidates for this tier (N/m, increasing); absent: the
    /// config's `stiffness`. A coarser cylinder shows its CN change at softer
    /// k (results/stiffness_low_k/), so a tier may need softer candidates.
    double *stiffness;
    unsigned stiffness_count;
    /// Stage 1's bed: the poured cylinder (0, absent: `cylinder`, at
    /// cylinder_lambda) or the tier's own drum (1: `drum`, exp_drum_bed.h: its
    /// λ, slice, fill and fill method, poured with pour_mu_s, pour_mu_r).
    int *stiffness_scene;
    int seeds;              ///< poured beds per stiffness (seed-to-seed spread)
    int grid;               ///< initial design: grid points per axis of (μs, log μr); absent: 0, none
    int max_evaluations;    ///< NLopt evaluations after the grid; absent: 0
    double angle_sd_deg;    ///< the tier's own angle spread (measured), added to the lab's in the constraint; absent: 0
    /// How the angle enters the friction search: "constraint" (absent: the
    /// paper's rule, sections 4.2-4.3: the angle within its tolerance first,
    /// then the best CSA misfit) or "misfit" (the angle is one more
    /// measurement in the misfit, weighed by its tolerance: for a tier whose
    /// single-run angle noise is as wide as the tolerance band, where a hard
    /// constraint lets that noise choose).
    char *angle_rule;
    /// The tier's own seed-to-seed spread of one run's CSA (percentage points),
    /// measured with `granucal study fidelity --seeds N` on the tier's drum:
    /// one value for every speed, or one per entry of rpm. With the lab's
    /// spread it sets which candidates the data cannot tell apart (the
    /// identified ranges); absent: the lab's spread alone.
    double *csa_sd_percent;
    unsigned csa_sd_percent_count;
    /// After the search, the best μs with μr at each search bound, so that the
    /// identified μr range says whether the data bound it (absent: true).
    int *bound_probes;
    /// With the grid, the four corners of the search box (absent: false), so
    /// that a map made from this tier's candidates spans the box a level
    /// above asks it about instead of extrapolating past the grid's cell
    /// centres (cal_stage_two_tier; the standard rerun's ci map stopped at
    /// μs 0.325 with a bound of 0.1, and its plane read 22° high at 0.1).
    int *design_corners;
    /// A cheaper tier that maps the friction plane first (cal_multifidelity.h):
    /// this tier then runs only where the map, corrected by the discrepancy it
    /// measures between the two, puts the optimum; max_evaluations bounds
    /// those runs and grid is unused. The map tier may have a map_tier of its
    /// own (levels: its result, runs and predictions, is this tier's map;
    /// at most CAL_MAX_MAP_DEPTH below, no cycle). NULL: a one-tier search.
    char *map_tier;
    /// How the discrepancy measured at this tier's runs corrects the map
    /// (cal_mf_correction_kind; absent: kriging).
    int *map_correction;
    /// With a map_tier: after the loop, at most this many more runs, each
    /// where the posterior on the corrected map is still held wide by the
    /// map's own uncertainty (cal_posterior_next_run); none where its width
    /// is the data's. Absent: 0.
    int posterior_runs;
    /// With posterior_runs: once the posterior's runs are made (one or more),
    /// at most this many more runs at the corrected map's optimum, the loop
    /// resumed (cal_mf_return): those runs moved the correction, and the
    /// stage must not end on an optimum no run checked. Absent: 0.
    int return_runs;
    /// With a map_tier: the loop (and its return runs) aims where the
    /// corrected map's angle stands inside the angle's tolerance by this many
    /// standard deviations of what a run there would read (the tier's run
    /// noise and the kriging's sd of the correction, in quadrature), at most
    /// the band's centre. 0 (absent): the band itself, where a soft penalty
    /// puts the optimum just outside the edge the CSA pulls toward (the
    /// standard rerun's runs 3, 4 and 7 were aimed 0.01-0.04° below its lower
    /// edge and read 0.3-1.0° lower still). Only where the next run goes: the
    /// stage still chooses among its runs by its angle_rule.
    double angle_aim_sd;
    /// Beds each drum candidate is run on (seeds seed, seed+1, ...), its
    /// measurements the mean over them. angle_sd_deg and csa_sd_percent stay
    /// one bed's spreads, as measured; the search divides them by sqrt(beds)
    /// (independent packings). 0: one.
    int beds;
    /// `purpose: demonstration` (1) marks a tier too coarse for its table to
    /// stand for the powder: every output of its runs says "demonstration —
    /// not a calibration of this powder". Absent or `calibration`: 0.
    int *demonstration;
} cal_tier;

/// 1 if the tier puts the angle into the misfit instead of a constraint.
int cal_tier_angle_in_misfit(const cal_tier *t);
/// Beds per drum candidate (1 when not given).
int cal_tier_beds(const cal_tier *t);
/// 1 if the tier's purpose is demonstration (cal_tier.demonstration).
int cal_tier_is_demonstration(const cal_tier *t);
/// 1 if stage 1 sweeps the stiffness on the tier's drum (stiffness_scene: drum).
int cal_tier_stiffness_on_drum(const cal_tier *t);
/// 1 if the tier probes the μr bounds after the search (the default).
int cal_tier_bound_probes(const cal_tier *t);
/// 1 when the tier's initial design adds the search box's corners (design_corners).
int cal_tier_design_corners(const cal_tier *t);
/// The tier's map_correction (kriging when absent).
cal_mf_correction_kind cal_tier_map_correction(const cal_tier *t);
/// The tier's CSA spread at speed index i of its rpm list (0: not measured).
double cal_tier_csa_sd(const cal_tier *t, unsigned i);
/// Seconds a run at `rpm` averages after its steady test: average_time_per_rpm's
/// entry for that speed, else average_time.
double cal_tier_average_time(const cal_tier *t, double rpm);

/// The first key of a calibration tier alone that t gives (a value other
/// than 0 or absent), NULL if none: a rung of the fidelity study may not.
const char *cal_tier_calibration_key(const cal_tier *t);

/// The fidelity study (`granucal study fidelity`): the drum lined with
/// granules (wall pair = granule pair: Table 3's aluminium drum, as in Table
/// B.1) at the config's granule-granule pair, over a ladder of rungs, several
/// seeds each.
typedef struct cal_fidelity {
    double *rpm;                 ///< speeds turned on each rung
    unsigned rpm_count;
    int seeds;                   ///< seeds per rung (the spread)
    double budget_hours;         ///< a rung predicted to take longer is listed, not run
    cal_tier *rungs;             ///< each the drum's knobs of a tier alone
    unsigned rungs_count;
} cal_fidelity;

typedef struct cal_config {
    char *calibration;                 ///< "drum"
    char *repose_angle, *occupied_area; ///< lab data, relative to the config file
    /// The log-normal GSD by number (absent with gsd_table; then the table's
    /// number median and geometric sd, derived on load; truncation 0).
    double density, median_diameter, geometric_sd, truncation_sigmas, xi;
    char *gsd_table;                   ///< measured size table (CSV, exp_gsd_table.h), relative to the config file
    char *gsd_basis;                   ///< what its percentages count: "volume" or "number"
    char *damping;
    double diameter, depth, fill;
    char *granule_surface;             ///< the granule-lined drum's name in the data files
    cal_material *materials;
    unsigned materials_count;
    double *stiffness;                 ///< k_n candidates of stage 1, N/m (real powder)
    unsigned stiffness_count;
    double stiffness_tolerance;        ///< CN tolerance; 0 = from the seed-to-seed spread
    double k_n;                        ///< stiffness used when stage 1 is skipped
    double granule_mu_s, granule_mu_r; ///< granule–granule pair used when stage 2 is skipped
    double pour_mu_s, pour_mu_r;       ///< prior friction of the stage-1 pour (before friction is known)
    cal_bounds granule, wall;
    char *tier;                        ///< the tier to run (override: --tier)
    cal_tier *tiers;
    unsigned tiers_count;
    int seed;
    cal_fidelity *fidelity;            ///< optional: the fidelity study
    // Derived on load:
    dem_gsd gsd;                       ///< the size distribution the simulations sample
    char dir[1024];                    ///< directory of the config file
    char path[1024];
} cal_config;

/// Load and validate; `tier_override` (may be NULL) replaces `tier`. NULL
/// with a message naming file, line and field.
cal_config *cal_config_load(const char *path, const char *tier_override, char *err, size_t len);
void cal_config_free(cal_config *c);

/// The tier the config selects.
const cal_tier *cal_config_tier(const cal_config *c);
/// The tier named `name`, NULL if none.
const cal_tier *cal_config_tier_named(const cal_config *c, const char *name);
/// The tier `level` steps down t's chain of map tiers (0: t itself, 1: its
/// map_tier, 2: that tier's map_tier...), NULL where the chain is shorter.
const cal_tier *cal_tier_map_level(const cal_config *c, const cal_tier *t, int level);
/// How many tiers map below t (0: a one-tier search), at most CAL_MAX_MAP_DEPTH.
int cal_tier_map_depth(const cal_config *c, const cal_tier *t);
/// Stage 1's candidates at tier t: the tier's `stiffness`, else the config's.
const double *cal_tier_stiffness(const cal_config *c, const cal_tier *t, unsigned *n);

/// A data path resolved against the config file's directory.
void cal_config_data_path(const cal_config *c, const char *rel, char *out, size_t len);

#endif
