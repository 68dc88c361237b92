// SPDX-License-Identifier: MIT
// A scene's `--set KEY=VALUE` (exp_apply_set, the one home of the four scene
// loaders' overrides): numbers, whole numbers, refused keys, and the message
// for each bad value naming the key and listing the known keys.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "exp_common.h"

typedef struct scene {
    double k_n;
    int seed;
} scene;

static int apply(scene *s, const char *set, char *err, size_t len)
{
    const exp_set_key keys[] = {EXP_SET_NUMBER("k_n", &s->k_n), EXP_SET_INTEGER("seed", &s->seed),
                                EXP_SET_REFUSED("mu_r", "this scene has no rolling resistance")};
    return exp_apply_set(set, keys, sizeof keys / sizeof *keys, err, len);
}

static void expect_refused(const char *set, const char *needle)
{
    scene s = {200, 1};
    char err[256] = "";
    assert_int_equal(apply(&s, set, err, sizeof err), 1);
    printf("--set %s -> %s\n", set, err);
    if (!strstr(err, needle)) fail_msg("message '%s' lacks '%s'", err, needle);
    assert_true(s.k_n == 200 && s.seed == 1); // nothing set by a refused value
}

static void test_values_are_set(void **state)
{
    (void)state;
    scene s = {200, 1};
    char err[256] = "";
    assert_int_equal(apply(&s, "k_n=1e3", err, sizeof err), 0);
    assert_int_equal(apply(&s, "seed=7", err, sizeof err), 0);
    assert_true(s.k_n == 1000.0);
    assert_int_equal(s.seed, 7);
}

static void test_bad_values_are_named(void **state)
{
    (void)state;
    expect_refused("k_n=soft", "--set k_n: 'soft' is not a number");
    expect_refused("k_n=inf", "is not a number");
    expect_refused("seed=1.5", "--set seed: '1.5' is not a non-negative integer");
    expect_refused("seed=-1", "non-negative integer");
    expect_refused("seed=3e9", "non-negative integer");
    expect_refused("mu_r=0.1", "--set mu_r: this scene has no rolling resistance");
    expect_refused("k_n", "expected key=value");
}

static void test_unknown_key_lists_the_known_ones(void **state)
{
    (void)state;
    // The refused key is not offered as a known one.
    expect_refused("colour=red", "--set colour: unknown key (known: k_n, seed)");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_values_are_set),
        cmocka_unit_test(test_bad_values_are_named),
        cmocka_unit_test(test_unknown_key_lists_the_known_ones),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
