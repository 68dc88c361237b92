// SPDX-License-Identifier: MIT
// The drum's circle in a photograph: found with no hint (a Hough transform),
// or moved from a circle given a few pixels off onto the drum's inner edge.
// A drum in a photograph has more than one circular edge (the inside of a
// rim or end-plate ring, its outside, the surround): the drum is the
// innermost of those concentric edges, which the powder touches.
#include "exp_photo.h"

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_vec.h"
#include "exp_image.h"

#define EDGE_SMOOTH_PX 1.5     // Gaussian sigma before edges: single-pixel pores and noise fade, rims stay
#define MIN_SUPPORT 0.25       // a drum edge is seen along at least this fraction of the rays
#define ON_CIRCLE_PX 1.5       // an edge point this close to a circle lies on it
#define RAY_STEP_PX 0.5

exp_gray *exp_gray_read_png(const char *path, char *err, size_t len)
{
    int w, h;
    unsigned char *bytes = exp_read_gray_png(path, &w, &h, err, len);
    if (!bytes) return NULL;
    exp_gray *g = calloc(1, sizeof *g);
    if (g) g->v = malloc((size_t)w * h * sizeof *g->v);
    if (!g || !g->v) {
        snprintf(err, len, "%s: cannot decode: out of memory", path);
        free(bytes);
        exp_gray_free(g);
        return NULL;
    }
    g->w = w, g->h = h;
    for (size_t k = 0; k < (size_t)w * h; ++k) g->v[k] = bytes[k];
    free(bytes);
    return g;
}

void exp_gray_free(exp_gray *g)
{
    if (!g) return;
    free(g->v);
    free(g);
}

static exp_gray *gray_new(int w, int h)
{
    exp_gray *g = calloc(1, sizeof *g);
    if (g) g->v = calloc((size_t)w * h, sizeof *g->v);
    if (!g || !g->v) return exp_gray_free(g), NULL;
    g->w = w, g->h = h;
    return g;
}

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

// One pass of a 1D Gaussian along x (dx = 1) or y (dx = 0), edges clamped.
static void blur_pass(const exp_gray *src, exp_gray *dst, const double *k, int radius, int along_x)
{
    for (int y = 0; y < src->h; ++y)
        for (int x = 0; x < src->w; ++x) {
            double sum = 0;
            for (int t = -radius; t <= radius; ++t) {
                int xx = along_x ? clampi(x + t, 0, src->w - 1) : x, yy = along_x ? y : clampi(y + t, 0, src->h - 1);
                sum += k[t + radius] * src->v[(size_t)yy * src->w + xx];
            }
            dst->v[(size_t)y * src->w + x] = (float)sum;
        }
}

exp_gray *exp_gray_smooth(const exp_gray *g, double sigma)
{
    int radius = (int)ceil(3 * sigma);
    double k[64], norm = 0;
    if (radius > 31) radius = 31;
    for (int t = -radius; t <= radius; ++t) norm += k[t + radius] = exp(-0.5 * t * t / (sigma * sigma));
    for (int t = 0; t <= 2 * radius; ++t) k[t] /= norm;
    exp_gray *tmp = gray_new(g->w, g->h), *out = gray_new(g->w, g->h);
    if (tmp && out) blur_pass(g, tmp, k, radius, 1), blur_pass(tmp, out, k, radius, 0);
    exp_gray_free(tmp);
    return out;
}

static double bilinear(const exp_gray *g, double x, double y)
{
    // Pixel centres at integer + 0.5.
    x -= 0.5, y -= 0.5;
    int i = (int)floor(x), j = (int)floor(y);
    if (i < 0 || j < 0 || i + 1 >= g->w || j + 1 >= g->h) return NAN;
    double fx = x - i, fy = y - j;
    const float *p = g->v + (size_t)j * g->w + i;
    return (1 - fy) * ((1 - fx) * p[0] + fx * p[1]) + fy * ((1 - fx) * p[g->w] + fx * p[g->w + 1]);
}

// ---------------------------------------------------------------------------
// Edge points along rays from a centre.

typedef struct edge_point {
    int ray;
    double x, y; // image coordinates
} edge_point;

typedef struct edge_set {
    edge_point *p;
    size_t n, cap;
    int rays;
} edge_set;

