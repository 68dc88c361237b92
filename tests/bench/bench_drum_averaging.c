// SPDX-License-Identifier: MIT
// What a shorter averaging would have measured (issue 37.1; a measurement, not a test). A
// calibration's drum run averages the angle and CSA over the steady test's two windows and then
// average_time more; its trajectory does not depend on when it will stop, so one run of the longest
// averaging holds every shorter one as a prefix. This runs one of a calibration's own drum runs (its
// record found in STORE by the key rebuilt from the config: the same simulation), keeps every
// sample, and prints the angle and CSA that averaging T s after the steady test would have given, for
// each T of TIMES, beside the record's own values. A key prints μ to 10 digits, so the record is found
// from the key's digits too, but only the search's own μ (the stage_*.yaml files, 17 digits;
// simulations.csv has 6) reproduces its bits: the line "this run ... record" says whether it did
// (results/benchmarks/averaging_ab.md).
//   usage: bench_drum_averaging CONFIG TIER K_N MU_S MU_R RPM BED STORE TIMES [TURN_ON_S]
//   (granule stage: the drum lined with granules; BED 0, 1, 2: the tier's beds, seeds config seed + BED;
//    TIMES e.g. 0,1,2,3,4,6,8). TURN_ON_S: average that long after the steady test instead of the
//    tier's average_time (a run's trajectory does not depend on when it stops, so the record is still
//    checked, against the mean over the tier's own averaging); it also prints the mean of each 2 s block
//    after the steady test, which shows a drift the running mean smooths.
//   With SERIES_CSV=FILE set, every sample is also written there (seconds turned, angle, CSA), so that a
//   rule for the transient or the averaging can be tried on the series without turning the bed again.
//   With PRE_TURN=MU_S,MU_R,SECONDS set, the copy is first turned SECONDS at RPM with another granule pair
//   (its samples in SERIES_CSV.pre when SERIES_CSV is set), then turned as above from where it is, without
//   the start tilt: a candidate started from another candidate's turned bed instead of a level one (issue
//   37.1's "start from a turned bed"). Such a run is not the record's; the line "this run" says so.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_case_runs.h"
#include "cal_config.h"
#include "cal_store.h"
#include "exp_drum.h"

typedef struct series {
    int n, cap;
    exp_drum_measure *m;
} series;

static void keep(int index, const exp_drum_measure *m, void *ctx)
{
    series *s = ctx;
    if (index >= s->cap) {
        s->cap = 2 * index + 64;
        s->m = realloc(s->m, (size_t)s->cap * sizeof *s->m);
        if (!s->m) abort();
    }
    s->m[index] = *m;
    s->n = index + 1;
}

// Samples in t seconds of turning, rounded as exp_drum.c counts its windows.
static int samples_in(const exp_drum_run_opts *o, double t) { return (int)(t / o->sample_interval + 0.5); }

// Every sample, one line each: seconds turned at the sample's end, angle (°), CSA (%).
static int write_series(const char *path, const series *s, double sample_interval)
{
    FILE *f = fopen(path, "w");
    if (!f) return fprintf(stderr, "%s: cannot write\n", path), 1;
    fprintf(f, "t_s,angle_deg,csa_percent\n");
    for (int i = 0; i < s->n; ++i)
        fprintf(f, "%.4f,%.17g,%.17g\n", (i + 1) * sample_interval, s->m[i].angle_deg, s->m[i].csa_percent);
    return fclose(f) != 0;
}

static void mean_over(const series *s, int from, int to, double *angle, double *csa)
{
    double a = 0, c = 0;
    for (int i = from; i < to; ++i) a += s->m[i].angle_deg, c += s->m[i].csa_percent;
    *angle = a / (to - from), *csa = c / (to - from);
}

