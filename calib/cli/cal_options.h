// SPDX-License-Identifier: MIT
/// @file cal_options.h
/// The command line of every granucal command, read from one table per
/// command: each row an option's name, the kind of value it takes (with its
/// range), where the value goes and its help line. getopt_long reads the
/// command line; this module checks each value against its row, says what is
/// wrong in one line, and prints `--help` from the same rows, so an option
/// cannot exist without its help line or with a help that says another range.
#ifndef CAL_OPTIONS_H
#define CAL_OPTIONS_H

#include <stddef.h>

/// The value an option takes.
typedef enum cal_option_kind {
    CAL_OPT_FLAG,   ///< none: *flag = set_to
    CAL_OPT_INT,    ///< a whole number in [lo, hi]: *integer
    CAL_OPT_REAL,   ///< a number in the range lo, hi (lo_open: > lo): *real
    CAL_OPT_TEXT,   ///< a word or a path, taken as given: *text (the last given wins)
    CAL_OPT_CHOICE, ///< one word of choices (NULL-terminated): *text
    CAL_OPT_LIST,   ///< repeatable: each value appended to list, at most max (--set KEY=VALUE)
    CAL_OPT_CUSTOM, ///< read by parse(text, context), which returns non-zero on a bad value
} cal_option_kind;

/// One option of a command: a row of its table.
typedef struct cal_option {
    const char *name;  ///< "jobs": given as --jobs
    char short_name;   ///< 'o' for -o, or 0
    cal_option_kind kind;
    const char *value; ///< what the help shows after the name: "N", "DIR" (NULL for a flag)
    const char *help;  ///< the help line (wrapped to the terminal's 80 columns); required
    /// What a bad value should have been, after "expected": "a number of
    /// hours" (INT, REAL: the range follows) or "NAME=MU_S,MU_R, both > 0"
    /// (CUSTOM). NULL: "a whole number" or "a number".
    const char *expected;
    double lo, hi;     ///< INT, REAL: the range, both ends in (hi: INFINITY for none)
    int lo_open;       ///< REAL: lo itself is out (> lo)
    int set_to;        ///< FLAG: the value stored
    int *flag, *integer;
    double *real;
    const char **text;
    const char *const *choices;
    char **list;
    int *count, max; ///< LIST: values so far, and room in list
    int (*parse)(const char *text, void *context);
    void *context;
} cal_option;

/// A command's line: its options, its operands and its help around them.
typedef struct cal_command_line {
    const char *command;  ///< "calibrate", "study fidelity": in every message
    const char *synopsis; ///< the help before the option list (usage line, what it does)
    const char *epilogue; ///< the help after the option list, or NULL
    const cal_option *options;
    size_t n_options;
    const char *operand;  ///< "CONFIG.yaml", "PHOTO.png": named when missing
    int min_operands, max_operands; ///< max -1: any number
} cal_command_line;

/// Read argv[1..argc-1] against the command's table. Returns 0 with the
/// operands (the arguments that are not options, in order) in *operands and
/// *n_operands; -1 when --help was printed (exit 0); else 2, the exit status
/// of a usage error, after one line on stderr naming the option, the bad value
/// and what it should be.
int cal_options_parse(const cal_command_line *line, int argc, char **argv, char ***operands, int *n_operands);

/// The same for the commands on a calibration config (calibrate, study,
/// synthesize): `line`'s operand is at most one CONFIG.yaml, which replaces
/// *config (its default) when given.
int cal_options_parse_config(const cal_command_line *line, int argc, char **argv, const char **config);

/// The command's help: synopsis, the options from the table, epilogue.
void cal_options_print_help(const cal_command_line *line);

// ---- the options several commands share, defined once ---------------------------------

/// Simulations side by side on this machine: 1..1024 (default: cal_default_jobs).
cal_option cal_option_jobs(int *jobs);
/// The results folder; `help` says its default, which differs by command.
cal_option cal_option_out(const char **out, const char *help);
/// Wall seconds between a drum run's checkpoints, [0, 86400] (0: none).
cal_option cal_option_checkpoint_every(double *seconds, const char *help);
/// Hours, > 0; `help` says what the budget judges.
cal_option cal_option_budget_hours(double *hours, const char *help);
/// --plan: check the inputs, print the plan and stop; `help` says what it shows.
cal_option cal_option_plan(int *plan_only, const char *help);
/// --tier NAME: a fidelity tier of the config.
cal_option cal_option_tier(const char **tier, const char *help);

/// The default of --jobs: this machine's cores (1 if unknown).
int cal_default_jobs(void);

#endif
