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
#include <unistd.h>

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

// configs/drum.yaml with its log-normal's three lines replaced by `lines`, in a temporary file.
static void write_drum_with(const char *path, const char *lines)
{
    FILE *in = fopen(config, "r"), *out = fopen(path, "w");
    assert_non_null(in);
    assert_non_null(out);
    char text[512];
    while (fgets(text, sizeof text, in)) {
        if (strncmp(text, "median_diameter:", 16) == 0) fputs(lines, out);
        else if (strncmp(text, "geometric_sd:", 13) && strncmp(text, "truncation_sigmas:", 18)) fputs(text, out);
    }
    fclose(in), fclose(out);
}

// A measured size table instead of the log-normal (configs/examples/psd_volume.csv, by volume: its
// number median about 200 um); both at once, or a table without its basis, refused with the key named.
static void test_gsd_table(void **state)
{
    (void)state;
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    char path[] = "/tmp/granucal_drum_table_XXXXXX", lines[1200], err[512];
    close(mkstemp(path));
    snprintf(lines, sizeof lines, "gsd_table: %s/configs/examples/psd_volume.csv\ngsd_basis: volume\n", src ? src : ".");
    write_drum_with(path, lines);
    exp_drum_yaml *y = exp_drum_config_load(path, 0, NULL, err, sizeof err);
    if (!y) fail_msg("%s", err);
    exp_drum_def d;
    exp_drum_run_opts r;
    assert_int_equal(exp_drum_config_defs(y, &d, &r, err, sizeof err), 0);
    printf("table: %d rows, number median %.1f um, %.0f-%.0f um\n", d.gsd.table.rows, 1e6 * d.gsd.median_diameter,
           1e6 * dem_gsd_min_diameter(&d.gsd), 1e6 * dem_gsd_max_diameter(&d.gsd));
    assert_int_equal(d.gsd.table.rows, 18);
    assert_true(d.gsd.median_diameter > 195e-6 && d.gsd.median_diameter < 205e-6);
    exp_drum_config_free(y);
    const struct { const char *extra, *needle; } bad[] = {
        {"median_diameter: 200e-6\n", "median_diameter: gsd_table gives the size distribution"},
        {"", "gsd_basis: 'absent'"}};
    for (size_t k = 0; k < 2; ++k) {
        snprintf(lines, sizeof lines, "gsd_table: %s/configs/examples/psd_volume.csv\n%s%s", src ? src : ".",
                 k ? "" : "gsd_basis: volume\n", bad[k].extra);
        write_drum_with(path, lines);
        assert_null(exp_drum_config_load(path, 0, NULL, err, sizeof err));
        printf("-> %s\n", err);
        if (!strstr(err, bad[k].needle)) fail_msg("message '%s' lacks '%s'", err, bad[k].needle);
    }
    remove(path);
}

int main(void)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(config, sizeof config, "%s/configs/drum.yaml", src ? src : ".");
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_shipped_config_loads), cmocka_unit_test(test_overrides),
                                       cmocka_unit_test(test_bad_values_named), cmocka_unit_test(test_malformed_file),
                                       cmocka_unit_test(test_gsd_table)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
