// SPDX-License-Identifier: MIT
// The fork pool (calib/runs/cal_pool.c): every task runs once and reports its
// exit code; a worker whose batch has nothing left to start is granted the
// cores of those that ended, as OpenMP threads, between two of its steps.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cmocka.h>

#include "cal_pool.h"

enum { TASKS = 3, NOT_RUN = -100 };

typedef struct batch {
    int wait_for_grant; ///< task 0 waits for a second thread (else it ends at once)
    int code[TASKS];    ///< each task's exit code as the parent saw it
} batch;

static void pause_ms(long ms)
{
    struct timespec t = {ms / 1000, (ms % 1000) * 1000000L};
    while (nanosleep(&t, &t) != 0) {
    }
}

// Task 0 stands for a batch's last long run: it steps (here, waits 10 ms at a
// time) and takes granted cores between steps; it succeeds (0) if it ends on
// two threads (a worker's exit code is 0 or 1). Tasks 1 and 2 are short, so task 0 is the one left running. It
// gives up after 30 s: a grant that never comes fails the test, it does not
// hang it.
static int task(int i, void *ctx)
{
    const batch *b = ctx;
    if (i > 0) return pause_ms(50), 0;
    int threads = cal_pool_take_granted_cores(); // 0 until a grant adds threads
    for (int k = 0; k < 3000 && !threads && b->wait_for_grant; ++k) pause_ms(10), threads = cal_pool_take_granted_cores();
    return threads == 2 ? 0 : 1;
}

static void done(int i, int code, void *ctx) { ((batch *)ctx)->code[i] = code; }

static void the_last_running_task_gets_the_idle_core(void **state)
{
    (void)state;
#ifndef _OPENMP
    skip();
#endif
    batch b = {.wait_for_grant = 1};
    for (int i = 0; i < TASKS; ++i) b.code[i] = NOT_RUN;
    // Two workers: tasks 0 and 1 start on one thread each; 2 starts when 1 ends; when 2 ends,
    // nothing is left to start and task 0, still running, is granted both cores.
    int failures = cal_pool_run(TASKS, task, done, &b, 2, 1);
    assert_int_equal(b.code[0], 0);
    assert_int_equal(b.code[1], 0), assert_int_equal(b.code[2], 0);
    assert_int_equal(failures, 0);
}

// Without fork (MPI ranks) the tasks run here, one after the other, on the
// process's own threads: nothing is granted.
static void without_fork_tasks_run_inline_and_nothing_is_granted(void **state)
{
    (void)state;
    batch b = {.wait_for_grant = 0};
    for (int i = 0; i < TASKS; ++i) b.code[i] = NOT_RUN;
    cal_pool_run(TASKS, task, done, &b, 2, 0);
    assert_int_equal(b.code[0], 1), assert_int_equal(b.code[1], 0), assert_int_equal(b.code[2], 0);
    assert_int_equal(cal_pool_take_granted_cores(), 0);
}

// A probe (cal_pool_probe): what the child leaves in `result` comes back whole,
// even past a pipe's buffer; what it does to its own memory does not; a child
// that fails is reported.
enum { PROBE_BYTES = 1 << 18 }; // 256 KiB: four times a Linux pipe's buffer

typedef struct probe_state {
    int touched; ///< set by the child: stays 0 here
} probe_state;

static int fill_result(void *ctx, void *result)
{
    ((probe_state *)ctx)->touched = 1;
    unsigned char *bytes = result;
    for (size_t i = 0; i < PROBE_BYTES; ++i) bytes[i] = (unsigned char)(i * 7 + 3);
    fputs("a probe's output goes to /dev/null\n", stderr);
    return 0;
}

static int fail_probe(void *ctx, void *result) { (void)ctx, (void)result; return 1; }

static void a_probe_returns_its_result_and_keeps_its_side_effects(void **state)
{
    (void)state;
    probe_state s = {0};
    unsigned char *result = calloc(PROBE_BYTES, 1);
    assert_non_null(result);
    assert_int_equal(cal_pool_probe(fill_result, &s, result, PROBE_BYTES), 0);
    for (size_t i = 0; i < PROBE_BYTES; ++i)
        if (result[i] != (unsigned char)(i * 7 + 3)) fail_msg("byte %zu came back as %u", i, result[i]);
    assert_int_equal(s.touched, 0);
    assert_int_equal(cal_pool_probe(fail_probe, &s, result, PROBE_BYTES), 1);
    free(result);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(the_last_running_task_gets_the_idle_core),
        cmocka_unit_test(without_fork_tasks_run_inline_and_nothing_is_granted),
        cmocka_unit_test(a_probe_returns_its_result_and_keeps_its_side_effects),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
