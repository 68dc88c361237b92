// SPDX-License-Identifier: MIT
// PNG figures with cairo (see cal_plot.h).
#include "cal_plot.h"
#include "cal_util.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "dem_vec.h"
#include "exp_common.h"

enum { W = 900, H = 620, LEFT = 90, RIGHT = 200, TOP = 50, BOTTOM = 70 };

typedef struct frame {
    double x0, x1, y0, y1;
    int log_x, log_y;
} frame;

static double tx(const frame *f, double x)
{
    double a = f->log_x ? log10(x) : x, lo = f->log_x ? log10(f->x0) : f->x0, hi = f->log_x ? log10(f->x1) : f->x1;
    return LEFT + (a - lo) / (hi - lo) * (W - LEFT - RIGHT);
}
static double ty(const frame *f, double y)
{
    double a = f->log_y ? log10(y) : y, lo = f->log_y ? log10(f->y0) : f->y0, hi = f->log_y ? log10(f->y1) : f->y1;
    return H - BOTTOM - (a - lo) / (hi - lo) * (H - TOP - BOTTOM);
}

static void text_at(cairo_t *cr, double x, double y, const char *s, double align, double size)
{
    cairo_text_extents_t e;
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - align * e.width, y);
    cairo_show_text(cr, s);
}

static void widen(double *lo, double *hi, int log)
{
    if (log) {
        *lo = pow(10, floor(log10(*lo))), *hi = pow(10, ceil(log10(*hi)));
        return;
    }
    double pad = *hi > *lo ? 0.08 * (*hi - *lo) : fmax(0.05 * fabs(*hi), 1e-3);
    *lo -= pad, *hi += pad;
}

static void axes(cairo_t *cr, const frame *f, const char *title, const char *xl, const char *yl)
{
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, LEFT, TOP, W - LEFT - RIGHT, H - TOP - BOTTOM);
    cairo_stroke(cr);
    char s[32];
    for (int axis = 0; axis < 2; ++axis) {
        int log = axis ? f->log_y : f->log_x;
        double lo = axis ? f->y0 : f->x0, hi = axis ? f->y1 : f->x1;
        int ticks = log ? (int)lround(log10(hi / lo)) : 5;
        for (int k = 0; k <= ticks; ++k) {
            double v = log ? lo * pow(10, k) : lo + (hi - lo) * k / ticks;
            if (v > hi * (1 + 1e-9)) break; // a log axis may end between decades
            snprintf(s, sizeof s, "%.3g", v);
            if (axis) {
                cairo_move_to(cr, LEFT - 5, ty(f, v)), cairo_line_to(cr, LEFT, ty(f, v));
                text_at(cr, LEFT - 8, ty(f, v) + 4, s, 1, 12);
            } else {
                cairo_move_to(cr, tx(f, v), H - BOTTOM), cairo_line_to(cr, tx(f, v), H - BOTTOM + 5);
                text_at(cr, tx(f, v), H - BOTTOM + 20, s, 0.5, 12);
            }
            cairo_stroke(cr);
        }
    }
    text_at(cr, (LEFT + W - RIGHT) / 2.0, 30, title, 0.5, 16);
    text_at(cr, (LEFT + W - RIGHT) / 2.0, H - 25, xl, 0.5, 14);
    cairo_save(cr);
    cairo_translate(cr, 25, (TOP + H - BOTTOM) / 2.0);
    cairo_rotate(cr, -DEM_PI / 2);
    text_at(cr, 0, 0, yl, 0.5, 14);
    cairo_restore(cr);
}

static int finish(cairo_surface_t *s, cairo_t *cr, const char *path, char *err, size_t len)
{
    cairo_destroy(cr);
    char tmp[1300];
    cal_temporary_name(path, tmp, sizeof tmp);
    cairo_status_t st = cairo_surface_write_to_png(s, tmp);
    cairo_surface_destroy(s);
    if (st != CAIRO_STATUS_SUCCESS || rename(tmp, path) != 0)
        return exp_fail(err, len, "%s: cannot write the PNG (%s)", path, cairo_status_to_string(st));
    return 0;
}

