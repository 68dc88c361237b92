// SPDX-License-Identifier: MIT
// The plan's prediction of when the MSER rule stops a run (calib/runs/cal_plan.c):
// from the store's runs of the same kind, worked by hand on records written here.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "cal_case_runs.h"
#include "cal_config.h"
#include "cal_plan.h"
#include "cal_store.h"

static char source[1024];

static void test_kind_masks_pairs_and_seed(void **state)
{
    (void)state;
    char kind[512];
    // As cal_drum_key writes them: each pair in a contact's text, the bed's seed, a turned start's pairs.
    const char *key = "drum D=0.1 depth=0.009 lambda=1000 granule[k=200,200,200 xi=0.7 mu=1,0.14 damping=0] "
                      "wall[k=400,400,400 xi=0.7 mu=0.3,0.01 damping=0] seed=12 rpm=4 "
                      "start=turned[time=10 granule[k=200,200,200 xi=0.7 mu=0.5,0.1 damping=0]]";
    cal_drum_key_kind(key, 0, kind, sizeof kind);
    assert_string_equal(kind, "drum D=0.1 depth=0.009 lambda=1000 granule[k=200,200,200 xi=0.7 mu=* damping=0] "
                              "wall[k=400,400,400 xi=0.7 mu=* damping=0] seed=* rpm=4 "
                              "start=turned[time=10 granule[k=200,200,200 xi=0.7 mu=* damping=0]]");
    // At any scale: λ, the slice depth and the stiffnesses too.
    cal_drum_key_kind(key, 1, kind, sizeof kind);
    assert_string_equal(kind, "drum D=0.1 depth=* lambda=* granule[k=* xi=0.7 mu=* damping=0] wall[k=* xi=0.7 mu=* "
                              "damping=0] seed=* rpm=4 start=turned[time=10 granule[k=* xi=0.7 mu=* damping=0]]");
}

// The standard tier's granule case: its 4 rpm runs start turned, under the MSER rule.
static cal_config *standard(const cal_tier **t)
{
    char path[1200], err[1024];
    snprintf(path, sizeof path, "%s/configs/calibration.yaml", source);
    cal_config *c = cal_config_load(path, "standard", err, sizeof err);
    if (!c) fail_msg("%s", err);
    *t = cal_config_tier(c);
    return c;
}

// A record of the granule case (mu_s, mu_r) on bed `seed` at rpm that turned `simulated` s.
static void put_run_k(const char *store, const cal_config *c, const cal_tier *t, double k_n, double mu_s, double mu_r,
                      int seed, double rpm, double simulated, const char *status)
{
    char key[4096], err[1024];
    cal_drum_case d = cal_drum_case_granule(c, t, k_n, mu_s, mu_r);
    cal_drum_case_set_seed(&d, (uint64_t)seed);
    cal_drum_key(&d, rpm, key, sizeof key);
    cal_record r = {.key = key, .status = (char *)status, .reason = "", .simulated_time_s = simulated, .granules = 1};
    if (cal_store_put(store, &r, err, sizeof err)) fail_msg("%s", err);
}

static void put_run(const char *store, const cal_config *c, const cal_tier *t, double mu_s, double mu_r, int seed,
                    double rpm, double simulated, const char *status)
{
    put_run_k(store, c, t, 200, mu_s, mu_r, seed, rpm, simulated, status);
}

