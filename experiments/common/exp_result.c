// SPDX-License-Identifier: MIT
// An experiment's result.h5 (see exp_result.h).
#include "exp_result.h"

#include <stdio.h>

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