static void range_of(const cal_chart *c, frame *f)
{
    f->x0 = f->y0 = HUGE_VAL, f->x1 = f->y1 = -HUGE_VAL;
    for (int s = 0; s < c->n_series; ++s)
        for (int i = 0; i < c->series[s].n; ++i) {
            double x = c->series[s].x[i], y = c->series[s].y[i], e = c->series[s].err ? c->series[s].err[i] : 0;
            if (!isfinite(x) || !isfinite(y) || (c->log_x && x <= 0) || (c->log_y && y <= 0)) continue;
            f->x0 = fmin(f->x0, x), f->x1 = fmax(f->x1, x);
            f->y0 = fmin(f->y0, y - (isfinite(e) ? e : 0)), f->y1 = fmax(f->y1, y + (isfinite(e) ? e : 0));
        }
    if (isfinite(c->hline)) f->y0 = fmin(f->y0, c->hline), f->y1 = fmax(f->y1, c->hline);
    if (!isfinite(f->x0)) f->x0 = 0, f->x1 = 1, f->y0 = 0, f->y1 = 1;
    if (f->x1 == f->x0) f->x1 = f->x0 + 1;
    widen(&f->x0, &f->x1, c->log_x), widen(&f->y0, &f->y1, c->log_y);
    f->log_x = c->log_x, f->log_y = c->log_y;
}

static void draw_series(cairo_t *cr, const frame *f, const cal_series_xy *s, int index)
{
    cairo_set_source_rgb(cr, s->r, s->g, s->b);
    cairo_set_line_width(cr, 2);
    int pen = 0;
    for (int i = 0; i < s->n && s->lines; ++i) {
        if (!isfinite(s->y[i])) { pen = 0; continue; }
        if (pen) cairo_line_to(cr, tx(f, s->x[i]), ty(f, s->y[i]));
        else cairo_move_to(cr, tx(f, s->x[i]), ty(f, s->y[i])), pen = 1;
    }
    cairo_stroke(cr);
    for (int i = 0; i < s->n; ++i) {
        if (!isfinite(s->y[i])) continue;
        double px = tx(f, s->x[i]), py = ty(f, s->y[i]);
        if (s->points) cairo_arc(cr, px, py, 4, 0, 2 * DEM_PI), cairo_fill(cr);
        if (s->err && isfinite(s->err[i]) && s->err[i] > 0) {
            cairo_set_line_width(cr, 1);
            cairo_move_to(cr, px, ty(f, s->y[i] - s->err[i])), cairo_line_to(cr, px, ty(f, s->y[i] + s->err[i]));
            cairo_stroke(cr);
        }
    }
    double ly = TOP + 15 + 20 * index;
    cairo_rectangle(cr, W - RIGHT + 12, ly - 8, 14, 8), cairo_fill(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, W - RIGHT + 32, ly, s->label ? s->label : "", 0, 12);
}

int cal_plot_chart(const char *path, const cal_chart *c, char *err, size_t len)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    cairo_t *cr = cairo_create(s);
    frame f;
    range_of(c, &f);
    axes(cr, &f, c->title, c->xlabel, c->ylabel);
    if (isfinite(c->hline)) {
        double dash[] = {6, 4};
        cairo_set_dash(cr, dash, 2, 0);
        cairo_move_to(cr, LEFT, ty(&f, c->hline)), cairo_line_to(cr, W - RIGHT, ty(&f, c->hline));
        cairo_stroke(cr);
        cairo_set_dash(cr, NULL, 0, 0);
        if (c->hline_label) text_at(cr, W - RIGHT - 5, ty(&f, c->hline) - 5, c->hline_label, 1, 11);
    }
    for (int k = 0; k < c->n_series; ++k) draw_series(cr, &f, &c->series[k], k);
    return finish(s, cr, path, err, len);
}

