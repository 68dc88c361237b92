// SPDX-License-Identifier: MIT
// Figures as PNG, drawn by PLplot's pngcairo device (see exp_plot.h).
#ifndef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L // gethostname, getpid: also when compiled alone (compare_silo.sh)
#endif
#include "exp_plot.h"

#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <plplot.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

// The module stands alone (tests/peers/compare_silo.sh compiles it with one
// program): its own message helper rather than exp_common's.
__attribute__((format(printf, 3, 4))) static int fail(char *err, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
    return 1;
}

#ifdef __SANITIZE_ADDRESS__
// fontconfig, which cairo asks for the text's fonts, keeps its configuration
// and font cache for the life of the process and never frees them: not a leak
// of ours. LeakSanitizer reads this hook in every binary that can draw a figure.
const char *__lsan_default_suppressions(void);
const char *__lsan_default_suppressions(void)
{
    return "leak:libfontconfig.so\n";
}
#endif

void exp_plot_colour(int k, double rgb[3])
{
    static const double palette[8][3] = {{0.12, 0.47, 0.71}, {0.84, 0.15, 0.16}, {0.17, 0.63, 0.17},
                                         {1.00, 0.50, 0.05}, {0.58, 0.40, 0.74}, {0.55, 0.34, 0.29},
                                         {0.89, 0.47, 0.76}, {0.50, 0.50, 0.50}};
    memcpy(rgb, palette[((k % 8) + 8) % 8], 3 * sizeof(double));
}

// ---- one figure: begun and ended in one call -------------------------------------

// Character scales: axis text, the title, and the small text (legend, point
// names, colour bar), relative to a character height of TEXT_MM.
static const double TEXT = 1.0, TITLE = 1.25, SMALL = 0.9, TEXT_MM = 5.0;

// PLplot scales its default character with the page; granucal's text keeps
// one size in pixels whatever the figure's size (set per figure).
static double text_base = 1;

static void text_size(double scale)
{
    plschr(0, text_base * scale);
}

// cmap0 slots: 0 background, 1 ink, 2 grid, 3 white, then one per series.
enum { INK = 1, GRID_GREY = 2, WHITE = 3, FIRST_SERIES_COLOUR = 4, N_COLOURS = 64 };

typedef struct figure {
    const char *path;
    char tmp[1300];
    char plplot_error[256]; ///< PLplot's first complaint during the figure ("" if none)
} figure;

// PLplot reports recoverable errors through its abort handler, a process-wide
// function pointer: this records the first one of the figure being drawn.
static figure *drawing;

static void record_plplot_error(const char *message)
{
    if (drawing && !drawing->plplot_error[0])
        snprintf(drawing->plplot_error, sizeof drawing->plplot_error, "%s", message);
}

// Without the driver plinit would ask on stdin for another device: check first.
static int have_pngcairo(void)
{
    enum { MAX_DEVICES = 128 };
    const char *menu_storage[MAX_DEVICES], *name_storage[MAX_DEVICES];
    const char **menu = menu_storage, **names = name_storage;
    int n = MAX_DEVICES; // in: room in the arrays; out: devices listed
    plgDevs(&menu, &names, &n);
    for (int k = 0; k < n; ++k)
        if (!strcmp(names[k], "pngcairo")) return 1;
    return 0;
}

// Our own temporary, opened here so that an unwritable path is an error we
// report (PLplot would prompt for another name, then exit). Named as
// calib's atomic files are (path.host.pid.tmp): a sweep of a dead run's
// temporaries finds these too.
static int open_temporary(figure *f, FILE **out, char *err, size_t len)
{
    char host[64] = "host";
    gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = 0;
    snprintf(f->tmp, sizeof f->tmp, "%s.%s.%ld.tmp", f->path, host, (long)getpid());
    *out = fopen(f->tmp, "wb");
    if (!*out) return fail(err, len, "%s: cannot write the plot (%s)", f->path, strerror(errno));
    return 0;
}

static int begin_figure(figure *f, const char *path, int width, int height, char *err, size_t len)
{
    memset(f, 0, sizeof *f);
    f->path = path;
    if (!have_pngcairo())
        return fail(err, len, "%s: PLplot has no pngcairo device (install plplot-driver-cairo)", path);
    FILE *png = NULL;
    if (open_temporary(f, &png, err, len)) return 1;
    PLINT stream;
    plmkstrm(&stream);
    plsdev("pngcairo");
    plsfile(png); // PLplot closes it at plend1
    plspage(0, 0, width, height, 0, 0);
    plscmap0n(N_COLOURS);
    plscolbg(255, 255, 255);
    drawing = f;
    plsabort(record_plplot_error);
    plinit();
    plscol0(INK, 0, 0, 0);
    plscol0(GRID_GREY, 225, 225, 225);
    plscol0(WHITE, 255, 255, 255);
    pladv(0);
    PLFLT def, ht;
    plgchr(&def, &ht);
    text_base = TEXT_MM / def;
    text_size(TEXT);
    return 0;
}

static int is_png(const char *path)
{
    static const unsigned char signature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8] = {0};
    FILE *f = fopen(path, "rb");
    size_t got = f ? fread(head, 1, sizeof head, f) : 0;
    if (f) fclose(f);
    return got == sizeof head && !memcmp(head, signature, sizeof head);
}

static int end_figure(figure *f, char *err, size_t len)
{
    plend1();
    plsabort(NULL);
    drawing = NULL;
    int rc = 0;
    if (f->plplot_error[0]) rc = fail(err, len, "%s: PLplot: %s", f->path, f->plplot_error);
    else if (!is_png(f->tmp)) rc = fail(err, len, "%s: PLplot wrote no PNG (disk full?)", f->path);
    else if (rename(f->tmp, f->path) != 0)
        rc = fail(err, len, "%s: cannot write the plot (%s)", f->path, strerror(errno));
    if (rc) remove(f->tmp);
    return rc;
}

static void set_colour(int slot, const double rgb[3])
{
    plscol0(slot, (PLINT)lround(255 * fmin(1, fmax(0, rgb[0]))), (PLINT)lround(255 * fmin(1, fmax(0, rgb[1]))),
            (PLINT)lround(255 * fmin(1, fmax(0, rgb[2]))));
}

static int series_colour(size_t k)
{
    return FIRST_SERIES_COLOUR + (int)(k % (N_COLOURS - FIRST_SERIES_COLOUR));
}

// ---- layout -----------------------------------------------------------------------

// The page in mm and the character height in mm (after plinit and pladv).
typedef struct page {
    double width, height, char_mm;
} page;

static page page_size(void)
{
    PLFLT x0, x1, y0, y1, def, ht;
    plgspa(&x0, &x1, &y0, &y1);
    plgchr(&def, &ht);
    return (page){x1 - x0, y1 - y0, ht};
}

// Width in mm of the widest of n strings (NULL ones skipped) at a character
// height of char_mm. PLplot 5.15 exports no string measure, so this counts
// code points at DejaVu Sans' mean advance as cairo draws PLplot's character
// (0.72 of its height: 17 characters of a rung's name measured 155 px at 14 px).
static double widest_text(size_t n, const char *const *text, double char_mm)
{
    size_t widest = 0;
    for (size_t k = 0; k < n; ++k) {
        size_t points = 0;
        for (const unsigned char *c = (const unsigned char *)text[k]; c && *c; ++c) points += (*c & 0xC0) != 0x80;
        if (points > widest) widest = points;
    }
    return 0.72 * char_mm * (double)widest;
}

// Characters of the widest y tick label granucal wrote itself in the last
// frame (a narrow log axis: label_narrow_log_axis), 0 where PLplot wrote them.
static int own_y_label_chars;

