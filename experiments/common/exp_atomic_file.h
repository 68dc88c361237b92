// SPDX-License-Identifier: MIT
/// @file exp_atomic_file.h
/// A file written whole or not at all, the one way every file of a run, a
/// calibration's store and its outputs is written: the writer fills a
/// temporary, PATH.HOST.PID.tmp, which is flushed to disk and renamed to PATH
/// on commit, so a killed process never leaves half a file under the final
/// name. The temporary's name says which process on which host wrote it, so
/// two ranks never share one and a later run can sweep a dead writer's
/// leftovers (exp_atomic_sweep) without touching a live writer's.
#ifndef EXP_ATOMIC_FILE_H
#define EXP_ATOMIC_FILE_H

#include <stddef.h>
#include <stdio.h>

/// This machine's host name ("host" if it cannot be read), at most 63 bytes.
void exp_host_name(char host[64]);

/// The temporary name PATH.HOST.PID.tmp a file is written under before it is
/// renamed to @p path.
void exp_temporary_name(const char *path, char *tmp, size_t len);

/// `f` writes the temporary; exp_atomic_commit renames it to `path`.
typedef struct exp_atomic_file {
    FILE *f;
    char path[1100], tmp[1200];
} exp_atomic_file;

/// 0, or 1 with a message naming the file.
int exp_atomic_open(exp_atomic_file *a, const char *path, char *err, size_t len);
/// Closes `f`, flushes it to disk and renames it into place; 0, or 1 with a
/// message naming the file (the temporary removed).
int exp_atomic_commit(exp_atomic_file *a, char *err, size_t len);
/// Closes `f` and removes the temporary: PATH is left as it was.
void exp_atomic_abort(exp_atomic_file *a);

/// Remove the temporaries in @p dir left by writers on this host that died
/// before committing (a SIGKILL between open and rename). Temporaries of live
/// processes, and of other hosts sharing the folder, are left alone.
/// Returns how many were removed.
int exp_atomic_sweep(const char *dir);

#endif