static void test_mser_stop_from_the_runs_of_its_kind(void **state)
{
    (void)state;
    const cal_tier *t;
    cal_config *c = standard(&t);
    char store[] = "/tmp/granucal_plan_XXXXXX", err[1024], path[1100];
    assert_non_null(mkdtemp(store));
    cal_drum_case d = cal_drum_case_granule(c, t, 200, 0.8, 0.2);
    const double max_time = cal_drum_run_opts(&d, 4).max_time;
    assert_int_equal(cal_drum_run_opts(&d, 4).steady_rule, EXP_STEADY_MSER);
    cal_plan_history h;
    int from_store;
    // Two runs of its kind: fewer than CAL_PLAN_HISTORY_MIN, so max_time.
    put_run(store, c, t, 1.0, 0.01, 1, 4, 3.0, "ok");
    put_run(store, c, t, 0.5, 0.3, 2, 4, max_time, "not steady");
    // Neither of these is of its kind: a failed run, and a run at another speed.
    put_run(store, c, t, 0.6, 0.1, 1, 4, 0.5, "failed");
    put_run(store, c, t, 0.6, 0.1, 1, 40, 0.5, "ok");
    // A damaged file is passed over, never read as a run.
    snprintf(path, sizeof path, "%s/0123456789abcdef.yaml", store);
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("key: 'drum", f), fclose(f);
    // So is a retry record another run's killed process left (absent to every run): were it read, it
    // would be the third run of the kind and set the mean.
    {
        char key[4096];
        cal_drum_case other = cal_drum_case_granule(c, t, 200, 0.9, 0.3);
        cal_drum_case_set_seed(&other, 7);
        cal_drum_key(&other, 4, key, sizeof key);
        cal_store_path(store, key, path, sizeof path);
        f = fopen(path, "w");
        assert_non_null(f);
        fprintf(f, "key: '%s'\nstatus: 'ok'\nreason: ''\nwriter: 'elsewhere:1'\nretry: true\n"
                   "simulated_time_s: 0.5\ngranules: 1\n", key);
        fclose(f);
        cal_record r;
        assert_int_equal(cal_store_get(store, key, &r, err, sizeof err), 1); // absent to a run, too
    }
    assert_int_equal(cal_plan_history_read(&h, store, err, sizeof err), 0);
    assert_float_equal(cal_plan_turn_time(&d, 4, 0, &h, &from_store), max_time, 0);
    assert_int_equal(from_store, 0);
    cal_plan_history_free(&h);
    // A third: the mean of the three (two modes: early stops and max_time).
    put_run(store, c, t, 0.7, 0.05, 3, 4, 6.0, "ok");
    assert_int_equal(cal_plan_history_read(&h, store, err, sizeof err), 0);
    assert_float_equal(cal_plan_turn_time(&d, 4, 0, &h, &from_store), (3.0 + max_time + 6.0) / 3, 1e-12);
    assert_int_equal(from_store, 1);
    // The worst case stays max_time; a speed under the windows' rule ignores the store.
    assert_float_equal(cal_plan_turn_time(&d, 4, 1, &h, &from_store), max_time, 0);
    assert_int_equal(from_store, 0);
    exp_drum_run_opts o = cal_drum_run_opts(&d, 40);
    assert_int_not_equal(o.steady_rule, EXP_STEADY_MSER);
    assert_float_equal(cal_plan_turn_time(&d, 40, 0, &h, &from_store), fmin(o.max_time, 2 * o.window + o.average_time), 0);
    // A batch of 3 candidates on one bed each at 4 and 40 rpm: 3 MSER runs, all from the store.
    cal_plan_cost cost = {0};
    const double rpm[] = {4, 40};
    cal_plan_drum_batch(&cost, &d, rpm, 2, 3, 1, 0, 0, 2, 0, &h);
    assert_int_equal(cost.runs, 6);
    assert_int_equal(cost.mser_runs, 3), assert_int_equal(cost.mser_from_store, 3);
    assert_int_equal(cost.mser_from_other_scale, 0);
    // The same drum at another k_n has no run of its own kind: those of its kind at any scale predict it.
    cal_drum_case soft = cal_drum_case_granule(c, t, 50, 0.8, 0.2);
    assert_float_equal(cal_plan_turn_time(&soft, 4, 0, &h, &from_store), (3.0 + max_time + 6.0) / 3, 1e-12);
    assert_int_equal(from_store, 2);
    cal_plan_history_free(&h);
    // Its own kind, where the store holds 3, comes first (stops of 1 s at k_n 50).
    for (int seed = 1; seed <= 3; ++seed) put_run_k(store, c, t, 50, 0.5, 0.1, seed, 4, 1.0, "ok");
    assert_int_equal(cal_plan_history_read(&h, store, err, sizeof err), 0);
    assert_float_equal(cal_plan_turn_time(&soft, 4, 0, &h, &from_store), 1.0, 1e-12);
    assert_int_equal(from_store, 1);
    cal_plan_history_free(&h);
    // No store yet: no history, no error.
    assert_int_equal(cal_plan_history_read(&h, "/tmp/granucal_plan_no_such_store", err, sizeof err), 0);
    assert_int_equal(h.n, 0);
    cal_plan_history_free(&h);
    char command[1200];
    snprintf(command, sizeof command, "rm -rf '%s'", store);
    assert_int_equal(system(command), 0);
    cal_config_free(c);
}

int main(void)
{
    const char *s = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(source, sizeof source, "%s", s ? s : ".");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kind_masks_pairs_and_seed),
        cmocka_unit_test(test_mser_stop_from_the_runs_of_its_kind),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
