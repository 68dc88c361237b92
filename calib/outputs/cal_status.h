// SPDX-License-Identifier: MIT
/// @file cal_status.h
/// What a calibration's outputs are, and what each value in them is: the
/// one home of the rules that every output (report, table in CSV, Markdown
/// and HDF5, exports) states.
///  - The run: calibration or demonstration (the tier's `purpose`), the tier,
///    the λ the drum and the cylinder ran at, and whether the data are the
///    lab's or synthetic (a SYNTHETIC comment in the data file).
///  - Each value: calibrated only when the data chose it: a search bound is
///    a bound (one-sided), a value outside the interval its own data leave
///    is not a result, and a parameter the data do not constrain is not
///    identified.
#ifndef CAL_STATUS_H
#define CAL_STATUS_H

#include <stdio.h>

#include "cal_report.h"

/// What one value of the table is.
typedef enum cal_value_status {
    CAL_VALUE_INPUT,          ///< given by the config (density, ξ)
    CAL_VALUE_DERIVED,        ///< set by a rule from another value (k_s = k_r = k_n; boundary = 2 k_n)
    CAL_VALUE_CALIBRATED,     ///< chosen by the data: inside its own interval, off the search's bounds
    CAL_VALUE_ONE_SIDED,      ///< the data close one side only: the value on a search bound, or the interval no
                              ///< run excludes running to one (with no posterior held off it): "≥ x" or "≤ x"
    CAL_VALUE_BOUNDED,        ///< the runs exclude values beyond both ends, but what they leave spans more than
                              ///< CAL_CALIBRATED_MAX_WIDTH of the search range and no posterior narrower than that
                              ///< holds the value: "x – y"
    CAL_VALUE_NOT_IDENTIFIED, ///< the data exclude no value of the search range
    CAL_VALUE_NOT_A_RESULT,   ///< the search's choice lies outside the interval its own data leave
    CAL_VALUE_NOT_RUN,        ///< its stage did not run: the config's value, or an unresolved stiffness sweep's
} cal_value_status;

/// A value's status with the facts behind it.
typedef struct cal_verdict {
    cal_value_status status;
    int side;         ///< one-sided: +1 open towards the search's upper bound, -1 towards its lower; else 0
    int on_bound;     ///< one-sided: 1 if the value itself is on that bound (0: off it, the interval reaching it)
    double known;     ///< one-sided: what the data do say, "≥ known" (side +1) or "≤ known" (side -1): the
                      ///< other end of the interval no candidate excludes (the value itself if none)
    double between[2]; ///< bounded: the interval no candidate excludes
    char flags[192];  ///< ';'-separated, "" when none: at_lower_bound, at_upper_bound, not_excluded_to_lower_bound,
                      ///< not_excluded_to_upper_bound (the value off the bound, the interval no run excludes
                      ///< running to it), outside_identified, outside_not_excluded, outside_credible,
                      ///< not_excluded_wide (the runs close both sides but leave more than
                      ///< CAL_CALIBRATED_MAX_WIDTH of the range), credible_correction_exact (the posterior
                      ///< takes a correction with no variance model as exact: it decided nothing), credible_wide (a posterior held off the
                      ///< bound the runs leave open, or within their wide interval, spanning more than that),
                      ///< not_identified, angle_not_matched, stage_not_run, stiffness_at_cylinder_lambda (stage 1
                      ///< swept a cylinder at another λ than the drum's)
} cal_verdict;

/// The widest interval, as a fraction of the search range on the search's
/// scale (μs, log10 μr), within which the data may be said to have chosen a
/// value: the runs' not-excluded interval or the posterior's 95 % one. A flat
/// posterior (the data say nothing) spans 0.95 and is held off neither bound;
/// runs excluded near both bounds, or a posterior held off one by a sliver,
/// still leave most of the range. A value is called calibrated only where the
/// data have excluded at least half of it.
#define CAL_CALIBRATED_MAX_WIDTH 0.5

/// A friction's verdict from its identified range g (cal_range; NAN lo: the
/// stage did not run), its stage's search bounds b and which friction it is
/// (0 μs, 1 μr: widths on the search's own scale, cal_friction_to_unit), and
/// whether its stage's chosen pair matched the angle (1, 0, or -1 unknown:
/// the stage was read from an earlier run's stage file).
cal_verdict cal_verdict_friction(double value, cal_range g, const cal_bounds *b, int which, int angle_matched);

