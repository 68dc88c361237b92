// SPDX-License-Identifier: MIT
// Files written whole or not at all (see exp_atomic_file.h).
#include "exp_atomic_file.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "exp_common.h"

void exp_host_name(char host[64])
{
    snprintf(host, 64, "host");
    gethostname(host, 63);
    host[63] = 0;
}

void exp_temporary_name(const char *path, char *tmp, size_t len)
{
    char host[64];
    exp_host_name(host);
    snprintf(tmp, len, "%s.%s.%ld.tmp", path, host, (long)getpid());
}

int exp_atomic_open(exp_atomic_file *a, const char *path, char *err, size_t len)
{
    snprintf(a->path, sizeof a->path, "%s", path);
    exp_temporary_name(path, a->tmp, sizeof a->tmp);
    a->f = fopen(a->tmp, "w");
    return a->f ? 0 : exp_fail(err, len, "cannot write '%s': %s", a->tmp, strerror(errno));
}

int exp_atomic_commit(exp_atomic_file *a, char *err, size_t len)
{
    // Read by scripts and by later runs as an outcome: on disk whole, or not replaced at all.
    int bad = ferror(a->f) | (fflush(a->f) != 0) | (fsync(fileno(a->f)) != 0);
    bad |= fclose(a->f) != 0;
    a->f = NULL;
    if (bad || rename(a->tmp, a->path) != 0) {
        int cause = errno;
        unlink(a->tmp);
        return exp_fail(err, len, "cannot write '%s': %s", a->path, strerror(cause));
    }
    return 0;
}

void exp_atomic_abort(exp_atomic_file *a)
{
    if (a->f) fclose(a->f);
    a->f = NULL;
    unlink(a->tmp);
}

/// Parse "NAME.HOST.PID.tmp"; 1 and the pid when the host is this one.
static int temporary_of_this_host(const char *name, const char *host, long *pid)
{
    size_t n = strlen(name);
    if (n < 5 || strcmp(name + n - 4, ".tmp") != 0) return 0;
    const char *end = name + n - 4, *dot = end;
    while (dot > name && dot[-1] != '.') dot--;
    if (dot == name || dot == end) return 0;
    char *stop;
    *pid = strtol(dot, &stop, 10);
    if (stop != end || *pid <= 0) return 0;
    size_t hl = strlen(host);
    const char *h = dot - 1 - hl;
    return h > name && h[-1] == '.' && strncmp(h, host, hl) == 0;
}

int exp_atomic_sweep(const char *dir)
{
    char host[64];
    exp_host_name(host);
    DIR *d = opendir(dir);
    if (!d) return 0;
    int removed = 0;
    for (struct dirent *e; (e = readdir(d));) {
        long pid;
        if (!temporary_of_this_host(e->d_name, host, &pid)) continue;
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH) continue; // its writer may still be alive
        char path[2048];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        removed += unlink(path) == 0;
    }
    closedir(d);
    return removed;
}