static int edge_push(edge_set *e, int ray, double x, double y)
{
    if (e->n == e->cap) {
        size_t cap = e->cap ? 2 * e->cap : 1024;
        edge_point *grown = realloc(e->p, cap * sizeof *grown);
        if (!grown) return 1;
        e->p = grown, e->cap = cap;
    }
    e->p[e->n++] = (edge_point){ray, x, y};
    return 0;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

// The grey level's derivative along each ray, sampled every RAY_STEP_PX
// from s0 on (NAN outside the image).
static void ray_derivatives(const exp_gray *s, double cx, double cy, double s0, int samples, int rays, float *d)
{
    double *profile = malloc((size_t)samples * sizeof *profile);
    if (!profile) return;
    for (int k = 0; k < rays; ++k) {
        double a = 2 * DEM_PI * k / rays, ca = cos(a), sa = sin(a);
        for (int i = 0; i < samples; ++i) {
            double t = s0 + i * RAY_STEP_PX;
            profile[i] = bilinear(s, cx + t * ca, cy + t * sa);
        }
        for (int i = 0; i < samples; ++i)
            d[(size_t)k * samples + i] =
                i < 2 || i + 2 >= samples ? NAN : (float)((profile[i + 2] - profile[i - 2]) / (4 * RAY_STEP_PX));
    }
    free(profile);
}

// Every local maximum of |derivative| above a threshold: a third of the
// median ray's strongest edge, so that noise and pores do not count but a
// weaker inner edge (powder against a dark rim) still does.
static int ray_edges(const exp_gray *s, double cx, double cy, double s0, double s1, edge_set *out)
{
    int samples = (int)((s1 - s0) / RAY_STEP_PX) + 1, rays = (int)fmin(2048, fmax(180, DEM_PI * 0.5 * (s0 + s1)));
    float *d = malloc((size_t)samples * rays * sizeof *d);
    double *strongest = malloc((size_t)rays * sizeof *strongest);
    if (!d || !strongest) return free(d), free(strongest), 1;
    ray_derivatives(s, cx, cy, s0, samples, rays, d);
    for (int k = 0; k < rays; ++k) {
        strongest[k] = 0;
        for (int i = 0; i < samples; ++i)
            if (fabs(d[(size_t)k * samples + i]) > strongest[k]) strongest[k] = fabs(d[(size_t)k * samples + i]);
    }
    qsort(strongest, (size_t)rays, sizeof *strongest, cmp_double);
    double threshold = fmax(1.0, strongest[rays / 2] / 3);
    out->rays = rays;
    int failed = 0;
    for (int k = 0; k < rays && !failed; ++k) {
        const float *dk = d + (size_t)k * samples;
        for (int i = 3; i + 3 < samples && !failed; ++i) {
            double m = fabs(dk[i]), before = fabs(dk[i - 1]), after = fabs(dk[i + 1]);
            if (!(m >= threshold && m >= before && m > after) || dk[i - 1] * dk[i] < 0) continue;
            double shift = 0.5 * (before - after) / (before - 2 * m + after); // parabola through the three
            double t = s0 + (i + (isfinite(shift) ? shift : 0)) * RAY_STEP_PX, a = 2 * DEM_PI * k / rays;
            failed = edge_push(out, k, cx + t * cos(a), cy + t * sin(a));
        }
    }
    free(d), free(strongest);
    return failed;
}

// ---------------------------------------------------------------------------
// The innermost well-supported circle among the edge points: a Hough
// transform over the centre's shift and the radius, one vote per ray.

typedef struct circle_votes {
    int bins;
    double r0, bin;
    int *votes, *last_ray;
} circle_votes;

static void count_votes(const edge_set *e, double cx, double cy, circle_votes *v)
{
    memset(v->votes, 0, (size_t)v->bins * sizeof *v->votes);
    for (int b = 0; b < v->bins; ++b) v->last_ray[b] = -1;
    for (size_t k = 0; k < e->n; ++k) {
        int b = (int)floor((hypot(e->p[k].x - cx, e->p[k].y - cy) - v->r0) / v->bin);
        if (b < 0 || b >= v->bins || v->last_ray[b] == e->p[k].ray) continue;
        v->last_ray[b] = e->p[k].ray;
        v->votes[b]++;
    }
}

// Rays with an edge within ON_CIRCLE_PX of radius bin b (a window of bins).
static int window_votes(const circle_votes *v, int b)
{
    int half = (int)(ON_CIRCLE_PX / v->bin), sum = 0;
    for (int t = b - half; t <= b + half; ++t)
        if (t >= 0 && t < v->bins) sum += v->votes[t];
    return sum;
}

typedef struct circle_guess {
    double cx, cy, r;
    int votes;
} circle_guess;

// The strongest circle over centre shifts of at most `shift` pixels, then,
// about its centre, the innermost radius whose votes reach MIN_SUPPORT of
// the rays and peak there.
static int vote_circle(const edge_set *e, double cx, double cy, double r_lo, double r_hi, double shift, circle_guess *out)
{
    circle_votes v = {.bin = 0.5, .r0 = r_lo};
    v.bins = (int)((r_hi - r_lo) / v.bin) + 1;
    v.votes = malloc((size_t)v.bins * sizeof *v.votes), v.last_ray = malloc((size_t)v.bins * sizeof *v.last_ray);
    if (!v.votes || !v.last_ray) return free(v.votes), free(v.last_ray), 1;
    circle_guess best = {cx, cy, 0, -1};
    int s = (int)ceil(shift);
    for (int dy = -s; dy <= s; ++dy)
        for (int dx = -s; dx <= s; ++dx) {
            count_votes(e, cx + dx, cy + dy, &v);
            for (int b = 0; b < v.bins; ++b)
                if (window_votes(&v, b) > best.votes) best = (circle_guess){cx + dx, cy + dy, 0, window_votes(&v, b)};
        }
    count_votes(e, best.cx, best.cy, &v);
    int need = (int)ceil(MIN_SUPPORT * e->rays), found = -1;
    for (int b = 0; b < v.bins && found < 0; ++b)
        if (window_votes(&v, b) >= need) found = b;
    while (found >= 0 && found + 1 < v.bins && window_votes(&v, found + 1) > window_votes(&v, found)) found++;
    if (found >= 0) best.r = v.r0 + (found + 0.5) * v.bin, best.votes = window_votes(&v, found);
    free(v.votes), free(v.last_ray);
    *out = best;
    return found < 0;
}

// x² + y² = A·x + B·y + C through the points (Kåsa's algebraic circle),
// with Tukey's biweight so that a stray edge (a pore at the wall, the rim's
// far side) does not pull it. Coordinates relative to the guess.
static int fit_circle(const double *xs, const double *ys, size_t n, const circle_guess *g, exp_circle *out)
{
    if (n < 8) return 1;
    gsl_matrix *X = gsl_matrix_alloc(n, 3);
    gsl_vector *y = gsl_vector_alloc(n), *c = gsl_vector_alloc(3);
    gsl_matrix *cov = gsl_matrix_alloc(3, 3);
    gsl_multifit_robust_workspace *work = gsl_multifit_robust_alloc(gsl_multifit_robust_bisquare, n, 3);
    int rc = !X || !y || !c || !cov || !work;
    if (!rc) {
        for (size_t k = 0; k < n; ++k) {
            double u = xs[k] - g->cx, v = ys[k] - g->cy;
            gsl_matrix_set(X, k, 0, u), gsl_matrix_set(X, k, 1, v), gsl_matrix_set(X, k, 2, 1.0);
            gsl_vector_set(y, k, u * u + v * v);
        }
        gsl_error_handler_t *previous = gsl_set_error_handler_off(); // GSL_EMAXITER still leaves a usable fit
        int status = gsl_multifit_robust(X, y, c, cov, work);
        gsl_set_error_handler(previous);
        double a = 0.5 * gsl_vector_get(c, 0), b = 0.5 * gsl_vector_get(c, 1), r2 = gsl_vector_get(c, 2) + a * a + b * b;
        rc = (status && status != GSL_EMAXITER) || !(r2 > 0);
        if (!rc) out->cx = g->cx + a, out->cy = g->cy + b, out->r = sqrt(r2);
    }
    gsl_multifit_robust_free(work);
    gsl_matrix_free(X), gsl_matrix_free(cov), gsl_vector_free(y), gsl_vector_free(c);
    return rc;
}

// Fit the circle through the edge points near a guess (the nearest per
// ray) and count the rays that see it.
static int fit_near(const edge_set *e, const circle_guess *g, exp_circle *out)
{
    double *xs = malloc((size_t)e->rays * sizeof *xs), *ys = malloc((size_t)e->rays * sizeof *ys);
    double *miss = malloc((size_t)e->rays * sizeof *miss);
    if (!xs || !ys || !miss) return free(xs), free(ys), free(miss), 1;
    for (int k = 0; k < e->rays; ++k) miss[k] = INFINITY;
    for (size_t k = 0; k < e->n; ++k) {
        double off = fabs(hypot(e->p[k].x - g->cx, e->p[k].y - g->cy) - g->r);
        int ray = e->p[k].ray;
        if (off <= ON_CIRCLE_PX && off < miss[ray]) miss[ray] = off, xs[ray] = e->p[k].x, ys[ray] = e->p[k].y;
    }
    size_t n = 0;
    for (int k = 0; k < e->rays; ++k)
        if (isfinite(miss[k])) xs[n] = xs[k], ys[n] = ys[k], n++;
    int rc = fit_circle(xs, ys, n, g, out);
    if (!rc) {
        int seen = 0;
        for (int k = 0; k < e->rays; ++k) miss[k] = INFINITY;
        for (size_t k = 0; k < e->n; ++k)
            if (fabs(hypot(e->p[k].x - out->cx, e->p[k].y - out->cy) - out->r) <= ON_CIRCLE_PX) miss[e->p[k].ray] = 0;
        for (int k = 0; k < e->rays; ++k) seen += miss[k] == 0;
        out->support = (double)seen / e->rays;
    }
    free(xs), free(ys), free(miss);
    return rc;
}

int exp_photo_refine_circle(const exp_gray *g, exp_circle *c, double inward, double outward, double shift, char *err,
                            size_t len)
{
    exp_gray *s = exp_gray_smooth(g, EDGE_SMOOTH_PX);
    edge_set e = {0};
    double r_lo = fmax(2, c->r - inward - shift), r_hi = c->r + outward + shift;
    int rc = !s || ray_edges(s, c->cx, c->cy, r_lo, r_hi, &e);
    if (rc) snprintf(err, len, "out of memory");
    circle_guess guess;
    if (!rc && (rc = vote_circle(&e, c->cx, c->cy, r_lo, r_hi, shift, &guess)) != 0)
        snprintf(err, len, "no circular edge seen along %.0f %% of the rim within %.0f px of the circle (centre %.1f,%.1f, radius %.1f px)",
                 100 * MIN_SUPPORT, fmax(inward, outward) + shift, c->cx, c->cy, c->r);
    exp_circle fitted = *c;
    if (!rc && (rc = fit_near(&e, &guess, &fitted)) != 0) snprintf(err, len, "the drum's edge points fit no circle");
    if (!rc) *c = fitted;
    free(e.p);
    exp_gray_free(s);
    return rc;
}

// ---------------------------------------------------------------------------
// The drum with no hint.

typedef struct gradient {
    float *gx, *gy, *mag;
    double threshold; // the edge pixels: magnitude at least this
} gradient;

static void gradient_free(gradient *d) { free(d->gx), free(d->gy), free(d->mag); }

// Sobel on the smoothed image; edges are the pixels above a quarter of the
// 99th percentile of the magnitude (a drum's rim is among its strongest).
static int sobel(const exp_gray *s, gradient *d)
{
    size_t n = (size_t)s->w * s->h;
    d->gx = calloc(n, sizeof *d->gx), d->gy = calloc(n, sizeof *d->gy), d->mag = calloc(n, sizeof *d->mag);
    double *sorted = malloc(n * sizeof *sorted);
    if (!d->gx || !d->gy || !d->mag || !sorted) return free(sorted), 1;
    for (int y = 1; y + 1 < s->h; ++y)
        for (int x = 1; x + 1 < s->w; ++x) {
            const float *p = s->v + (size_t)y * s->w + x;
            int w = s->w;
            double gx = (p[1 - w] + 2 * p[1] + p[1 + w]) - (p[-1 - w] + 2 * p[-1] + p[-1 + w]);
            double gy = (p[w - 1] + 2 * p[w] + p[w + 1]) - (p[-w - 1] + 2 * p[-w] + p[-w + 1]);
            size_t k = (size_t)y * s->w + x;
            d->gx[k] = (float)gx, d->gy[k] = (float)gy, d->mag[k] = (float)hypot(gx, gy);
        }
    for (size_t k = 0; k < n; ++k) sorted[k] = d->mag[k];
    qsort(sorted, n, sizeof *sorted, cmp_double);
    d->threshold = fmax(1e-3, 0.25 * sorted[(size_t)(0.99 * (n - 1))]);
    free(sorted);
    return 0;
}

// Every edge pixel votes for the points along its gradient line at the
// radii a drum may have; the drum's centre collects the votes of its whole
// rim (and of the powder's curved side), a straight edge spreads its own.
static int vote_centre(const exp_gray *s, const gradient *d, double r_min, double r_max, double *cx, double *cy)
{
    exp_gray *acc = gray_new(s->w, s->h);
    if (!acc) return 1;
    for (int y = 0; y < s->h; ++y)
        for (int x = 0; x < s->w; ++x) {
            size_t k = (size_t)y * s->w + x;
            if (d->mag[k] < d->threshold) continue;
            double ux = d->gx[k] / d->mag[k], uy = d->gy[k] / d->mag[k];
            for (double t = r_min; t <= r_max; t += 1.0)
                for (int sign = -1; sign <= 1; sign += 2) {
                    int xi = (int)lround(x + sign * t * ux), yi = (int)lround(y + sign * t * uy);
                    if (xi >= 0 && yi >= 0 && xi < s->w && yi < s->h) acc->v[(size_t)yi * s->w + xi] += 1;
                }
        }
    exp_gray *smooth = exp_gray_smooth(acc, 1.5);
    exp_gray_free(acc);
    if (!smooth) return 1;
    size_t best = 0;
    for (size_t k = 0; k < (size_t)s->w * s->h; ++k)
        if (smooth->v[k] > smooth->v[best]) best = k;
    *cx = (double)(best % s->w) + 0.5, *cy = (double)(best / s->w) + 0.5;
    exp_gray_free(smooth);
    return 0;
}

// The radius most edge pixels facing the centre lie at.
static double strongest_radius(const exp_gray *s, const gradient *d, double cx, double cy, double r_min, double r_max)
{
    int bins = (int)(r_max - r_min) + 1;
    double *count = calloc((size_t)bins, sizeof *count), best_r = NAN, best = 0;
    if (!count) return NAN;
    for (int y = 0; y < s->h; ++y)
        for (int x = 0; x < s->w; ++x) {
            size_t k = (size_t)y * s->w + x;
            double dx = x + 0.5 - cx, dy = y + 0.5 - cy, r = hypot(dx, dy);
            int b = (int)lround(r - r_min);
            if (d->mag[k] < d->threshold || b < 0 || b >= bins) continue;
            if (fabs(d->gx[k] * dx + d->gy[k] * dy) >= 0.9 * d->mag[k] * r) count[b] += 1;
        }
    for (int b = 1; b + 1 < bins; ++b) {
        double v = count[b - 1] + 2 * count[b] + count[b + 1];
        if (v > best) best = v, best_r = r_min + b;
    }
    free(count);
    return best_r;
}

int exp_photo_find_drum(const exp_gray *g, exp_circle *out, char *err, size_t len)
{
    // A drum worth measuring fills a good part of the picture, and lies inside it.
    double short_side = g->w < g->h ? g->w : g->h, r_min = 0.15 * short_side, r_max = 0.5 * short_side;
    exp_gray *s = exp_gray_smooth(g, EDGE_SMOOTH_PX);
    gradient d = {0};
    double cx = NAN, cy = NAN, r = NAN;
    int rc = !s || sobel(s, &d) || vote_centre(s, &d, r_min, r_max, &cx, &cy);
    if (!rc) r = strongest_radius(s, &d, cx, cy, r_min, r_max);
    gradient_free(&d);
    exp_gray_free(s);
    if (rc || isnan(r)) return snprintf(err, len, "no drum circle found in the image"), 1;
    *out = (exp_circle){cx, cy, r, 0};
    // The strongest circle may be a rim's outer edge: the drum is the
    // innermost one concentric with it, up to a rim of 15 % of the radius.
    return exp_photo_refine_circle(g, out, 0.15 * r + 3, 0.02 * r + 3, 0.01 * r + 2, err, len);
}
