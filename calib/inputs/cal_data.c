// SPDX-License-Identifier: MIT
// Lab data files: libcsv does the CSV grammar (quotes, separators); this
// file checks the schema and the values, and counts lines for messages.
#include "cal_data.h"

#include <csv.h>
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "exp_common.h"

enum { N_COLUMNS = 4 };

typedef struct reader {
    const char *path;
    cal_data_kind kind;
    char fields[N_COLUMNS][64];
    int n_fields, too_long, line, header_seen;
    cal_series *s;
    size_t cap;
    char *err;
    size_t len;
    int failed;
} reader;

static const char *const column_names[2][N_COLUMNS] = {
    {"surface", "rpm", "angle_deg", "angle_sd_deg"},
    {"surface", "rpm", "csa_percent", "csa_sd_percent"},
};

static void on_field(void *text, size_t n, void *ctx)
{
    reader *r = ctx;
    if (r->n_fields < N_COLUMNS) {
        if (n >= sizeof r->fields[0]) r->too_long = 1, n = sizeof r->fields[0] - 1;
        memcpy(r->fields[r->n_fields], text ? text : "", n);
        r->fields[r->n_fields][n] = '\0';
    }
    r->n_fields++;
}

static int fail_at(reader *r, const char *field, const char *fmt, const char *detail)
{
    char msg[256];
    snprintf(msg, sizeof msg, fmt, detail);
    r->failed = 1;
    return exp_fail(r->err, r->len, "%s:%d: %s: %s", r->path, r->line, field, msg);
}

static int parse_value(reader *r, int column, double lo, double hi, int lo_open, double *out)
{
    const char *text = r->fields[column], *name = column_names[r->kind][column];
    char *end;
    errno = 0;
    double v = strtod(text, &end);
    while (*end == ' ') end++;
    if (!*text || end == text || *end || errno) return fail_at(r, name, "'%s' is not a number", text);
    if (!isfinite(v)) return fail_at(r, name, "'%s' is not a finite number", text);
    if (v > hi || v < lo || (lo_open && v == lo)) {
        char range[96];
        snprintf(range, sizeof range, "%g is outside %s%g, %g]", v, lo_open ? "(" : "[", lo, hi);
        return fail_at(r, name, "%s", range);
    }
    *out = v;
    return 0;
}

static void check_header(reader *r)
{
    for (int c = 0; c < N_COLUMNS; ++c)
        if (strcmp(r->fields[c], column_names[r->kind][c]) != 0) {
            char want[128];
            snprintf(want, sizeof want, "expected the header %s,%s,%s,%s", column_names[r->kind][0],
                     column_names[r->kind][1], column_names[r->kind][2], column_names[r->kind][3]);
            fail_at(r, "header", "%s", want);
            return;
        }
    r->header_seen = 1;
}

static void add_point(reader *r)
{
    cal_point p = {.line = r->line};
    if (!r->fields[0][0]) return (void)fail_at(r, "surface", "%s", "empty");
    // A quoted field may span lines in CSV, not in this schema (and a '#'
    // line inside it would have been dropped as a comment).
    for (const char *c = r->fields[0]; *c; ++c)
        if (iscntrl((unsigned char)*c))
            return (void)fail_at(r, "surface", "%s", "holds a line break or a control character");
    snprintf(p.surface, sizeof p.surface, "%s", r->fields[0]);
    double hi = r->kind == CAL_DATA_ANGLE ? 90 : 100;
    if (parse_value(r, 1, 0, 1000, 1, &p.rpm) || parse_value(r, 2, 0, hi, 1, &p.value) ||
        parse_value(r, 3, 0, hi, 0, &p.sd))
        return;
    for (size_t k = 0; k < r->s->count; ++k)
        if (strcasecmp(r->s->points[k].surface, p.surface) == 0 && r->s->points[k].rpm == p.rpm) {
            char dup[160];
            snprintf(dup, sizeof dup, "%s at %g rpm already given on line %d", p.surface, p.rpm, r->s->points[k].line);
            return (void)fail_at(r, "surface", "%s", dup);
        }
    if (r->s->count == r->cap) {
        size_t cap = r->cap ? 2 * r->cap : 16;
        cal_point *grown = realloc(r->s->points, cap * sizeof *grown);
        if (!grown) return (void)fail_at(r, "row", "%s", "out of memory");
        r->s->points = grown, r->cap = cap;
    }
    r->s->points[r->s->count++] = p;
}

