// SPDX-License-Identifier: MIT
/// @file exp_drum_config.h
/// The drum experiment as a YAML file (configs/drum.yaml), with `--set
/// key=value` overrides, validated field by field.
#ifndef EXP_DRUM_CONFIG_H
#define EXP_DRUM_CONFIG_H

#include "exp_drum.h"

/// A wall material: its friction against the granules. Its stiffness
/// follows the granule–boundary rule (twice the granule stiffness, springs
/// in series, Table 3) and its damping the granule contact.
typedef struct exp_material_yaml {
    char *name;
    double mu_s, mu_r;
} exp_material_yaml;

typedef struct exp_drum_yaml {
    char *experiment;     ///< "drum"
    double diameter, depth, fill;
    int periodic;         ///< a periodic slice of depth `slice_depth`
    double slice_depth;
    double density, median_diameter, geometric_sd, truncation_sigmas; ///< the log-normal (absent with gsd_table)
    char *gsd_table;      ///< optional: a measured size table (exp_gsd_table.h), relative to the config file
    char *gsd_basis;      ///< with gsd_table: "volume" or "number"
    double lambda;
    double k_n;           ///< real granule stiffness, k_n = k_s = k_r (section 3.2)
    double xi, mu_s, mu_r;
    char *damping;
    char *fill_method;    ///< optional: "pour" (default) or "pack" (exp_drum_fill_method)
    char *wall;           ///< lining material: "granules" or a name in materials
    exp_material_yaml *materials;
    unsigned materials_count;
    double rpm, max_time, window, sample_interval;
    double pixel;
    double *start_tilt_deg; ///< optional (NULL: exp_default_drum_run_opts' 20°)
    int closing_px;
    int seed;
    dem_gsd gsd;          ///< derived on load: the size distribution (the log-normal's keys or the table)
} exp_drum_yaml;

/// 1 if the file is a drum experiment (its first key is `experiment: drum`).
int exp_is_drum_config(const char *path);

/// Load, apply `--set` overrides ("key=value": rpm, mu_s, mu_r, k_n, wall,
/// lambda, seed, fill, slice_depth, max_time), validate. NULL with a message
/// naming the file, line and field.
exp_drum_yaml *exp_drum_config_load(const char *path, int n_sets, char **sets, char *err, size_t len);
void exp_drum_config_free(exp_drum_yaml *y);

/// The drum and run definitions the config describes.
int exp_drum_config_defs(const exp_drum_yaml *y, exp_drum_def *def, exp_drum_run_opts *run, char *err, size_t len);

#endif
