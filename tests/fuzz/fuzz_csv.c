// SPDX-License-Identifier: MIT
// libFuzzer target: the lab data loader (calib/inputs/cal_data.c, libcsv) on any
// bytes, read as a repose-angle file and as an occupied-area file.
// Invariant: cal_series_load either accepts the file, and then every point
// is a valid measurement (what the loader promises its callers), or refuses
// it with a non-empty message naming the file and leaves nothing allocated;
// never a crash, a leak or undefined behaviour (ASan, UBSan). A file with a
// NUL byte is not text: it must be refused, and so must a row whose field
// count differs from the header's (issue 26).
#include <math.h>
#include <string.h>
#include <strings.h>

#include "cal_data.h"
#include "fuzz_common.h"

static void check_accepted(const cal_series *s, cal_data_kind kind, const char *path)
{
    char detail[256];
    double hi = kind == CAL_DATA_ANGLE ? 90 : 100;
    if (strcmp(s->path, path) != 0) fuzz_violation("cal_series_load: path not recorded", s->path);
    if (s->count == 0 || !s->points) fuzz_violation("cal_series_load accepted a file without measurements", NULL);
    for (size_t k = 0; k < s->count; ++k) {
        const cal_point *p = &s->points[k];
        snprintf(detail, sizeof detail, "point %zu (line %d): '%.64s' rpm %g value %g sd %g", k, p->line, p->surface,
                 p->rpm, p->value, p->sd);
        if (!memchr(p->surface, '\0', sizeof p->surface) || !p->surface[0])
            fuzz_violation("accepted an empty or unterminated surface", detail);
        for (const char *c = p->surface; *c; ++c)
            if ((unsigned char)*c < 0x20 || *c == 0x7f) fuzz_violation("accepted a control character in a surface", detail);
        if (!(isfinite(p->rpm) && p->rpm > 0 && p->rpm <= 1000)) fuzz_violation("accepted an rpm outside (0, 1000]", detail);
        if (!(isfinite(p->value) && p->value > 0 && p->value <= hi)) fuzz_violation("accepted a value out of range", detail);
        if (!(isfinite(p->sd) && p->sd >= 0 && p->sd <= hi)) fuzz_violation("accepted a spread out of range", detail);
        // Non-decreasing, not increasing: libcsv also ends rows at a lone CR
        // (old Mac files), which getline does not count as a line.
        if (p->line < 1 || (k && p->line < s->points[k - 1].line)) fuzz_violation("line numbers out of order", detail);
        for (size_t j = 0; j < k; ++j)
            if (strcasecmp(s->points[j].surface, p->surface) == 0 && s->points[j].rpm == p->rpm)
                fuzz_violation("accepted a duplicate (surface, rpm)", detail);
    }
}

/// Independent of libcsv: in a file without quotes every row is its commas
/// plus one fields, so an accepted file must have exactly three commas on
/// every row (the header included). Rows as the loader sees them: a physical
/// line (to LF) that is blank or a '#' comment after leading blanks and CRs
/// is dropped whole, a CR inside it included; any other line goes to libcsv,
/// which also ends a row at a lone CR and skips a row of blanks.
static void check_row_commas(const uint8_t *data, size_t start, size_t end)
{
    size_t first = start;
    while (first < end && (data[first] == ' ' || data[first] == '\t')) first++;
    if (first == end) return;
    int commas = 0;
    for (size_t k = first; k < end; ++k) commas += data[k] == ',';
    if (commas != 3) {
        char detail[96];
        snprintf(detail, sizeof detail, "a row at byte %zu has %d fields", start, commas + 1);
        fuzz_violation("cal_series_load accepted a row whose field count is not the header's 4", detail);
    }
}

static void check_field_counts(const uint8_t *data, size_t size)
{
    if (memchr(data, '"', size)) return;
    size_t start = 0;
    while (start < size) {
        const uint8_t *lf = memchr(data + start, '\n', size - start);
        size_t end = lf ? (size_t)(lf - data) : size;
        size_t first = start;
        while (first < end && (data[first] == ' ' || data[first] == '\t' || data[first] == '\r')) first++;
        if (first < end && data[first] != '#')
            for (size_t row = start; row <= end;) {
                const uint8_t *cr = memchr(data + row, '\r', end - row);
                size_t row_end = cr ? (size_t)(cr - data) : end;
                check_row_commas(data, row, row_end);
                row = row_end + 1;
            }
        start = end + 1;
    }
}

static void load(const uint8_t *data, size_t size, const char *path, cal_data_kind kind, int has_nul)
{
    char err[2048];
    cal_series s;
    memset(err, 0, sizeof err);
    if (cal_series_load(&s, path, kind, err, sizeof err) == 0) {
        if (has_nul) fuzz_violation("cal_series_load accepted a file with a NUL byte", NULL);
        fuzz_report(kind == CAL_DATA_ANGLE ? "cal_series_load(angle)" : "cal_series_load(csa)", NULL);
        check_accepted(&s, kind, path);
        check_field_counts(data, size);
        cal_series_free(&s);
        if (s.points || s.count) fuzz_violation("cal_series_free left points behind", NULL);
        return;
    }
    fuzz_check_failure_message(kind == CAL_DATA_ANGLE ? "cal_series_load(angle)" : "cal_series_load(csa)", path, err);
    if (s.points || s.count) fuzz_violation("cal_series_load failed but kept points", err);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *path = fuzz_write_temp(data, size);
    int has_nul = size > 0 && memchr(data, '\0', size) != NULL;
    load(data, size, path, CAL_DATA_ANGLE, has_nul);
    load(data, size, path, CAL_DATA_CSA, has_nul);
    return 0;
}
