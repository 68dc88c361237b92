// SPDX-License-Identifier: MIT
// The start and end the pipeline commands share (see cal_cli_frame.h).
#include "cal_cli_frame.h"

#include <stdio.h>
#include <string.h>

#include "cal_mpi.h"

#ifdef _OPENMP
#include <omp.h>
#endif

void cal_cli_begin(int *argc, char ***argv, char *command, size_t len)
{
    snprintf(command, len, "granucal");
    for (int k = 0; k < *argc; ++k) snprintf(command + strlen(command), len - strlen(command), " %s", (*argv)[k]);
    cal_mpi_init(argc, argv);
#ifdef _OPENMP
    // The parent of forked workers stays on one thread for good: after a region on more threads,
    // libgomp's thread pool makes a forked child hang (calib/runs/cal_case_runs.c, turned_bed_of).
    // Threads go to the workers (calib/runs/cal_pool.c).
    omp_set_num_threads(1);
#endif
}

int cal_cli_end(const char *name, int status, const char *err, cal_env *env, cal_config *c)
{
    if (status) fprintf(stderr, "granucal %s: %s\n", name, err);
    status = cal_mpi_any(status);
    cal_sim_release(env); // the bed kept between candidates
    if (c) cal_config_free(c);
    cal_mpi_finalize();
    return status ? 1 : 0;
}
