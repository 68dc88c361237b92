// SPDX-License-Identifier: MIT
/// @file exp_csv.h
/// A CSV file read the way granucal's inputs and outputs are written: one
/// row a line, so that every message names its line (a lone CR, as in old
/// Mac files, also ends a row, as libcsv reads it: such rows share a line); '#' comment lines and
/// blank lines skipped (each comment handed on, for provenance lines); each
/// line split by libcsv (its quoting and separators, strict: a stray quote
/// or a quote left open at the end of the line is an error). The schema
/// (which header, which fields, their values) stays with each reader.
#ifndef EXP_CSV_H
#define EXP_CSV_H

#include <stddef.h>

enum { EXP_CSV_MAX_FIELDS = 32, EXP_CSV_FIELD_CHARS = 256 };

/// One line's fields.
typedef struct exp_csv_row {
    int line;     ///< 1-based line number in the file
    int n;        ///< fields in the line, also those beyond EXP_CSV_MAX_FIELDS (not kept)
    int too_long; ///< a field was cut to EXP_CSV_FIELD_CHARS - 1 characters
    char field[EXP_CSV_MAX_FIELDS][EXP_CSV_FIELD_CHARS];
} exp_csv_row;

/// A row to the reader's schema: 0 to go on; nonzero to stop, with err
/// already written (the reader's own message, named by file and line).
typedef int (*exp_csv_on_row)(const exp_csv_row *row, void *ctx);
/// A comment line ('#' after optional blanks), as it stands; NULL: ignored.
typedef void (*exp_csv_on_comment)(const char *line, void *ctx);

/// Read path: each row to on_row, each comment to on_comment. 0 when every
/// line was read; 1 with err: the file cannot be opened ("PATH: cannot open:
/// why"), a line holds a NUL byte, libcsv finds it malformed or a quote left
/// open ("PATH:LINE: row: ..."), or on_row stopped.
int exp_csv_read(const char *path, exp_csv_on_row on_row, exp_csv_on_comment on_comment, void *ctx, char *err,
                 size_t len);

/// The index of the field named `name` in a header row, -1 if none.
int exp_csv_column(const exp_csv_row *header, const char *name);

#endif
