// SPDX-License-Identifier: MIT
// MPI wrappers (see cal_mpi.h).
#include "cal_mpi.h"

#ifdef GRANUCAL_HAVE_MPI
#include <mpi.h>

#include <stdlib.h>

static int started;

// Whether an MPI launcher started this process: mpirun/mpiexec of Open MPI,
// MPICH's or Intel MPI's Hydra, srun with PMI or PMIx.
static int launched_by_mpi(void)
{
    static const char *const set_by_launchers[] = {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMI_RANK", "PMIX_RANK"};
    for (size_t i = 0; i < sizeof set_by_launchers / sizeof *set_by_launchers; ++i)
        if (getenv(set_by_launchers[i])) return 1;
    return 0;
}

// Run on its own, granucal is one rank and starts no MPI: Open MPI 4's
// singleton MPI_Init forks and execs an orted daemon as a child of the
// process, which then forks its own workers (cal_pool.c) beside it and has
// no use for any of it.
void cal_mpi_init(int *argc, char ***argv)
{
    int already = 0;
    MPI_Initialized(&already);
    if (!already && launched_by_mpi()) MPI_Init(argc, argv), started = 1;
}
void cal_mpi_finalize(void)
{
    if (started) MPI_Finalize(), started = 0;
}
int cal_mpi_rank(void)
{
    int r = 0;
    if (started) MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}
int cal_mpi_size(void)
{
    int s = 1;
    if (started) MPI_Comm_size(MPI_COMM_WORLD, &s);
    return s;
}
void cal_mpi_barrier(void)
{
    if (started) MPI_Barrier(MPI_COMM_WORLD);
}
int cal_mpi_any(int flag)
{
    int any = flag;
    if (started) MPI_Allreduce(&flag, &any, 1, MPI_INT, MPI_LOR, MPI_COMM_WORLD);
    return any;
}
#else
void cal_mpi_init(int *argc, char ***argv) { (void)argc, (void)argv; }
void cal_mpi_finalize(void) {}
int cal_mpi_rank(void) { return 0; }
int cal_mpi_size(void) { return 1; }
void cal_mpi_barrier(void) {}
int cal_mpi_any(int flag) { return flag; }
#endif
