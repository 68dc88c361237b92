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

#endif
