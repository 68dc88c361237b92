// SPDX-License-Identifier: MIT
// Stage 1 on the drum's own poured bed (stiffness_scene: drum) at the check
// tier's scale (~170 granules): every bed gives a finite coordination number,
// recorded in the store under a drum-bed key and resumed from it, and the
// stage chooses by stage 1's one rule (cal_stiffness_choose). A tier without
// the key keeps the cylinder and the cylinder's keys.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "cal_case_runs.h"
#include "cal_files.h"
#include "cal_stages.h"
#include "exp_common.h"

static const double candidates[] = {10, 50}; // soft: cheap (a stiffer bed needs a smaller step)
enum { N_K = 2 };

static void source_path(const char *rel, char *path, size_t len)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(path, len, "%s/%s", src ? src : ".", rel);
}

// The shipped config with `lines` added to the check tier's block; its path in *out.
static void write_config(const char *dir, const char *lines, char *out, size_t len)
{
    char shipped[1024];
    source_path("configs/calibration.yaml", shipped, sizeof shipped);
    FILE *in = fopen(shipped, "r");
    snprintf(out, len, "%s/calibration.yaml", dir);
    FILE *f = fopen(out, "w");
    assert_non_null(in), assert_non_null(f);
    char line[1024];
    int added = 0;
    while (fgets(line, sizeof line, in)) {
        fputs(line, f);
        if (strcmp(line, "  - name: check\n") == 0) fputs(lines, f), added = 1;
    }
    fclose(in), fclose(f);
    assert_true(added);
}

// Remove a scratch folder this test made (its name is ours: no quoting needed).
static void remove_scratch(const char *dir)
{
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
}

static cal_config *load(const char *dir, const char *lines)
{
    char path[1100], err[1024];
    write_config(dir, lines, path, sizeof path);
    cal_config *c = cal_config_load(path, "check", err, sizeof err);
    if (!c) fail_msg("%s", err);
    return c;
}

static void scratch(char *dir, size_t len, const char *name)
{
    const char *bin = getenv("GRANUCAL_BINARY_DIR");
    snprintf(dir, len, "%s/%s.%d", bin ? bin : "/tmp", name, (int)getpid());
    char err[512];
    if (cal_mkdirs(dir, err, sizeof err)) fail_msg("%s", err);
}

static void stage_one(cal_env *env, const char *store, const cal_config *c, cal_stiffness_result *out)
{
    memset(env, 0, sizeof *env);
    snprintf(env->store, sizeof env->store, "%s", store);
    env->workers = 1, env->use_fork = 0, env->started = exp_wall_seconds();
    char err[1024];
    if (cal_stage_stiffness(env, c, cal_config_tier(c), out, err, sizeof err)) fail_msg("%s", err);
}

static int same(double a, double b) { return a == b || (isnan(a) && isnan(b)); }

static void test_drum_bed_recorded_resumed_chosen(void **state)
{
    (void)state;
    char dir[1024], store[1100], lines[256];
    scratch(dir, sizeof dir, "stiffness_drum");
    snprintf(lines, sizeof lines, "    stiffness_scene: drum\n    stiffness: [%g, %g]\n", candidates[0], candidates[1]);
    cal_config *c = load(dir, lines);
    const cal_tier *t = cal_config_tier(c);
    snprintf(store, sizeof store, "%s/store", dir);
    char err[512];
    if (cal_mkdirs(store, err, sizeof err)) fail_msg("%s", err);
    cal_env env;
    cal_stiffness_result s;
    stage_one(&env, store, c, &s);
    assert_int_equal(env.simulations_run, N_K * t->seeds);
    assert_string_equal(s.scene, "drum's own poured bed");
    for (int i = 0; i < N_K; ++i) {
        printf("k_n %g N/m: CN %.4f ± %.4f, %d granules, solid fraction %.3f\n", s.k[i], s.cn_mean[i], s.cn_sd[i],
               s.granules[i], s.solid_fraction[i]);
        assert_true(s.k[i] == candidates[i] && s.failed[i] == 0);
        for (int j = 0; j < t->seeds; ++j) {
            cal_bed_case b = cal_bed_case_make(c, t, s.k[i], (uint64_t)(c->seed + j));
            char key[2048];
            cal_bed_key(&b, key, sizeof key);
            assert_int_equal(strncmp(key, "drum_bed drum ", 14), 0);
            // The drum's own bed: its λ and slice, not the cylinder's λ.
            assert_true(b.drum_bed.lambda == t->lambda && b.drum_bed.periodic && b.drum_bed.depth == t->slice_depth);
            assert_true(b.drum_bed.granule.mu_s == c->pour_mu_s && b.drum_bed.wall.mu_r == c->pour_mu_r);
            cal_record r;
            assert_int_equal(cal_store_get(store, key, &r, err, sizeof err), 0);
            assert_string_equal(r.status, "ok");
            assert_true(isfinite(r.coordination) && r.coordination > 0 && r.coordination < 12 && r.granules > 20);
            cal_record_free(&r);
        }
    }
    // Stage 1's one rule, on the stage's own numbers.
    cal_stiffness_result again = s;
    again.chosen_k = -1, again.resolved = -1;
    cal_stiffness_choose(&again);
    assert_true(same(again.chosen_k, s.chosen_k) && again.resolved == s.resolved);
    assert_true(s.stiff_limit == s.cn_mean[N_K - 1]);
    // Run again on the same store: nothing simulated, the same numbers.
    cal_stiffness_result resumed;
    stage_one(&env, store, c, &resumed);
    assert_int_equal(env.simulations_run, 0);
    for (int i = 0; i < N_K; ++i) assert_true(resumed.cn_mean[i] == s.cn_mean[i] && resumed.cn_sd[i] == s.cn_sd[i]);
    assert_true(same(resumed.chosen_k, s.chosen_k) && resumed.resolved == s.resolved);
    cal_config_free(c);
    remove_scratch(dir);
}

// Without the key (or with `cylinder`) stage 1 pours the cylinder under the
// cylinder's own key: the stores of every earlier calibration stay valid.
static void test_cylinder_by_default(void **state)
{
    (void)state;
    char dir[1024];
    scratch(dir, sizeof dir, "stiffness_cylinder");
    const char *variants[] = {"", "    stiffness_scene: cylinder\n"};
    for (int v = 0; v < 2; ++v) {
        cal_config *c = load(dir, variants[v]);
        const cal_tier *t = cal_config_tier(c);
        assert_false(cal_tier_stiffness_on_drum(t));
        cal_bed_case b = cal_bed_case_make(c, t, 200, 1);
        exp_cylinder_def cyl = cal_cylinder_case_make(c, t, 200, 1);
        char bed_key[2048], cyl_key[2048];
        cal_bed_key(&b, bed_key, sizeof bed_key), cal_cylinder_key(&cyl, cyl_key, sizeof cyl_key);
        assert_string_equal(bed_key, cyl_key);
        cal_config_free(c);
    }
    remove_scratch(dir);
}

static void test_unknown_scene_refused(void **state)
{
    (void)state;
    char dir[1024], path[1100], err[1024];
    scratch(dir, sizeof dir, "stiffness_scene_bad");
    write_config(dir, "    stiffness_scene: barrel\n", path, sizeof path);
    cal_config *c = cal_config_load(path, "check", err, sizeof err);
    assert_null(c);
    printf("%s\n", err);
    assert_non_null(strstr(err, "stiffness_scene"));
    remove_scratch(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_cylinder_by_default),
                                       cmocka_unit_test(test_unknown_scene_refused),
                                       cmocka_unit_test(test_drum_bed_recorded_resumed_chosen)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
