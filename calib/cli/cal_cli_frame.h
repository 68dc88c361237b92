// SPDX-License-Identifier: MIT
/// @file cal_cli_frame.h
/// What the pipeline commands (calibrate, study, synthesize) do the same way
/// around their work: at the start, the command line as one string (for
/// their reports), MPI, one OpenMP thread a simulation; at the end, the
/// error, the status every rank agrees on, the workers and config released.
#ifndef CAL_CLI_FRAME_H
#define CAL_CLI_FRAME_H

#include <stddef.h>

#include "cal_case_runs.h"
#include "cal_config.h"

/// `command` gets "granucal ARGV..." (before MPI may take its own
/// arguments out of argv); then MPI starts and OpenMP is held to one thread:
/// parallelism is across simulations (forked workers, ranks), each on one
/// thread, which also keeps forked children clear of the OpenMP runtime's
/// threads.
void cal_cli_begin(int *argc, char ***argv, char *command, size_t len);

/// "granucal NAME: ERR" on stderr when `status` is not 0; the status any
/// rank failed with; `env`'s kept bed and workers and the config (may be
/// NULL) released; MPI finalised. Returns the exit status, 0 or 1.
int cal_cli_end(const char *name, int status, const char *err, cal_env *env, cal_config *c);

#endif
