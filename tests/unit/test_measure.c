// SPDX-License-Identifier: MIT
// Raster measurements on constructed beds with known answers: a flat
// half-filled drum (0°, 50 %), the same bed tilted by a known angle, and a
// lone ring of granules (an annulus of known area).
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>
#include <math.h>

#include "exp_face_measure.h"
#include "dem_vec.h"

#define DRUM_R 0.05  // m, the paper's 100 mm drum
#define GRAIN_R 1e-3 // m
#define PIXEL 2e-4   // m: 500 pixels across the drum, 10 per granule diameter

#define FINE_R (1.5 * PIXEL) // fine granules, so the bed's edges are sharp

// Fine granules, overlapping on a square grid, filling exactly the part of
// the drum below a line through the centre tilted by `tilt_deg`: its area is
// half the drum and its surface is that line.
static size_t tilted_bed(double tilt_deg, double *x, double *y, double *r, size_t cap)
{
    double c = cos(tilt_deg * DEM_PI / 180), s = sin(tilt_deg * DEM_PI / 180), step = FINE_R;
    size_t n = 0;
    for (double v = -FINE_R; v > -DRUM_R; v -= step)
        for (double u = -DRUM_R; u <= DRUM_R; u += step) {
            double px = c * u - s * v, py = s * u + c * v;
            if (px * px + py * py > (DRUM_R - FINE_R) * (DRUM_R - FINE_R) || n == cap) continue;
            x[n] = px, y[n] = py, r[n++] = FINE_R;
        }
    return n;
}

static void measure_bed(double tilt, double *csa, exp_angle *angle)
{
    size_t cap = 200000;
    double *x = malloc(cap * sizeof *x), *y = malloc(cap * sizeof *y), *r = malloc(cap * sizeof *r);
    size_t n = tilted_bed(tilt, x, y, r, cap);
    exp_raster *img = exp_raster_create(DRUM_R, PIXEL);
    assert_non_null(img);
    exp_raster_paint_discs(img, n, x, y, r);
    assert_int_equal(exp_raster_close(img, 3), 0);
    *csa = exp_raster_csa_percent(img, DRUM_R);
    assert_int_equal(exp_raster_surface_angle(img, DRUM_R, 0.6, angle), 0);
    exp_raster_free(img);
    free(x), free(y), free(r);
}

static void test_flat_half_filled(void **state)
{
    (void)state;
    double csa;
    exp_angle a;
    measure_bed(0.0, &csa, &a);
    printf("flat bed: CSA %.3f %% (50 expected), angle %.4f deg (spread %.2e m, %d columns)\n", csa, a.angle_deg,
           a.residual_sd, a.columns);
    // Pixels straddling the chord and the wall: about one pixel of perimeter.
    assert_true(fabs(csa - 50.0) < 0.5);
    assert_true(fabs(a.angle_deg) < 0.1);
}

static void test_tilted_bed_gives_its_angle(void **state)
{
    (void)state;
    const double tilts[] = {20.0, 34.6, -31.9};
    for (int k = 0; k < 3; ++k) {
        double csa;
        exp_angle a;
        measure_bed(tilts[k], &csa, &a);
        printf("tilted %.1f deg: measured %.3f deg, CSA %.2f %%\n", tilts[k], a.angle_deg, csa);
        // A staircase of pixels along a tilted line: about one pixel over the fitted chord.
        assert_true(fabs(a.angle_deg - tilts[k]) < 0.5);
        assert_true(fabs(csa - 50.0) < 0.5);
    }
}

static void test_ring_area(void **state)
{
    (void)state;
    // A lone ring of separate granules (gaps of 0.2 r): the area is exactly
    // n·π·r², i.e. n·r²/R² of the drum, up to the pixelisation of the discs.
    const double rho = 0.03;
    int n = (int)(2 * DEM_PI * rho / (2.2 * GRAIN_R));
    double *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y), *r = malloc(n * sizeof *r);
    for (int k = 0; k < n; ++k) x[k] = rho * cos(2 * DEM_PI * k / n), y[k] = rho * sin(2 * DEM_PI * k / n), r[k] = GRAIN_R;
    exp_raster *img = exp_raster_create(DRUM_R, PIXEL / 2);
    exp_raster_paint_discs(img, (size_t)n, x, y, r);
    double csa = exp_raster_csa_percent(img, DRUM_R), expected = 100.0 * n * GRAIN_R * GRAIN_R / (DRUM_R * DRUM_R);
    printf("ring of %d granules: CSA %.4f %% (exact %.4f %%)\n", n, csa, expected);
    assert_true(fabs(csa - expected) < 0.01 * expected);
    exp_raster_free(img);
    free(x), free(y), free(r);
}

static void test_closing_fills_pores(void **state)
{
    (void)state;
    // Touching granules on a square grid leave pores (π/4 of the square is
    // covered); closing with a disc wider than the pores fills them, without
    // growing the bed's outline.
    double x[400], y[400], r[400];
    int n = 0;
    for (int i = 0; i < 20; ++i)
        for (int j = 0; j < 20; ++j) x[n] = (2 * i - 19) * GRAIN_R, y[n] = (2 * j - 19) * GRAIN_R, r[n++] = GRAIN_R;
    exp_raster *img = exp_raster_create(DRUM_R, PIXEL / 2);
    exp_raster_paint_discs(img, (size_t)n, x, y, r);
    double square = 100.0 * (40 * GRAIN_R) * (40 * GRAIN_R) / (DEM_PI * DRUM_R * DRUM_R);
    double before = exp_raster_csa_percent(img, DRUM_R);
    assert_int_equal(exp_raster_close(img, 4), 0);
    double after = exp_raster_csa_percent(img, DRUM_R);
    printf("square of touching granules: %.3f %% open, %.3f %% closed; the square is %.3f %%, pi/4 of it %.3f %%\n",
           before, after, square, square * DEM_PI / 4);
    assert_true(fabs(before - square * DEM_PI / 4) < 0.02 * square);
    // Closed: the pores are gone; the scallops of the outline stay (a disc
    // of 4 pixels cannot enter them), at most 1 - π/4 of a border strip.
    assert_true(after > before + 0.15 * square && after <= square * 1.001);
    exp_raster_free(img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_flat_half_filled),
                                       cmocka_unit_test(test_tilted_bed_gives_its_angle),
                                       cmocka_unit_test(test_ring_area), cmocka_unit_test(test_closing_fills_pores)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
