// SPDX-License-Identifier: MIT
/// @file exp_silo_runner.h
/// The silo discharge run as `granucal simulate` makes it.
#ifndef EXP_SILO_RUNNER_H
#define EXP_SILO_RUNNER_H

/// `granucal simulate configs/silo.yaml [--set k=v ...] [--out DIR]`: JSON
/// on stdout; DIR gets result.json, result.h5 (final frame), series.csv,
/// contacts.png, kinetic_energy.png and silo_initial.data (for LIGGGHTS).
/// Returns 0 on success.
int exp_silo_simulate(const char *path, int n_sets, char **sets, const char *out);

#endif
