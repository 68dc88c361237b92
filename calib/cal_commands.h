// SPDX-License-Identifier: MIT
/// @file cal_commands.h
/// The sub-commands of granucal; each reads its options from its own table
/// (cal_options.h).
#ifndef CAL_COMMANDS_H
#define CAL_COMMANDS_H

int cal_cmd_simulate(int argc, char **argv);
int cal_cmd_measure(int argc, char **argv);
int cal_cmd_calibrate(int argc, char **argv);
int cal_cmd_study(int argc, char **argv);
int cal_cmd_synthesize(int argc, char **argv);

/// Run a drum experiment config with `--set` overrides, at the config's rpm or
/// at each of `rpm_list` ("4,40,80") from one settled bed; results in `out`.
int cal_simulate_drum(const char *path, int n_sets, char **sets, const char *out, const char *rpm_list,
                      double checkpoint_every_s);

#endif
