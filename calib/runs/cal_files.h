// SPDX-License-Identifier: MIT
/// @file cal_files.h
/// The files a granucal run writes: results folders (made, checked, swept of
/// a killed run's temporaries), copies, and the build's commit for their
/// provenance lines. Every file is written whole or not at all through
/// exp_atomic_file (experiments/common/exp_atomic_file.h).
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

/// Copy a file byte for byte, atomically (exp_atomic_file); nothing to do
/// when both names are the same file. 0, else 1 with a message.
int cal_copy_file(const char *from, const char *to, char *err, size_t err_len);

/// The commit the binary was built from ("git describe --dirty" at build
/// time), for the provenance line of files a run writes.
const char *cal_build_commit(void);

#endif
