// SPDX-License-Identifier: MIT
// Fork pool (see cal_pool.h).
#include "cal_pool.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>
#ifdef _OPENMP
#include <omp.h>
#endif

static int run_inline(int n, cal_task_fn task, cal_done_fn done, void *ctx)
{
    int failures = 0;
    for (int i = 0; i < n; ++i) {
        int code = task(i, ctx);
        failures += code != 0;
        if (done) done(i, code, ctx);
    }
    return failures;
}

/// In a fresh child: die with the parent. A driver killed with SIGKILL cannot
/// stop its workers itself, and an orphan would go on writing into a store that
/// the rerun is already using (and leave a temporary behind when it is killed).
static void die_with_parent(pid_t parent)
{
    prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (getppid() != parent) _exit(1); // the parent died before prctl took effect
}

/// Threads for each simulation of a batch of n: the cores of workers that no simulation of the batch
/// can use go to those that run. Never more threads while another simulation waits for a core: one
/// run on T threads gives less than T runs on one (results/benchmarks/threads_node/: 16 runs x 1
/// thread gave a 16-core node 4.5 times what 1 run x 16 threads did). Results do not depend on it:
/// the engine sums each granule's forces in one order on any number of threads.
static int threads_each(int n, int workers) { return n < workers ? workers / n : 1; }

// Cores freed later go the same way. When a worker ends with no task left to
// start, its core idles while the others run on (a batch's last long run: a
// 4 rpm drum that MSER keeps turning long after its 40 and 116 rpm runs have
// ended); the parent then tells each running worker its new share,
// workers / running, by a queued real-time signal whose value is that share,
// and the worker takes it between two of its steps (cal_pool_take_granted_cores;
// a signal handler must not call OpenMP). The handler is installed before the
// fork, so a worker can never receive the signal before it can handle it.
#define GRANT_SIGNAL SIGRTMIN
static volatile sig_atomic_t granted_threads; ///< in a worker: the share the parent last granted; 0 none

static void on_grant(int sig, siginfo_t *info, void *uc)
{
    (void)sig, (void)uc;
    granted_threads = info->si_value.sival_int;
}

int cal_pool_take_granted_cores(void)
{
#ifdef _OPENMP
    int share = granted_threads;
    if (share <= omp_get_max_threads()) return 0;
    omp_set_num_threads(share);
    return share;
#else
    return 0;
#endif
}

// After a worker ended: with nothing left to start, each running worker's
// share of the cores, told to those it grows for. threads[i]: task i's now.
static void grant_idle_cores(const pid_t *pids, int *threads, int n, int running, int workers)
{
    if (running <= 0) return;
    int share = workers / running;
    for (int i = 0; i < n; ++i)
        if (pids[i] > 0 && share > threads[i] &&
            sigqueue(pids[i], GRANT_SIGNAL, (union sigval){.sival_int = share}) == 0)
            threads[i] = share;
}

static int exit_code_of(int status) { return WIFEXITED(status) ? WEXITSTATUS(status) : -WTERMSIG(status); }

int cal_pool_run(int n, cal_task_fn task, cal_done_fn done, void *ctx, int workers, int use_fork)
{
    if (!use_fork || n <= 0) return run_inline(n, task, done, ctx);
    if (workers < 1) workers = 1;
    pid_t *pids = calloc((size_t)n, sizeof *pids);
    int *threads = calloc((size_t)n, sizeof *threads);
    if (!pids || !threads) return free(pids), free(threads), run_inline(n, task, done, ctx);
    int next = 0, running = 0, failures = 0;
    fflush(NULL); // no buffered output duplicated into the children
    const pid_t parent = getpid();
    struct sigaction grant = {.sa_sigaction = on_grant, .sa_flags = SA_SIGINFO | SA_RESTART}, before;
    sigemptyset(&grant.sa_mask);
    sigaction(GRANT_SIGNAL, &grant, &before);
    while (next < n || running > 0) {
        while (running < workers && next < n) {
            pid_t pid = fork();
            if (pid == 0) {
                die_with_parent(parent);
                granted_threads = 0;
#ifdef _OPENMP
                omp_set_num_threads(threads_each(n, workers)); // the parent runs on one (cal_cmd_calibrate.c)
#endif
                _exit(task(next, ctx) ? 1 : 0);
            }
            if (pid < 0) { // no process to spare: run it here
                int code = task(next, ctx);
                failures += code != 0;
                if (done) done(next, code, ctx);
            } else pids[next] = pid, threads[next] = threads_each(n, workers), running++;
            next++;
        }
        int status;
        pid_t pid = wait(&status);
        if (pid < 0 && errno == EINTR) continue; // a signal, not the end of the children
        if (pid < 0) break;
        for (int i = 0; i < n; ++i)
            if (pids[i] == pid) {
                pids[i] = 0, running--;
                int code = exit_code_of(status);
                failures += code != 0;
                if (done) done(i, code, ctx);
            }
        if (next == n) grant_idle_cores(pids, threads, n, running, workers);
    }
    sigaction(GRANT_SIGNAL, &before, NULL);
    free(pids), free(threads);
    return failures;
}

// The child: its output silenced, fn's result written whole to the pipe.
static void probe_child(int fd, pid_t parent, int (*fn)(void *, void *), void *ctx, void *result, size_t size)
{
    die_with_parent(parent);
    int devnull = open("/dev/null", O_WRONLY);
    if (devnull >= 0) dup2(devnull, 1), dup2(devnull, 2);
    if (fn(ctx, result)) _exit(1);
    for (size_t sent = 0; sent < size;) {
        ssize_t w = write(fd, (const char *)result + sent, size - sent);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) _exit(1);
        sent += (size_t)w;
    }
    _exit(0);
}

int cal_pool_probe(int (*fn)(void *ctx, void *result), void *ctx, void *result, size_t size)
{
    int fd[2];
    if (pipe(fd) != 0) return 1;
    fflush(NULL); // no buffered output duplicated into the child
    const pid_t parent = getpid();
    pid_t pid = fork();
    if (pid == 0) close(fd[0]), probe_child(fd[1], parent, fn, ctx, result, size);
    close(fd[1]);
    if (pid < 0) return close(fd[0]), 1;
    size_t got = 0; // read while the child writes: a result larger than the pipe's buffer
    while (got < size) {
        ssize_t r = read(fd[0], (char *)result + got, size - got);
        if (r < 0 && errno == EINTR) continue;
        if (r <= 0) break;
        got += (size_t)r;
    }
    close(fd[0]);
    int status;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) return 1;
    return !(got == size && WIFEXITED(status) && WEXITSTATUS(status) == 0);
}