// Where the y label goes (in character heights from the axis): clear of the
// widest tick label of the last frame (PLplot's: plgyax gives its characters;
// a digit is about 0.85 of the character height wide at this font).
static double ylabel_offset(void)
{
    PLINT digmax = 0, digits = 0;
    plgyax(&digmax, &digits);
    int chars = digits > own_y_label_chars ? digits : own_y_label_chars;
    return fmin(7.0, fmax(5.0, 0.7 + 0.85 * chars + 0.9));
}

// Room above the viewport: the title's, and a stamp's line above it.
static double top_margin_chars(const char *stamp) { return stamp ? 5.0 : 3.2; }

// What the figure is from, small and at the left above the title (the
// current viewport's top): a figure copied alone still says it.
static void stamp_line(const char *stamp)
{
    if (!stamp) return;
    plcol0(INK);
    text_size(SMALL);
    plmtex("t", 3.4, 0.0, 0.0, stamp);
    text_size(TEXT);
}

static void title_and_labels(const char *title, const char *stamp, const char *xlabel, const char *ylabel)
{
    plcol0(INK);
    if (xlabel) plmtex("b", 3.2, 0.5, 0.5, xlabel);
    if (ylabel) plmtex("l", ylabel_offset(), 0.5, 0.5, ylabel);
    if (title) {
        text_size(TITLE);
        plmtex("t", 1.2, 0.5, 0.5, title);
        text_size(TEXT);
    }
    stamp_line(stamp);
}

// Grey grid lines at the major ticks, under what is drawn next.
static void grid_lines(int log_x, int log_y)
{
    plcol0(GRID_GREY);
    plwidth(1);
    plbox(log_x ? "gl" : "g", 0, 0, log_y ? "gl" : "g", 0, 0);
}

// A log axis spanning less than NARROW_DECADES gets labels at 1, 2 and 5 times
// each power of ten: PLplot labels only the decades, which leaves it one label
// or none.
static const double NARROW_DECADES = 2.5;

static void label_narrow_log_axis(int y_axis, double lo, double hi)
{
    char text[32];
    for (int e = (int)floor(lo); e <= (int)ceil(hi); ++e)
        for (int m = 1; m <= 5; m += m == 1 ? 1 : 3) {
            double at = log10(m) + e;
            if (at < lo - 1e-9 || at > hi + 1e-9) continue;
            snprintf(text, sizeof text, "%g", m * pow(10, e));
            if (y_axis && (int)strlen(text) > own_y_label_chars) own_y_label_chars = (int)strlen(text);
            if (y_axis) plmtex("lv", 0.7, (at - lo) / (hi - lo), 1.0, text);
            else plmtex("b", 1.6, (at - lo) / (hi - lo), 0.5, text);
        }
}

// The box with PLplot's ticks and labels. Fixed-point labels on a log axis
// while its decades stay readable as plain numbers.
static void frame(int log_x, int log_y, double x0, double x1, double y0, double y1)
{
    char xopt[16], yopt[16];
    int narrow_x = log_x && x1 - x0 < NARROW_DECADES, narrow_y = log_y && y1 - y0 < NARROW_DECADES;
    // (a map's axes reach a little past its decades: the half decade allowed)
    int fixed_x = log_x && x0 >= -3.5 && x1 <= 5.5, fixed_y = log_y && y0 >= -3.5 && y1 <= 5.5;
    plcol0(INK);
    plwidth(1);
    snprintf(xopt, sizeof xopt, "bcst%s%s%s", narrow_x ? "" : "n", log_x ? "l" : "", fixed_x ? "f" : "");
    snprintf(yopt, sizeof yopt, "bcstv%s%s%s", narrow_y ? "" : "n", log_y ? "l" : "", fixed_y ? "f" : "");
    plbox(xopt, 0, 0, yopt, 0, 0);
    own_y_label_chars = 0;
    if (narrow_x) label_narrow_log_axis(0, x0, x1);
    if (narrow_y) label_narrow_log_axis(1, y0, y1);
}

// ---- markers ----------------------------------------------------------------------

// Unicode glyphs, drawn by cairo's fonts: crisp at any size.
static const char *glyph(exp_plot_marker m)
{
    switch (m) {
    case EXP_MARK_SQUARE: return "■";
    case EXP_MARK_TRIANGLE: return "▲";
    case EXP_MARK_DIAMOND: return "◆";
    case EXP_MARK_STAR: return "★";
    case EXP_MARK_CROSS: return "✕";
    case EXP_MARK_OPEN_CIRCLE: return "○";
    case EXP_MARK_OPEN_SQUARE: return "□";
    case EXP_MARK_OPEN_DIAMOND: return "◇";
    case EXP_MARK_CIRCLE: break;
    }
    return "●";
}

// An open marker's filled twin, drawn white under it on a map so that it
// reads on the map's colours (NULL for the others). On a chart open markers
// are hollow: what lies under them shows through.
static const char *white_inside(exp_plot_marker m)
{
    switch (m) {
    case EXP_MARK_OPEN_CIRCLE: return glyph(EXP_MARK_CIRCLE);
    case EXP_MARK_OPEN_SQUARE: return glyph(EXP_MARK_SQUARE);
    case EXP_MARK_OPEN_DIAMOND: return glyph(EXP_MARK_DIAMOND);
    default: return NULL;
    }
}

static double marker_scale(exp_plot_marker m)
{
    return m == EXP_MARK_STAR ? 1.9 : 1.0;
}

// Half the size of a marker drawn at a character height of char_mm (the
// glyphs fill about 0.9 of the character's height).
static double marker_half_mm(exp_plot_marker m, double char_mm)
{
    return 0.45 * char_mm * marker_scale(m);
}

static void mark(double x, double y, exp_plot_marker m, int colour)
{
    text_size(marker_scale(m));
    plcol0(colour);
    plstring(1, &x, &y, glyph(m));
    text_size(TEXT);
}

// A map's marker: an open one white inside.
static void map_mark(double x, double y, exp_plot_marker m, int colour)
{
    text_size(marker_scale(m));
    const char *under = white_inside(m);
    if (under) plcol0(WHITE), plstring(1, &x, &y, under);
    plcol0(colour);
    plstring(1, &x, &y, glyph(m));
    text_size(TEXT);
}

// ---- charts -----------------------------------------------------------------------

// World coordinate of a value on an axis (log10 on a log axis; NAN where
// a log axis cannot show it).
static double world(double v, int log)
{
    if (!isfinite(v)) return NAN;
    if (!log) return v;
    return v > 0 ? log10(v) : NAN;
}

typedef struct range {
    double lo, hi;
} range;

static void extend(range *r, double v)
{
    if (isfinite(v)) r->lo = fmin(r->lo, v), r->hi = fmax(r->hi, v);
}

// What the series span on one axis, in world coordinates, error bars included on y.
static range data_span(size_t ns, const exp_plot_series *s, int y_axis, int log)
{
    range r = {INFINITY, -INFINITY};
    for (size_t k = 0; k < ns; ++k)
        for (size_t i = 0; i < s[k].n; ++i) {
            if (s[k].style == EXP_PLOT_HLINE && (!y_axis || i > 0)) continue;
            double v = y_axis ? s[k].y[i] : s[k].x[i];
            extend(&r, world(v, log));
            if (y_axis && s[k].err && isfinite(s[k].err[i])) {
                extend(&r, world(v - s[k].err[i], log));
                extend(&r, world(v + s[k].err[i], log));
            }
        }
    return r;
}

// A padded range for an axis: 5 % each side, and a single value widened to
// ±10 % of itself (±1 at zero) so that PLplot finds several distinct ticks.
static range padded(range r)
{
    if (!isfinite(r.lo)) return (range){0, 1};
    if (r.hi - r.lo <= 1e-9 * fmax(fabs(r.lo), fabs(r.hi))) {
        double half = r.lo != 0 ? 0.1 * fabs(r.lo) : 1;
        return (range){r.lo - half, r.lo + half};
    }
    double pad = 0.05 * (r.hi - r.lo);
    return (range){r.lo - pad, r.hi + pad};
}

