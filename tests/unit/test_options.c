// SPDX-License-Identifier: MIT
// The command line of every granucal command (calib/cli/cal_options.c): each kind
// of value stored where its row says, a bad one refused in one line naming the
// option, the value and its range, and --help printed from the same rows.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>

#include "cal_options.h"
#include "capture_fd.h"

typedef struct values {
    int flag, whole, n_list;
    double real;
    const char *text, *choice;
    char *list[2];
    double pair[2];
} values;

// "A,B": two numbers.
static int take_pair(const char *text, void *context)
{
    double *pair = context;
    return sscanf(text, "%lf,%lf", &pair[0], &pair[1]) != 2;
}

static const char *const colours[] = {"red", "green", NULL};

// One row of each kind, the values going into v.
static size_t make_table(cal_option *t, values *v)
{
    size_t n = 0;
    t[n++] = (cal_option){.name = "flag", .short_name = 'f', .kind = CAL_OPT_FLAG, .flag = &v->flag, .set_to = 7,
                          .help = "a flag"};
    t[n++] = cal_option_jobs(&v->whole);
    t[n++] = cal_option_budget_hours(&v->real, "a budget");
    t[n++] = cal_option_out(&v->text, "a folder");
    t[n++] = (cal_option){.name = "colour", .kind = CAL_OPT_CHOICE, .text = &v->choice, .choices = colours,
                          .value = "C", .help = "a colour"};
    t[n++] = (cal_option){.name = "set", .kind = CAL_OPT_LIST, .list = v->list, .count = &v->n_list, .max = 2,
                          .value = "K=V", .help = "repeatable"};
    t[n++] = (cal_option){.name = "pair", .kind = CAL_OPT_CUSTOM, .parse = take_pair, .context = v->pair,
                          .value = "A,B", .expected = "A,B: two numbers", .help = "a pair"};
    return n;
}

// Parse argv (NULL-terminated) with the test table, what the parse writes to
// stdout or stderr (fd 1 or 2) into `said`; returns what the parse returned.
static int parse(values *v, char **argv, int fd, char *said, size_t len, char ***operands, int *n_operands)
{
    cal_option table[8];
    *v = (values){0};
    size_t n = make_table(table, v);
    cal_command_line line = {.command = "test", .synopsis = "usage: granucal test [options] FILE\n", .options = table,
                             .n_options = n, .operand = "FILE", .min_operands = 1, .max_operands = 2};
    int argc = 0;
    while (argv[argc]) ++argc;
    capture_fd capture;
    assert_int_equal(capture_begin(&capture, fd), 0);
    int status = cal_options_parse(&line, argc, argv, operands, n_operands);
    capture_end(&capture, said, len);
    return status;
}

static void test_every_kind_stored(void **state)
{
    (void)state;
    char *argv[] = {"test", "-f", "--jobs", "3", "--budget-hours=0.5", "--out", "dir", "--colour", "green", "a.yaml",
                    "--set", "k=1", "--set", "j=2", "--pair", "1.5,2", NULL};
    values v;
    char said[512], **operands;
    int n;
    assert_int_equal(parse(&v, argv, 2, said, sizeof said, &operands, &n), 0);
    assert_string_equal(said, "");
    assert_int_equal(v.flag, 7), assert_int_equal(v.whole, 3);
    assert_true(v.real == 0.5);
    assert_string_equal(v.text, "dir"), assert_string_equal(v.choice, "green");
    assert_int_equal(v.n_list, 2), assert_string_equal(v.list[0], "k=1"), assert_string_equal(v.list[1], "j=2");
    assert_true(v.pair[0] == 1.5 && v.pair[1] == 2);
    assert_int_equal(n, 1), assert_string_equal(operands[0], "a.yaml");
}

// argv (NULL-terminated) is refused: exit status 2 and exactly `line` on stderr.
static void assert_refused(char **argv, const char *line)
{
    values v;
    char said[512], **operands;
    int n;
    assert_int_equal(parse(&v, argv, 2, said, sizeof said, &operands, &n), 2);
    assert_string_equal(said, line);
}

