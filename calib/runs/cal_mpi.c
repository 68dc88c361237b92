// SPDX-License-Identifier: MIT
// MPI wrappers (see cal_mpi.h).
#include "cal_mpi.h"

#ifdef GRANUCAL_HAVE_MPI
#include <mpi.h>

static int started;

void cal_mpi_init(int *argc, char ***argv)
{
    int already = 0;
    MPI_Initialized(&already);
    if (!already) MPI_Init(argc, argv), started = 1;
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
