// SPDX-License-Identifier: MIT
// Raster measurements of the drum face (angle of repose, eq. 20 CSA).
#include "exp_face_measure.h"

#include <gsl/gsl_fit.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "dem_vec.h"

exp_raster *exp_raster_create(double radius, double pixel)
{
    if (!(radius > 0) || !(pixel > 0) || !isfinite(radius) || radius / pixel > 1e5) return NULL;
    exp_raster *r = calloc(1, sizeof *r);
    if (!r) return NULL;
    r->nx = r->ny = (int)ceil(2 * radius / pixel);
    r->x0 = r->y0 = -0.5 * r->nx * pixel;
    r->pixel = pixel;
    r->occupied = calloc((size_t)r->nx * (size_t)r->ny, 1);
    if (!r->occupied) {
        free(r);
        return NULL;
    }
    return r;
}

void exp_raster_free(exp_raster *r)
{
    if (!r) return;
    free(r->occupied);
    free(r);
}

static int clampi(int v, int lo, int hi) { return v < lo ? lo : v > hi ? hi : v; }

void exp_raster_paint_discs(exp_raster *r, size_t n, const double *x, const double *y, const double *radius)
{
    for (size_t k = 0; k < n; ++k) {
        int i0 = clampi((int)floor((x[k] - radius[k] - r->x0) / r->pixel), 0, r->nx - 1);
        int i1 = clampi((int)floor((x[k] + radius[k] - r->x0) / r->pixel), 0, r->nx - 1);
        int j0 = clampi((int)floor((y[k] - radius[k] - r->y0) / r->pixel), 0, r->ny - 1);
        int j1 = clampi((int)floor((y[k] + radius[k] - r->y0) / r->pixel), 0, r->ny - 1);
        double r2 = radius[k] * radius[k];
        for (int j = j0; j <= j1; ++j)
            for (int i = i0; i <= i1; ++i) {
                double dx = r->x0 + (i + 0.5) * r->pixel - x[k], dy = r->y0 + (j + 0.5) * r->pixel - y[k];
                if (dx * dx + dy * dy <= r2) r->occupied[(size_t)j * r->nx + i] = 1;
            }
    }
}

// Dilate (value 1) or erode (value 0) with a disc, within the box: a pixel
// becomes `value` if any pixel of the disc around it (in the box) has that value.
static int morph(unsigned char *m, int w, int h, int x0, int y0, int x1, int y1, int radius, unsigned char value)
{
    size_t n = (size_t)w * h;
    unsigned char *src = malloc(n);
    if (!src) return 1;
    memcpy(src, m, n);
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            if (src[(size_t)y * w + x] == value) continue;
            int hit = 0;
            for (int dy = -radius; dy <= radius && !hit; ++dy)
                for (int dx = -radius; dx <= radius && !hit; ++dx) {
                    int xx = x + dx, yy = y + dy;
                    if (dx * dx + dy * dy > radius * radius || xx < x0 || yy < y0 || xx >= x1 || yy >= y1) continue;
                    hit = src[(size_t)yy * w + xx] == value;
                }
            if (hit) m[(size_t)y * w + x] = value;
        }
    free(src);
    return 0;
}

int exp_mask_close(unsigned char *mask, int width, int height, int x0, int y0, int x1, int y1, int radius_px)
{
    if (radius_px <= 0) return 0;
    return morph(mask, width, height, x0, y0, x1, y1, radius_px, 1) ||
           morph(mask, width, height, x0, y0, x1, y1, radius_px, 0);
}

int exp_raster_close(exp_raster *r, int radius_px)
{
    return exp_mask_close(r->occupied, r->nx, r->ny, 0, 0, r->nx, r->ny, radius_px);
}

static int inside_circle(const exp_raster *r, int i, int j, double radius)
{
    double x = r->x0 + (i + 0.5) * r->pixel, y = r->y0 + (j + 0.5) * r->pixel;
    return x * x + y * y <= radius * radius;
}

double exp_raster_csa_percent(const exp_raster *r, double drum_radius)
{
    size_t inside = 0, occupied = 0;
    for (int j = 0; j < r->ny; ++j)
        for (int i = 0; i < r->nx; ++i) {
            if (!inside_circle(r, i, j, drum_radius)) continue;
            inside++;
            occupied += r->occupied[(size_t)j * r->nx + i];
        }
    return inside ? 100.0 * (double)occupied / (double)inside : 0.0;
}

// Height of the top of the highest occupied pixel in column i inside the
// drum, or NAN if the column is empty.
static double column_top(const exp_raster *r, int i, double drum_radius)
{
    for (int j = r->ny - 1; j >= 0; --j)
        if (r->occupied[(size_t)j * r->nx + i] && inside_circle(r, i, j, drum_radius)) return r->y0 + (j + 1) * r->pixel;
    return NAN;
}

int exp_raster_surface_angle(const exp_raster *r, double drum_radius, double central_fraction, exp_angle *out)
{
    int first = -1, last = -1;
    for (int i = 0; i < r->nx; ++i)
        if (!isnan(column_top(r, i, drum_radius))) {
            if (first < 0) first = i;
            last = i;
        }
    memset(out, 0, sizeof *out);
    if (first < 0) return 1;
    int span = last - first + 1, margin = (int)(0.5 * (1.0 - central_fraction) * span);
    double *xs = malloc((size_t)span * sizeof *xs), *ys = malloc((size_t)span * sizeof *ys);
    int m = 0;
    for (int i = first + margin; xs && ys && i <= last - margin; ++i) {
        double top = column_top(r, i, drum_radius);
        if (isnan(top)) continue;
        xs[m] = r->x0 + (i + 0.5) * r->pixel;
        ys[m++] = top;
    }
    int rc = 1;
    if (m >= 3) {
        double c0, c1, cov00, cov01, cov11, sumsq;
        gsl_fit_linear(xs, 1, ys, 1, (size_t)m, &c0, &c1, &cov00, &cov01, &cov11, &sumsq);
        out->angle_deg = atan(c1) * 180.0 / DEM_PI;
        out->residual_sd = sqrt(sumsq / m);
        out->columns = m;
        rc = 0;
    }
    free(xs);
    free(ys);
    return rc;
}
