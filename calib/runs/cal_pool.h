// SPDX-License-Identifier: MIT
/// @file cal_pool.h
/// Independent simulations run side by side on one machine: each in a
/// forked process of its own (at most `workers` at a time), so a crash is
/// one failed simulation, not a lost calibration. Without fork (under MPI,
/// where forking is unsafe) they run one after the other in this process.
/// A batch of fewer simulations than workers gives each the idle workers'
/// cores as OpenMP threads (the same results on any number of threads), and
/// so does a batch whose last tasks run on after the others have ended: a
/// worker's core, once nothing is left to start, goes to those still running.
#ifndef CAL_POOL_H
#define CAL_POOL_H

#include <stddef.h>

/// Runs task i; returns 0 on success. In a child, its return is the exit code.
typedef int (*cal_task_fn)(int i, void *ctx);
/// Called in the parent when task i ends: `code` is its exit code, or
/// -signal if it was killed by a signal.
typedef void (*cal_done_fn)(int i, int code, void *ctx);

/// Run tasks[0..n) with up to `workers` processes. Returns the number of
/// tasks that did not end with 0.
int cal_pool_run(int n, cal_task_fn task, cal_done_fn done, void *ctx, int workers, int use_fork);

/// In a task (a forked worker): take the cores the pool has granted it since
/// it started, as OpenMP threads for the parallel regions to come. Call it
/// between parallel regions, as a simulation's progress does between two
/// samples. Returns the threads it runs on from now if this call added some,
/// else 0 (nothing granted since, or not a worker).
int cal_pool_take_granted_cores(void);

/// Run fn(ctx, result) in a forked child whose stdout and stderr go to
/// /dev/null, and copy the `size` bytes it leaves in `result` back here:
/// whatever fn does to memory, prints or leaks stays in the child (a plan's
/// replay of a calibration from its store). Returns 0 if fn returned 0 and
/// every byte came back; else 1, with `result` unspecified.
int cal_pool_probe(int (*fn)(void *ctx, void *result), void *ctx, void *result, size_t size);

#endif
