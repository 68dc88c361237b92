// SPDX-License-Identifier: MIT
/// @file exp_silo_config.h
/// The silo discharge benchmark (exp_silo.h) as a YAML file,
/// configs/silo.yaml, with `--set key=value` overrides, validated field by
/// field; exp_silo_runner.h runs what it loads.
#ifndef EXP_SILO_CONFIG_H
#define EXP_SILO_CONFIG_H

#include <stddef.h>

#include "exp_silo.h"

/// 1 if the file is a silo config (first key `experiment: silo`).
int exp_is_silo_config(const char *path);

/// Load a silo config with `--set` overrides ("key=value": k_n, mu_s, xi,
/// dt, duration, orifice_radius, silo_radius, plate_z, n_granules, seed)
/// into a definition, checked (exp_silo_check). 0, or 1 with a message
/// naming the file, line and YAML key ("FILE:LINE: KEY: problem"), or the
/// `--set` that gave the bad value.
int exp_silo_load(const char *path, int n_sets, char **sets, exp_silo_def *d, char *err, size_t len);

#endif
