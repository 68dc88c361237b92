// SPDX-License-Identifier: MIT
// A photograph of the drum face measured: the powder segmented inside the
// drum's circle under uneven light, the largest connected piece of it kept
// and its pores filled, its upper boundary traced away from the wall and a
// line fitted to it robustly.
#include "exp_photo.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_vec.h"
#include "exp_face_measure.h"
#include "exp_image.h"

#define CLASS_SMOOTH_PX 1.0        // Gaussian sigma before thresholding: JPEG blocks and noise average out
#define WALL_BAND_PX 2.5           // next to the circle the rim's blurred edge or shadow darkens the drum
#define SURFACE_WALL_FRACTION 0.05 // surface points this close to the wall (of R) are the wall's, not the slope's
#define MIN_CLASS_FRACTION 0.005   // a tone covering less of the drum is not there
#define MIN_SURFACE_POINTS 10
#define LIGHTING_ITERATIONS 20

enum { OUTSIDE = 0, EMPTY = 1, POWDER = 2, SURFACE_USED = 3 };

exp_photo_opts exp_default_photo_opts(void)
{
    return (exp_photo_opts){.tone = EXP_POWDER_AUTO, .closing_px = 3, .central_fraction = 0.6, .max_sd_fraction = 0.04};
}

// The pixels the drum's circle covers, clipped to the image.
typedef struct drum_box {
    const exp_circle *c;
    int w, h, x0, x1, y0, y1; // x0 <= x < x1, y0 <= y < y1
} drum_box;

static drum_box box_of(const exp_circle *c, int w, int h)
{
    drum_box b = {c, w, h, (int)floor(c->cx - c->r), (int)ceil(c->cx + c->r) + 1, (int)floor(c->cy - c->r),
                  (int)ceil(c->cy + c->r) + 1};
    b.x0 = b.x0 < 0 ? 0 : b.x0, b.y0 = b.y0 < 0 ? 0 : b.y0;
    b.x1 = b.x1 > w ? w : b.x1, b.y1 = b.y1 > h ? h : b.y1;
    return b;
}

// Pixel centre within r - margin of the centre.
static int within(const drum_box *b, int x, int y, double margin)
{
    double dx = x + 0.5 - b->c->cx, dy = y + 0.5 - b->c->cy, r = b->c->r - margin;
    return dx * dx + dy * dy <= r * r;
}

// ---------------------------------------------------------------------------
// Two tones under uneven light: a threshold that is, at each pixel, halfway
// between two planes fitted to the grey levels of each class (a linear
// lighting gradient scales both tones alike), starting from Otsu's.

typedef struct plane {
    double a, b, c; // grey = a + b·u + c·v, u and v the offsets from the centre over R
} plane;

static double plane_at(const plane *p, const drum_box *b, int x, int y)
{
    return p->a + p->b * (x + 0.5 - b->c->cx) / b->c->r + p->c * (y + 0.5 - b->c->cy) / b->c->r;
}

static double det3(const double m[3][3])
{
    return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
           m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
}

// Least squares over the core pixels of class `dark`; 1 if too few.
static int fit_plane(const exp_gray *s, const drum_box *b, const unsigned char *is_dark, int dark, plane *p)
{
    double m[3][3] = {{0}}, t[3] = {0};
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            size_t k = (size_t)y * b->w + x;
            if (!within(b, x, y, WALL_BAND_PX) || is_dark[k] != dark) continue;
            double f[3] = {1, (x + 0.5 - b->c->cx) / b->c->r, (y + 0.5 - b->c->cy) / b->c->r};
            for (int i = 0; i < 3; ++i) {
                t[i] += f[i] * s->v[k];
                for (int j = 0; j < 3; ++j) m[i][j] += f[i] * f[j];
            }
        }
    double d = det3(m);
    if (m[0][0] < 3 || fabs(d) < 1e-9 * m[0][0] * m[0][0] * m[0][0]) return 1;
    double coef[3];
    for (int col = 0; col < 3; ++col) { // Cramer's rule
        double mc[3][3];
        memcpy(mc, m, sizeof mc);
        for (int i = 0; i < 3; ++i) mc[i][col] = t[i];
        coef[col] = det3(mc) / d;
    }
    *p = (plane){coef[0], coef[1], coef[2]};
    return 0;
}

