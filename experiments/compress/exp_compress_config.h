// SPDX-License-Identifier: MIT
/// @file exp_compress_config.h
/// The confined compression test (exp_compress.h) as a YAML file,
/// configs/compression.yaml, with `--set key=value` overrides, validated
/// field by field; exp_compress_runner.h runs what it loads.
#ifndef EXP_COMPRESS_CONFIG_H
#define EXP_COMPRESS_CONFIG_H

#include <stddef.h>

#include "exp_compress.h"

/// 1 if the file is a compression config (first key `experiment: compression`).
int exp_is_compress_config(const char *path);

/// Load a compression config with `--set` overrides ("key=value": k_n, mu_s,
/// wall_mu_s, xi, lambda, seed, sigma_min, sigma_max, piston_speed, cycles,
/// max_time) into a definition, checked (exp_compress_check). 0, or 1 with a
/// message naming the file, line and field ("FILE:LINE: FIELD: problem"), or
/// the `--set` that gave the bad value.
int exp_compress_load(const char *path, int n_sets, char **sets, exp_compress_def *d, char *err, size_t len);

#endif