// An axis range: the caller's if it gave one, else the data's, padded.
static range axis_range(double lo, double hi, range data, int log)
{
    if (lo < hi && (!log || lo > 0)) return (range){world(lo, log), world(hi, log)};
    return padded(data);
}

// A log axis is worth it only where the data span a decade or more: on a
// narrower range PLplot labels at most one tick, so such an axis is drawn linear.
static int wants_log(int asked, size_t ns, const exp_plot_series *s, int y_axis)
{
    if (!asked) return 0;
    range r = data_span(ns, s, y_axis, 1);
    return isfinite(r.lo) && r.hi - r.lo >= 1 - 1e-9;
}

static void draw_polyline(const exp_plot_series *s, int log_x, int log_y, double shift)
{
    double x[256], y[256];
    size_t m = 0;
    for (size_t i = 0; i <= s->n; ++i) {
        double wx = i < s->n ? world(s->x[i], log_x) + shift : NAN, wy = i < s->n ? world(s->y[i], log_y) : NAN;
        int breaks = !isfinite(wx) || !isfinite(wy);
        if (!breaks) x[m] = wx, y[m] = wy, m++;
        if ((breaks || m == 256) && m > 0) {
            if (m > 1) plline((PLINT)m, x, y);
            // a full buffer continues from its last point
            if (!breaks) x[0] = x[m - 1], y[0] = y[m - 1], m = 1;
            else m = 0;
        }
    }
}

static void draw_error_bars(const exp_plot_series *s, int log_x, int log_y, double shift)
{
    plwidth(1.2);
    for (size_t i = 0; s->err && i < s->n; ++i) {
        double x = world(s->x[i], log_x) + shift, e = s->err[i];
        if (!isfinite(x) || !isfinite(s->y[i]) || !isfinite(e) || e <= 0) continue;
        double lo = world(s->y[i] - e, log_y), hi = world(s->y[i] + e, log_y);
        if (!isfinite(lo)) lo = -1e30; // a bar below zero on a log axis runs off the bottom
        if (isfinite(hi)) plerry(1, &x, &lo, &hi);
    }
}

static void draw_markers(const exp_plot_series *s, int colour, int log_x, int log_y, double shift)
{
    for (size_t i = 0; i < s->n; ++i) {
        double x = world(s->x[i], log_x) + shift, y = world(s->y[i], log_y);
        if (isfinite(x) && isfinite(y)) mark(x, y, s->marker, colour);
    }
}

// Line, then markers, then the error bars over them: a bar shorter than its
// marker still shows on an open one.
static void draw_series(const exp_plot_series *s, int colour, int log_x, int log_y, range xr)
{
    double shift = s->dodge * (xr.hi - xr.lo);
    plcol0(colour);
    pllsty(s->dashed ? 3 : 1);
    plwidth(2);
    if (s->style == EXP_PLOT_HLINE) {
        double y = s->n ? world(s->y[0], log_y) : NAN;
        if (isfinite(y)) pljoin(xr.lo, y, xr.hi, y);
    } else if (s->style != EXP_PLOT_POINTS) draw_polyline(s, log_x, log_y, shift);
    pllsty(1);
    if (s->style != EXP_PLOT_HLINE && s->style != EXP_PLOT_LINE) draw_markers(s, colour, log_x, log_y, shift);
    plcol0(colour);
    draw_error_bars(s, log_x, log_y, shift);
    plwidth(1);
}

// ---- names beside points ------------------------------------------------------------

static int boxes_overlap(const exp_plot_box *a, const exp_plot_box *b)
{
    return a->x0 < b->x1 && b->x0 < a->x1 && a->y0 < b->y1 && b->y0 < a->y1;
}

static int box_is_free(const exp_plot_box *b, double width, double height, size_t n_obstacles,
                       const exp_plot_box *obstacles, size_t n_placed, const exp_plot_box *placed)
{
    if (b->x0 < 0 || b->y0 < 0 || b->x1 > width || b->y1 > height) return 0;
    for (size_t k = 0; k < n_obstacles; ++k)
        if (boxes_overlap(b, &obstacles[k])) return 0;
    for (size_t k = 0; k < n_placed; ++k)
        if (boxes_overlap(b, &placed[k])) return 0;
    return 1;
}

// The label's box on one side of its point (right: side 0, left: 1), its row
// `row` rows of `pitch` above (row > 0) or below the point's.
static exp_plot_box label_box(double px, double py, double w, double h, double reach, int side, double row_y)
{
    double x0 = side == 0 ? px + reach : px - reach - w;
    return (exp_plot_box){x0, py + row_y - h / 2, x0 + w, py + row_y + h / 2};
}

size_t exp_plot_place_labels(size_t n, const double *px, const double *py, const double *w, double h, double mark,
                             double gap, size_t n_obstacles, const exp_plot_box *obstacles, double width,
                             double height, exp_plot_box *out)
{
    size_t unplaced = 0, rows = (size_t)ceil(height / (h + 0.5 * gap)) + 1;
    for (size_t k = 0; k < n; ++k) {
        int found = 0;
        for (size_t r = 0; r <= rows && !found; ++r)
            for (int dir = 0; dir < (r ? 2 : 1) && !found; ++dir) // the point's row, then above, then below
                for (int side = 0; side < 2 && !found; ++side) {
                    double row_y = (double)r * (h + 0.5 * gap) * (dir ? -1 : 1);
                    out[k] = label_box(px[k], py[k], w[k], h, mark + gap, side, row_y);
                    found = box_is_free(&out[k], width, height, n_obstacles, obstacles, k, out);
                }
        if (!found) out[k] = label_box(px[k], py[k], w[k], h, mark + gap, 0, 0), unplaced++;
    }
    return unplaced;
}

// The viewport's place on the page and the world rectangle it shows: mm <-> world.
typedef struct plot_area {
    double x0, y0, width, height; ///< mm on the page
    range xr, yr;                 ///< world coordinates
} plot_area;

static plot_area current_area(page p, range xr, range yr)
{
    PLFLT x0, x1, y0, y1;
    plgvpd(&x0, &x1, &y0, &y1);
    return (plot_area){x0 * p.width, y0 * p.height, (x1 - x0) * p.width, (y1 - y0) * p.height, xr, yr};
}

static double mm_x(const plot_area *a, double wx)
{
    return (wx - a->xr.lo) / (a->xr.hi - a->xr.lo) * a->width;
}

static double mm_y(const plot_area *a, double wy)
{
    return (wy - a->yr.lo) / (a->yr.hi - a->yr.lo) * a->height;
}

static double world_x(const plot_area *a, double mm)
{
    return a->xr.lo + mm / a->width * (a->xr.hi - a->xr.lo);
}

static double world_y(const plot_area *a, double mm)
{
    return a->yr.lo + mm / a->height * (a->yr.hi - a->yr.lo);
}

// Every marker and error bar drawn, as boxes in the area's mm.
static size_t marker_boxes(size_t ns, const exp_plot_series *s, int log_x, int log_y, const plot_area *a,
                           double char_mm, exp_plot_box *out, size_t cap)
{
    size_t n = 0;
    for (size_t k = 0; k < ns; ++k) {
        int marked = s[k].style == EXP_PLOT_POINTS || s[k].style == EXP_PLOT_LINE_POINTS;
        double shift = s[k].dodge * (a->xr.hi - a->xr.lo), half = marker_half_mm(s[k].marker, char_mm);
        for (size_t i = 0; i < s[k].n && n + 2 <= cap; ++i) {
            double x = world(s[k].x[i], log_x) + shift, y = world(s[k].y[i], log_y);
            if (!isfinite(x) || !isfinite(y) || s[k].style == EXP_PLOT_HLINE) continue;
            double mx = mm_x(a, x), my = mm_y(a, y);
            if (marked) out[n++] = (exp_plot_box){mx - half, my - half, mx + half, my + half};
            double e = s[k].err ? s[k].err[i] : NAN;
            if (!isfinite(e) || e <= 0) continue;
            double lo = world(s[k].y[i] - e, log_y), hi = world(s[k].y[i] + e, log_y);
            lo = isfinite(lo) ? mm_y(a, lo) : 0;
            if (isfinite(hi)) out[n++] = (exp_plot_box){mx - 0.3 * char_mm, lo, mx + 0.3 * char_mm, mm_y(a, hi)};
        }
    }
    return n;
}

