// SPDX-License-Identifier: MIT
/// @file exp_photo.h
/// Measuring a real photograph of the drum face (`granucal measure`): the
/// same two numbers the simulation's raster gives (eq. 20 CSA, the dynamic
/// angle of repose), by a path that survives what real photographs have and
/// rendered drums do not: a dark rim or end-plate ring and a surround around
/// the drum, a circle given a few pixels off (or not given at all), pores and
/// texture in the powder, uneven lighting, compression noise.
///
/// The simulation keeps its own path (exp_face_measure.h): calibrations and
/// studies store results that depend on it bit for bit.
#ifndef EXP_PHOTO_H
#define EXP_PHOTO_H

#include <stddef.h>

/// A greyscale photograph, 0..255, row-major, image y downwards.
typedef struct exp_gray {
    int w, h;
    float *v;
} exp_gray;

/// Read any PNG as grey (libpng's conversion); NULL with a message naming
/// the file.
exp_gray *exp_gray_read_png(const char *path, char *err, size_t len);
void exp_gray_free(exp_gray *g);

/// A Gaussian blur of `sigma` pixels (edges clamped); NULL on out-of-memory.
exp_gray *exp_gray_smooth(const exp_gray *g, double sigma);

/// The drum's inner circle in image pixels (y downwards).
typedef struct exp_circle {
    double cx, cy, r;
    double support; ///< fraction of the rays from the centre that see an edge on this circle
} exp_circle;

/// Find the drum with no hint: the centre where the image's edges point
/// (a Hough transform along each edge's gradient), the strongest circle
/// about it, then exp_photo_refine_circle inwards from it (a rim has two
/// edges; the drum is the inner one). 0, or 1 with a message.
int exp_photo_find_drum(const exp_gray *g, exp_circle *out, char *err, size_t len);

/// Move a circle onto the drum's inner edge near it: within `inward` and
/// `outward` pixels of its radius and `shift` pixels of its centre, the
/// innermost circle that edges along at least a quarter of the rays from
/// its centre lie on, fitted through them (GSL robust least squares).
/// 0, or 1 with a message when no such circle is there.
int exp_photo_refine_circle(const exp_gray *g, exp_circle *c, double inward, double outward, double shift, char *err,
                            size_t len);

/// Which grey level the powder has.
typedef enum exp_powder_tone {
    EXP_POWDER_AUTO = 0, ///< whichever class lies lower in the drum (gravity)
    EXP_POWDER_DARK = 1,
    EXP_POWDER_LIGHT = 2,
} exp_powder_tone;

typedef struct exp_photo_opts {
    exp_powder_tone tone;
    int closing_px;          ///< disc closing the powder's pores (3)
    double central_fraction; ///< of the surface's width the line is fitted to (0.6, as the simulation)
    double max_sd_fraction;  ///< refuse a surface whose robust spread about the line exceeds this·R (0.04)
} exp_photo_opts;

exp_photo_opts exp_default_photo_opts(void);

/// What one photograph gave. The angle is that of the fitted line to the
/// horizontal, counter-clockwise positive, as the simulation's.
typedef struct exp_photo_result {
    exp_circle circle;
    int powder_dark;
    double csa_percent;
    double angle_deg;
    double surface_sd_px; ///< robust spread of the traced surface about the line
    int surface_points;
    double line_c0, line_c1;  ///< the line y = c0 + c1·x, drum coordinates in pixels, y up
    double fit_x0, fit_x1;    ///< the horizontal range it was fitted over
    unsigned char *label;     ///< w·h: 0 outside the drum, 1 empty, 2 powder, 3 surface point used
    exp_gray *photo;
} exp_photo_result;

/// Status of exp_photo_measure.
enum { EXP_PHOTO_OK = 0, EXP_PHOTO_ERROR = 1, EXP_PHOTO_NO_SURFACE = 2 };

/// Measure one photograph. `given` NULL: find the drum; else the circle is
/// refined within a few percent of it. EXP_PHOTO_NO_SURFACE: the circle
/// and the CSA are measured but there is no straight free surface (the
/// message says why). `out` must be freed either way but on EXP_PHOTO_ERROR.
int exp_photo_measure(const char *path, const exp_circle *given, const exp_photo_opts *o, exp_photo_result *out,
                      char *err, size_t len);
void exp_photo_result_free(exp_photo_result *r);

/// The photograph dimmed, the powder tinted, the circle in red, the traced
/// surface points in blue and the fitted line in green; an RGB PNG.
int exp_photo_write_mask(const char *path, const exp_photo_result *r, char *err, size_t len);

#endif
