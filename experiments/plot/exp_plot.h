// SPDX-License-Identifier: MIT
/// @file exp_plot.h
/// Every figure granucal draws, as PNG, drawn by PLplot through its pngcairo
/// device: charts of series on one pair of axes (lines, markers, error bars,
/// a name beside each point, a labelled horizontal reference line, log axes)
/// and filled maps of a quantity measured at scattered points of a plane.
/// PLplot chooses the ticks; every labelled series with a point to draw gets a
/// legend entry, an unlabelled or empty one none.
///
/// PLplot's state is process-global: each call begins and ends its figure, so
/// figures never interleave. Call from one thread only (never inside an
/// OpenMP region).
#ifndef EXP_PLOT_H
#define EXP_PLOT_H

#include <stddef.h>

/// How a series is drawn. The zero value is a line, so a series written as a
/// positional initialiser without the trailing fields stays a line.
typedef enum exp_plot_style {
    EXP_PLOT_LINE = 0,
    EXP_PLOT_POINTS,
    EXP_PLOT_LINE_POINTS,
    EXP_PLOT_HLINE, ///< a horizontal line across the whole x range at y[0] (n ≥ 1)
} exp_plot_style;

typedef enum exp_plot_marker {
    EXP_MARK_CIRCLE = 0,
    EXP_MARK_SQUARE,
    EXP_MARK_TRIANGLE,
    EXP_MARK_DIAMOND,
    EXP_MARK_STAR, ///< reserved by convention for what was chosen
    EXP_MARK_CROSS,
    EXP_MARK_OPEN_CIRCLE,
    EXP_MARK_OPEN_SQUARE,  ///< open markers are hollow on a chart (what lies under them, and a
    EXP_MARK_OPEN_DIAMOND, ///< bar shorter than the marker, show through) and white inside on a map
} exp_plot_marker;

/// One series: n points (x[k], y[k]); a non-finite value breaks the line and
/// is not marked.
typedef struct exp_plot_series {
    size_t n;
    const double *x, *y;
    const char *label; ///< legend text; NULL: drawn, but not in the legend
    double rgb[3];     ///< colour, components in [0, 1]
    int dashed;
    const double *err;         ///< y error bars y ± err[k], or NULL
    exp_plot_style style;
    exp_plot_marker marker;    ///< for POINTS and LINE_POINTS
    const char *const *names;  ///< text beside each point (NULL, or NULL entries: none)
    double dodge;              ///< drawn shifted sideways by this fraction of the x axis, so that
                               ///< series measured at the same x stay apart (0: none)
} exp_plot_series;

/// Axes of a chart; a range with lo >= hi is taken from the data (and the
/// error bars), padded; a range of one value is widened to ±10 % of it.
typedef struct exp_plot_axes {
    const char *title, *xlabel, *ylabel;
    const char *stamp; ///< what the figure is from (a run's tier, λ, data), small above the title; NULL: none
    double xlo, xhi, ylo, yhi;
    int log_y; ///< logarithmic y axis (non-positive values are skipped)
    int log_x; ///< logarithmic x axis (non-positive values are skipped)
} exp_plot_axes;

/// Write a PNG of `width` × `height` pixels with the series on one pair of
/// axes. Error bars are drawn over the markers; a series whose every bar is
/// shorter than its marker says so in its legend entry. Names beside points
/// are placed where they overlap no other name, no marker and stay inside the
/// axes (exp_plot_place_labels), joined to their point by a thin line when moved
/// off its row. 0 on success, else non-zero with a message naming the file.
int exp_plot_png(const char *path, const exp_plot_axes *axes, size_t n_series, const exp_plot_series *series,
                 int width, int height, char *err, size_t len);

