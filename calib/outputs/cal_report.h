// SPDX-License-Identifier: MIT
/// @file cal_report.h
/// What a calibration writes into its results folder: the table (Table 3's
/// layout) as CSV, Markdown and HDF5; every simulation; the plots; the
/// table as input for LIGGGHTS and LAMMPS; and a report with the evidence
/// behind every number.
#ifndef CAL_REPORT_H
#define CAL_REPORT_H

#include "cal_stages.h"

/// The calibrated values and where each came from.
typedef struct cal_table {
    double density, xi, k_n;
    const char *k_source;
    int k_calibrated;     ///< 1: k_n chosen by stage 1 (this run or an earlier one); 0: the config's
    double gg_mu_s, gg_mu_r;
    cal_range gg_mu_s_range, gg_mu_r_range; ///< identified ranges; NAN where the stage was not run
    const char *gg_source;
    int gg_angle_matched; ///< the stage's pair matched the angle: 1, 0, or -1 unknown (an earlier run's stage file)
    int n_walls;
    char wall_name[16][32];
    double wall_mu_s[16], wall_mu_r[16];
    cal_range wall_mu_s_range[16], wall_mu_r_range[16];
    char wall_source[16][96];
    int wall_angle_matched[16]; ///< as gg_angle_matched
} cal_table;

/// Everything the run found; stages not run are NULL.
typedef struct cal_outcome {
    const cal_config *config;
    const cal_tier *tier;
    const cal_stiffness_result *stiffness;
    const cal_friction_result *granule;
    const cal_friction_result *walls[16];
    int n_walls;
    cal_table table;
    int angle_data_synthetic, csa_data_synthetic; ///< the data files say SYNTHETIC (cal_series.synthetic)
    const char *command;
    double wall_time_s;
    int ranks, workers;
    /// [stage][0: μs, 1: μr], stage 0 the granule stage, 1 + w wall w: each
    /// friction's credible interval, which its status is judged against
    /// (cal_table_rows). cal_report_write fills it from the posteriors it
    /// samples; the caller leaves it zero.
    cal_credible credible[17][2];
} cal_outcome;

/// Write every output into dir. 0 on success, else 1 with a message.
int cal_report_write(const char *dir, const cal_outcome *o, char *err, size_t len);

#endif
