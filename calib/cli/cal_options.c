// SPDX-License-Identifier: MIT
// Every command's options from its table (cal_options.h): getopt_long reads
// the command line, each value is checked against its row, and --help is
// printed from the same rows.
#include "cal_options.h"

#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "exp_common.h"

enum { MAX_OPTIONS = 40, HELP_WIDTH = 80, MAX_LABEL = 24 };

int cal_default_jobs(void)
{
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    return cores > 0 ? (int)cores : 1;
}

cal_option cal_option_jobs(int *jobs)
{
    return (cal_option){.name = "jobs", .kind = CAL_OPT_INT, .integer = jobs, .lo = 1, .hi = 1024, .value = "N",
                        .help = "cores this run may use (default: all): simulations side by side, one thread each, "
                                "an idle core a thread of one that runs; two jobs on one machine: give each its share"};
}

cal_option cal_option_out(const char **out, const char *help)
{
    return (cal_option){.name = "out", .kind = CAL_OPT_TEXT, .text = out, .value = "DIR", .help = help};
}

cal_option cal_option_checkpoint_every(double *seconds, const char *help)
{
    return (cal_option){.name = "checkpoint-every", .kind = CAL_OPT_REAL, .real = seconds, .lo = 0, .hi = 86400,
                        .value = "S", .expected = "wall seconds", .help = help};
}

cal_option cal_option_budget_hours(double *hours, const char *help)
{
    return (cal_option){.name = "budget-hours", .kind = CAL_OPT_REAL, .real = hours, .lo = 0, .lo_open = 1,
                        .hi = INFINITY, .value = "H", .expected = "a number of hours", .help = help};
}

cal_option cal_option_plan(int *plan_only, const char *help)
{
    return (cal_option){.name = "plan", .kind = CAL_OPT_FLAG, .flag = plan_only, .set_to = 1, .help = help};
}

cal_option cal_option_tier(const char **tier, const char *help)
{
    return (cal_option){.name = "tier", .kind = CAL_OPT_TEXT, .text = tier, .value = "NAME", .help = help};
}

// ---- what a bad value should have been ----------------------------------------------

// "in 1..1024", "> 0", "in [0, 86400]": the range of an INT or REAL row.
static void describe_range(const cal_option *o, char *out, size_t len)
{
    if (o->kind == CAL_OPT_INT) snprintf(out, len, "in %.15g..%.15g", o->lo, o->hi);
    else if (isinf(o->hi)) snprintf(out, len, "%s %.15g", o->lo_open ? ">" : ">=", o->lo);
    else snprintf(out, len, "in %c%.15g, %.15g]", o->lo_open ? '(' : '[', o->lo, o->hi);
}

// "all, stiffness, granule or wall"
static void describe_choices(const char *const *choices, char *out, size_t len)
{
    out[0] = 0;
    for (int k = 0; choices[k]; ++k)
        snprintf(out + strlen(out), len - strlen(out), "%s%s", k == 0 ? "" : choices[k + 1] ? ", " : " or ", choices[k]);
}

static void describe_expected(const cal_option *o, char *out, size_t len)
{
    char range[96];
    switch (o->kind) {
    case CAL_OPT_INT:
    case CAL_OPT_REAL:
        describe_range(o, range, sizeof range);
        snprintf(out, len, "%s %s", o->expected ? o->expected : o->kind == CAL_OPT_INT ? "a whole number" : "a number",
                 range);
        break;
    case CAL_OPT_CHOICE: describe_choices(o->choices, out, len); break;
    default: snprintf(out, len, "%s", o->expected ? o->expected : "a value");
    }
}

static int bad_value(const cal_command_line *line, const cal_option *o, const char *text)
{
    char expected[512];
    describe_expected(o, expected, sizeof expected);
    fprintf(stderr, "granucal %s: --%s '%s': expected %s\n", line->command, o->name, text, expected);
    return 2;
}

// ---- reading one value ---------------------------------------------------------------

static int in_range(const cal_option *o, double v)
{
    if (o->kind == CAL_OPT_INT) return exp_integer_in(v, o->lo, o->hi);
    return (o->lo_open ? v > o->lo : v >= o->lo) && v <= o->hi;
}

