// SPDX-License-Identifier: MIT
// A CSV file line by line through libcsv (see exp_csv.h).
#include "exp_csv.h"

#include <csv.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"

static void on_field(void *text, size_t n, void *ctx)
{
    exp_csv_row *r = ctx;
    if (r->n < EXP_CSV_MAX_FIELDS) {
        if (n >= EXP_CSV_FIELD_CHARS) r->too_long = 1, n = EXP_CSV_FIELD_CHARS - 1;
        memcpy(r->field[r->n], text ? text : "", n);
        r->field[r->n][n] = '\0';
    }
    r->n++;
}

static void on_end(int terminator, void *ctx) { (void)terminator, (void)ctx; }

static int blank_or_comment(const char *line, int *comment)
{
    while (*line == ' ' || *line == '\t' || *line == '\r') line++;
    *comment = *line == '#';
    return *comment || *line == '\n' || *line == '\0';
}

// One line split into r; 0, or 1 with the message.
static int split(struct csv_parser *p, const char *path, const char *line, size_t n, exp_csv_row *r, char *err,
                 size_t len)
{
    int at = r->line;
    memset(r, 0, sizeof *r);
    r->line = at;
    if (csv_parse(p, line, n, on_field, on_end, r) != n)
        return exp_fail(err, len, "%s:%d: row: malformed CSV (%s)", path, at, csv_strerror(csv_error(p)));
    if (csv_fini(p, on_field, on_end, r) != 0) return exp_fail(err, len, "%s:%d: row: unterminated quoted field", path, at);
    return 0;
}

int exp_csv_read(const char *path, exp_csv_on_row on_row, exp_csv_on_comment on_comment, void *ctx, char *err,
                 size_t len)
{
    FILE *f = fopen(path, "r");
    if (!f) return exp_fail(err, len, "%s: cannot open: %s", path, strerror(errno));
    exp_csv_row *r = calloc(1, sizeof *r);
    struct csv_parser p;
    if (!r || csv_init(&p, CSV_STRICT | CSV_APPEND_NULL | CSV_STRICT_FINI) != 0)
        return fclose(f), free(r), exp_fail(err, len, "out of memory");
    char *line = NULL;
    size_t cap = 0;
    ssize_t n;
    int bad = 0, comment;
    while (!bad && (n = getline(&line, &cap, f)) > 0) {
        r->line++;
        // A NUL byte would end the line early for the C string checks (a line
        // starting with one read as blank) and cut a field short for strtod.
        if (memchr(line, '\0', (size_t)n))
            bad = exp_fail(err, len, "%s:%d: row: contains a NUL byte: not a text file", path, r->line);
        else if (blank_or_comment(line, &comment)) {
            if (comment && on_comment) on_comment(line, ctx);
        } else bad = split(&p, path, line, (size_t)n, r, err, len) || on_row(r, ctx);
    }
    free(line), csv_free(&p), fclose(f), free(r);
    return bad;
}

int exp_csv_column(const exp_csv_row *header, const char *name)
{
    for (int k = 0; k < header->n && k < EXP_CSV_MAX_FIELDS; ++k)
        if (strcmp(header->field[k], name) == 0) return k;
    return -1;
}
