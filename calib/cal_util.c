// SPDX-License-Identifier: MIT
#include "cal_util.h"

#include "exp_common.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

int cal_mkdirs(const char *path, char *err, size_t err_len)
{
    if (exp_mkdirs(path, err, err_len)) return 1;
    if (access(path, W_OK) != 0)
        return snprintf(err, err_len, "cannot write in directory '%s': %s", path, strerror(errno)), 1;
    return 0;
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

