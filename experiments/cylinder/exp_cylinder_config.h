// SPDX-License-Identifier: MIT
/// @file exp_cylinder_config.h
/// The poured cylinder (section 4.1, exp_cylinder.h) as a YAML scene,
/// configs/cylinder.yaml, with `--set key=value` overrides, validated field
/// by field; exp_cylinder_runner.h runs what it loads.
#ifndef EXP_CYLINDER_CONFIG_H
#define EXP_CYLINDER_CONFIG_H

#include <stddef.h>

#include "exp_cylinder.h"

/// 1 if the file is a poured-cylinder config (its first key is `experiment: cylinder`).
int exp_is_cylinder_config(const char *path);

/// Load `path`, apply `--set` overrides ("key=value": k_n, mu_s, mu_r, xi,
/// lambda, seed, diameter, depth, density) and validate. 0, or 1 with a
/// message naming the file, line and field ("FILE:LINE: FIELD: problem"), or
/// the `--set` that gave the bad value.
int exp_cylinder_load(const char *path, int n_sets, char **sets, exp_cylinder_def *d, char *err, size_t len);

#endif
