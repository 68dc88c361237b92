// SPDX-License-Identifier: MIT
#include "exp_common.h"

#include <errno.h>
#include <stdarg.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/resource.h>
#include <time.h>

const char *exp_version(void) { return DEM_VERSION; }

#define EXP_STR(x) #x
#define EXP_XSTR(x) EXP_STR(x)
const char *exp_results_version(void) { return DEM_VERSION "/r" EXP_XSTR(EXP_RESULTS_VERSION); }

int exp_fail(char *err, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
    return 1;
}

double exp_wall_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void exp_print_progress(const char *phase, double t, size_t granules, void *printer)
{
    exp_progress_printer *p = printer;
    double now = exp_wall_seconds();
    if (now - p->last < (p->every_s > 0 ? p->every_s : 10.0)) return;
    p->last = now;
    fprintf(stderr, "%s: %s t = %.4f s, %zu granules, wall %.0f s\n", p->scene, phase, t, granules, now - p->start);
}

int exp_split_set(const char *set, char key[32], const char **value, char *err, size_t len)
{
    const char *eq = strchr(set, '=');
    if (!eq) return exp_fail(err, len, "--set %s: expected key=value", set);
    snprintf(key, 32, "%.*s", (int)(eq - set < 31 ? eq - set : 31), set);
    *value = eq + 1;
    return 0;
}

int exp_parse_number(const char *text, double *out)
{
    char *end;
    errno = 0;
    *out = strtod(text, &end);
    return errno != 0 || end == text || *end != '\0' || !isfinite(*out);
}

int exp_integer_in(double v, double lo, double hi) { return v == floor(v) && v >= lo && v <= hi; }

int exp_set_key_value(const exp_set_key *keys, size_t n, const char *key, const char *value, char *err, size_t len)
{
    for (size_t k = 0; k < n; ++k) {
        if (strcmp(key, keys[k].name) != 0) continue;
        if (keys[k].refused) return exp_fail(err, len, "--set %s: %s", key, keys[k].refused);
        double v;
        if (exp_parse_number(value, &v)) return exp_fail(err, len, "--set %s: '%s' is not a number", key, value);
        if (!keys[k].integer) return *keys[k].number = v, 0;
        if (!exp_integer_in(v, 0, 2147483647.0))
            return exp_fail(err, len, "--set %s: '%s' is not a non-negative integer", key, value);
        *keys[k].integer = (int)v;
        return 0;
    }
    return -1;
}

int exp_set_unknown(const exp_set_key *keys, size_t n, const char *more, const char *key, char *err, size_t len)
{
    char known[512] = "";
    for (size_t k = 0; k < n; ++k)
        if (!keys[k].refused)
            snprintf(known + strlen(known), sizeof known - strlen(known), "%s%s", *known ? ", " : "", keys[k].name);
    if (more) snprintf(known + strlen(known), sizeof known - strlen(known), ", %s", more);
    return exp_fail(err, len, "--set %s: unknown key (known: %s)", key, known);
}

int exp_apply_set(const char *set, const exp_set_key *keys, size_t n, char *err, size_t len)
{
    char key[32];
    const char *value = NULL;
    if (exp_split_set(set, key, &value, err, len)) return 1;
    int found = exp_set_key_value(keys, n, key, value, err, len);
    return found >= 0 ? found : exp_set_unknown(keys, n, NULL, key, err, len);
}

double exp_peak_rss_mb(void)
{
    struct rusage ru;
    if (getrusage(RUSAGE_SELF, &ru) != 0) return NAN;
    return (double)ru.ru_maxrss / 1024.0; // Linux reports KiB
}

int exp_mkdirs(const char *path, char *err, size_t len)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", path);
    for (char *p = buf + 1;; ++p) {
        if (*p && *p != '/') continue;
        char c = *p;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST) return exp_fail(err, len, "cannot create '%s': %s", buf, strerror(errno));
        if (!c) return 0;
        *p = c;
    }
}
