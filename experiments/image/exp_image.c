// SPDX-License-Identifier: MIT
// PNG in and out with libpng's simplified API.
#include "exp_image.h"

#include <math.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int exp_write_png(const char *path, const unsigned char *pixels, int w, int h, int channels, char *err, size_t len)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = (png_uint_32)w;
    img.height = (png_uint_32)h;
    img.format = channels == 3 ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    if (!png_image_write_to_file(&img, tmp, 0, pixels, 0, NULL) || rename(tmp, path) != 0) {
        snprintf(err, len, "cannot write '%s': %s", path, img.message[0] ? img.message : "rename failed");
        remove(tmp);
        return 1;
    }
    return 0;
}

// A blue-to-red ramp for t in [0, 1].
static void ramp(double t, unsigned char rgb[3])
{
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    rgb[0] = (unsigned char)(255 * t);
    rgb[1] = (unsigned char)(255 * (1 - fabs(2 * t - 1)) * 0.8);
    rgb[2] = (unsigned char)(255 * (1 - t));
}

static void disc(unsigned char *px, int width, double cx, double cy, double r, const unsigned char rgb[3])
{
    int x0 = (int)floor(cx - r), x1 = (int)ceil(cx + r), y0 = (int)floor(cy - r), y1 = (int)ceil(cy + r);
    for (int y = y0 < 0 ? 0 : y0; y <= y1 && y < width; ++y)
        for (int x = x0 < 0 ? 0 : x0; x <= x1 && x < width; ++x)
            if ((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy) <= r * r)
                memcpy(px + 3 * ((size_t)y * width + x), rgb, 3);
}

int exp_render_drum_png(const char *path, const dem_world *w, double drum_radius, int width, exp_colour_by colour,
                        char *err, size_t len)
{
    unsigned char *px = malloc((size_t)width * width * 3);
    if (!px) return snprintf(err, len, "out of memory"), 1;
    memset(px, 255, (size_t)width * width * 3);
    double scale = width / (2.1 * drum_radius), c = 0.5 * width;
    const unsigned char wall[3] = {60, 60, 60};
    for (int k = 0; k < 4 * width; ++k) { // the drum circle
        double a = 2 * DEM_PI * k / (4 * width);
        disc(px, width, c + scale * drum_radius * cos(a), c - scale * drum_radius * sin(a), 1.0, wall);
    }
    dem_granules_view g = dem_world_granules(w);
    double lo = INFINITY, hi = 0;
    for (size_t i = 0; i < g.count; ++i) {
        double v = colour == EXP_COLOUR_SIZE ? g.radius[i] : dem_v3_norm(g.velocity[i]);
        lo = fmin(lo, v), hi = fmax(hi, v);
    }
    for (size_t i = 0; i < g.count; ++i) {
        double v = colour == EXP_COLOUR_SIZE ? g.radius[i] : dem_v3_norm(g.velocity[i]);
        unsigned char rgb[3];
        ramp(hi > lo ? (v - lo) / (hi - lo) : 0.5, rgb);
        disc(px, width, c + scale * g.position[i].x, c - scale * g.position[i].y, scale * g.radius[i], rgb);
    }
    int rc = exp_write_png(path, px, width, width, 3, err, len);
    free(px);
    return rc;
}

int exp_otsu_threshold(const unsigned long hist[256])
{
    unsigned long total = 0;
    double sum = 0;
    for (int k = 0; k < 256; ++k) total += hist[k], sum += (double)k * hist[k];
    double sum_b = 0, best = -1;
    unsigned long w_b = 0;
    int threshold = 128;
    for (int k = 0; k < 256; ++k) {
        w_b += hist[k];
        if (w_b == 0 || w_b == total) continue;
        sum_b += (double)k * hist[k];
        double m_b = sum_b / w_b, m_f = (sum - sum_b) / (total - w_b);
        double between = (double)w_b * (total - w_b) * (m_b - m_f) * (m_b - m_f);
        if (between > best) best = between, threshold = k;
    }
    return threshold;
}

unsigned char *exp_read_gray_png(const char *path, int *w, int *h, char *err, size_t len)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) {
        snprintf(err, len, "%s: cannot read as PNG: %s", path, img.message);
        return NULL;
    }
    img.format = PNG_FORMAT_GRAY;
    unsigned char *gray = malloc(PNG_IMAGE_SIZE(img));
    if (!gray || !png_image_finish_read(&img, NULL, gray, 0, NULL)) {
        snprintf(err, len, "%s: cannot decode: %s", path, gray ? img.message : "out of memory");
        free(gray);
        png_image_free(&img);
        return NULL;
    }
    *w = (int)img.width, *h = (int)img.height;
    return gray;
}

exp_raster *exp_read_photo(const char *path, double cx, double cy, double radius, int invert, double *threshold,
                           char *err, size_t len)
{
    int w, h;
    unsigned char *gray = exp_read_gray_png(path, &w, &h, err, len);
    if (!gray) return NULL;
    if (!(radius > 1) || cx - radius < -0.5 || cy - radius < -0.5 || cx + radius > w + 0.5 || cy + radius > h + 0.5) {
        snprintf(err, len, "%s: the drum circle (centre %g,%g, radius %g px) must lie inside the %dx%d image", path,
                 cx, cy, radius, w, h);
        free(gray);
        return NULL;
    }
    exp_raster *r = exp_raster_create(radius, 1.0);
    unsigned long hist[256] = {0};
    for (int j = 0; r && j < r->ny; ++j)
        for (int i = 0; i < r->nx; ++i) {
            double x = r->x0 + i + 0.5, y = r->y0 + j + 0.5; // drum coordinates, y up
            int px = (int)floor(cx + x), py = (int)floor(cy - y);
            if (x * x + y * y > radius * radius || px < 0 || py < 0 || px >= w || py >= h) continue;
            hist[gray[(size_t)py * w + px]]++;
        }
    int t = exp_otsu_threshold(hist);
    for (int j = 0; r && j < r->ny; ++j)
        for (int i = 0; i < r->nx; ++i) {
            double x = r->x0 + i + 0.5, y = r->y0 + j + 0.5;
            int px = (int)floor(cx + x), py = (int)floor(cy - y);
            if (x * x + y * y > radius * radius || px < 0 || py < 0 || px >= w || py >= h) continue;
            int dark = gray[(size_t)py * w + px] <= t;
            r->occupied[(size_t)j * r->nx + i] = (unsigned char)(invert ? !dark : dark);
        }
    free(gray);
    if (!r) snprintf(err, len, "out of memory");
    if (threshold) *threshold = t;
    return r;
}

int exp_write_raster_png(const char *path, const exp_raster *r, char *err, size_t len)
{
    unsigned char *px = malloc((size_t)r->nx * r->ny);
    if (!px) return snprintf(err, len, "out of memory"), 1;
    for (int j = 0; j < r->ny; ++j)
        for (int i = 0; i < r->nx; ++i) px[(size_t)(r->ny - 1 - j) * r->nx + i] = r->occupied[(size_t)j * r->nx + i] ? 0 : 255;
    int rc = exp_write_png(path, px, r->nx, r->ny, 1, err, len);
    free(px);
    return rc;
}