// Each bad option after one operand: the one line it must print.
static void test_bad_values_refused_in_one_line(void **state)
{
    (void)state;
    static const struct {
        const char *args[6], *said;
    } cases[] = {
        {{"--jobs", "2.5"}, "granucal test: --jobs '2.5': expected a whole number in 1..1024\n"},
        {{"--budget-hours", "0"}, "granucal test: --budget-hours '0': expected a number of hours > 0\n"},
        {{"--colour", "blue"}, "granucal test: --colour 'blue': expected red or green\n"},
        {{"--pair", "1"}, "granucal test: --pair '1': expected A,B: two numbers\n"},
        {{"--set", "a", "--set", "b", "--set", "c"}, "granucal test: --set 'c': at most 2 --set options\n"},
        {{"--frobnicate"}, "granucal test: unknown option '--frobnicate'; see `granucal test --help`\n"},
        {{"--out"}, "granucal test: a value is missing after '--out'; see `granucal test --help`\n"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof *cases; ++k) {
        char *argv[9] = {"test", "file"};
        for (int j = 0; j < 6 && cases[k].args[j]; ++j) argv[2 + j] = (char *)cases[k].args[j];
        assert_refused(argv, cases[k].said);
    }
}

static void test_operands_counted(void **state)
{
    (void)state;
    assert_refused((char *[]){"test", "-f", NULL}, "granucal test: no FILE given; see `granucal test --help`\n");
    assert_refused((char *[]){"test", "a", "b", "c", NULL},
                   "granucal test: unexpected argument 'c'; see `granucal test --help`\n");
}

// --help: the synopsis, then every row with its value and its range, then -h.
static void test_help_from_the_table(void **state)
{
    (void)state;
    values v;
    char said[4096], **operands;
    int n;
    char *argv[] = {"test", "--help", NULL};
    assert_int_equal(parse(&v, argv, 1, said, sizeof said, &operands, &n), -1);
    assert_non_null(strstr(said, "usage: granucal test [options] FILE\n\noptions:\n"));
    assert_non_null(strstr(said, "  -f, --flag "));
    assert_non_null(strstr(said, "  --jobs N "));
    // A row's help wraps where its width falls: its words are checked with the wrapping undone.
    char flat[4096];
    size_t m = 0;
    for (const char *c = said; *c && m + 1 < sizeof flat; ++c)
        if (*c == '\n') {
            while (c[1] == ' ') ++c;
            if (m && flat[m - 1] != ' ') flat[m++] = ' ';
        } else flat[m++] = *c;
    flat[m] = '\0';
    assert_non_null(strstr(flat, "accepts a whole number in 1..1024"));
    assert_non_null(strstr(flat, "a budget; accepts a number of hours > 0"));
    assert_non_null(strstr(flat, "a colour; one of red or green"));
    assert_non_null(strstr(said, "  --pair A,B "));
    assert_non_null(strstr(said, "  -h, --help "));
    for (const char *line = said; *line; line = strchr(line, '\n') + 1) assert_true(strcspn(line, "\n") <= 80);
}

// A row without its help line fails every run of its command.
static void test_a_row_without_help_is_refused(void **state)
{
    (void)state;
    int whole = 0;
    cal_option table[] = {{.name = "seeds", .kind = CAL_OPT_INT, .integer = &whole, .lo = 1, .hi = 16}};
    cal_command_line line = {.command = "test", .synopsis = "", .options = table, .n_options = 1, .max_operands = -1};
    char *argv[] = {"test", "--seeds", "2", NULL}, **operands;
    int n;
    char said[512];
    capture_fd capture;
    assert_int_equal(capture_begin(&capture, 2), 0);
    int status = cal_options_parse(&line, 3, argv, &operands, &n);
    capture_end(&capture, said, sizeof said);
    assert_int_equal(status, 2);
    assert_int_equal(whole, 0);
    assert_non_null(strstr(said, "--seeds) has no help line")); // names the row at fault
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_every_kind_stored), cmocka_unit_test(test_bad_values_refused_in_one_line),
        cmocka_unit_test(test_operands_counted), cmocka_unit_test(test_help_from_the_table),
        cmocka_unit_test(test_a_row_without_help_is_refused)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
