// SPDX-License-Identifier: MIT
/// @file cal_mpi.h
/// The calibration's use of MPI, behind four calls that are no-ops in a
/// build without MPI. Every rank runs the same deterministic search; the
/// simulations of each batch are dealt out over the ranks, written to the
/// shared result store, and read back by all after a barrier.
#ifndef CAL_MPI_H
#define CAL_MPI_H

void cal_mpi_init(int *argc, char ***argv);
void cal_mpi_finalize(void);
int cal_mpi_rank(void);
int cal_mpi_size(void);
void cal_mpi_barrier(void);
/// 1 if any rank passes a non-zero flag (a failure anywhere stops all).
int cal_mpi_any(int flag);

#endif
