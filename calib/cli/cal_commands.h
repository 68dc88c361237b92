// SPDX-License-Identifier: MIT
/// @file cal_commands.h
/// The sub-commands of granucal; each reads its options from its own table
/// (cal_options.h).
#ifndef CAL_COMMANDS_H
#define CAL_COMMANDS_H

#include "exp_drum_config.h"

int cal_cmd_simulate(int argc, char **argv);
int cal_cmd_measure(int argc, char **argv);
int cal_cmd_calibrate(int argc, char **argv);
int cal_cmd_study(int argc, char **argv);
int cal_cmd_synthesize(int argc, char **argv);

/// The drum's runner: turn the settled bed of a loaded drum config
/// (exp_drum_config_load) at its rpm or at each of `rpm_list` ("4,40,80");
/// results in `out_dir` (NULL: results/runs/drum). It lives in calib, not
/// with its experiment, because its checkpoints are labelled with the
/// calibration's record key (cal_drum_key).
int cal_simulate_drum(const exp_drum_yaml *config, const char *out_dir, const char *rpm_list,
                      double checkpoint_every_s);

#endif
