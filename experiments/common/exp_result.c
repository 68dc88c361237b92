// SPDX-License-Identifier: MIT
// An experiment's result.h5 and result.json (see exp_result.h).
#include "exp_result.h"

#include <stdio.h>
#include <unistd.h>

#include "dem_output.h"
#include "exp_common.h"

int exp_result_write_h5(const char *dir, const dem_world *w, char *err, size_t len)
{
    char path[1100];
    snprintf(path, sizeof path, "%s/result.h5", dir);
    dem_h5_writer *h5 = dem_h5_open(path, err, len);
    if (!h5) return 1;
    dem_granules_view g = dem_world_granules(w);
    dem_diagnostics d = dem_world_diagnose(w);
    int bad = dem_h5_write_frame(h5, dem_world_time(w), &g, &d) ||
              dem_h5_write_attribute_string(h5, "dt_report", dem_world_dt_report(w));
    if (bad) exp_fail(err, len, "%s", dem_h5_error(h5));
    if (dem_h5_close(h5, bad ? NULL : err, bad ? 0 : len)) bad = 1;
    return bad;
}

int exp_result_write_json(const char *dir, exp_result_json_fn write, const void *ctx, char *err, size_t len)
{
    char path[1100], tmp[1200];
    snprintf(path, sizeof path, "%s/result.json", dir);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) return exp_fail(err, len, "cannot write '%s'", path);
    write(f, ctx);
    // A result.json is read by scripts as the run's outcome: on disk whole,
    // or not replaced at all (a crash leaves the .tmp, never half a file).
    int bad = ferror(f) | (fflush(f) != 0) | (fsync(fileno(f)) != 0);
    bad |= fclose(f) != 0;
    if (bad || rename(tmp, path) != 0) {
        remove(tmp);
        return exp_fail(err, len, "cannot write '%s'", path);
    }
    return 0;
}

void exp_result_print_failure(const char *experiment, const char *err)
{
    printf("{\"experiment\": \"%s\", \"status\": \"failed\", \"error\": \"", experiment);
    for (const char *c = err; *c; ++c) // a JSON string: escape quotes, backslashes, control characters
        if (*c == '"' || *c == '\\') printf("\\%c", *c);
        else if ((unsigned char)*c < 0x20) printf("\\u%04x", (unsigned)(unsigned char)*c);
        else putchar(*c);
    printf("\"}\n");
}
