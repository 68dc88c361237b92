// SPDX-License-Identifier: MIT
/// @file exp_incline_config.h
/// The sphere on an inclined plane (exp_incline.h) as a YAML file,
/// configs/incline.yaml, with `--set key=value` overrides, validated field by
/// field; exp_incline_runner.h runs what it loads.
#ifndef EXP_INCLINE_CONFIG_H
#define EXP_INCLINE_CONFIG_H

#include <stddef.h>

#include "exp_incline.h"

/// 1 if the file is an incline config (its first key is `experiment: incline`).
int exp_is_incline_config(const char *path);

/// Load `path`, apply `--set` overrides ("key=value": angle_deg, mu_s, mu_r,
/// k_n, xi, diameter, density, duration) and validate (exp_incline_check).
/// 0, or 1 with a message naming the file, line and field ("FILE:LINE:
/// FIELD: problem"), or the `--set` that gave the bad value.
int exp_incline_load(const char *path, int n_sets, char **sets, exp_incline_def *d, char *err, size_t len);

#endif
