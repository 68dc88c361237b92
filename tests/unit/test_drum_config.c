// SPDX-License-Identifier: MIT
// The drum config: the shipped configs/drum.yaml loads; overrides apply; bad
// values and unknown keys are refused with the file, line and field named.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "exp_drum_config.h"

static char config[1024];

static void test_shipped_config_loads(void **state)
{
    (void)state;
    char err[512];
    assert_true(exp_is_drum_config(config));
    exp_drum_yaml *y = exp_drum_config_load(config, 0, NULL, err, sizeof err);
    if (!y) fail_msg("%s", err);
    exp_drum_def d;
    exp_drum_run_opts r;
    assert_int_equal(exp_drum_config_defs(y, &d, &r, err, sizeof err), 0);
    // Table 3: granule–boundary stiffness is twice the granule–granule one.
    assert_true(d.wall.k_n == 2 * d.granule.k_n && d.granule.k_n == 200);
    assert_true(d.granule.mu_s == 0.8 && d.granule.mu_r == 0.2 && d.wall.mu_s == 0.8);
    exp_drum_config_free(y);
}

static void test_overrides(void **state)
{
    (void)state;
    char err[512], *sets[] = {"rpm=40", "wall=PTFE", "mu_s=0.5", "seed=7"};
    exp_drum_yaml *y = exp_drum_config_load(config, 4, sets, err, sizeof err);
    if (!y) fail_msg("%s", err);
    exp_drum_def d;
    exp_drum_run_opts r;
    assert_int_equal(exp_drum_config_defs(y, &d, &r, err, sizeof err), 0);
    assert_true(r.rpm == 40 && d.granule.mu_s == 0.5 && d.seed == 7);
    assert_true(d.wall.mu_s == 0.9 && d.wall.mu_r == 0.0001); // PTFE, Table 3
    exp_drum_config_free(y);
}

static void expect_error(char *set, const char *needle)
{
    char err[512];
    char *sets[] = {set};
    exp_drum_yaml *y = exp_drum_config_load(config, 1, sets, err, sizeof err);
    assert_null(y);
    printf("--set %s -> %s\n", set, err);
    if (!strstr(err, needle)) fail_msg("message '%s' lacks '%s'", err, needle);
}

static void test_bad_values_named(void **state)
{
    (void)state;
    expect_error("rpm=-4", "drum.yaml: --set rpm=-4: "); // the file, and the --set that gave the value
    expect_error("rpm=-4", "rpm");               // field
    expect_error("mu_s=-0.1", "mu_s");
    expect_error("mu_r=nan", "not a number");
    expect_error("wall=teflon", "teflon");
    expect_error("fill=1.2", "fill");
    expect_error("lambda=0.5", "lambda");
    expect_error("start_tilt_deg=120", "start_tilt_deg"); // the optional field, allocated by the override
    expect_error("start_tilt_deg=steep", "not a number");
    expect_error("colour=red", "unknown key");
    expect_error("rpm", "key=value");
}

static void test_malformed_file(void **state)
{
    (void)state;
    char path[] = "/tmp/granucal_drum_XXXXXX", err[512];
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    FILE *f = fdopen(fd, "w");
    fputs("experiment: drum\ndiameter: [oops\n", f);
    fclose(f);
    assert_null(exp_drum_config_load(path, 0, NULL, err, sizeof err));
    printf("malformed -> %s\n", err);
    assert_non_null(strstr(err, path));
    remove(path);
}

int main(void)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(config, sizeof config, "%s/configs/drum.yaml", src ? src : ".");
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_shipped_config_loads), cmocka_unit_test(test_overrides),
                                       cmocka_unit_test(test_bad_values_named), cmocka_unit_test(test_malformed_file)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
