// SPDX-License-Identifier: MIT
// The poured cylinder of section 4.1 from its YAML scene (configs/cylinder.yaml),
// through the functions `granucal simulate` runs, at the shipped (coarse) lambda:
//  - the shipped scene is the calibration's stage-1 cylinder (configs/calibration.yaml,
//    its default tier, k_n = 200 N/m, seed 1): the same definition, field by field;
//  - the bed at rest, checked from the positions with an own contact search (no
//    engine code): every centre below the rim and inside the container, the
//    granule-granule coordination and the wall contacts per granule recounted from
//    overlaps, a coordination between 1 and 12, wall contacts > 0, a solid fraction
//    in (0.2, 0.75), the bed (nearly) at rest;
//  - result.json and result.h5 are written and hold the numbers;
//  - bad input is named by file, line and field, or by the --set that gave it.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>

#include "cal_case_runs.h"
#include "cal_config.h"
#include "dem_scaling.h"
#include "exp_cylinder_config.h"
#include "exp_cylinder_runner.h"

static void source_path(const char *rel, char *path, size_t len)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(path, len, "%s/%s", src ? src : ".", rel);
}

// A copy of the shipped scene with the line starting `key:` replaced by
// `replacement` (NULL: unchanged) and `extra` appended; the replaced or
// appended line's number in *line.
static void write_variant(const char *tmp, const char *key, const char *replacement, const char *extra, int *line)
{
    char path[1024], text[512];
    source_path("configs/cylinder.yaml", path, sizeof path);
    FILE *in = fopen(path, "r"), *out = fopen(tmp, "w");
    assert_non_null(in);
    assert_non_null(out);
    int n = 0;
    *line = 0;
    while (fgets(text, sizeof text, in)) {
        ++n;
        if (key && strncmp(text, key, strlen(key)) == 0 && text[strlen(key)] == ':') {
            snprintf(text, sizeof text, "%s\n", replacement);
            *line = n;
        }
        fputs(text, out);
    }
    if (extra) fprintf(out, "%s\n", extra), *line = n + 1;
    fclose(in), fclose(out);
}

static void test_bad_input_is_named(void **state)
{
    (void)state;
    char tmp[] = "/tmp/granucal_cylinder_XXXXXX", err[1024], want[96], path[1024];
    int fd = mkstemp(tmp), line = 0;
    assert_true(fd >= 0);
    close(fd);
    exp_cylinder_def d;

    write_variant(tmp, "mu_s", "mu_s: -0.1", NULL, &line);
    assert_true(line > 0);
    assert_int_not_equal(exp_cylinder_load(tmp, 0, NULL, &d, err, sizeof err), 0);
    printf("%s\n", err);
    snprintf(want, sizeof want, "%s:%d: mu_s: ", tmp, line);
    assert_non_null(strstr(err, want));

    write_variant(tmp, NULL, NULL, "wall_mu_s: 0.2", &line);
    assert_int_not_equal(exp_cylinder_load(tmp, 0, NULL, &d, err, sizeof err), 0);
    printf("%s\n", err);
    snprintf(want, sizeof want, "%s:%d: wall_mu_s: ", tmp, line);
    assert_non_null(strstr(err, want));

    write_variant(tmp, "depth", "depth: 0", NULL, &line);
    assert_int_not_equal(exp_cylinder_load(tmp, 0, NULL, &d, err, sizeof err), 0);
    printf("%s\n", err);
    snprintf(want, sizeof want, "%s:%d: depth: ", tmp, line);
    assert_non_null(strstr(err, want));
    remove(tmp);

    // Overrides: a bad value is blamed on the --set, not on the file's line.
    source_path("configs/cylinder.yaml", path, sizeof path);
    char s1[] = "mu_r=-1", s2[] = "bogus=1", s3[] = "lambda=1e9", s4[] = "seed=1.5", *set[1];
    set[0] = s1;
    assert_int_not_equal(exp_cylinder_load(path, 1, set, &d, err, sizeof err), 0);
    printf("%s\n", err);
    assert_non_null(strstr(err, "--set mu_r=-1: "));
    set[0] = s2;
    assert_int_not_equal(exp_cylinder_load(path, 1, set, &d, err, sizeof err), 0);
    assert_non_null(strstr(err, "unknown key"));
    set[0] = s3; // the largest scaled granule (0.41 m) in a 0.1 m container
    assert_int_not_equal(exp_cylinder_load(path, 1, set, &d, err, sizeof err), 0);
    printf("%s\n", err);
    assert_non_null(strstr(err, "does not fit"));
    set[0] = s4;
    assert_int_not_equal(exp_cylinder_load(path, 1, set, &d, err, sizeof err), 0);
    assert_non_null(strstr(err, "integer"));
}

