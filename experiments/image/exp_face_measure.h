// SPDX-License-Identifier: MIT
/// @file exp_face_measure.h
/// What the lab measures on a drum photograph, done the same way on a
/// simulated drum: the granules projected along the drum axis onto a pixel
/// image of the drum face, closed (to fill the pores between granules, as a
/// photo of a powder shows no pores) and binarised; then
///  - the occupied cross-section area, eq. 20: occupied pixels over pixels
///    inside the drum circle, in %;
///  - the dynamic angle of repose: the angle between the horizontal and a
///    straight line fitted to the free surface over its central part.
#ifndef EXP_FACE_MEASURE_H
#define EXP_FACE_MEASURE_H

#include <stddef.h>

/// A binary image of the drum face; pixel (i, j) covers x in
/// [x0 + i·pixel, x0 + (i+1)·pixel), y likewise, y upwards.
typedef struct exp_raster {
    int nx, ny;
    double x0, y0, pixel;
    unsigned char *occupied; ///< nx·ny, row-major from the bottom row
} exp_raster;

/// An empty raster covering the drum circle of `radius` centred at the
/// origin, with square pixels of `pixel` metres. NULL on bad input.
exp_raster *exp_raster_create(double radius, double pixel);
void exp_raster_free(exp_raster *r);

/// Mark every pixel whose centre lies inside a disc (x, y, radius).
void exp_raster_paint_discs(exp_raster *r, size_t n, const double *x, const double *y, const double *radius);

/// Morphological closing (dilation then erosion) with a disc of
/// `radius_px` pixels: fills pores and gaps narrower than about 2·radius_px.
int exp_raster_close(exp_raster *r, int radius_px);

/// The same closing on the part x0 <= x < x1, y0 <= y < y1 of a row-major
/// mask of width × height bytes (0 or 1): pixels outside that part are
/// neither read nor changed (a photo's drum box, exp_photo.c). Nothing
/// happens for radius_px <= 0; non-zero if out of memory.
int exp_mask_close(unsigned char *mask, int width, int height, int x0, int y0, int x1, int y1, int radius_px);

/// Eq. 20: occupied pixels inside the drum circle over all pixels inside
/// it, in %.
double exp_raster_csa_percent(const exp_raster *r, double drum_radius);

/// Result of the free-surface fit.
typedef struct exp_angle {
    double angle_deg;    ///< angle of the fitted line to the horizontal, counter-clockwise positive
    double residual_sd;  ///< spread of the surface about the line, m
    int columns;         ///< pixel columns used in the fit
} exp_angle;

/// Fit a line to the free surface: in each pixel column of the central
/// `central_fraction` of the surface's horizontal extent, the top of the
/// highest occupied run; a least-squares line through those points (GSL).
/// Returns non-zero if fewer than 3 columns are usable.
int exp_raster_surface_angle(const exp_raster *r, double drum_radius, double central_fraction, exp_angle *out);

#endif