/// Judge v against the friction's credible interval c: a value outside it is
/// not a result (flag outside_credible), except beyond an end that runs to
/// its search bound (a value on that bound: the posterior's 97.5 % point
/// sits below the upper bound by construction). A value off the bounds that
/// is one-sided only because the interval no run excludes reaches a bound is
/// calibrated after all where the posterior is held off that bound and spans
/// at most CAL_CALIBRATED_MAX_WIDTH of the range: the posterior, which weighs
/// every run and the map between them, closes the side the Δχ² cut over the
/// runs leaves open. Held off but wider, the value stays one-sided (flag
/// credible_wide). A bounded value is calibrated where its posterior spans at
/// most CAL_CALIBRATED_MAX_WIDTH (and holds it); wider, it stays bounded.
/// A posterior that takes its correction as exact (c->correction_exact: the
/// correction measured at one run of the deciding tier, or fitted as a
/// plane, has no variance model) decides nothing: the value keeps the
/// status its runs gave it, flagged credible_correction_exact.
void cal_verdict_credible(cal_verdict *v, double value, const cal_credible *c);

/// Whether the verdict carries that flag.
int cal_verdict_has_flag(const cal_verdict *v, const char *flag);

/// The clause the outputs append to a one-sided or bounded value whose
/// posterior did not decide it: flagged credible_correction_exact ("; its
/// posterior takes a correction with no variance model as exact, and decides
/// nothing") or credible_wide ("; its posterior spans more than half the
/// search range"); "" otherwise.
const char *cal_verdict_posterior_clause(const cal_verdict *v);

/// The status's name as the CSV writes it: "calibrated", "one-sided", ...
const char *cal_value_status_name(cal_value_status s);

/// The value as a person should read it: "0.192", "≥ 0.775", "0.11 – 0.95",
/// "not identified", "not a result". `out` holds at least 48 bytes.
const char *cal_verdict_value_text(char *out, size_t len, double value, const cal_verdict *v);

/// One row of the table (Table 3's layout) with its verdict.
typedef struct cal_table_row {
    const char *contact;   ///< "granule-granule" or "granule-boundary"
    char material[32];     ///< "" except for a wall's frictions
    const char *parameter; ///< density, k_n, k_s, k_r, xi, mu_s, mu_r
    double value;
    const char *unit;
    cal_range range;       ///< a calibrated friction's identified range; NAN otherwise
    cal_verdict verdict;
} cal_table_row;

enum { CAL_TABLE_MAX_ROWS = 64 };

/// The table's rows, each judged; how many (at most CAL_TABLE_MAX_ROWS).
int cal_table_rows(const cal_outcome *o, cal_table_row *rows);

/// What the run is, for every output.
typedef struct cal_run_status {
    int demonstration;                 ///< the tier's purpose is "demonstration"
    const char *tier;
    double drum_lambda, cylinder_lambda;
    int stiffness_on_drum;             ///< stage 1 swept the drum's own bed (stiffness_scene: drum), at its λ
    int angle_synthetic, csa_synthetic; ///< the data files say SYNTHETIC
} cal_run_status;

cal_run_status cal_run_status_of(const cal_outcome *o);

/// "calibration" or "demonstration".
const char *cal_run_purpose(const cal_run_status *s);

/// The data's provenance in one field without commas or semicolons: "angle lab / CSA synthetic".
const char *cal_run_data_text(char *out, size_t len, const cal_run_status *s);

/// The banner's first three lines in one, for a figure: "CALIBRATION, tier
/// 'standard', drum λ = 1000; angle: lab, CSA: SYNTHETIC".
const char *cal_run_stamp(char *out, size_t len, const cal_run_status *s);

/// The banner every output opens with, each line led by `prefix` ("# ",
/// "> ", ""): what the run is, its λ, its data, and how to read each value's
/// status.
void cal_run_status_banner(FILE *f, const cal_run_status *s, const char *prefix);

/// One line a value for every friction of the table the data did not choose
/// (one-sided, not identified, not a result, stage not run), led by
/// `prefix`; nothing when every friction is calibrated. For files a user
/// copies values from (the exports), where the table's columns are absent.
void cal_table_caveats(FILE *f, const cal_outcome *o, const char *prefix);

#endif
