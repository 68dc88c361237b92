// SPDX-License-Identifier: MIT
#include "cal_files.h"

#include "exp_atomic_file.h"
#include "exp_common.h"

#include <errno.h>
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

int cal_prepare_output(const char *dir, char *err, size_t len)
{
    char probe[1200];
    if (cal_mkdirs(dir, err, len)) return 1;
    snprintf(probe, sizeof probe, "%s/store", dir);
    if (cal_mkdirs(probe, err, len)) return 1;
    exp_atomic_sweep(probe); // what a killed earlier run was writing when it died
    exp_atomic_sweep(dir);
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

int cal_copy_file(const char *from, const char *to, char *err, size_t err_len)
{
    struct stat a, b;
    if (stat(from, &a) == 0 && stat(to, &b) == 0 && a.st_dev == b.st_dev && a.st_ino == b.st_ino) return 0;
    FILE *in = fopen(from, "rb");
    if (!in) return snprintf(err, err_len, "cannot read '%s': %s", from, strerror(errno)), 1;
    exp_atomic_file out;
    if (exp_atomic_open(&out, to, err, err_len)) return fclose(in), 1;
    char buf[8192];
    for (size_t n; (n = fread(buf, 1, sizeof buf, in)) > 0;) fwrite(buf, 1, n, out.f);
    int unread = ferror(in);
    fclose(in);
    if (unread) return exp_atomic_abort(&out), snprintf(err, err_len, "cannot read '%s'", from), 1;
    return exp_atomic_commit(&out, err, err_len);
}

