// SPDX-License-Identifier: MIT
/// @file exp_silo_config.h
/// The silo's configuration file (configs/silo.yaml: Table A.2's values)
/// read into its definition, `--set key=value` applied, every error located
/// by file and line.
#ifndef EXP_SILO_CONFIG_H
#define EXP_SILO_CONFIG_H

#include <stddef.h>

#include "exp_silo.h"

/// Whether the file at path is a silo config (`experiment: silo` first).
int exp_is_silo_config(const char *path);

/// Read path, apply sets[0..n_sets), check: 0 with *d filled, or 1 with a
/// message naming the file, line and key in err.
int exp_silo_load(const char *path, int n_sets, char **sets, exp_silo_def *d, char *err, size_t len);

#endif
