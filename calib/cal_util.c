// SPDX-License-Identifier: MIT
#include "cal_util.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

int cal_mkdirs(const char *path, char *err, size_t err_len)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1; *p; ++p) {
        if (*p != '/') continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST) goto fail;
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST) goto fail;
    if (access(buf, W_OK) != 0) goto fail;
    return 0;
fail:
    snprintf(err, err_len, "cannot create or write directory '%s': %s", buf, strerror(errno));
    return 1;
}

int cal_atomic_open(cal_atomic_file *a, const char *path, char *err, size_t err_len)
{
    snprintf(a->path, sizeof a->path, "%s", path);
    snprintf(a->tmp, sizeof a->tmp, "%s.%ld.tmp", path, (long)getpid()); // per process: two ranks never share a temporary
    a->f = fopen(a->tmp, "w");
    if (!a->f) {
        snprintf(err, err_len, "cannot write '%s': %s", a->tmp, strerror(errno));
        return 1;
    }
    return 0;
}

int cal_atomic_commit(cal_atomic_file *a, char *err, size_t err_len)
{
    int bad = ferror(a->f) | (fflush(a->f) != 0) | (fsync(fileno(a->f)) != 0);
    bad |= fclose(a->f) != 0;
    a->f = NULL;
    if (bad || rename(a->tmp, a->path) != 0) {
        snprintf(err, err_len, "cannot write '%s': %s", a->path, strerror(errno));
        unlink(a->tmp);
        return 1;
    }
    return 0;
}

void cal_atomic_abort(cal_atomic_file *a)
{
    if (a->f) fclose(a->f);
    a->f = NULL;
    unlink(a->tmp);
}

double cal_wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
