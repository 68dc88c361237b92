// SPDX-License-Identifier: MIT
// Lab data files: exp_csv (libcsv) reads the lines and does the CSV grammar
// (quotes, separators); this file checks the schema and the values.
#include "cal_data.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "exp_common.h"
#include "exp_csv.h"

enum { N_COLUMNS = 4, FIELD_CHARS = 64 };

typedef struct reader {
    const char *path;
    cal_data_kind kind;
    const exp_csv_row *row; ///< the row being read
    int line, header_seen;
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

static int fail_at(reader *r, const char *field, const char *fmt, const char *detail)
{
    char msg[256];
    snprintf(msg, sizeof msg, fmt, detail);
    r->failed = 1;
    return exp_fail(r->err, r->len, "%s:%d: %s: %s", r->path, r->line, field, msg);
}

static int parse_value(reader *r, int column, double lo, double hi, int lo_open, double *out)
{
    const char *text = r->row->field[column], *name = column_names[r->kind][column];
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
        if (r->row->n != N_COLUMNS || strcmp(r->row->field[c], column_names[r->kind][c]) != 0) {
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
    const char *surface = r->row->field[0];
    if (!surface[0]) return (void)fail_at(r, "surface", "%s", "empty");
    // A quoted field may span lines in CSV, not in this schema (and a '#'
    // line inside it would have been dropped as a comment).
    for (const char *c = surface; *c; ++c)
        if (iscntrl((unsigned char)*c))
            return (void)fail_at(r, "surface", "%s", "holds a line break or a control character");
    snprintf(p.surface, sizeof p.surface, "%.63s", surface); // too_long refused longer
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

// A field longer than this schema allows.
static int too_long(const exp_csv_row *row)
{
    if (row->too_long) return 1;
    for (int c = 0; c < N_COLUMNS; ++c)
        if (strlen(row->field[c]) >= FIELD_CHARS) return 1;
    return 0;
}

static int on_row(const exp_csv_row *row, void *ctx)
{
    reader *r = ctx;
    r->row = row, r->line = row->line;
    if (!r->header_seen) check_header(r);
    else if (row->n != N_COLUMNS) {
        char n[32];
        snprintf(n, sizeof n, "%d", row->n);
        fail_at(r, "row", "has %s fields, expected 4", n);
    } else if (too_long(row)) fail_at(r, "row", "%s", "a field is longer than 63 characters");
    else add_point(r);
    return r->failed;
}

// A comment line that says the numbers are synthetic, and at what lambda.
static void read_provenance(const char *line, void *ctx)
{
    cal_series *s = ((reader *)ctx)->s;
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
    reader r = {.path = path, .kind = kind, .s = s, .err = err, .len = len};
    // exp_csv writes its own messages (the file, a NUL byte, malformed CSV) and stops on ours.
    if (exp_csv_read(path, on_row, read_provenance, &r, err, len)) r.failed = 1;
    else if (!r.header_seen) r.line = 1, fail_at(&r, "header", "%s", "the file is empty (no header row)");
    else if (s->count == 0) fail_at(&r, "row", "%s", "no measurements after the header");
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
