// SPDX-License-Identifier: MIT
// The sphere on an inclined plane's runner: run, report, write the results.
// See exp_incline_runner.h.
#include "exp_incline_runner.h"

#include <stdio.h>

#include "exp_common.h"
#include "exp_result.h"

// What result.json says of a finished run (exp_result_json_fn's ctx).
typedef struct incline_report {
    const exp_incline_def *d;
    const exp_incline_result *r;
    const dem_world *w;
    double wall_time_s;
} incline_report;

static void write_json(FILE *f, const void *ctx)
{
    const incline_report *rep = ctx;
    const exp_incline_def *d = rep->d;
    const exp_incline_result *r = rep->r;
    char effects[1024];
    dem_world_describe_features(rep->w, effects, sizeof effects);
    fprintf(f,
            "{\"experiment\": \"incline\", \"status\": \"%s\", \"angle_deg\": %g, \"mu_s\": %g, \"mu_r\": %g, "
            "\"k_n\": %g, \"diameter_m\": %g, \"regime\": \"%s\", \"regime_analytic\": \"%s\", "
            "\"acceleration_m_s2\": %.6g, \"acceleration_analytic_m_s2\": %.6g, \"relative_error\": %.3g, "
            "\"spin_acceleration_m_s2\": %.6g, \"speed_m_s\": %.6g, \"slip_speed_m_s\": %.3g, \"travel_m\": %.6g, "
            "\"samples\": %zu, \"simulated_time_s\": %.4f, \"wall_time_s\": %.2f, \"dt_s\": %.6g, \"effects\": \"%s\"}\n",
            r->regime == r->analytic.regime ? "ok" : "regime differs", d->angle_deg, d->contact.mu_s, d->contact.mu_r,
            d->contact.k_n, d->diameter, exp_incline_regime_name(r->regime), exp_incline_regime_name(r->analytic.regime),
            r->acceleration, r->analytic.acceleration, r->relative_error, r->spin_acceleration, r->speed, r->slip_speed,
            r->travel, r->samples, r->simulated_time_s, rep->wall_time_s, dem_world_dt(rep->w), effects);
}

int exp_incline_simulate(const exp_incline_def *d, const char *out_dir)
{
    char err[1024], dir[1024];
    snprintf(dir, sizeof dir, "%s", out_dir ? out_dir : "results/runs/incline");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    double start = exp_wall_seconds();
    exp_incline_result r;
    dem_world *w = exp_incline_run(d, &r, err, sizeof err);
    if (!w) {
        fprintf(stderr, "granucal simulate: %s\n", err);
        exp_result_print_failure("incline", err);
        return 1;
    }
    fprintf(stderr, "granucal simulate: one sphere on a %g deg incline; %s\n", d->angle_deg, dem_world_dt_report(w));
    const incline_report rep = {d, &r, w, exp_wall_seconds() - start};
    int bad = exp_result_write_h5(dir, w, err, sizeof err) || exp_result_write_json(dir, write_json, &rep, err, sizeof err);
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    write_json(stdout, &rep);
    dem_world_destroy(w);
    return bad;
}