static void on_row(int terminator, void *ctx)
{
    (void)terminator;
    reader *r = ctx;
    if (r->failed) return;
    if (!r->header_seen) {
        if (r->n_fields != N_COLUMNS) r->fields[0][0] = '\0'; // not the header, whatever its fields
        check_header(r);
    } else if (r->n_fields != N_COLUMNS) {
        char n[32];
        snprintf(n, sizeof n, "%d", r->n_fields);
        fail_at(r, "row", "has %s fields, expected 4", n);
    } else if (r->too_long) fail_at(r, "row", "%s", "a field is longer than 63 characters");
    else add_point(r);
    r->n_fields = 0, r->too_long = 0;
}

static int blank_or_comment(const char *line)
{
    while (*line == ' ' || *line == '\t' || *line == '\r') line++;
    return *line == '#' || *line == '\n' || *line == '\0';
}

// A comment line that says the numbers are synthetic, and at what lambda.
static void read_provenance(const char *line, cal_series *s)
{
    if (!strstr(line, "SYNTHETIC")) return;
    s->synthetic = 1;
    const char *at = strstr(line, "lambda ");
    char *end = NULL;
    double lambda = at ? strtod(at + 7, &end) : NAN;
    if (at && end != at + 7 && lambda > 0 && !isfinite(s->synthetic_lambda)) s->synthetic_lambda = lambda;
}

int cal_series_load(cal_series *s, const char *path, cal_data_kind kind, char *err, size_t len)
{
    memset(s, 0, sizeof *s);
    snprintf(s->path, sizeof s->path, "%s", path);
    s->synthetic_lambda = NAN;
    FILE *f = fopen(path, "r");
    if (!f) return exp_fail(err, len, "%s: cannot open: %s", path, strerror(errno));
    struct csv_parser p;
    csv_init(&p, CSV_STRICT | CSV_APPEND_NULL | CSV_STRICT_FINI);
    reader r = {.path = path, .kind = kind, .s = s, .err = err, .len = len};
    char *line = NULL;
    size_t cap = 0;
    ssize_t n;
    // One physical line at a time so every row knows its line number; a
    // quoted newline inside a field is not part of this schema.
    while (!r.failed && (n = getline(&line, &cap, f)) > 0) {
        r.line++;
        // A NUL byte would end the line early for the C string checks (a line
        // starting with one read as blank) and cut a field short for strtod.
        if (memchr(line, '\0', (size_t)n)) {
            fail_at(&r, "row", "%s", "contains a NUL byte: not a text file");
            break;
        }
        if (blank_or_comment(line)) {
            read_provenance(line, s);
            continue;
        }
        if (csv_parse(&p, line, (size_t)n, on_field, on_row, &r) != (size_t)n && !r.failed)
            fail_at(&r, "row", "malformed CSV (%s)", csv_strerror(csv_error(&p)));
        if (!r.failed && line[n - 1] != '\n') csv_fini(&p, on_field, on_row, &r);
    }
    if (!r.failed && csv_fini(&p, on_field, on_row, &r) != 0) fail_at(&r, "row", "%s", "unterminated quoted field");
    free(line);
    csv_free(&p);
    fclose(f);
    if (!r.failed && !r.header_seen) r.line = 1, fail_at(&r, "header", "%s", "the file is empty (no header row)");
    if (!r.failed && s->count == 0) fail_at(&r, "row", "%s", "no measurements after the header");
    if (r.failed) cal_series_free(s);
    return r.failed;
}

void cal_series_free(cal_series *s)
{
    free(s->points);
    s->points = NULL, s->count = 0;
}

size_t cal_series_select(const cal_series *s, const char *surface, const cal_point **out, size_t cap)
{
    size_t n = 0;
    for (size_t k = 0; k < s->count && n < cap; ++k)
        if (strcasecmp(s->points[k].surface, surface) == 0) out[n++] = &s->points[k];
    return n;
}