enum { MAX_NAMES = 256 };

// The names of every series' points, placed clear of each other and of the markers.
static void draw_names(size_t ns, const exp_plot_series *s, int log_x, int log_y, const plot_area *a, page p)
{
    static exp_plot_box obstacles[4 * MAX_NAMES], box[MAX_NAMES];
    double px[MAX_NAMES], py[MAX_NAMES], w[MAX_NAMES], half[MAX_NAMES];
    const char *text[MAX_NAMES];
    int colour[MAX_NAMES];
    double small_mm = p.char_mm * SMALL / TEXT;
    size_t n = 0;
    for (size_t k = 0; k < ns; ++k)
        for (size_t i = 0; s[k].names && i < s[k].n && n < MAX_NAMES; ++i) {
            double x = world(s[k].x[i], log_x) + s[k].dodge * (a->xr.hi - a->xr.lo), y = world(s[k].y[i], log_y);
            if (!s[k].names[i] || !isfinite(x) || !isfinite(y)) continue;
            px[n] = mm_x(a, x), py[n] = mm_y(a, y), text[n] = s[k].names[i], colour[n] = series_colour(k);
            w[n] = widest_text(1, &text[n], small_mm), half[n] = marker_half_mm(s[k].marker, p.char_mm);
            n++;
        }
    if (n == 0) return;
    size_t n_obstacles = marker_boxes(ns, s, log_x, log_y, a, p.char_mm, obstacles, 4 * MAX_NAMES);
    double mark_mm = 0;
    for (size_t k = 0; k < n; ++k) mark_mm = fmax(mark_mm, half[k]);
    exp_plot_place_labels(n, px, py, w, 1.1 * small_mm, mark_mm, 0.4 * p.char_mm, n_obstacles, obstacles, a->width,
                          a->height, box);
    text_size(SMALL);
    plwidth(0.8);
    for (size_t k = 0; k < n; ++k) {
        double cy = (box[k].y0 + box[k].y1) / 2, edge = box[k].x0 > px[k] ? box[k].x0 : box[k].x1;
        plcol0(colour[k]);
        if (fabs(cy - py[k]) > 0.5 * (box[k].y1 - box[k].y0)) // moved off its row: a line back to the point
            pljoin(world_x(a, px[k]), world_y(a, py[k]), world_x(a, edge), world_y(a, cy));
        plptex(world_x(a, box[k].x0), world_y(a, cy), 1, 0, 0, text[k]);
    }
    plwidth(1);
    text_size(TEXT);
}

// Whether every error bar of a series is shorter than its marker (so hidden
// behind a filled one): 0 where it has none.
static int bars_within_marker(const exp_plot_series *s, int log_x, int log_y, const plot_area *a, double char_mm)
{
    int any = 0;
    double half = marker_half_mm(s->marker, char_mm);
    for (size_t i = 0; s->err && i < s->n; ++i) {
        double x = world(s->x[i], log_x), e = s->err[i];
        if (!isfinite(x) || !isfinite(s->y[i]) || !isfinite(e) || e <= 0) continue;
        double lo = world(s->y[i] - e, log_y), hi = world(s->y[i] + e, log_y);
        double reach = isfinite(lo) ? (hi - lo) / 2 : INFINITY;
        if (!(reach / (a->yr.hi - a->yr.lo) * a->height < half)) return 0;
        any = 1;
    }
    return any;
}

// The legend's entries: one per labelled series, nothing for the others.
typedef struct legend {
    int n;
    PLINT opt[24], colour[24], text_colour[24], style[24], symbol_count[24], box_pattern[24];
    PLFLT width[24], symbol_scale[24], box_scale[24], box_line_width[24];
    const char *text[24], *symbol[24];
} legend;

static void legend_add(legend *l, const char *text, int colour, int line, int dashed, const char *symbol, double scale)
{
    if (!text || l->n >= 24) return;
    int k = l->n++;
    l->opt[k] = (line ? PL_LEGEND_LINE : 0) | (symbol ? PL_LEGEND_SYMBOL : 0);
    l->colour[k] = colour, l->text_colour[k] = INK, l->style[k] = dashed ? 3 : 1, l->width[k] = 2;
    l->symbol[k] = symbol ? symbol : "", l->symbol_scale[k] = scale, l->symbol_count[k] = symbol ? 1 : 0;
    l->text[k] = text;
    l->box_pattern[k] = 0, l->box_scale[k] = 0.8, l->box_line_width[k] = 1;
}

// A band: its hatch behind its edge line.
static void legend_add_band(legend *l, const char *text, int colour)
{
    int before = l->n;
    legend_add(l, text, colour, 1, 0, NULL, 1);
    if (l->n == before) return;
    l->opt[before] |= PL_LEGEND_COLOR_BOX;
    l->box_pattern[before] = 3; // PLplot's 45° lines
}

// The notes a series' legend entry carries after its label.
static char legend_notes[24][320];

// Whether a series draws anything: an entry for a series with nothing drawn
// would name what the figure does not show.
static int draws_something(const exp_plot_series *s)
{
    for (size_t i = 0; i < s->n; ++i)
        if (isfinite(s->y[i]) && (s->style == EXP_PLOT_HLINE || isfinite(s->x[i]))) return 1;
    return 0;
}

// hidden[k]: series k's error bars are all shorter than its marker (NULL: none is).
static void legend_of_series(legend *l, size_t ns, const exp_plot_series *s, const int *hidden)
{
    *l = (legend){0};
    for (size_t k = 0; k < ns; ++k) {
        int points = s[k].style == EXP_PLOT_POINTS || s[k].style == EXP_PLOT_LINE_POINTS;
        const char *text = draws_something(&s[k]) ? s[k].label : NULL;
        if (text && hidden && hidden[k] && l->n < 24) {
            snprintf(legend_notes[l->n], sizeof legend_notes[0], "%s: error bars shorter than the marker", text);
            text = legend_notes[l->n];
        }
        legend_add(l, text, series_colour(k), s[k].style != EXP_PLOT_POINTS, s[k].dashed,
                   points ? glyph(s[k].marker) : NULL, points ? marker_scale(s[k].marker) : 1);
    }
}

// The legend goes below the x label, in as many columns (up to 3) as the
// page's width holds: it never covers the data.
static int legend_columns(const legend *l, page p)
{
    double small_mm = p.char_mm * SMALL / TEXT, room = p.width - 10 * p.char_mm;
    double entry_mm = widest_text((size_t)l->n, l->text, small_mm) + 0.06 * room + 4 * small_mm;
    int columns = 3;
    while (columns > 1 && columns * entry_mm > room) columns--;
    return l->n < columns ? (l->n ? l->n : 1) : columns;
}

static double legend_height_mm(const legend *l, page p)
{
    if (l->n == 0) return 0;
    int rows = (l->n + legend_columns(l, p) - 1) / legend_columns(l, p);
    return (2.0 * rows + 1.0) * p.char_mm * SMALL / TEXT;
}

