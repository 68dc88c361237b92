// SPDX-License-Identifier: MIT
// A measured size distribution table (CSV) read for dem_gsd_from_table; see
// exp_gsd_table.h for the format.
#include "exp_gsd_table.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_common.h"
#include "exp_csv.h"

static const char HEADER[] = "size_um,cumulative_percent";

typedef struct table_reader {
    const char *path;
    char *err;
    size_t len;
    int header_seen;
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

// A data row "size,percent" into the reader.
static int add_row(table_reader *r, const exp_csv_row *row)
{
    char *err = r->err;
    size_t len = r->len;
    int line = row->line;
    if (row->n != 2) return exp_fail(err, len, "%s:%d: row: expected 2 fields (%s)", r->path, line, HEADER);
    if (row->too_long) return exp_fail(err, len, "%s:%d: row: a field is longer than %d characters", r->path, line,
                                       EXP_CSV_FIELD_CHARS - 1);
    if (r->rows == DEM_GSD_TABLE_MAX_ROWS)
        return exp_fail(err, len, "%s:%d: row: more than %d rows", r->path, line, DEM_GSD_TABLE_MAX_ROWS);
    char size_text[EXP_CSV_FIELD_CHARS], percent_text[EXP_CSV_FIELD_CHARS];
    memcpy(size_text, row->field[0], sizeof size_text), memcpy(percent_text, row->field[1], sizeof percent_text);
    double size_um = 0, percent = 0;
    if (parse_number(r->path, line, "size_um", size_text, &size_um, err, len) ||
        parse_number(r->path, line, "cumulative_percent", percent_text, &percent, err, len))
        return 1;
    r->size_m[r->rows] = size_um * 1e-6, r->percent[r->rows] = percent, r->line_of[r->rows] = line;
    r->rows++;
    return 0;
}

static int is_header(const exp_csv_row *row)
{
    char a[EXP_CSV_FIELD_CHARS], b[EXP_CSV_FIELD_CHARS];
    memcpy(a, row->field[0], sizeof a), memcpy(b, row->field[1], sizeof b);
    return row->n == 2 && !strcmp(trim(a), "size_um") && !strcmp(trim(b), "cumulative_percent");
}

// exp_csv_on_row: the header first, then the data rows.
static int on_row(const exp_csv_row *row, void *ctx)
{
    table_reader *r = ctx;
    if (r->header_seen) return add_row(r, row);
    r->header_seen = is_header(row);
    return r->header_seen ? 0 : exp_fail(r->err, r->len, "%s:%d: header: expected %s", r->path, row->line, HEADER);
}

int exp_gsd_table_load(const char *path, const char *basis_name, dem_gsd *out, char *err, size_t len)
{
    dem_gsd_basis basis;
    if (exp_gsd_basis_from_name(basis_name, &basis))
        return exp_fail(err, len, "gsd_basis: '%s': say what the table counts: volume (laser diffraction, sieving) "
                                  "or number", basis_name ? basis_name : "(absent)");
    table_reader *r = calloc(1, sizeof *r);
    if (!r) return exp_fail(err, len, "out of memory");
    r->path = path, r->err = err, r->len = len;
    // exp_csv skips comments and blank lines and writes its own messages (the file, malformed CSV).
    int bad = exp_csv_read(path, on_row, NULL, r, err, len);
    if (!bad && !r->header_seen) bad = exp_fail(err, len, "%s: header: the file is empty (expected %s)", path, HEADER);
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