static size_t otsu_split(const exp_gray *s, const drum_box *b, unsigned char *is_dark)
{
    unsigned long hist[256] = {0};
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x)
            if (within(b, x, y, WALL_BAND_PX)) hist[(int)fmin(255, fmax(0, lround(s->v[(size_t)y * b->w + x])))]++;
    int t = exp_otsu_threshold(hist);
    size_t dark = 0;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            size_t k = (size_t)y * b->w + x;
            is_dark[k] = within(b, x, y, WALL_BAND_PX) && s->v[k] <= t + 0.5;
            dark += is_dark[k];
        }
    return dark;
}

static void split_tones(const exp_gray *s, const drum_box *b, unsigned char *is_dark)
{
    otsu_split(s, b, is_dark);
    for (int it = 0; it < LIGHTING_ITERATIONS; ++it) {
        plane dark, light;
        if (fit_plane(s, b, is_dark, 1, &dark) || fit_plane(s, b, is_dark, 0, &light)) return;
        size_t changed = 0;
        for (int y = b->y0; y < b->y1; ++y)
            for (int x = b->x0; x < b->x1; ++x) {
                size_t k = (size_t)y * b->w + x;
                if (!within(b, x, y, WALL_BAND_PX)) continue;
                unsigned char d = s->v[k] <= 0.5 * (plane_at(&dark, b, x, y) + plane_at(&light, b, x, y));
                changed += d != is_dark[k];
                is_dark[k] = d;
            }
        if (changed == 0) return;
    }
}

// The powder lies at the bottom of the drum: of the two tones, the one whose
// pixels lie lower on average, unless the user says which.
static int powder_is_dark(const drum_box *b, const unsigned char *is_dark, exp_powder_tone tone, double *dark_fraction)
{
    double y_sum[2] = {0}, n[2] = {0};
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x)
            if (within(b, x, y, WALL_BAND_PX)) {
                int d = is_dark[(size_t)y * b->w + x];
                y_sum[d] += y, n[d] += 1;
            }
    *dark_fraction = n[1] / fmax(1, n[0] + n[1]);
    if (tone != EXP_POWDER_AUTO) return tone == EXP_POWDER_DARK;
    return n[1] > 0 && (n[0] == 0 || y_sum[1] / n[1] > y_sum[0] / n[0]);
}

// ---------------------------------------------------------------------------
// Shape: the wall band, closing, the largest piece, its pores.

// Pixels in the band next to the wall take the class of the pixel just
// inside the band on the same radius.
static void extend_to_wall(const drum_box *b, unsigned char *powder)
{
    double inner = b->c->r - WALL_BAND_PX - 0.5;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            if (!within(b, x, y, 0) || within(b, x, y, WALL_BAND_PX)) continue;
            double dx = x + 0.5 - b->c->cx, dy = y + 0.5 - b->c->cy, scale = inner / fmax(1e-9, hypot(dx, dy));
            int xi = (int)floor(b->c->cx + dx * scale), yi = (int)floor(b->c->cy + dy * scale);
            int ok = xi >= 0 && yi >= 0 && xi < b->w && yi < b->h;
            powder[(size_t)y * b->w + x] = ok && powder[(size_t)yi * b->w + xi];
        }
}

// Keep only the largest 4-connected piece of the set pixels in the box.
static int keep_largest(const drum_box *b, unsigned char *m)
{
    size_t n = (size_t)b->w * b->h;
    int *label = calloc(n, sizeof *label);
    size_t *stack = malloc(n * sizeof *stack);
    if (!label || !stack) return free(label), free(stack), 1;
    int next = 0, best = 0;
    size_t best_size = 0;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            size_t k0 = (size_t)y * b->w + x, top = 0, size = 0;
            if (!m[k0] || label[k0]) continue;
            label[k0] = ++next, stack[top++] = k0;
            while (top) {
                size_t k = stack[--top];
                int kx = (int)(k % b->w), ky = (int)(k / b->w);
                size++;
                const int nx[4] = {kx - 1, kx + 1, kx, kx}, ny[4] = {ky, ky, ky - 1, ky + 1};
                for (int t = 0; t < 4; ++t) {
                    if (nx[t] < b->x0 || ny[t] < b->y0 || nx[t] >= b->x1 || ny[t] >= b->y1) continue;
                    size_t q = (size_t)ny[t] * b->w + nx[t];
                    if (m[q] && !label[q]) label[q] = next, stack[top++] = q;
                }
            }
            if (size > best_size) best_size = size, best = next;
        }
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) m[(size_t)y * b->w + x] = label[(size_t)y * b->w + x] == best && best;
    free(label), free(stack);
    return 0;
}

