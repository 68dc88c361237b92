// SPDX-License-Identifier: MIT
#include "cal_files.h"

#include "exp_common.h"

#include <dirent.h>
#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

int cal_mkdirs(const char *path, char *err, size_t err_len)
{
    if (exp_mkdirs(path, err, err_len)) return 1;
    if (access(path, W_OK) != 0)
        return snprintf(err, err_len, "cannot write in directory '%s': %s", path, strerror(errno)), 1;
    return 0;
}

void cal_host_name(char host[64])
{
    snprintf(host, 64, "host");
    gethostname(host, 63);
    host[63] = 0;
}

void cal_temporary_name(const char *path, char *tmp, size_t len)
{
    // Per host and process: two ranks never share a temporary, and a later run can tell
    // which temporaries belonged to a process that died (cal_atomic_sweep).
    char host[64];
    cal_host_name(host);
    snprintf(tmp, len, "%s.%s.%ld.tmp", path, host, (long)getpid());
}

int cal_prepare_output(const char *dir, char *err, size_t len)
{
    char probe[1200];
    if (cal_mkdirs(dir, err, len)) return 1;
    snprintf(probe, sizeof probe, "%s/store", dir);
    if (cal_mkdirs(probe, err, len)) return 1;
    cal_atomic_sweep(probe); // what a killed earlier run was writing when it died
    cal_atomic_sweep(dir);
    snprintf(probe, sizeof probe, "%s/.write_test.%ld", dir, (long)getpid());
    FILE *f = fopen(probe, "w");
    if (!f || fputs("x", f) < 0 || fclose(f) != 0)
        return exp_fail(err, len, "%s: results folder is not writable: %s", dir, strerror(errno));
    unlink(probe);
    struct statvfs fs;
    const double need = 50e6; // a calibration's records, tables and plots: a few MB; keep margin
    if (statvfs(dir, &fs) == 0 && (double)fs.f_bavail * (double)fs.f_frsize < need)
        return exp_fail(err, len, "%s: only %.1f MB free; a calibration needs about %.0f MB", dir,
                        (double)fs.f_bavail * (double)fs.f_frsize / 1e6, need / 1e6);
    return 0;
}

int cal_atomic_open(cal_atomic_file *a, const char *path, char *err, size_t err_len)
{
    snprintf(a->path, sizeof a->path, "%s", path);
    cal_temporary_name(path, a->tmp, sizeof a->tmp);
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

int cal_copy_file(const char *from, const char *to, char *err, size_t err_len)
{
    struct stat a, b;
    if (stat(from, &a) == 0 && stat(to, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino) return 0;
    FILE *in = fopen(from, "rb");
    if (!in) return snprintf(err, err_len, "cannot read '%s': %s", from, strerror(errno)), 1;
    cal_atomic_file out;
    if (cal_atomic_open(&out, to, err, err_len)) return fclose(in), 1;
    char buf[8192];
    for (size_t n; (n = fread(buf, 1, sizeof buf, in)) > 0;) fwrite(buf, 1, n, out.f);
    int unread = ferror(in);
    fclose(in);
    if (unread) return cal_atomic_abort(&out), snprintf(err, err_len, "cannot read '%s'", from), 1;
    return cal_atomic_commit(&out, err, err_len);
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

int cal_atomic_sweep(const char *dir)
{
    char host[64];
    cal_host_name(host);
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
