// SPDX-License-Identifier: MIT
/// @file exp_common.h
/// Shared pieces of the virtual experiments (prefix exp_).
#ifndef EXP_COMMON_H
#define EXP_COMMON_H

#include <stddef.h>

/// Version string of the program (--version, report headers).
const char *exp_version(void);

/// Version of what a simulation returns: bumped by every change that alters
/// a result for the same input (contact law, step choice, fill, even the order
/// forces are summed in). Every stored record's key carries it, so a store
/// written by an older engine is never served as this one's results.
/// 2: forces added directly on one thread, wall near-lists, beds sorted along
///    a Morton curve after the fill (summation order).
/// 3: the drum turns from a bed tilted 20° (exp_drum_run_opts.start_tilt_deg).
#define EXP_RESULTS_VERSION 3
const char *exp_results_version(void);

/// Progress callback of long phases: phase name, simulated time, granules.
typedef void (*exp_progress_fn)(const char *phase, double t, size_t granules, void *ctx);

/// A scene's progress printer (an exp_progress_fn's ctx): one line on stderr
/// at most every `every_s` of wall time (0: 10 s), "<scene>: <phase> t = ...
/// s, N granules, wall W s". Start it with {.scene, .start = exp_wall_seconds()}
/// (a first line at once), or with last = start to wait a whole interval.
typedef struct exp_progress_printer {
    const char *scene;
    double last, start;
    double every_s;
} exp_progress_printer;
void exp_print_progress(const char *phase, double t, size_t granules, void *printer);

/// Format a message into err (printf-style) and return 1: the error path of
/// every loader and builder here.
int exp_fail(char *err, size_t len, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/// Seconds of wall-clock time (monotonic) since an arbitrary origin.
double exp_wall_seconds(void);

/// Split a `--set key=value` into its key and the text of its value (a
/// pointer into `set`): 0, else 1 with a message.
int exp_split_set(const char *set, char key[32], const char **value, char *err, size_t len);
/// A finite number that fills the whole text: 0, else 1.
int exp_parse_number(const char *text, double *out);
/// 1 if v is a whole number in [lo, hi] (a seed, a count), else 0.
int exp_integer_in(double v, double lo, double hi);

/// A key a scene's `--set KEY=VALUE` may set: a number, or (integer) a whole
/// number >= 0 (a seed, a count); or, with `refused`, a key the scene names
/// only to say why it has none (the silo's mu_r).
typedef struct exp_set_key {
    const char *name;
    double *number;
    int *integer;
    const char *refused;
} exp_set_key;

#define EXP_SET_NUMBER(key, field) {.name = (key), .number = (field)}
#define EXP_SET_INTEGER(key, field) {.name = (key), .integer = (field)}
#define EXP_SET_REFUSED(key, why) {.name = (key), .refused = (why)}

/// Sets the key of keys[0..n) named `key` from the text `value`: 0; 1 with a
/// message naming the key when the value is not a finite number (for an
/// integer key, not a whole number in [0, 2^31)) or the key is refused; -1
/// when no key has that name.
int exp_set_key_value(const exp_set_key *keys, size_t n, const char *key, const char *value, char *err, size_t len);
/// Refuses `key` as unknown, listing the names of keys[0..n) (not the refused
/// ones) and then `more` (the scene's other keys, or NULL): always 1.
int exp_set_unknown(const exp_set_key *keys, size_t n, const char *more, const char *key, char *err, size_t len);
/// A whole `--set KEY=VALUE` for a scene whose keys are all in keys[0..n):
/// 0, else 1 with a message.
int exp_apply_set(const char *set, const exp_set_key *keys, size_t n, char *err, size_t len);

/// Peak resident memory of this process so far, MiB (getrusage).
double exp_peak_rss_mb(void);

/// Create a directory and its parents (like mkdir -p); 0, or 1 with a message.
int exp_mkdirs(const char *path, char *err, size_t len);

#endif
