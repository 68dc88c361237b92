// SPDX-License-Identifier: MIT
// Line plots to PNG with cairo.
#include "exp_plot.h"

#include "dem_vec.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void exp_plot_colour(int k, double rgb[3])
{
    static const double palette[8][3] = {{0.12, 0.47, 0.71}, {0.84, 0.15, 0.16}, {0.17, 0.63, 0.17},
                                         {1.00, 0.50, 0.05}, {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29},
                                         {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50}};
    memcpy(rgb, palette[((k % 8) + 8) % 8], 3 * sizeof(double));
}

// A "nice" tick step of about range/6 (1, 2 or 5 times a power of ten).
static double tick_step(double range)
{
    double raw = range / 6.0, p = pow(10.0, floor(log10(raw))), f = raw / p;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

static void data_range(size_t ns, const exp_plot_series *s, int y, int log_y, double *lo, double *hi)
{
    *lo = INFINITY, *hi = -INFINITY;
    for (size_t k = 0; k < ns; ++k)
        for (size_t i = 0; i < s[k].n; ++i) {
            double v = y ? s[k].y[i] : s[k].x[i];
            if (!isfinite(v) || (y && log_y && v <= 0)) continue;
            if (y && log_y) v = log10(v);
            *lo = fmin(*lo, v), *hi = fmax(*hi, v);
        }
    if (!isfinite(*lo)) *lo = 0, *hi = 1;
    if (*hi <= *lo) *hi = *lo + (*lo != 0 ? fabs(*lo) * 0.1 : 1.0), *lo -= (*lo != 0 ? fabs(*lo) * 0.1 : 0.0);
    if (!(y && log_y)) {
        double pad = 0.04 * (*hi - *lo);
        *lo -= pad, *hi += pad;
    }
}

int exp_plot_png(const char *path, const exp_plot_axes *a, size_t ns, const exp_plot_series *s, int width, int height,
                 char *err, size_t len)
{
    double xlo = a->xlo, xhi = a->xhi, ylo = a->ylo, yhi = a->yhi;
    if (!(xlo < xhi)) data_range(ns, s, 0, 0, &xlo, &xhi);
    if (!(ylo < yhi)) data_range(ns, s, 1, a->log_y, &ylo, &yhi);
    else if (a->log_y) ylo = log10(ylo), yhi = log10(yhi);
    if (a->log_y) ylo = floor(ylo), yhi = ceil(yhi) > floor(ylo) ? ceil(yhi) : floor(ylo) + 1;
    cairo_surface_t *surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
    cairo_t *cr = cairo_create(surf);
    const double L = 90, R = 20, T = 40, B = 60, pw = width - L - R, ph = height - T - B;
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, 13);
#define PX(v) (L + ((v) - xlo) / (xhi - xlo) * pw)
#define PY(v) (T + ph - ((v) - ylo) / (yhi - ylo) * ph)
    cairo_text_extents_t te;
    char buf[64];
    cairo_set_line_width(cr, 1);
    // Ticks and grid.
    double xs = tick_step(xhi - xlo), ys = a->log_y ? 1.0 : tick_step(yhi - ylo);
    for (double v = ceil(xlo / xs) * xs; v <= xhi + 1e-9 * xs; v += xs) {
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
        cairo_move_to(cr, PX(v), T), cairo_line_to(cr, PX(v), T + ph), cairo_stroke(cr);
        snprintf(buf, sizeof buf, "%g", fabs(v) < 1e-12 * xs ? 0.0 : v);
        cairo_text_extents(cr, buf, &te);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, PX(v) - te.width / 2, T + ph + 18), cairo_show_text(cr, buf);
    }
    for (double v = ceil(ylo / ys) * ys; v <= yhi + 1e-9 * ys; v += ys) {
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
        cairo_move_to(cr, L, PY(v)), cairo_line_to(cr, L + pw, PY(v)), cairo_stroke(cr);
        if (a->log_y) snprintf(buf, sizeof buf, "1e%g", v);
        else snprintf(buf, sizeof buf, "%g", fabs(v) < 1e-12 * ys ? 0.0 : v);
        cairo_text_extents(cr, buf, &te);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, L - te.width - 6, PY(v) + 4), cairo_show_text(cr, buf);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, L, T, pw, ph), cairo_stroke(cr);
    // Labels and title.
    if (a->xlabel) {
        cairo_text_extents(cr, a->xlabel, &te);
        cairo_move_to(cr, L + pw / 2 - te.width / 2, height - 18), cairo_show_text(cr, a->xlabel);
    }
    if (a->ylabel) {
        cairo_save(cr);
        cairo_text_extents(cr, a->ylabel, &te);
        cairo_move_to(cr, 20, T + ph / 2 + te.width / 2), cairo_rotate(cr, -DEM_PI / 2), cairo_show_text(cr, a->ylabel);
        cairo_restore(cr);
    }
    if (a->title) {
        cairo_set_font_size(cr, 15);
        cairo_text_extents(cr, a->title, &te);
        cairo_move_to(cr, L + pw / 2 - te.width / 2, 24), cairo_show_text(cr, a->title);
        cairo_set_font_size(cr, 13);
    }
    // Curves, clipped to the plot area.
    cairo_save(cr);
    cairo_rectangle(cr, L, T, pw, ph), cairo_clip(cr);
    cairo_set_line_width(cr, 1.6);
    for (size_t k = 0; k < ns; ++k) {
        double dash = 6;
        cairo_set_dash(cr, &dash, s[k].dashed ? 1 : 0, 0);
        cairo_set_source_rgb(cr, s[k].rgb[0], s[k].rgb[1], s[k].rgb[2]);
        int pen = 0;
        for (size_t i = 0; i < s[k].n; ++i) {
            double y = s[k].y[i];
            if (a->log_y) y = y > 0 ? log10(y) : NAN;
            if (!isfinite(y) || !isfinite(s[k].x[i])) {
                if (pen) cairo_stroke(cr);
                pen = 0;
                continue;
            }
            if (pen) cairo_line_to(cr, PX(s[k].x[i]), PY(y));
            else cairo_move_to(cr, PX(s[k].x[i]), PY(y)), pen = 1;
        }
        if (pen) cairo_stroke(cr);
    }
    cairo_restore(cr);
    // Legend, top left inside the plot.
    double ly = T + 18;
    for (size_t k = 0; k < ns; ++k) {
        if (!s[k].label) continue;
        double dash = 6;
        cairo_set_dash(cr, &dash, s[k].dashed ? 1 : 0, 0);
        cairo_set_source_rgb(cr, s[k].rgb[0], s[k].rgb[1], s[k].rgb[2]);
        cairo_set_line_width(cr, 2);
        cairo_move_to(cr, L + 10, ly - 4), cairo_line_to(cr, L + 34, ly - 4), cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_move_to(cr, L + 40, ly), cairo_show_text(cr, s[k].label);
        ly += 17;
    }
#undef PX
#undef PY
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    cairo_status_t st = cairo_surface_write_to_png(surf, tmp);
    cairo_destroy(cr);
    cairo_surface_destroy(surf);
    if (st != CAIRO_STATUS_SUCCESS || rename(tmp, path) != 0) {
        snprintf(err, len, "cannot write '%s': %s", path, cairo_status_to_string(st));
        remove(tmp);
        return 1;
    }
    return 0;
}