// Below the viewport, clear of the tick labels and the x label.
static void legend_draw(const legend *l, page p)
{
    if (l->n == 0) return;
    PLFLT x0, x1, y0, y1, w, h;
    plgvpd(&x0, &x1, &y0, &y1);
    int columns = legend_columns(l, p);
    double below = 4.6 * p.char_mm / ((y1 - y0) * p.height); // in the viewport's heights
    // pllegend takes its sizes relative to PLplot's default character, not the current one.
    PLFLT symbol_scale[24];
    for (int k = 0; k < l->n; ++k) symbol_scale[k] = text_base * l->symbol_scale[k];
    pllegend(&w, &h, PL_LEGEND_BACKGROUND | PL_LEGEND_BOUNDING_BOX, PL_POSITION_BOTTOM | PL_POSITION_OUTSIDE, 0, below,
             0.06, WHITE, INK, 1, (l->n + columns - 1) / columns, columns, l->n, l->opt, 1.0, text_base * SMALL, 2.0,
             0.0, l->text_colour, l->text, l->colour, l->box_pattern, l->box_scale, l->box_line_width, l->colour,
             l->style, l->width, l->colour,
             symbol_scale, l->symbol_count, l->symbol);
    text_size(TEXT);
}

// The viewport in mm: room on the left for the y labels, below for the x
// label and the legend, above for the title, and on the right for `right_mm`.
static void viewport(page p, double right_mm, const legend *l, const char *stamp)
{
    double left = 8.0 * p.char_mm, top = top_margin_chars(stamp) * p.char_mm;
    double bottom = 4.4 * p.char_mm + (l->n ? legend_height_mm(l, p) + 0.8 * p.char_mm : 0);
    plsvpa(left, p.width - right_mm, bottom, p.height - top);
}

int exp_plot_png(const char *path, const exp_plot_axes *a, size_t ns, const exp_plot_series *s, int width, int height,
                 char *err, size_t len)
{
    figure f;
    if (begin_figure(&f, path, width, height, err, len)) return 1;
    int log_x = wants_log(a->log_x, ns, s, 0), log_y = wants_log(a->log_y, ns, s, 1);
    range xr = axis_range(a->xlo, a->xhi, data_span(ns, s, 0, log_x), log_x);
    range yr = axis_range(a->ylo, a->yhi, data_span(ns, s, 1, log_y), log_y);
    legend l;
    legend_of_series(&l, ns, s, NULL);
    page p = page_size();
    viewport(p, 2.5 * p.char_mm, &l, a->stamp);
    // Which series' bars hide behind their markers needs the viewport's height,
    // which needs the legend's: its entries are redone with the note, the viewport after.
    int *hidden = calloc(ns ? ns : 1, sizeof *hidden), any_hidden = 0;
    plot_area area = current_area(p, xr, yr);
    for (size_t k = 0; hidden && k < ns; ++k)
        any_hidden |= hidden[k] = s[k].label && bars_within_marker(&s[k], log_x, log_y, &area, p.char_mm);
    if (any_hidden) {
        legend_of_series(&l, ns, s, hidden);
        viewport(p, 2.5 * p.char_mm, &l, a->stamp);
        area = current_area(p, xr, yr);
    }
    free(hidden);
    plwind(xr.lo, xr.hi, yr.lo, yr.hi);
    grid_lines(log_x, log_y);
    for (size_t k = 0; k < ns; ++k) {
        set_colour(series_colour(k), s[k].rgb);
        draw_series(&s[k], series_colour(k), log_x, log_y, xr);
    }
    draw_names(ns, s, log_x, log_y, &area, p);
    frame(log_x, log_y, xr.lo, xr.hi, yr.lo, yr.hi); // over what was drawn at its edges
    title_and_labels(a->title, a->stamp, a->xlabel, a->ylabel);
    legend_draw(&l, p);
    return end_figure(&f, err, len);
}

// ---- maps -------------------------------------------------------------------------

enum { MAP_NODES = 321, MAP_LEVELS = 16 };

// The interpolated map: z at MAP_NODES × MAP_NODES nodes over the rectangle in
// world coordinates (NAN outside the points' convex hull).
typedef struct map_grid {
    double x0, x1, y0, y1;
    double *z[MAP_NODES];
    double storage[MAP_NODES * MAP_NODES];
    double zlo, zhi;
    int filled; ///< 0 where the points do not span an area
} map_grid;

// The points, in the unit square, with failed and repeated ones dropped
// (the triangulation needs distinct points; a repeat's z is averaged in).
static size_t unit_points(const exp_plot_map *m, const map_grid *g, double *u, double *v, double *z)
{
    size_t n = 0;
    int *count = calloc(m->n ? m->n : 1, sizeof *count);
    for (size_t i = 0; count && i < m->n; ++i) {
        double wy = world(m->y[i], m->log_y);
        if (!isfinite(m->z[i]) || !isfinite(m->x[i]) || !isfinite(wy)) continue;
        double pu = (m->x[i] - g->x0) / (g->x1 - g->x0), pv = (wy - g->y0) / (g->y1 - g->y0);
        size_t k = 0;
        while (k < n && (fabs(u[k] - pu) > 1e-9 || fabs(v[k] - pv) > 1e-9)) ++k;
        if (k == n) u[n] = pu, v[n] = pv, z[n] = 0, count[n] = 0, n++;
        z[k] = (z[k] * count[k] + m->z[i]) / (count[k] + 1), count[k]++;
    }
    free(count);
    return n;
}

// Whether the points span an area (the triangulation fails on a line).
static int spans_area(size_t n, const double *u, const double *v)
{
    for (size_t j = 1; j < n; ++j)
        for (size_t k = j + 1; k < n; ++k)
            if (fabs((u[j] - u[0]) * (v[k] - v[0]) - (u[k] - u[0]) * (v[j] - v[0])) > 1e-6) return 1;
    return 0;
}

static void grid_range(map_grid *g)
{
    g->zlo = INFINITY, g->zhi = -INFINITY;
    for (int k = 0; k < MAP_NODES * MAP_NODES; ++k)
        if (isfinite(g->storage[k])) g->zlo = fmin(g->zlo, g->storage[k]), g->zhi = fmax(g->zhi, g->storage[k]);
    g->filled = isfinite(g->zlo);
    if (g->filled && g->zhi - g->zlo < 1e-9) g->zlo -= 0.5, g->zhi += 0.5;
}

// qhull, under plgriddata's triangulation, ends the process on input whose
// first sites lie on one circle (a search's 2 × 2 start grid is a square), so
// every site is moved by a fixed pseudo-random amount of at most 5e-6 of the
// axes: no four sites stay cocircular, and none moves by a hundredth of a
// pixel (a map node is 3e-3 of an axis). At 5e-8 the sites were still so nearly cocircular that qhull
// printed a "precision warning: The initial hull is narrow" into every log of
// a run whose map was its 2 × 2 grid alone.
static void joggle(size_t n, double *u, double *v)
{
    uint64_t s = 0x2545F4914F6CDD1Dull;
    for (size_t k = 0; k < n; ++k) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        u[k] += 1e-5 * ((double)(s >> 11) / 9007199254740992.0 - 0.5);
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        v[k] += 1e-5 * ((double)(s >> 11) / 9007199254740992.0 - 0.5);
    }
}

static void interpolate(const exp_plot_map *m, map_grid *g)
{
    for (int i = 0; i < MAP_NODES; ++i) g->z[i] = g->storage + (size_t)i * MAP_NODES;
    for (int k = 0; k < MAP_NODES * MAP_NODES; ++k) g->storage[k] = NAN;
    size_t cap = m->n ? m->n : 1;
    double *u = malloc(cap * sizeof *u), *v = malloc(cap * sizeof *v), *z = malloc(cap * sizeof *z);
    size_t n = u && v && z ? unit_points(m, g, u, v, z) : 0;
    if (n >= 3 && spans_area(n, u, v)) {
        joggle(n, u, v);
        double nodes[MAP_NODES];
        for (int i = 0; i < MAP_NODES; ++i) nodes[i] = (double)i / (MAP_NODES - 1);
        plgriddata(u, v, z, (PLINT)n, nodes, MAP_NODES, nodes, MAP_NODES, g->z, GRID_DTLI, 0);
    }
    free(u), free(v), free(z);
    grid_range(g);
}