// The powder: its largest piece; then the drum's empty part is the largest
// piece of the rest, and everything else inside the drum (pores, gaps the
// closing left) is powder. Writes label[] (OUTSIDE, EMPTY, POWDER).
static int shape_powder(const drum_box *b, unsigned char *powder, int closing_px, unsigned char *label)
{
    extend_to_wall(b, powder);
    if (exp_mask_close(powder, b->w, b->h, b->x0, b->y0, b->x1, b->y1, closing_px)) return 1;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) powder[(size_t)y * b->w + x] &= (unsigned char)within(b, x, y, 0);
    if (keep_largest(b, powder)) return 1;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            size_t k = (size_t)y * b->w + x;
            powder[k] = within(b, x, y, 0) && !powder[k]; // now: not powder
        }
    if (keep_largest(b, powder)) return 1;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            size_t k = (size_t)y * b->w + x;
            label[k] = !within(b, x, y, 0) ? OUTSIDE : powder[k] ? EMPTY : POWDER;
        }
    return 0;
}

static double csa_of(const drum_box *b, const unsigned char *label)
{
    size_t inside = 0, powder = 0;
    for (int y = b->y0; y < b->y1; ++y)
        for (int x = b->x0; x < b->x1; ++x) {
            unsigned char l = label[(size_t)y * b->w + x];
            inside += l != OUTSIDE, powder += l == POWDER;
        }
    return inside ? 100.0 * (double)powder / (double)inside : 0;
}

// ---------------------------------------------------------------------------
// The free surface.

typedef struct surface_points {
    double *x, *y; // drum coordinates, pixels, y up
    size_t *pixel;
    size_t n;
} surface_points;

// Per column, the top edge of the highest powder pixel with the drum's
// empty part right above it, over the central fraction of the powder's
// horizontal extent (as the simulation's fit: exp_raster_surface_angle),
// less the points near the wall.
static void trace_surface(const drum_box *b, const unsigned char *label, double central_fraction, surface_points *s)
{
    int first = -1, last = -1;
    for (int x = b->x0; x < b->x1; ++x)
        for (int y = b->y0; y < b->y1; ++y)
            if (label[(size_t)y * b->w + x] == POWDER) {
                if (first < 0) first = x;
                last = x;
                break;
            }
    s->n = 0;
    if (first < 0) return;
    int margin = (int)(0.5 * (1 - central_fraction) * (last - first + 1));
    double reach = (1 - SURFACE_WALL_FRACTION) * b->c->r;
    for (int x = first + margin; x <= last - margin; ++x)
        for (int y = b->y0 + 1; y < b->y1; ++y) {
            size_t k = (size_t)y * b->w + x;
            if (label[k] != POWDER) continue;
            double px = x + 0.5 - b->c->cx, py = b->c->cy - y;
            if (label[k - b->w] == EMPTY && hypot(px, py) <= reach)
                s->x[s->n] = px, s->y[s->n] = py, s->pixel[s->n++] = k;
            break;
        }
}

// y = c0 + c1·x with Tukey's biweight (GSL's robust least squares): a
// clump or a dip on the slope weighs nothing. sd: GSL's robust sigma.
static int robust_line(const surface_points *s, double *c0, double *c1, double *sd)
{
    gsl_matrix *X = gsl_matrix_alloc(s->n, 2), *cov = gsl_matrix_alloc(2, 2);
    gsl_vector *y = gsl_vector_alloc(s->n), *c = gsl_vector_alloc(2);
    gsl_multifit_robust_workspace *work = gsl_multifit_robust_alloc(gsl_multifit_robust_bisquare, s->n, 2);
    int rc = !X || !cov || !y || !c || !work;
    if (!rc) {
        for (size_t k = 0; k < s->n; ++k) {
            gsl_matrix_set(X, k, 0, 1.0), gsl_matrix_set(X, k, 1, s->x[k]);
            gsl_vector_set(y, k, s->y[k]);
        }
        gsl_error_handler_t *previous = gsl_set_error_handler_off(); // GSL_EMAXITER still leaves a usable fit
        int status = gsl_multifit_robust(X, y, c, cov, work);
        gsl_set_error_handler(previous);
        rc = status && status != GSL_EMAXITER;
        *c0 = gsl_vector_get(c, 0), *c1 = gsl_vector_get(c, 1);
        *sd = gsl_multifit_robust_statistics(work).sigma;
    }
    gsl_multifit_robust_free(work);
    gsl_matrix_free(X), gsl_matrix_free(cov), gsl_vector_free(y), gsl_vector_free(c);
    return rc;
}

