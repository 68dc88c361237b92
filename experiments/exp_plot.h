// SPDX-License-Identifier: MIT
/// @file exp_plot.h
/// Line plots of measured curves (force–displacement, contacts and kinetic
/// energy over time) as PNG, drawn with cairo: axes with ticks, one colour
/// per series, a legend. Enough for a result to be looked at, no more.
#ifndef EXP_PLOT_H
#define EXP_PLOT_H

#include <stddef.h>

/// One curve: n points (x[k], y[k]); a NaN y breaks the line.
typedef struct exp_plot_series {
    size_t n;
    const double *x, *y;
    const char *label; ///< legend text, or NULL
    double rgb[3];     ///< colour, components in [0, 1]
    int dashed;
} exp_plot_series;

/// Axes of a plot; a range with lo >= hi is taken from the data.
typedef struct exp_plot_axes {
    const char *title, *xlabel, *ylabel;
    double xlo, xhi, ylo, yhi;
    int log_y; ///< logarithmic y axis (non-positive values are skipped)
} exp_plot_axes;

/// Write a PNG of `width` × `height` pixels with the series on one pair of
/// axes. 0 on success, else non-zero with a message naming the file.
int exp_plot_png(const char *path, const exp_plot_axes *axes, size_t n_series, const exp_plot_series *series,
                 int width, int height, char *err, size_t len);

/// A colour of a small qualitative palette (k wraps around).
void exp_plot_colour(int k, double rgb[3]);

#endif