// plshades' `defined` callback gets world coordinates and no user data:
// the grid being drawn is held here for the length of one figure.
static const map_grid *shading;

// Inside the hull: the grid node nearest (x, y) was interpolated.
static PLINT inside_hull(PLFLT x, PLFLT y)
{
    const map_grid *g = shading;
    long i = lround((x - g->x0) / (g->x1 - g->x0) * (MAP_NODES - 1));
    long j = lround((y - g->y0) / (g->y1 - g->y0) * (MAP_NODES - 1));
    if (i < 0 || j < 0 || i >= MAP_NODES || j >= MAP_NODES) return 0;
    return isfinite(g->z[i][j]);
}

// Stricter, for the band's hatch: the grid cell holding (x, y) has four
// interpolated corners. A cell across the hull's edge is out: its part between
// the value outside and the one inside would hatch a dotted line along the edge.
static PLINT cell_inside_hull(PLFLT x, PLFLT y)
{
    const map_grid *g = shading;
    double u = (x - g->x0) / (g->x1 - g->x0) * (MAP_NODES - 1), v = (y - g->y0) / (g->y1 - g->y0) * (MAP_NODES - 1);
    long i = (long)floor(u), j = (long)floor(v);
    if (i == MAP_NODES - 1) i--; // the rectangle's far edges belong to the last cells
    if (j == MAP_NODES - 1) j--;
    if (i < 0 || j < 0 || i >= MAP_NODES - 1 || j >= MAP_NODES - 1) return 0;
    return isfinite(g->z[i][j]) && isfinite(g->z[i + 1][j]) && isfinite(g->z[i][j + 1]) && isfinite(g->z[i + 1][j + 1]);
}

// A pale-to-deep sequential colour map (cmap1): readable under black markers
// at both ends.
static void sequential_colours(void)
{
    PLFLT at[] = {0, 0.35, 0.7, 1}, r[] = {0.99, 0.60, 0.25, 0.20}, gr[] = {0.95, 0.85, 0.60, 0.30},
          b[] = {0.75, 0.60, 0.75, 0.65};
    plscmap1n(256);
    plscmap1l(1, 4, at, r, gr, b, NULL);
}

// The grid's rows for plshade(s), which read every node: the nodes outside the
// hull get a value below every level and band (`floor`), so that no shade
// spans them, and inside_hull trims the cells along the hull's edge. (Given a
// value inside a shade, plshade merges them with the hull into rectangles that
// the `defined` callback cannot cut back to the hull.)
static void finite_rows(const map_grid *g, double floor, const double **rows)
{
    static double copy_storage[MAP_NODES * MAP_NODES];
    for (int k = 0; k < MAP_NODES * MAP_NODES; ++k) copy_storage[k] = isfinite(g->storage[k]) ? g->storage[k] : floor;
    for (int i = 0; i < MAP_NODES; ++i) rows[i] = copy_storage + (size_t)i * MAP_NODES;
}

static void shade(const map_grid *g, double *levels)
{
    const double *rows[MAP_NODES];
    finite_rows(g, g->zlo - (g->zhi - g->zlo) - 1, rows);
    for (int k = 0; k < MAP_LEVELS; ++k) levels[k] = g->zlo + (g->zhi - g->zlo) * k / (MAP_LEVELS - 1);
    shading = g;
    plshades(rows, MAP_NODES, MAP_NODES, inside_hull, g->x0, g->x1, g->y0, g->y1, levels, MAP_LEVELS, 1, 0, 0, plfill,
             1, NULL, NULL);
    shading = NULL;
}

// The band between two levels hatched, so that it reads as a band even where
// only one of its edges crosses the map.
static const PLINT HATCH_ANGLE[1] = {450}, HATCH_SPACING[1] = {2500}; // tenths of a degree, micrometres

static void hatch_band(const map_grid *g, double lo, double hi, int colour)
{
    const double *rows[MAP_NODES];
    lo = isfinite(lo) ? lo : g->zlo - 1, hi = isfinite(hi) ? hi : g->zhi + 1;
    finite_rows(g, fmin(lo, g->zlo) - (g->zhi - g->zlo) - 1, rows);
    shading = g;
    plpat(1, HATCH_ANGLE, HATCH_SPACING);
    plwidth(1);
    plshade(rows, MAP_NODES, MAP_NODES, cell_inside_hull, g->x0, g->x1, g->y0, g->y1, lo, hi, 0, colour, 1, 0, 0, 0, 0, plfill,
            1, NULL, NULL);
    plpsty(0);
    shading = NULL;
}

// One contour level by marching squares over the grid's cells whose four
// corners are all inside the hull: no line is drawn where the map is white.
static void contour(const map_grid *g, double level)
{
    double dx = (g->x1 - g->x0) / (MAP_NODES - 1), dy = (g->y1 - g->y0) / (MAP_NODES - 1);
    static const int corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int i = 0; i + 1 < MAP_NODES; ++i)
        for (int j = 0; j + 1 < MAP_NODES; ++j) {
            double px[4], py[4];
            int crossings = 0, whole = 1;
            for (int e = 0; e < 4 && whole; ++e) {
                const int *p = corner[e], *q = corner[(e + 1) % 4];
                double a = g->z[i + p[0]][j + p[1]] - level, b = g->z[i + q[0]][j + q[1]] - level;
                whole = isfinite(a) && isfinite(b);
                if (!whole || (a > 0) == (b > 0)) continue;
                double t = a / (a - b);
                px[crossings] = g->x0 + dx * (i + p[0] + t * (q[0] - p[0]));
                py[crossings] = g->y0 + dy * (j + p[1] + t * (q[1] - p[1]));
                crossings++;
            }
            for (int c = 0; whole && c + 1 < crossings; c += 2) pljoin(px[c], py[c], px[c + 1], py[c + 1]);
        }
}

// The colour scale on the right, PLplot choosing its ticks.
static void colour_bar(const exp_plot_map *m, const double *levels)
{
    PLFLT w, h;
    const char *axis_opts[] = {"bcvtm"};
    PLFLT ticks[] = {0};
    PLINT sub_ticks[] = {0}, n_values[] = {MAP_LEVELS}, label_opts[] = {PL_COLORBAR_LABEL_RIGHT};
    const PLFLT *values[] = {levels};
    const char *labels[] = {m->zlabel ? m->zlabel : ""};
    plcol0(INK);
    text_size(SMALL);
    plcolorbar(&w, &h, PL_COLORBAR_SHADE, PL_POSITION_RIGHT | PL_POSITION_OUTSIDE, 0.02, 0, 0.035, 1.0, 0, INK, 0, 0, 0,
               0, 0, 1, label_opts, labels, 1, axis_opts, ticks, sub_ticks, n_values, values);
    text_size(TEXT);
}

static int is_predicted(const exp_plot_map *m, size_t i)
{
    return m->predicted && m->predicted[i];
}