// Blue (low) to red (high).
static void colour(cairo_t *cr, double t)
{
    t = fmin(1, fmax(0, t));
    cairo_set_source_rgb(cr, t, 0.2 + 0.5 * (1 - fabs(2 * t - 1)), 1 - t);
}

// Marching squares for angle = target over the grid points (first g*g, in
// i-major order: mu_s index i, mu_r index j).
static void iso_curve(cairo_t *cr, const frame *f, const double *xs, const double *ys, const double *a, int g, double target)
{
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2.5);
    for (int i = 0; i + 1 < g; ++i)
        for (int j = 0; j + 1 < g; ++j) {
            int id[4] = {i * g + j, (i + 1) * g + j, (i + 1) * g + j + 1, i * g + j + 1};
            double px[4], py[4];
            int m = 0;
            for (int e = 0; e < 4; ++e) {
                int p = id[e], q = id[(e + 1) % 4];
                double u = a[p] - target, v = a[q] - target;
                if (!isfinite(u) || !isfinite(v) || (u > 0) == (v > 0)) continue;
                double w = u / (u - v);
                px[m] = tx(f, xs[p] + w * (xs[q] - xs[p]));
                py[m] = ty(f, pow(10, log10(ys[p]) + w * (log10(ys[q]) - log10(ys[p]))));
                m++;
            }
            for (int e = 0; e + 1 < m; e += 2) cairo_move_to(cr, px[e], py[e]), cairo_line_to(cr, px[e + 1], py[e + 1]);
        }
    cairo_stroke(cr);
}

int cal_plot_angle_map(const char *path, const char *title, const double *mu_s, const double *mu_r,
                       const double *angle, int n, int grid, double target, double tolerance, int chosen,
                       double mu_s_lo, double mu_s_hi, double mu_r_lo, double mu_r_hi, char *err, size_t len)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, W, H);
    cairo_t *cr = cairo_create(s);
    frame f = {mu_s_lo, mu_s_hi, mu_r_lo, mu_r_hi, 0, 1};
    axes(cr, &f, title, "sliding friction mu_s", "rolling friction mu_r (log)");
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (int i = 0; i < n; ++i)
        if (isfinite(angle[i])) lo = fmin(lo, angle[i]), hi = fmax(hi, angle[i]);
    if (grid >= 2 && n >= grid * grid) iso_curve(cr, &f, mu_s, mu_r, angle, grid, target);
    char s_[48];
    for (int i = 0; i < n; ++i) {
        double px = tx(&f, mu_s[i]), py = ty(&f, mu_r[i]);
        if (!isfinite(angle[i])) {
            cairo_set_source_rgb(cr, 0.5, 0.5, 0.5);
            text_at(cr, px, py + 4, "x", 0.5, 14);
            continue;
        }
        colour(cr, hi > lo ? (angle[i] - lo) / (hi - lo) : 0.5);
        cairo_arc(cr, px, py, 7, 0, 2 * DEM_PI), cairo_fill(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        if (fabs(angle[i] - target) <= tolerance) cairo_arc(cr, px, py, 11, 0, 2 * DEM_PI), cairo_stroke(cr);
        if (i == chosen) text_at(cr, px, py - 14, "*", 0.5, 26);
        snprintf(s_, sizeof s_, "%.1f", angle[i]);
        text_at(cr, px + 10, py + 4, s_, 0, 10);
    }
    double ly = TOP + 15;
    const char *legend[] = {"colour: angle (blue low, red high)", "ring: matches the angle", "* chosen",
                            "black line: iso-angle (grid)"};
    cairo_set_source_rgb(cr, 0, 0, 0);
    for (int k = 0; k < 4; ++k) text_at(cr, W - RIGHT + 10, ly + 18 * k, legend[k], 0, 11);
    snprintf(s_, sizeof s_, "target %.2f ± %.2f deg", target, tolerance);
    text_at(cr, W - RIGHT + 10, ly + 18 * 4, s_, 0, 11);
    return finish(s, cr, path, err, len);
}
