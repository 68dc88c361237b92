// SPDX-License-Identifier: MIT
/// @file cal_plot.h
/// The calibration's figures as PNG, drawn with cairo: x–y charts (a log
/// axis where a quantity spans decades) and the map of the angle of repose
/// over the (μs, μr) plane with its iso-angle curve.
#ifndef CAL_PLOT_H
#define CAL_PLOT_H

#include <stddef.h>

enum { CAL_PLOT_MAX_SERIES = 12 };

typedef struct cal_series_xy {
    const char *label;
    const double *x, *y, *err; ///< err may be NULL (no error bars)
    int n;
    int lines, points;         ///< draw a polyline, markers, or both
    double r, g, b;
} cal_series_xy;

typedef struct cal_chart {
    const char *title, *xlabel, *ylabel;
    int log_x, log_y;
    cal_series_xy series[CAL_PLOT_MAX_SERIES];
    int n_series;
    double hline;              ///< a horizontal reference line, NAN for none
    const char *hline_label;
} cal_chart;

/// Write a chart to a PNG; 0 on success, else 1 with a message.
int cal_plot_chart(const char *path, const cal_chart *c, char *err, size_t len);

/// The angle over the (μs, log μr) plane: each evaluated point coloured by
/// its angle and labelled; the curve angle = target (marching squares over
/// the g×g grid of the first g² points, when g ≥ 2); points matching within
/// the tolerance ringed; the chosen point starred.
int cal_plot_angle_map(const char *path, const char *title, const double *mu_s, const double *mu_r,
                       const double *angle, int n, int grid, double target, double tolerance, int chosen,
                       double mu_s_lo, double mu_s_hi, double mu_r_lo, double mu_r_hi, char *err, size_t len);

#endif
