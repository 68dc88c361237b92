// SPDX-License-Identifier: MIT
/// @file fuzz_common.h
/// Shared by the libFuzzer targets of the input loaders (fuzz_csv.c,
/// fuzz_yaml.c): the loaders read files, so each input is written to one
/// temporary file per process, and a broken invariant aborts with the reason
/// so that libFuzzer (or replay_main.c) reports the input.
#ifndef FUZZ_COMMON_H
#define FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static char fuzz_path[512];

static void fuzz_remove_temp(void)
{
    if (fuzz_path[0]) unlink(fuzz_path);
}

/// Stop the run: libFuzzer saves the input as crash-*; the replay prints its file.
static _Noreturn void fuzz_violation(const char *what, const char *detail)
{
    fprintf(stderr, "\nFUZZ INVARIANT VIOLATED: %s\n  file: %s\n  detail: %s\n", what, fuzz_path, detail ? detail : "");
    abort();
}

/// Write the input to this process's temporary file ($TMPDIR or /tmp) and
/// return its path.
static const char *fuzz_write_temp(const uint8_t *data, size_t size)
{
    if (!fuzz_path[0]) {
        const char *dir = getenv("TMPDIR");
        snprintf(fuzz_path, sizeof fuzz_path, "%s/granucal_fuzz_XXXXXX", dir && *dir ? dir : "/tmp");
        int fd = mkstemp(fuzz_path);
        if (fd < 0) perror(fuzz_path), fuzz_violation("cannot create the temporary file", NULL);
        close(fd);
        atexit(fuzz_remove_temp);
    }
    FILE *f = fopen(fuzz_path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0)
        fuzz_violation("cannot write the temporary file", NULL);
    return fuzz_path;
}

/// GRANUCAL_FUZZ_VERBOSE=1: print each loader's verdict (to curate the corpus).
static void fuzz_report(const char *loader, const char *err)
{
    static int verbose = -1;
    if (verbose < 0) verbose = getenv("GRANUCAL_FUZZ_VERBOSE") != NULL;
    if (verbose) fprintf(stderr, "  %s: %s\n", loader, err ? err : "accepted");
}

/// The failure contract of every loader: a non-empty message naming the file.
static void fuzz_check_failure_message(const char *loader, const char *path, const char *err)
{
    char what[160];
    fuzz_report(loader, err);
    snprintf(what, sizeof what, "%s failed with an empty message", loader);
    if (!err[0]) fuzz_violation(what, NULL);
    snprintf(what, sizeof what, "%s failed with a message that does not name the file", loader);
    if (!strstr(err, path)) fuzz_violation(what, err);
}

#endif