// PRE_TURN's "MU_S,MU_R,SECONDS": `w` turned SECONDS at `rpm` with that granule pair (every sample in
// `pre`), and the measured run set to go on from there without its start tilt. 0, or 1 with a message.
static int pre_turn_bed(dem_world *w, const cal_config *c, const cal_tier *t, double k_n, int bed, double rpm,
                        const char *spec, series *pre, exp_drum_run_opts *measured)
{
    double mu_s, mu_r, seconds;
    if (sscanf(spec, "%lf,%lf,%lf", &mu_s, &mu_r, &seconds) != 3 || !(seconds > 0))
        return fprintf(stderr, "PRE_TURN=%s: want MU_S,MU_R,SECONDS\n", spec), 1;
    cal_drum_case a = cal_drum_case_granule(c, t, k_n, mu_s, mu_r);
    cal_drum_case_set_seed(&a, (uint64_t)(c->seed + bed));
    exp_drum_run_opts o = cal_drum_run_opts(&a, rpm);
    o.max_time = o.window = seconds; // every sample of the pre-turn kept, none averaged
    o.steady_rule = EXP_STEADY_WINDOWS;
    o.on_sample = keep, o.sample_ctx = pre;
    exp_drum_result r;
    if (exp_drum_rotate(w, &a.def, &o, NULL, NULL, &r) != DEM_OK) return fprintf(stderr, "the pre-turn failed\n"), 1;
    printf("pre-turned %.2f s at mu_s %.17g, mu_r %.17g (ended at angle %.4f, CSA %.4f: its last sample)\n", seconds, mu_s,
           mu_r, pre->n ? pre->m[pre->n - 1].angle_deg : NAN, pre->n ? pre->m[pre->n - 1].csa_percent : NAN);
    measured->start_tilt_deg = 0; // the bed is already turned
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 10 && argc != 11)
        return fprintf(stderr, "usage: %s CONFIG TIER K_N MU_S MU_R RPM BED STORE TIMES [TURN_ON_S]\n", argv[0]), 2;
    char err[1024], key[4096];
    cal_config *c = cal_config_load(argv[1], argv[2], err, sizeof err);
    if (!c) return fprintf(stderr, "%s\n", err), 1;
    const cal_tier *t = cal_config_tier(c);
    double rpm = atof(argv[6]);
    cal_drum_case d = cal_drum_case_granule(c, t, atof(argv[3]), atof(argv[4]), atof(argv[5]));
    cal_drum_case_set_seed(&d, (uint64_t)(c->seed + atoi(argv[7]))); // as the friction stage sets a bed's seed
    cal_drum_key(&d, rpm, key, sizeof key);
    cal_record rec;
    const int got = cal_store_get(argv[8], key, &rec, err, sizeof err);
    if (got != 0)
        return fprintf(stderr, "%s: %s\n  key %s\n", argv[8], got > 0 ? "no record of this simulation" : err, key), 1;
    exp_drum_run_opts o = cal_drum_run_opts(&d, rpm);
    series s = {0};
    o.on_sample = keep, o.sample_ctx = &s;
    const double tier_average_time = o.average_time;
    if (argc == 11 && atof(argv[10]) > o.average_time) {
        o.max_time += atof(argv[10]) - o.average_time; // the steady test may take as long as before
        o.average_time = atof(argv[10]);
    }
    dem_world *bed = exp_drum_fill(&d.fill, NULL, NULL, err, sizeof err);
    if (!bed) return fprintf(stderr, "%s\n", err), 1;
    // A copy of the settled bed, as the calibration turns one (calib/runs/cal_case_runs.c; a copy steps to the
    // same bits as the bed itself, tests/physics/test_clone.c, and did here).
    dem_world *w = dem_world_clone(bed);
    if (!w) return fprintf(stderr, "out of memory\n"), 1;
    series pre = {0};
    const char *pre_turn = getenv("PRE_TURN");
    if (pre_turn && pre_turn_bed(w, c, t, atof(argv[3]), atoi(argv[7]), rpm, pre_turn, &pre, &o)) return 1;
    exp_drum_result r;
    if (exp_drum_rotate(w, &d.def, &o, NULL, NULL, &r) != DEM_OK || !r.steady)
        return fprintf(stderr, "the run failed or was not steady\n"), 1;
    int per_window = samples_in(&o, o.window), avg = samples_in(&o, o.average_time);
    int steady_at = s.n - avg, from = steady_at - 2 * per_window;
    // What the tier's own run reported: the mean over its averaging (the same sum as exp_drum.c's).
    mean_over(&s, from, steady_at + samples_in(&o, tier_average_time), &r.angle_deg, &r.csa_percent);
    const int same = rec.angle_deg == r.angle_deg && rec.csa_percent == r.csa_percent;
    printf("record: angle %.17g, CSA %.17g; this run: angle %.17g, CSA %.17g (%s the record); steady test held at "
           "%.2f s of turning\n",
           rec.angle_deg, rec.csa_percent, r.angle_deg, r.csa_percent,
           pre_turn ? "pre-turned, so not" : same ? "reproduces" : "does NOT reproduce", steady_at * o.sample_interval);
    char *list = strdup(argv[9]), *save = NULL;
    for (char *tok = strtok_r(list, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        double T = atof(tok), angle, csa;
        int to = steady_at + samples_in(&o, T);
        if (to > s.n) continue;
        mean_over(&s, from, to, &angle, &csa);
        printf("average_time=%g turned_s=%.2f angle_deg=%.17g csa_percent=%.17g\n", T, to * o.sample_interval, angle,
               csa);
    }
    const int block = samples_in(&o, 2.0);
    for (int b0 = steady_at; b0 + block <= s.n; b0 += block) {
        double angle, csa;
        mean_over(&s, b0, b0 + block, &angle, &csa);
        printf("block_from_s=%.2f block_to_s=%.2f angle_deg=%.4f csa_percent=%.4f\n", b0 * o.sample_interval,
               (b0 + block) * o.sample_interval, angle, csa);
    }
    const char *series_path = getenv("SERIES_CSV");
    int unwritten = series_path && write_series(series_path, &s, o.sample_interval);
    if (series_path && pre_turn) {
        char pre_path[1100];
        snprintf(pre_path, sizeof pre_path, "%s.pre", series_path);
        unwritten |= write_series(pre_path, &pre, o.sample_interval);
    }
    free(pre.m);
    free(list), free(s.m);
    cal_record_free(&rec);
    if (w != bed) dem_world_destroy(w);
    dem_world_destroy(bed);
    cal_config_free(c);
    return unwritten;
}
