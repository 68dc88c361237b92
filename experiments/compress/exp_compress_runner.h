// SPDX-License-Identifier: MIT
/// @file exp_compress_runner.h
/// The confined compression test run as `granucal simulate` makes it.
#ifndef EXP_COMPRESS_RUNNER_H
#define EXP_COMPRESS_RUNNER_H

/// `granucal simulate configs/compression.yaml [--set k=v ...] [--out DIR]`:
/// load, validate (errors name file, line, field), run, print one JSON
/// object on stdout and write DIR/result.json, result.h5, curve.csv and
/// force_displacement.png. Returns the process exit status.
int exp_compress_simulate(const char *path, int n_sets, char **sets, const char *out);

#endif
