// SPDX-License-Identifier: MIT
// A CSV file line by line through libcsv (see exp_csv.h).
#include "exp_csv.h"

#include <csv.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"

// A line being split: libcsv's callbacks fill the row, and each record it
// ends goes to the reader's on_row.
typedef struct splitting {
    exp_csv_row *row;
    exp_csv_on_row on_row;
    void *ctx;
    int stopped; ///< on_row returned nonzero
} splitting;

static void on_field(void *text, size_t n, void *data)
{
    exp_csv_row *r = ((splitting *)data)->row;
    if (r->n < EXP_CSV_MAX_FIELDS) {
        if (n >= EXP_CSV_FIELD_CHARS) r->too_long = 1, n = EXP_CSV_FIELD_CHARS - 1;
        memcpy(r->field[r->n], text ? text : "", n);
        r->field[r->n][n] = '\0';
    }
    r->n++;
}

static void clear_row(exp_csv_row *r)
{
    int at = r->line;
    memset(r, 0, sizeof *r);
    r->line = at;
}

// libcsv also ends a record at a lone CR (old Mac line ends), which getline
// does not: such a line holds several rows, each its own (same line number).
static void on_end(int terminator, void *data)
{
    (void)terminator;
    splitting *s = data;
    if (!s->stopped) s->stopped = s->on_row(s->row, s->ctx);
    clear_row(s->row);
}

static int blank_or_comment(const char *line, int *comment)
{
    while (*line == ' ' || *line == '\t' || *line == '\r') line++;
    *comment = *line == '#';
    return *comment || *line == '\n' || *line == '\0';
}

// One line through libcsv, each of its records to on_row; 0, or 1 with the
// message (written here, or by on_row when it stopped).
static int split(struct csv_parser *p, const char *path, const char *line, size_t n, splitting *s, char *err,
                 size_t len)
{
    int at = s->row->line;
    clear_row(s->row);
    if (csv_parse(p, line, n, on_field, on_end, s) != n)
        return exp_fail(err, len, "%s:%d: row: malformed CSV (%s)", path, at, csv_strerror(csv_error(p)));
    if (csv_fini(p, on_field, on_end, s) != 0) return exp_fail(err, len, "%s:%d: row: unterminated quoted field", path, at);
    return s->stopped;
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
    splitting s = {.row = r, .on_row = on_row, .ctx = ctx};
    while (!bad && (n = getline(&line, &cap, f)) > 0) {
        r->line++;
        // A NUL byte would end the line early for the C string checks (a line
        // starting with one read as blank) and cut a field short for strtod.
        if (memchr(line, '\0', (size_t)n))
            bad = exp_fail(err, len, "%s:%d: row: contains a NUL byte: not a text file", path, r->line);
        else if (blank_or_comment(line, &comment)) {
            if (comment && on_comment) on_comment(line, ctx);
        } else bad = split(&p, path, line, (size_t)n, &s, err, len);
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