static int is_choice(const cal_option *o, const char *text)
{
    for (int k = 0; o->choices[k]; ++k)
        if (strcmp(o->choices[k], text) == 0) return 1;
    return 0;
}

// Store the value of row o given as text; 0, else the exit status of a usage error.
static int take_value(const cal_command_line *line, const cal_option *o, char *text)
{
    double v;
    switch (o->kind) {
    case CAL_OPT_FLAG: *o->flag = o->set_to; return 0;
    case CAL_OPT_INT:
    case CAL_OPT_REAL:
        if (exp_parse_number(text, &v) || !in_range(o, v)) return bad_value(line, o, text);
        if (o->kind == CAL_OPT_INT) *o->integer = (int)v;
        else *o->real = v;
        return 0;
    case CAL_OPT_TEXT: *o->text = text; return 0;
    case CAL_OPT_CHOICE:
        if (!is_choice(o, text)) return bad_value(line, o, text);
        *o->text = text;
        return 0;
    case CAL_OPT_LIST:
        if (*o->count >= o->max)
            return fprintf(stderr, "granucal %s: --%s '%s': at most %d --%s options\n", line->command, o->name, text,
                           o->max, o->name), 2;
        o->list[(*o->count)++] = text;
        return 0;
    case CAL_OPT_CUSTOM: return o->parse(text, o->context) ? bad_value(line, o, text) : 0;
    }
    return 2;
}

// ---- getopt_long's view of the table -------------------------------------------------

// An option getopt_long refused (it returned '?' or ':'; opterr = 0 and the
// optstring starts with ':'): one line naming it and where the options are.
static int refused_option(const char *command, int code, char *const argv[])
{
    const char *arg = optind > 0 ? argv[optind - 1] : "";
    char shown[80];
    if (optopt > 0 && optopt < 128 && strncmp(arg, "--", 2) != 0) snprintf(shown, sizeof shown, "-%c", optopt);
    else snprintf(shown, sizeof shown, "%.*s", (int)strcspn(arg, "="), arg); // "--name=value": the name
    fprintf(stderr, "granucal %s: %s '%s'; see `granucal %s --help`\n", command,
            code == ':' ? "a value is missing after" : "unknown option", shown, command);
    return 2;
}

// A row without its help line, or a table too long, is the program's error:
// refused on every run, so that no test of the command passes with it.
static int check_table(const cal_command_line *line)
{
    if (line->n_options >= MAX_OPTIONS)
        return fprintf(stderr, "granucal %s: internal error: %zu options, room for %d\n", line->command,
                       line->n_options, MAX_OPTIONS - 1), 2;
    for (size_t k = 0; k < line->n_options; ++k)
        if (!line->options[k].name || !line->options[k].help || !line->options[k].help[0])
            return fprintf(stderr, "granucal %s: internal error: option %zu (--%s) has no help line\n", line->command, k,
                           line->options[k].name ? line->options[k].name : "?"), 2;
    return 0;
}

// getopt_long's table and short-option string; an option's code is 256 +
// its row (a short option comes back as its letter, found by row_of).
static void getopt_table(const cal_command_line *line, struct option *longs, char *shorts)
{
    char *s = shorts;
    *s++ = ':'; // a missing value returns ':', not '?'
    for (size_t k = 0; k < line->n_options; ++k) {
        const cal_option *o = &line->options[k];
        longs[k] = (struct option){o->name, o->kind == CAL_OPT_FLAG ? no_argument : required_argument, 0, 256 + (int)k};
        if (o->short_name) *s++ = o->short_name;
        if (o->short_name && o->kind != CAL_OPT_FLAG) *s++ = ':';
    }
    longs[line->n_options] = (struct option){"help", no_argument, 0, 'h'};
    longs[line->n_options + 1] = (struct option){0, 0, 0, 0};
    *s++ = 'h', *s = 0;
}

// The row getopt_long's code names, or -1 for one the table does not have.
static int row_of(const cal_command_line *line, int code)
{
    if (code >= 256) return code - 256;
    for (size_t k = 0; k < line->n_options; ++k)
        if (line->options[k].short_name == code) return (int)k;
    return -1;
}