// Every measured point as a white disc ringed in black (visible on any
// colour), a predicted one as a grey open diamond, a failed one as a cross,
// the chosen one as a large star; the measured over the predicted.
static void map_markers(const exp_plot_map *m, int chosen_colour, int predicted_colour)
{
    for (int pass = 0; pass < 2; ++pass)
        for (size_t i = 0; i < m->n; ++i) {
            double x = m->x[i], y = world(m->y[i], m->log_y);
            if (!isfinite(x) || !isfinite(y) || is_predicted(m, i) != !pass) continue;
            if (!isfinite(m->z[i])) map_mark(x, y, EXP_MARK_CROSS, INK);
            else if (is_predicted(m, i)) map_mark(x, y, EXP_MARK_OPEN_DIAMOND, predicted_colour);
            else map_mark(x, y, EXP_MARK_OPEN_CIRCLE, INK);
        }
    if (m->chosen >= 0 && (size_t)m->chosen < m->n) {
        double x = m->x[m->chosen], y = world(m->y[m->chosen], m->log_y);
        if (isfinite(x) && isfinite(y)) map_mark(x, y, EXP_MARK_STAR, chosen_colour);
    }
}

// The search's rectangle, dashed: the axes reach past it.
static void bounds_box(const map_grid *g)
{
    double x[5] = {g->x0, g->x1, g->x1, g->x0, g->x0}, y[5] = {g->y0, g->y0, g->y1, g->y1, g->y0};
    plcol0(INK);
    plwidth(1);
    pllsty(2);
    plline(5, x, y);
    pllsty(1);
}

int exp_plot_band_reached(double lo, double hi, size_t n, const double *z, double *zmin, double *zmax)
{
    *zmin = INFINITY, *zmax = -INFINITY;
    for (size_t i = 0; i < n; ++i)
        if (isfinite(z[i])) *zmin = fmin(*zmin, z[i]), *zmax = fmax(*zmax, z[i]);
    if (!isfinite(*zmin)) {
        *zmin = *zmax = NAN;
        return 1;
    }
    if (!isfinite(lo) && !isfinite(hi)) return 1;
    return !(isfinite(lo) && lo > *zmax) && !(isfinite(hi) && hi < *zmin);
}

double exp_plot_settled_from(size_t n, const double *t, const double *y, double tolerance)
{
    if (n == 0) return NAN;
    size_t k = n - 1;
    while (k > 0 && fabs(y[k - 1] - y[n - 1]) <= tolerance) k--;
    return t[k];
}

// Without a fill (points that span no area) each point's value is written beside it.
static void map_values(const exp_plot_map *m, const map_grid *g)
{
    char text[32];
    plcol0(INK);
    text_size(SMALL);
    for (size_t i = 0; i < m->n; ++i) {
        double x = m->x[i], y = world(m->y[i], m->log_y);
        if (!isfinite(x) || !isfinite(y) || !isfinite(m->z[i])) continue;
        snprintf(text, sizeof text, "%.3g", m->z[i]);
        plptex(x + 0.02 * (g->x1 - g->x0), y, 1, 0, 0, text);
    }
    text_size(TEXT);
}

static int any_failed(const exp_plot_map *m)
{
    for (size_t i = 0; i < m->n; ++i)
        if (!isfinite(m->z[i])) return 1;
    return 0;
}

// The band's legend text, or where the points' values never reach the band
// that: "not reached", with the range they span.
static const char *band_text(const exp_plot_map *m, int *reached)
{
    static char text[320];
    double zmin, zmax;
    *reached = exp_plot_band_reached(m->band_lo, m->band_hi, m->n, m->z, &zmin, &zmax);
    if (*reached) return m->band_label;
    snprintf(text, sizeof text, "%s: NOT REACHED, the points span %.3g to %.3g", m->band_label ? m->band_label : "band",
             zmin, zmax);
    return text;
}

static size_t count_predicted(const exp_plot_map *m)
{
    size_t n = 0;
    for (size_t i = 0; i < m->n; ++i) n += is_predicted(m, i);
    return n;
}

static legend map_legend(const exp_plot_map *m, int filled, int band_colour, int chosen_colour, int predicted_colour)
{
    legend l = {0};
    legend_add(&l, m->points_label ? m->points_label : "evaluated", INK, 0, 0, glyph(EXP_MARK_OPEN_CIRCLE), 1);
    if (count_predicted(m))
        legend_add(&l, m->predicted_label ? m->predicted_label : "predicted, not measured", predicted_colour, 0, 0,
                   glyph(EXP_MARK_OPEN_DIAMOND), 1);
    if (any_failed(m)) legend_add(&l, "failed run", INK, 0, 0, glyph(EXP_MARK_CROSS), 1);
    if (m->chosen >= 0)
        legend_add(&l, m->chosen_label ? m->chosen_label : "chosen", chosen_colour, 0, 0, glyph(EXP_MARK_STAR), 1.4);
    int reached = 1;
    const char *band = band_text(m, &reached);
    if (!reached) { // no line to show: the text alone, in the chosen star's red
        legend_add(&l, band, chosen_colour, 0, 0, NULL, 1);
        l.text_colour[l.n - 1] = chosen_colour;
    } else if (filled && (isfinite(m->band_lo) || isfinite(m->band_hi)))
        legend_add_band(&l, band, band_colour);
    legend_add(&l, "search bounds", INK, 1, 1, NULL, 1);
    l.style[l.n - 1] = 2, l.width[l.n - 1] = 1;
    return l;
}

// How far the axes reach past the rectangle (world units): a star's half
// width and a little, so that a marker on the rectangle's edge is drawn whole.
static void pad_window(const map_grid *g, page p, double *px, double *py)
{
    PLFLT x0, x1, y0, y1;
    plgvpd(&x0, &x1, &y0, &y1);
    double reach_mm = marker_half_mm(EXP_MARK_STAR, p.char_mm) + 0.3 * p.char_mm;
    double fx = reach_mm / ((x1 - x0) * p.width), fy = reach_mm / ((y1 - y0) * p.height);
    *px = fx / (1 - 2 * fx) * (g->x1 - g->x0), *py = fy / (1 - 2 * fy) * (g->y1 - g->y0);
}

int exp_plot_map_png(const char *path, const exp_plot_map *m, int width, int height, char *err, size_t len)
{
    map_grid *g = calloc(1, sizeof *g);
    if (!g) return fail(err, len, "%s: out of memory for the map", path);
    g->x0 = m->xlo, g->x1 = m->xhi, g->y0 = world(m->ylo, m->log_y), g->y1 = world(m->yhi, m->log_y);
    if (!(g->x0 < g->x1) || !(g->y0 < g->y1)) {
        free(g);
        return fail(err, len, "%s: the map's rectangle is empty", path);
    }
    figure f;
    if (begin_figure(&f, path, width, height, err, len)) return free(g), 1;
    interpolate(m, g);
    enum { BAND = FIRST_SERIES_COLOUR, CHOSEN, PREDICTED };
    plscol0(BAND, 0, 0, 0), plscol0(CHOSEN, 215, 25, 28), plscol0(PREDICTED, 90, 90, 90);
    legend l = map_legend(m, g->filled, BAND, CHOSEN, PREDICTED);
    page p = page_size();
    viewport(p, (g->filled ? 10 : 2.5) * p.char_mm, &l, m->stamp);
    double pad_x, pad_y;
    pad_window(g, p, &pad_x, &pad_y);
    plwind(g->x0 - pad_x, g->x1 + pad_x, g->y0 - pad_y, g->y1 + pad_y);
    double levels[MAP_LEVELS];
    if (g->filled) {
        sequential_colours();
        shade(g, levels);
        if (isfinite(m->band_lo) || isfinite(m->band_hi)) hatch_band(g, m->band_lo, m->band_hi, BAND);
        plcol0(BAND), plwidth(2.5);
        if (isfinite(m->band_lo)) contour(g, m->band_lo);
        if (isfinite(m->band_hi)) contour(g, m->band_hi);
        plwidth(1);
    }
    bounds_box(g);
    frame(0, m->log_y, g->x0 - pad_x, g->x1 + pad_x, g->y0 - pad_y, g->y1 + pad_y);
    map_markers(m, CHOSEN, PREDICTED);
    if (!g->filled) map_values(m, g);
    if (g->filled) colour_bar(m, levels);
    title_and_labels(m->title, m->stamp, m->xlabel, m->ylabel);
    legend_draw(&l, p);
    free(g);
    return end_figure(&f, err, len);
}

