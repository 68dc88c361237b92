// SPDX-License-Identifier: MIT
// A measured size distribution table (CSV) read for dem_gsd_from_table; see
// exp_gsd_table.h for the format.
#include "exp_gsd_table.h"

#include <csv.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"

static const char HEADER[] = "size_um,cumulative_percent";

typedef struct table_reader {
    const char *path;
    int rows;
    double size_m[DEM_GSD_TABLE_MAX_ROWS], percent[DEM_GSD_TABLE_MAX_ROWS];
    int line_of[DEM_GSD_TABLE_MAX_ROWS]; ///< file line of each row, for messages
} table_reader;

int exp_gsd_basis_from_name(const char *name, dem_gsd_basis *out)
{
    if (name && strcmp(name, "volume") == 0) return *out = DEM_GSD_VOLUME, 0;
    if (name && strcmp(name, "number") == 0) return *out = DEM_GSD_NUMBER, 0;
    return 1;
}

static char *trim(char *s)
{
    while (*s == ' ' || *s == '\t') s++;
    char *end = s + strlen(s);
    while (end > s && (end[-1] == ' ' || end[-1] == '\t' || end[-1] == '\r' || end[-1] == '\n')) *--end = '\0';
    return s;
}

// One number field; 1 (with the message) if it is not one.
static int parse_number(const char *path, int line, const char *field, char *text, double *out, char *err, size_t len)
{
    char *t = trim(text), *end;
    errno = 0;
    double v = strtod(t, &end);
    if (!*t || *end || errno || !isfinite(v))
        return exp_fail(err, len, "%s:%d: %s: '%s' is not a finite number", path, line, field, t);
    *out = v;
    return 0;
}

// The fields of one line as libcsv splits it (quoting and all), at most
// MAX_FIELDS kept; n counts them all.
enum { MAX_FIELDS = 3, FIELD_CHARS = 64 };
typedef struct line_fields {
    int n;
    char text[MAX_FIELDS][FIELD_CHARS];
} line_fields;

static void on_field(void *s, size_t len, void *data)
{
    line_fields *l = data;
    if (l->n < MAX_FIELDS) snprintf(l->text[l->n], FIELD_CHARS, "%.*s", (int)len, s ? (const char *)s : "");
    l->n++;
}

static void on_row(int c, void *data) { (void)c, (void)data; }

// One line's fields (one line is one row in this schema); 1 if libcsv finds it malformed.
static int split_line(struct csv_parser *p, const char *line, line_fields *l)
{
    memset(l, 0, sizeof *l);
    return csv_parse(p, line, strlen(line), on_field, on_row, l) != strlen(line) ||
           csv_fini(p, on_field, on_row, l) != 0;
}

// A data row "size,percent" into the reader.
static int add_row(table_reader *r, int line, line_fields *l, char *err, size_t len)
{
    if (l->n != 2) return exp_fail(err, len, "%s:%d: row: expected 2 fields (%s)", r->path, line, HEADER);
    if (r->rows == DEM_GSD_TABLE_MAX_ROWS)
        return exp_fail(err, len, "%s:%d: row: more than %d rows", r->path, line, DEM_GSD_TABLE_MAX_ROWS);
    double size_um = 0, percent = 0;
    if (parse_number(r->path, line, "size_um", l->text[0], &size_um, err, len) ||
        parse_number(r->path, line, "cumulative_percent", l->text[1], &percent, err, len))
        return 1;
    r->size_m[r->rows] = size_um * 1e-6, r->percent[r->rows] = percent, r->line_of[r->rows] = line;
    r->rows++;
    return 0;
}

static int is_header(line_fields *l)
{
    return l->n == 2 && !strcmp(trim(l->text[0]), "size_um") && !strcmp(trim(l->text[1]), "cumulative_percent");
}

// Line by line (so that every message names its line), comments and blank
// lines skipped, each line split by libcsv.
static int read_rows(FILE *f, table_reader *r, char *err, size_t len)
{
    char text[256];
    int line = 0, header_seen = 0, bad = 0;
    struct csv_parser p;
    csv_init(&p, CSV_STRICT | CSV_APPEND_NULL | CSV_STRICT_FINI);
    while (!bad && fgets(text, sizeof text, f)) {
        line++;
        if (!strchr(text, '\n') && !feof(f))
            bad = exp_fail(err, len, "%s:%d: row: longer than %zu characters", r->path, line, sizeof text - 2);
        char *t = trim(text);
        if (bad || *t == '#' || *t == '\0') continue;
        line_fields l;
        if (split_line(&p, t, &l))
            bad = exp_fail(err, len, "%s:%d: row: malformed CSV (%s)", r->path, line, csv_strerror(csv_error(&p)));
        else if (!header_seen) {
            header_seen = is_header(&l);
            if (!header_seen) bad = exp_fail(err, len, "%s:%d: header: expected %s", r->path, line, HEADER);
        } else bad = add_row(r, line, &l, err, len);
    }
    csv_free(&p);
    if (!bad && !header_seen) return exp_fail(err, len, "%s: header: the file is empty (expected %s)", r->path, HEADER);
    return bad;
}

int exp_gsd_table_load(const char *path, const char *basis_name, dem_gsd *out, char *err, size_t len)
{
    dem_gsd_basis basis;
    if (exp_gsd_basis_from_name(basis_name, &basis))
        return exp_fail(err, len, "gsd_basis: '%s': say what the table counts: volume (laser diffraction, sieving) "
                                  "or number", basis_name ? basis_name : "(absent)");
    table_reader *r = calloc(1, sizeof *r);
    if (!r) return exp_fail(err, len, "out of memory");
    r->path = path;
    FILE *f = fopen(path, "r");
    if (!f) {
        free(r);
        return exp_fail(err, len, "%s: cannot open: %s", path, strerror(errno));
    }
    int bad = read_rows(f, r, err, len);
    fclose(f);
    char msg[300];
    int row = -1;
    if (!bad && dem_gsd_from_table(r->size_m, r->percent, r->rows, basis, out, &row, msg, sizeof msg)) {
        bad = 1;
        if (row >= 0) exp_fail(err, len, "%s:%d: %s", path, r->line_of[row], msg);
        else exp_fail(err, len, "%s: %s", path, msg);
    }
    free(r);
    return bad;
}