static int measure_surface(const drum_box *b, const exp_photo_opts *o, exp_photo_result *out, char *err, size_t len)
{
    size_t cap = (size_t)(b->x1 - b->x0) + 1;
    surface_points s = {malloc(cap * sizeof *s.x), malloc(cap * sizeof *s.y), malloc(cap * sizeof *s.pixel), 0};
    int rc = EXP_PHOTO_NO_SURFACE;
    if (!s.x || !s.y || !s.pixel) snprintf(err, len, "out of memory"), rc = EXP_PHOTO_ERROR;
    else if (trace_surface(b, out->label, o->central_fraction, &s), s.n < MIN_SURFACE_POINTS)
        snprintf(err, len, "no free surface: the powder meets the drum's empty part in %zu columns away from the wall",
                 s.n);
    else if (robust_line(&s, &out->line_c0, &out->line_c1, &out->surface_sd_px))
        snprintf(err, len, "the line fit to the free surface failed");
    else {
        out->surface_points = (int)s.n;
        out->angle_deg = atan(out->line_c1) * 180 / DEM_PI;
        out->fit_x0 = s.x[0], out->fit_x1 = s.x[s.n - 1];
        for (size_t k = 0; k < s.n; ++k) out->label[s.pixel[k]] = SURFACE_USED;
        double limit = o->max_sd_fraction * b->c->r;
        rc = out->surface_sd_px > limit ? EXP_PHOTO_NO_SURFACE : EXP_PHOTO_OK;
        if (rc)
            snprintf(err, len,
                     "no straight free surface: the powder's upper boundary lies %.1f px about the best line "
                     "(robust sd), more than %.0f %% of the drum radius (%.1f px)",
                     out->surface_sd_px, 100 * o->max_sd_fraction, limit);
    }
    free(s.x), free(s.y), free(s.pixel);
    return rc;
}

// ---------------------------------------------------------------------------

static int circle_in_image(const exp_circle *c, int w, int h, double slack)
{
    return c->r > 1 && c->cx - c->r >= -slack && c->cy - c->r >= -slack && c->cx + c->r <= w + slack &&
           c->cy + c->r <= h + slack;
}

// The circle given, moved onto the drum's inner edge near it (a centre up
// to 3 % of R off, a radius up to 4 % off), or found.
static int locate_drum(const char *path, const exp_gray *g, const exp_circle *given, exp_circle *c, char *err,
                       size_t len)
{
    char why[512];
    if (given && !circle_in_image(given, g->w, g->h, 0.5)) {
        snprintf(err, len, "%s: the drum circle (centre %g,%g, radius %g px) must lie inside the %dx%d image", path,
                 given->cx, given->cy, given->r, g->w, g->h);
        return 1;
    }
    if (given) {
        *c = *given;
        double window = 0.04 * c->r + 3;
        if (exp_photo_refine_circle(g, c, window, window, 0.03 * c->r + 2, why, sizeof why))
            return snprintf(err, len, "%s: %s", path, why), 1;
    } else if (exp_photo_find_drum(g, c, why, sizeof why))
        return snprintf(err, len, "%s: %s; give --center X,Y --radius R", path, why), 1;
    if (!circle_in_image(c, g->w, g->h, 1.5)) {
        snprintf(err, len, "%s: the drum circle found (centre %.1f,%.1f, radius %.1f px) is not inside the %dx%d image",
                 path, c->cx, c->cy, c->r, g->w, g->h);
        return 1;
    }
    return 0;
}