static void test_shipped_scene_is_stage_one(void **state)
{
    (void)state;
    char path[1024], err[1024];
    exp_cylinder_def d;
    source_path("configs/cylinder.yaml", path, sizeof path);
    if (exp_cylinder_load(path, 0, NULL, &d, err, sizeof err)) fail_msg("%s", err);
    source_path("configs/calibration.yaml", path, sizeof path);
    cal_config *c = cal_config_load(path, NULL, err, sizeof err);
    if (!c) fail_msg("%s", err);
    exp_cylinder_def s = cal_cylinder_case_make(c, cal_config_tier(c), 200, (uint64_t)c->seed);
    cal_config_free(c);
    assert_true(d.diameter == s.diameter && d.depth == s.depth && d.lambda == s.lambda && d.density == s.density);
    assert_true(d.gsd.median_diameter == s.gsd.median_diameter && d.gsd.geometric_sd == s.gsd.geometric_sd &&
                d.gsd.truncation_sigmas == s.gsd.truncation_sigmas);
    assert_memory_equal(&d.granule, &s.granule, sizeof d.granule);
    assert_memory_equal(&d.wall, &s.wall, sizeof d.wall);
    assert_true(d.seed == s.seed);
}

static void test_shipped_scene_at_rest(void **state)
{
    (void)state;
    char path[1024], err[1024];
    exp_cylinder_def d;
    source_path("configs/cylinder.yaml", path, sizeof path);
    if (exp_cylinder_load(path, 0, NULL, &d, err, sizeof err)) fail_msg("%s", err);
    exp_cylinder_result r;
    exp_cylinder_report rep;
    dem_world *w = exp_cylinder_pour_and_report(&d, 0, &r, &rep, err, sizeof err);
    if (!w) fail_msg("%s", err);
    printf("%zu granules, coordination %.3f (interior %.3f), wall contacts/granule %.3f, solid fraction %.3f, "
           "KE ratio %.2g, %.2f s simulated in %.1f s wall\n",
           r.granules, r.coordination, r.coordination_interior, r.wall_contacts_per_granule, r.solid_fraction,
           rep.ke_ratio, r.simulated_time_s, rep.wall_time_s);

    dem_granules_view g = dem_world_granules(w);
    assert_int_equal(g.count, r.granules);
    assert_true(r.granules >= 40 && r.granules <= 200); // the shipped lambda holds ~70-90
    // Own contact search: overlapping pairs, and granules touching the floor or the side.
    double R = 0.5 * d.diameter, solid = 0, top = 0;
    size_t pairs = 0, walls = 0;
    for (size_t i = 0; i < g.count; ++i) {
        dem_vec3 p = g.position[i];
        double ri = g.radius[i], rho = sqrt(p.x * p.x + p.z * p.z);
        assert_true(p.y <= d.depth);              // struck off at the rim, only settled since
        assert_true(p.y - ri > -0.05 * ri);       // above the floor (overlap < 5 % of a radius)
        assert_true(rho + ri < R + 0.05 * ri);    // inside the container
        walls += (p.y < ri) + (rho + ri > R);
        solid += 4.0 / 3.0 * DEM_PI * ri * ri * ri;
        top = fmax(top, p.y + ri);
        for (size_t j = i + 1; j < g.count; ++j)
            if (dem_v3_norm(dem_v3_sub(g.position[j], p)) < ri + g.radius[j]) pairs++;
    }
    double n = (double)g.count, z_own = 2.0 * (double)pairs / n, zw_own = (double)walls / n;
    printf("own count: coordination %.3f, wall contacts/granule %.3f; bed top %.1f mm (rim %.1f mm)\n", z_own,
           zw_own, 1e3 * top, 1e3 * d.depth);
    assert_true(isfinite(r.coordination) && r.coordination >= 1 && r.coordination <= 12);
    assert_true(r.wall_contacts_per_granule > 0);
    assert_true(r.solid_fraction > 0.2 && r.solid_fraction < 0.75);
    assert_true(fabs(r.solid_fraction - solid / (DEM_PI * R * R * d.depth)) < 1e-12);
    // The engine's contacts are the overlapping pairs (a pair just touching may
    // differ: allow one contact in either count).
    assert_true(fabs(r.coordination - z_own) <= 2.0 / n + 1e-12);
    assert_true(fabs(r.wall_contacts_per_granule - zw_own) <= 1.0 / n + 1e-12);
    assert_true(rep.bed_surface_m <= d.depth + dem_gsd_max_diameter(&d.gsd) * cbrt(d.lambda) / 2);
    assert_true(fabs(rep.bed_top_m - top) < 1e-12);
    // Settled: the settle stops at a kinetic energy ratio of 1e-6 or after 2 s;
    // 1e-4 is a mean speed of ~1 % of sqrt(g d50).
    assert_true(rep.ke_ratio < 1e-4);

    // The files `granucal simulate` writes.
    char dir[] = "/tmp/granucal_cylinder_out_XXXXXX", file[1100], json[4096];
    assert_non_null(mkdtemp(dir));
    if (exp_cylinder_write_outputs(dir, &d, &r, &rep, w, err, sizeof err)) fail_msg("%s", err);
    struct stat st;
    snprintf(file, sizeof file, "%s/result.h5", dir);
    assert_int_equal(stat(file, &st), 0);
    assert_true(st.st_size > 0);
    remove(file);
    snprintf(file, sizeof file, "%s/result.xmf", dir);
    remove(file);
    snprintf(file, sizeof file, "%s/result.json", dir);
    FILE *f = fopen(file, "r");
    assert_non_null(f);
    size_t got = fread(json, 1, sizeof json - 1, f);
    json[got] = '\0';
    fclose(f);
    remove(file);
    rmdir(dir);
    char want[96];
    snprintf(want, sizeof want, "\"granules\": %zu,", r.granules);
    assert_non_null(strstr(json, want));
    snprintf(want, sizeof want, "\"coordination\": %.4f,", r.coordination);
    assert_non_null(strstr(json, want));
    snprintf(want, sizeof want, "\"wall_contacts_per_granule\": %.4f,", r.wall_contacts_per_granule);
    assert_non_null(strstr(json, want));
    assert_true(r.particle_steps >= (double)r.granules); // the engine's own count: at least one step of the bed
    snprintf(want, sizeof want, "\"particle_steps\": %.0f,", r.particle_steps);
    assert_non_null(strstr(json, want));
    const char *keys[] = {"\"experiment\": \"cylinder\"", "\"status\": ", "\"k_n\": 200,", "\"mu_s\": 0.5,",
                          "\"mu_r\": 0.1,", "\"lambda\": 262144,", "\"seed\": 1,", "\"coordination_interior\": ",
                          "\"solid_fraction\": ", "\"simulated_time_s\": ", "\"wall_time_s\": ", "\"dt_s\": ",
                          "\"effects\": \"granule-granule: damping on (approaching), tangential on, rolling on"};
    for (size_t k = 0; k < sizeof keys / sizeof *keys; ++k)
        if (!strstr(json, keys[k])) fail_msg("result.json lacks %s: %s", keys[k], json);
    assert_null(strstr(json, "nan")); // JSON has no NaN
    dem_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_bad_input_is_named),
                                       cmocka_unit_test(test_shipped_scene_is_stage_one),
                                       cmocka_unit_test(test_shipped_scene_at_rest)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