static int check_operands(const cal_command_line *line, char **operands, int n)
{
    if (n < line->min_operands)
        return fprintf(stderr, "granucal %s: no %s given; see `granucal %s --help`\n", line->command, line->operand,
                       line->command), 2;
    if (line->max_operands >= 0 && n > line->max_operands)
        return fprintf(stderr, "granucal %s: unexpected argument '%s'; see `granucal %s --help`\n", line->command,
                       operands[line->max_operands], line->command), 2;
    return 0;
}

int cal_options_parse(const cal_command_line *line, int argc, char **argv, char ***operands, int *n_operands)
{
    struct option longs[MAX_OPTIONS + 1];
    char shorts[2 * MAX_OPTIONS + 3];
    int status = check_table(line);
    if (status) return status;
    getopt_table(line, longs, shorts);
    optind = 0, opterr = 0; // 0: glibc starts afresh, whatever argv an earlier parse read
    for (int code; (code = getopt_long(argc, argv, shorts, longs, NULL)) != -1;) {
        if (code == 'h') return cal_options_print_help(line), -1;
        int row = code == '?' || code == ':' ? -1 : row_of(line, code);
        if (row < 0) return refused_option(line->command, code, argv);
        if ((status = take_value(line, &line->options[row], optarg))) return status;
    }
    *operands = argv + optind, *n_operands = argc - optind;
    return check_operands(line, *operands, *n_operands);
}

int cal_options_parse_config(const cal_command_line *line, int argc, char **argv, const char **config)
{
    cal_command_line with_config = *line;
    with_config.operand = "CONFIG.yaml", with_config.min_operands = 0, with_config.max_operands = 1;
    char **operands;
    int n_operands, status = cal_options_parse(&with_config, argc, argv, &operands, &n_operands);
    if (!status && n_operands == 1) *config = operands[0];
    return status;
}

// ---- --help --------------------------------------------------------------------------

// "-o, --out DIR"
static void option_label(const cal_option *o, char *out, size_t len)
{
    char brief[8] = "";
    if (o->short_name) snprintf(brief, sizeof brief, "-%c, ", o->short_name);
    snprintf(out, len, "%s--%s%s%s", brief, o->name, o->value ? " " : "", o->value ? o->value : "");
}

// Print text from column `at` (already reached) wrapped at HELP_WIDTH, each
// further line indented to `indent`.
static void print_wrapped(const char *text, int at, int indent)
{
    int column = at;
    for (const char *p = text; *p;) {
        while (*p == ' ') ++p;
        int word = (int)strcspn(p, " ");
        if (word == 0) break;
        if (column > indent && column + 1 + word > HELP_WIDTH) printf("\n%*s", indent, ""), column = indent;
        else if (column > indent) putchar(' '), ++column;
        printf("%.*s", word, p);
        column += word, p += word;
    }
    putchar('\n');
}

static void print_option(const char *label, const char *help, int indent)
{
    printf("  %s", label);
    int column = 2 + (int)strlen(label);
    if (column + 2 > indent) printf("\n%*s", indent, ""), column = indent; // a long label: its help below
    else printf("%*s", indent - column, ""), column = indent;
    print_wrapped(help, column, indent);
}

void cal_options_print_help(const cal_command_line *line)
{
    char label[96];
    int widest = (int)strlen("-h, --help");
    for (size_t k = 0; k < line->n_options; ++k) {
        option_label(&line->options[k], label, sizeof label);
        int n = (int)strlen(label);
        if (n <= MAX_LABEL && n > widest) widest = n;
    }
    fputs(line->synopsis, stdout);
    fputs("\noptions:\n", stdout);
    for (size_t k = 0; k < line->n_options; ++k) {
        const cal_option *o = &line->options[k];
        char help[1536], expected[512];
        option_label(o, label, sizeof label);
        describe_expected(o, expected, sizeof expected);
        // The accepted values, from the row that checks them: the help cannot say another range.
        if (o->kind == CAL_OPT_INT || o->kind == CAL_OPT_REAL) snprintf(help, sizeof help, "%s; accepts %s", o->help, expected);
        else if (o->kind == CAL_OPT_CHOICE) snprintf(help, sizeof help, "%s; one of %s", o->help, expected);
        else snprintf(help, sizeof help, "%s", o->help);
        print_option(label, help, 2 + widest + 2);
    }
    print_option("-h, --help", "this text", 2 + widest + 2);
    if (line->epilogue) putchar('\n'), fputs(line->epilogue, stdout);
}
