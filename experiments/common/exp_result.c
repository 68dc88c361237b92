// SPDX-License-Identifier: MIT
// An experiment's result.h5 and result.json (see exp_result.h).
#include "exp_result.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "dem_output.h"
#include "exp_atomic_file.h"
#include "exp_common.h"

dem_h5_writer *exp_result_h5_open(const char *dir, char *err, size_t len)
{
    char path[1100];
    snprintf(path, sizeof path, "%s/result.h5", dir);
    return dem_h5_open(path, err, len);
}

int exp_result_h5_frame(dem_h5_writer *h5, const dem_world *w)
{
    dem_granules_view g = dem_world_granules(w);
    dem_diagnostics d = dem_world_diagnose(w);
    return dem_h5_write_frame(h5, dem_world_time(w), &g, &d);
}

int exp_result_write_h5(const char *dir, const dem_world *w, char *err, size_t len)
{
    dem_h5_writer *h5 = exp_result_h5_open(dir, err, len);
    if (!h5) return 1;
    int bad = exp_result_h5_frame(h5, w) || dem_h5_write_attribute_string(h5, "dt_report", dem_world_dt_report(w));
    if (bad) exp_fail(err, len, "%s", dem_h5_error(h5));
    if (dem_h5_close(h5, bad ? NULL : err, bad ? 0 : len)) bad = 1;
    return bad;
}

int exp_result_write_json(const char *dir, exp_result_json_fn write, const void *ctx, char *err, size_t len)
{
    char path[1100];
    exp_atomic_file a;
    snprintf(path, sizeof path, "%s/result.json", dir);
    if (exp_atomic_open(&a, path, err, len)) return 1;
    write(a.f, ctx);
    return exp_atomic_commit(&a, err, len);
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