// ---- corner plots ---------------------------------------------------------------------

enum { CORNER_BINS = 30, CORNER_MAX_POINTS = 4000 };

// Counts of v (world coordinates) in CORNER_BINS bins over [lo, hi], as a
// fraction of the largest, at each bin's left edge (plbin's layout).
static void histogram(size_t n, const double *v, int log, double lo, double hi, double *edge, double *height)
{
    double count[CORNER_BINS] = {0}, most = 0;
    for (size_t i = 0; i < n; ++i) {
        double w = world(v[i], log);
        if (!isfinite(w)) continue;
        int b = (int)((w - lo) / (hi - lo) * CORNER_BINS);
        if (b >= 0 && b <= CORNER_BINS) count[b < CORNER_BINS ? b : CORNER_BINS - 1]++;
    }
    for (int b = 0; b < CORNER_BINS; ++b) most = fmax(most, count[b]);
    for (int b = 0; b < CORNER_BINS; ++b)
        edge[b] = lo + (hi - lo) * b / CORNER_BINS, height[b] = most > 0 ? count[b] / most : 0;
}

// A vertical (x) or horizontal (y) line across the current window, dashed or solid.
static void corner_line(int vertical, double at, int dashed, double w0, double w1)
{
    if (!isfinite(at)) return;
    PLFLT x[2] = {at, at}, y[2] = {w0, w1};
    pllsty(dashed ? 2 : 1);
    if (vertical) plline(2, x, y);
    else plline(2, y, x);
    pllsty(1);
}

// One histogram panel: bars along x (vertical = 0: the y histogram drawn sideways).
static void corner_histogram(const exp_plot_corner *c, int of_y, double lo, double hi)
{
    double edge[CORNER_BINS], height[CORNER_BINS];
    double s0 = of_y ? world(c->ylo, c->log_y) : c->xlo, s1 = of_y ? world(c->yhi, c->log_y) : c->xhi;
    histogram(c->n, of_y ? c->y : c->x, of_y && c->log_y, s0, s1, edge, height);
    if (of_y) plwind(0, 1.05, lo, hi);
    else plwind(lo, hi, 0, 1.05);
    plcol0(FIRST_SERIES_COLOUR);
    for (int b = 0; b < CORNER_BINS; ++b) { // each bin a filled box, drawn as the plot's axes run
        double w = (s1 - s0) / CORNER_BINS;
        PLFLT bx[4] = {edge[b], edge[b] + w, edge[b] + w, edge[b]}, by[4] = {0, 0, height[b], height[b]};
        if (of_y) plfill(4, by, bx);
        else plfill(4, bx, by);
    }
    plcol0(INK);
    double med = of_y ? world(c->y_median, c->log_y) : c->x_median;
    double q_lo = of_y ? world(c->y_lo, c->log_y) : c->x_lo, q_hi = of_y ? world(c->y_hi, c->log_y) : c->x_hi;
    corner_line(!of_y, med, 0, 0, 1.05);
    corner_line(!of_y, q_lo, 1, 0, 1.05);
    corner_line(!of_y, q_hi, 1, 0, 1.05);
    plbox(of_y ? "bc" : "bc", 0, 0, of_y ? "bcst" : "bc", 0, 0);
}

// The joint panel: the samples (at most CORNER_MAX_POINTS, evenly taken), the medians and intervals, the choice.
static void corner_joint(const exp_plot_corner *c, double x0, double x1, double y0, double y1, int chosen_colour)
{
    plwind(x0, x1, y0, y1);
    grid_lines(0, c->log_y);
    size_t every = c->n > CORNER_MAX_POINTS ? c->n / CORNER_MAX_POINTS : 1;
    text_size(0.35);
    plcol0(FIRST_SERIES_COLOUR);
    for (size_t i = 0; i < c->n; i += every) {
        double x = c->x[i], y = world(c->y[i], c->log_y);
        if (isfinite(x) && isfinite(y)) plstring(1, &x, &y, "•");
    }
    text_size(TEXT);
    plcol0(INK);
    corner_line(1, c->x_median, 0, y0, y1), corner_line(1, c->x_lo, 1, y0, y1), corner_line(1, c->x_hi, 1, y0, y1);
    corner_line(0, world(c->y_median, c->log_y), 0, x0, x1);
    corner_line(0, world(c->y_lo, c->log_y), 1, x0, x1), corner_line(0, world(c->y_hi, c->log_y), 1, x0, x1);
    double cy = world(c->chosen_y, c->log_y);
    if (isfinite(c->chosen_x) && isfinite(cy)) map_mark(c->chosen_x, cy, EXP_MARK_STAR, chosen_colour);
    frame(0, c->log_y, x0, x1, y0, y1);
}

// The free corner's text, one line under the other from its top.
static void corner_note(const char *note)
{
    if (!note) return;
    plwind(0, 1, 0, 1);
    plcol0(INK);
    text_size(SMALL);
    char line[256];
    double at = 0.92;
    for (const char *p = note; *p; at -= 0.11) {
        size_t k = strcspn(p, "\n");
        snprintf(line, sizeof line, "%.*s", (int)(k < 255 ? k : 255), p);
        plptex(0.02, at, 1, 0, 0, line);
        p += k + (p[k] == '\n');
    }
    text_size(TEXT);
}

int exp_plot_corner_png(const char *path, const exp_plot_corner *c, int width, int height, char *err, size_t len)
{
    figure f;
    if (begin_figure(&f, path, width, height, err, len)) return 1;
    enum { CHOSEN = FIRST_SERIES_COLOUR + 1 };
    double rgb[3];
    exp_plot_colour(0, rgb);
    set_colour(FIRST_SERIES_COLOUR, rgb);
    plscol0(CHOSEN, 215, 25, 28);
    page p = page_size();
    double left = 8.0 * p.char_mm, bottom = 4.4 * p.char_mm, top = top_margin_chars(c->stamp) * p.char_mm;
    double right = 2.5 * p.char_mm;
    double gap = 1.0 * p.char_mm;
    double a_w = (p.width - left - right - gap) * 0.7, a_h = (p.height - bottom - top - gap) * 0.7;
    double b_w = p.width - left - right - gap - a_w, b_h = p.height - bottom - top - gap - a_h;
    // The windows reach 3 % past the support, so that a star on a bound is whole.
    double y0 = world(c->ylo, c->log_y), y1 = world(c->yhi, c->log_y), pad_y = 0.03 * (y1 - y0);
    double pad_x = 0.03 * (c->xhi - c->xlo), x0 = c->xlo - pad_x, x1 = c->xhi + pad_x;
    y0 -= pad_y, y1 += pad_y;
    plsvpa(left, left + a_w, bottom, bottom + a_h); // joint, below left
    corner_joint(c, x0, x1, y0, y1, CHOSEN);
    plcol0(INK);
    plmtex("b", 3.2, 0.5, 0.5, c->xlabel);
    plmtex("l", ylabel_offset(), 0.5, 0.5, c->ylabel);
    plsvpa(left, left + a_w, bottom + a_h + gap, bottom + a_h + gap + b_h); // x histogram above
    corner_histogram(c, 0, x0, x1);
    if (c->title) text_size(TITLE), plmtex("t", 1.2, 0.0, 0.0, c->title), text_size(TEXT);
    stamp_line(c->stamp);
    plsvpa(left + a_w + gap, left + a_w + gap + b_w, bottom, bottom + a_h); // y histogram to the right
    corner_histogram(c, 1, y0, y1);
    plsvpa(left + a_w + gap, left + a_w + gap + b_w, bottom + a_h + gap, bottom + a_h + gap + b_h);
    corner_note(c->note);
    return end_figure(&f, err, len);
}
