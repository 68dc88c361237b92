// SPDX-License-Identifier: MIT
// YAML loading with located errors (see exp_yaml.h).
#include "exp_yaml.h"

#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "exp_common.h"

typedef struct log_capture {
    char problem[256]; ///< the first error libcyaml reported
    char field[64];    ///< innermost field of the backtrace
    int line;          ///< its line
} log_capture;

static void chomp(char *s)
{
    size_t n = strlen(s);
    while (n && (s[n - 1] == '\n' || s[n - 1] == ' ')) s[--n] = '\0';
}

// libcyaml logs "Load: <problem>", then "Load: Backtrace:", then lines
// "  in mapping field 'x' (line: L, column: C)" from the innermost out.
static void capture(cyaml_log_t level, void *ctx, const char *fmt, va_list args)
{
    log_capture *c = ctx;
    char text[256];
    if (level < CYAML_LOG_ERROR) return;
    vsnprintf(text, sizeof text, fmt, args);
    chomp(text);
    const char *body = strncmp(text, "Load: ", 6) == 0 ? text + 6 : text;
    if (strstr(body, "Backtrace:") == body) return;
    if (!c->problem[0]) {
        snprintf(c->problem, sizeof c->problem, "%s", body);
        return;
    }
    int line = 0;
    const char *at = strstr(body, "(line: ");
    if (at && c->line == 0 && sscanf(at, "(line: %d", &line) == 1) {
        c->line = line;
        const char *q = strchr(body, '\'');
        const char *q2 = q ? strchr(q + 1, '\'') : NULL;
        if (q && q2 && q2 - q - 1 < (long)sizeof c->field) snprintf(c->field, sizeof c->field, "%.*s", (int)(q2 - q - 1), q + 1);
    }
}

static const cyaml_config_t quiet = {.log_fn = NULL, .mem_fn = cyaml_mem, .log_level = CYAML_LOG_ERROR};

int exp_yaml_load(const char *path, const cyaml_schema_value_t *schema, void **out, const char *hint, char *err,
                  size_t len)
{
    FILE *f = fopen(path, "r");
    if (!f) return exp_fail(err, len, "%s: cannot open: %s", path, strerror(errno));
    fclose(f);
    log_capture c = {{0}, {0}, 0};
    cyaml_config_t cfg = {.log_fn = capture, .log_ctx = &c, .mem_fn = cyaml_mem, .log_level = CYAML_LOG_ERROR};
    *out = NULL;
    cyaml_err_t e = cyaml_load_file(path, &cfg, schema, (cyaml_data_t **)out, NULL);
    // An empty document (no bytes, only comments) loads as CYAML_OK and NULL.
    if (e == CYAML_OK && !*out) {
        if (hint) return exp_fail(err, len, "%s: no YAML document in the file (%s)", path, hint);
        return exp_fail(err, len, "%s: no YAML document in the file", path);
    }
    if (e == CYAML_OK) return 0;
    const char *why = c.problem[0] ? c.problem : cyaml_strerror(e);
    // An unknown key is reported against its enclosing mapping; find the key's own line.
    char key[64] = {0};
    if (sscanf(why, "Unexpected key: %63s", key) == 1) {
        int line = exp_yaml_line_of(path, key, 1);
        if (line > 0) c.line = line;
        snprintf(c.field, sizeof c.field, "%s", key);
    }
    char where[96] = "";
    if (c.line > 0) snprintf(where, sizeof where, "%d: ", c.line);
    if (c.field[0]) snprintf(where + strlen(where), sizeof where - strlen(where), "%s: ", c.field);
    if (hint) return exp_fail(err, len, "%s:%s%s (%s)", path, where, why, hint);
    return exp_fail(err, len, "%s:%s%s", path, where, why);
}

void exp_yaml_free(const cyaml_schema_value_t *schema, void *data)
{
    if (data) cyaml_free(&quiet, schema, data, 0);
}

int exp_yaml_starts_with(const char *path, const char *first)
{
    FILE *f = fopen(path, "r");
    char line[256];
    int yes = 0;
    while (f && fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n') continue;
        yes = strncmp(line, first, strlen(first)) == 0;
        break;
    }
    if (f) fclose(f);
    return yes;
}

int exp_yaml_line_of(const char *path, const char *key, int from_line)
{
    FILE *f = fopen(path, "r");
    if (!f) return 0;
    char line[1024], pattern[80];
    snprintf(pattern, sizeof pattern, "%s:", key);
    int n = 0, found = 0;
    while (!found && fgets(line, sizeof line, f)) {
        ++n;
        char *hit = n >= from_line ? strstr(line, pattern) : NULL;
        if (hit && (hit == line || strchr(" \t{,-", hit[-1]))) found = n;
    }
    fclose(f);
    return found;
}

int exp_field_error(const char *path, int n_sets, char *const *sets, const char *field, const char *msg, char *err,
                    size_t len)
{
    size_t n = strlen(field);
    for (int k = n_sets - 1; k >= 0; --k)
        if (strncmp(sets[k], field, n) == 0 && sets[k][n] == '=')
            return exp_fail(err, len, "%s: --set %s: %s", path, sets[k], msg);
    int line = exp_yaml_line_of(path, field, 1);
    if (line > 0) return exp_fail(err, len, "%s:%d: %s: %s", path, line, field, msg);
    return exp_fail(err, len, "%s: %s: %s", path, field, msg);
}

const char *exp_message_field(const char *msg, char field[EXP_FIELD_LEN])
{
    size_t n = strcspn(msg, " =:");
    snprintf(field, EXP_FIELD_LEN, "%.*s", (int)(n < EXP_FIELD_LEN ? n : EXP_FIELD_LEN - 1), msg);
    const char *leaf = strrchr(field, '.');
    return leaf ? leaf + 1 : field;
}

int exp_seed_check(const char *path, int seed, char *err, size_t len)
{
    if (seed >= 0) return 0;
    char msg[64];
    snprintf(msg, sizeof msg, "seed = %d: must be >= 0", seed);
    return exp_field_error(path, 0, NULL, "seed", msg, err, len);
}