static int segment(const exp_gray *g, const drum_box *b, const exp_photo_opts *o, exp_photo_result *out, char *err,
                   size_t len)
{
    size_t n = (size_t)g->w * g->h;
    exp_gray *s = exp_gray_smooth(g, CLASS_SMOOTH_PX);
    unsigned char *is_dark = calloc(n, 1);
    out->label = calloc(n, 1);
    int rc = !s || !is_dark || !out->label;
    double dark_fraction = 0;
    if (!rc) {
        split_tones(s, b, is_dark);
        out->powder_dark = powder_is_dark(b, is_dark, o->tone, &dark_fraction);
        if (!out->powder_dark)
            for (size_t k = 0; k < n; ++k) is_dark[k] = !is_dark[k];
        rc = shape_powder(b, is_dark, o->closing_px, out->label);
    }
    exp_gray_free(s);
    free(is_dark);
    if (rc) return snprintf(err, len, "out of memory"), EXP_PHOTO_ERROR;
    out->csa_percent = csa_of(b, out->label);
    if (dark_fraction < MIN_CLASS_FRACTION || dark_fraction > 1 - MIN_CLASS_FRACTION) {
        snprintf(err, len, "no free surface: the drum shows one tone only (no powder, or full)");
        return EXP_PHOTO_NO_SURFACE;
    }
    return EXP_PHOTO_OK;
}

int exp_photo_measure(const char *path, const exp_circle *given, const exp_photo_opts *o, exp_photo_result *out,
                      char *err, size_t len)
{
    memset(out, 0, sizeof *out);
    out->angle_deg = out->surface_sd_px = NAN;
    out->photo = exp_gray_read_png(path, err, len);
    if (!out->photo) return EXP_PHOTO_ERROR;
    if (locate_drum(path, out->photo, given, &out->circle, err, len)) return exp_photo_result_free(out), EXP_PHOTO_ERROR;
    drum_box b = box_of(&out->circle, out->photo->w, out->photo->h);
    char why[512] = "";
    int rc = segment(out->photo, &b, o, out, why, sizeof why);
    if (rc == EXP_PHOTO_OK) rc = measure_surface(&b, o, out, why, sizeof why);
    if (rc == EXP_PHOTO_ERROR) exp_photo_result_free(out);
    if (rc) snprintf(err, len, "%s: %s", path, why);
    return rc;
}

void exp_photo_result_free(exp_photo_result *r)
{
    exp_gray_free(r->photo);
    free(r->label);
    r->photo = NULL, r->label = NULL;
}

// ---------------------------------------------------------------------------
// The mask: what was measured, over the photograph.

static void put(unsigned char *rgb, int w, int h, double x, double y, const unsigned char c[3])
{
    int xi = (int)floor(x), yi = (int)floor(y);
    if (xi >= 0 && yi >= 0 && xi < w && yi < h) memcpy(rgb + 3 * ((size_t)yi * w + xi), c, 3);
}

static void draw_overlays(const exp_photo_result *r, unsigned char *rgb)
{
    int w = r->photo->w, h = r->photo->h;
    const unsigned char red[3] = {230, 30, 30}, green[3] = {20, 200, 40};
    const exp_circle *c = &r->circle;
    for (int k = 0, n = (int)(8 * DEM_PI * c->r); k < n; ++k) {
        double a = 2 * DEM_PI * k / n;
        put(rgb, w, h, c->cx + c->r * cos(a), c->cy + c->r * sin(a), red);
    }
    if (isnan(r->angle_deg)) return;
    // Dashed, so that the traced points (blue) show between the dashes.
    for (double x = r->fit_x0; x <= r->fit_x1; x += 0.25)
        if (fmod(x - r->fit_x0, 8) < 5) put(rgb, w, h, c->cx + x, c->cy - (r->line_c0 + r->line_c1 * x), green);
}

int exp_photo_write_mask(const char *path, const exp_photo_result *r, char *err, size_t len)
{
    int w = r->photo->w, h = r->photo->h;
    unsigned char *rgb = malloc((size_t)w * h * 3);
    if (!rgb) return snprintf(err, len, "out of memory"), 1;
    for (size_t k = 0; k < (size_t)w * h; ++k) {
        double v = 0.5 * r->photo->v[k] + 64; // dimmed, so that the marks stand out
        unsigned char *p = rgb + 3 * k, l = r->label[k];
        p[0] = p[1] = p[2] = (unsigned char)v;
        if (l == POWDER) p[0] = (unsigned char)(0.5 * v + 127), p[1] = (unsigned char)(0.5 * v + 60), p[2] = (unsigned char)(0.5 * v);
        if (l == SURFACE_USED) p[0] = 30, p[1] = 60, p[2] = 255;
    }
    draw_overlays(r, rgb);
    int rc = exp_write_png(path, rgb, w, h, 3, err, len);
    free(rgb);
    return rc;
}