/// A quantity z measured at n scattered points (x, y) of a rectangle, drawn
/// as a filled map: z interpolated linearly over the Delaunay triangulation of
/// the points (PLplot's plgriddata), left white outside their convex hull;
/// each point marked; two contour lines (a band, e.g. a target ± its
/// tolerance) drawn only where the map is filled; one point starred.
typedef struct exp_plot_map {
    const char *title, *xlabel, *ylabel, *zlabel; ///< zlabel: the colour bar's
    const char *stamp;                            ///< as exp_plot_axes.stamp
    size_t n;
    const double *x, *y, *z; ///< a non-finite z: a failed evaluation, marked by a cross
    double xlo, xhi, ylo, yhi; ///< the rectangle (the search's bounds)
    int log_y;                 ///< y on a log axis; the interpolation is in log y too
    double band_lo, band_hi;   ///< contour levels; non-finite: none
    const char *band_label;    ///< legend text of the band's lines
    const char *points_label;  ///< legend text of the markers
    long chosen;               ///< index of the starred point, or -1
    const char *chosen_label;  ///< legend text of the star
    const int *predicted;        ///< per point, 1: a value predicted, not measured (drawn as a grey
                                 ///< open diamond, in the fill); NULL: every point measured
    const char *predicted_label; ///< legend text of the predicted points
} exp_plot_map;

/// Write a map as a PNG of `width` × `height` pixels. The axes reach a little
/// past the rectangle (drawn dashed, "search bounds") so that a marker on its
/// edge is drawn whole. Where the band lies wholly outside the range of the
/// points' values its legend entry says "not reached" and gives that range.
/// 0 on success, else non-zero with a message naming the file.
int exp_plot_map_png(const char *path, const exp_plot_map *map, int width, int height, char *err, size_t len);

/// Whether the band [lo, hi] (a non-finite end: open on that side; both
/// non-finite: no band, 1) meets [min, max] of the finite values z[0..n);
/// writes that range (NAN, NAN where none is finite, and then returns 1).
int exp_plot_band_reached(double lo, double hi, size_t n, const double *z, double *zmin, double *zmax);

/// A box on the page, in mm.
typedef struct exp_plot_box {
    double x0, y0, x1, y1;
} exp_plot_box;

/// Places n labels, label k of w[k] × h mm, beside its point (px[k], py[k])
/// in an area [0, width] × [0, height] (mm) so that no label overlaps another,
/// nor any of the obstacles (the markers), nor leaves the area: for each label
/// in turn the first free place of right of the point, left of it, then rows
/// above and below, nearest first, on either side (`gap` mm from the point's
/// marker of half-size `mark`). Writes each label's box to out[k]; returns how
/// many found no free place (placed right of their point, where they may overlap).
size_t exp_plot_place_labels(size_t n, const double *px, const double *py, const double *w, double h, double mark,
                             double gap, size_t n_obstacles, const exp_plot_box *obstacles, double width,
                             double height, exp_plot_box *out);

/// The end of the event a series y(t) records: the first t from which y stays
/// within `tolerance` of its last value (t[n-1] where it never settles; NAN if
/// n == 0). An axis to a little past it shows the event, not the wait after it.
double exp_plot_settled_from(size_t n, const double *t, const double *y, double tolerance);

/// A corner plot of samples of two parameters (a posterior): the joint
/// scatter below left, each one's histogram beside it (x above, y to the
/// right), each median a solid line and its interval dashed, the search's
/// choice starred, and a note in the free corner. The axes are the prior's
/// support (the search's bounds).
typedef struct exp_plot_corner {
    const char *title, *xlabel, *ylabel;
    const char *stamp;         ///< as exp_plot_axes.stamp
    size_t n;
    const double *x, *y;       ///< the samples
    double xlo, xhi, ylo, yhi; ///< the axes: the support
    int log_y;                 ///< y (and its histogram) in log10
    double x_median, x_lo, x_hi, y_median, y_lo, y_hi;
    double chosen_x, chosen_y; ///< starred; non-finite: none
    const char *chosen_label;  ///< the star's legend text
    const char *note;          ///< text in the free corner ('\n' between lines), or NULL
} exp_plot_corner;

/// Write a corner plot as a PNG of `width` × `height` pixels. 0 on success,
/// else non-zero with a message naming the file.
int exp_plot_corner_png(const char *path, const exp_plot_corner *c, int width, int height, char *err, size_t len);

/// A colour of a small qualitative palette (k wraps around).
void exp_plot_colour(int k, double rgb[3]);

#endif
