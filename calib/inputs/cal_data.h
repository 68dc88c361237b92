// SPDX-License-Identifier: MIT
/// @file cal_data.h
/// The lab measurements a calibration fits, read with libcsv and validated
/// row by row before any simulation starts:
///   repose_angle.csv   surface,rpm,angle_deg,angle_sd_deg   (Table 2)
///   occupied_area.csv  surface,rpm,csa_percent,csa_sd_percent (eq. 20)
/// Lines starting with '#' are comments (provenance, units). A comment line
/// holding the word SYNTHETIC (as `granucal synthesize` writes) marks the
/// file as simulated, not measured: every output then says so.
#ifndef CAL_DATA_H
#define CAL_DATA_H

#include <stddef.h>

/// One measurement: a value and its spread at one speed on one drum lining.
typedef struct cal_point {
    char surface[64]; ///< drum lining as the file names it ("PTFE", "spray-dried powder")
    double rpm, value, sd;
    int line;         ///< line in the file, for messages
} cal_point;

typedef struct cal_series {
    char path[1024];
    cal_point *points;
    size_t count;
    int synthetic;    ///< 1 if a comment line says SYNTHETIC: simulated data, not the lab's
    double synthetic_lambda; ///< the scale factor "lambda N" a SYNTHETIC line names (NAN: none)
} cal_series;

/// What a figure says of a data file's numbers (cal_series.synthetic and
/// synthetic_lambda), kept with the stage's result.
typedef struct cal_provenance {
    int synthetic;
    double lambda; ///< NAN: not named
} cal_provenance;

typedef enum cal_data_kind { CAL_DATA_ANGLE, CAL_DATA_CSA } cal_data_kind;

/// Read and validate a file of `kind`; on error a message naming the file,
/// line and field, and 1.
int cal_series_load(cal_series *s, const char *path, cal_data_kind kind, char *err, size_t len);
void cal_series_free(cal_series *s);

/// The points of one surface (case-insensitive match), in file order;
/// returns how many were written to `out` (at most cap).
size_t cal_series_select(const cal_series *s, const char *surface, const cal_point **out, size_t cap);

#endif
