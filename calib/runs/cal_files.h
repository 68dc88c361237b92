// SPDX-License-Identifier: MIT
/// @file cal_files.h
/// The files a granucal run writes: results folders (made, checked, swept of
/// a killed run's temporaries), files written atomically, copies, and the
/// build's commit for their provenance lines.
#ifndef CAL_FILES_H
#define CAL_FILES_H

#include <stdio.h>

/// Create a directory and its parents (exp_mkdirs) and check that it is
/// writable; 0 on success, else a message.
int cal_mkdirs(const char *path, char *err, size_t err_len);

/// Make a results folder DIR and DIR/store, check that files can be written in
/// it and that 50 MB are free, and remove temporaries a killed run left there:
/// a bad folder is an error before any work starts. 0, else 1 with a message.
int cal_prepare_output(const char *dir, char *err, size_t len);

/// This machine's host name ("host" if it cannot be read), at most 63 bytes.
void cal_host_name(char host[64]);

/// The temporary name a file is written under before it is renamed to @p path:
/// PATH.HOST.PID.tmp, so cal_atomic_sweep can tell a dead writer's leftovers.
void cal_temporary_name(const char *path, char *tmp, size_t len);

/// A file written under a temporary name and renamed into place on commit,
/// so a killed run never leaves a half-written file under the final name.
typedef struct cal_atomic_file {
    FILE *f;
    char path[1024], tmp[1064];
} cal_atomic_file;

int cal_atomic_open(cal_atomic_file *a, const char *path, char *err, size_t err_len);
int cal_atomic_commit(cal_atomic_file *a, char *err, size_t err_len);
void cal_atomic_abort(cal_atomic_file *a);

/// Copy a file byte for byte, atomically (cal_atomic_file); nothing to do
/// when both names are the same file. 0, else 1 with a message.
int cal_copy_file(const char *from, const char *to, char *err, size_t err_len);

/// Remove the temporaries in @p dir left by writers on this host that died
/// before committing (a SIGKILL between open and rename). Temporaries of live
/// processes, and of other hosts sharing the folder, are left alone.
/// Returns how many were removed.
int cal_atomic_sweep(const char *dir);

/// The commit the binary was built from ("git describe --dirty" at build
/// time), for the provenance line of files a run writes.
const char *cal_build_commit(void);

#endif
