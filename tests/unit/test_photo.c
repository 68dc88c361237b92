// SPDX-License-Identifier: MIT
// Photograph measurement on rendered images of known answer: a drum whose
// lower half, below a line tilted by a known angle, is dark powder with
// noise and light pores, on a light drum (and the inverse). Also: the drum
// circle must lie inside the image; a file that is not a PNG is an error.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cmocka.h>
#include <math.h>
#include <png.h>

#include "dem_vec.h"
#include "exp_image.h"

#define W 600
#define CX 300.0
#define CY 310.0
#define R 250.0

// Powder below the line through the centre at `tilt` degrees (image y down).
static void render(const char *path, double tilt, int light_powder)
{
    unsigned char *px = malloc(W * W);
    double s = sin(tilt * DEM_PI / 180), c = cos(tilt * DEM_PI / 180);
    unsigned seed = 12345;
    for (int y = 0; y < W; ++y)
        for (int x = 0; x < W; ++x) {
            double dx = x + 0.5 - CX, dy = CY - (y + 0.5); // drum coordinates, y up
            seed = seed * 1103515245u + 12345u;
            int noise = (int)((seed >> 16) % 61) - 30;
            int powder = dx * dx + dy * dy <= R * R && (-s * dx + c * dy) < 0;
            int pore = powder && (seed >> 8) % 100 < 5; // 5 % light pores
            int v = powder && !pore ? 60 + noise : 200 + noise / 2;
            if (light_powder) v = 255 - v;
            px[y * W + x] = (unsigned char)v;
        }
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    img.width = img.height = W;
    img.format = PNG_FORMAT_GRAY;
    assert_true(png_image_write_to_file(&img, path, 0, px, 0, NULL));
    free(px);
}

static void measure(double tilt, int invert)
{
    char path[] = "/tmp/granucal_photo_XXXXXX", err[512];
    int fd = mkstemp(path);
    close(fd);
    render(path, tilt, invert);
    double t;
    exp_raster *r = exp_read_photo(path, CX, CY, R, invert, &t, err, sizeof err);
    if (!r) fail_msg("%s", err);
    assert_int_equal(exp_raster_close(r, 3), 0);
    exp_angle a;
    assert_int_equal(exp_raster_surface_angle(r, R, 0.6, &a), 0);
    double csa = exp_raster_csa_percent(r, R);
    printf("tilt %.1f deg%s: measured %.3f deg, CSA %.3f %% (50), Otsu threshold %.0f\n", tilt,
           invert ? " (light powder)" : "", a.angle_deg, csa, t);
    assert_true(fabs(a.angle_deg - tilt) < 0.3);
    assert_true(fabs(csa - 50.0) < 0.5);
    exp_raster_free(r);
    remove(path);
}

static void test_dark_powder(void **state)
{
    (void)state;
    measure(34.6, 0);
    measure(0.0, 0);
}

static void test_light_powder_inverted(void **state)
{
    (void)state;
    measure(31.9, 1);
}

static void test_bad_inputs(void **state)
{
    (void)state;
    char path[] = "/tmp/granucal_photo_XXXXXX", err[512];
    int fd = mkstemp(path);
    close(fd);
    render(path, 30, 0);
    assert_null(exp_read_photo(path, CX, CY, 400, 0, NULL, err, sizeof err));
    printf("circle outside: %s\n", err);
    assert_non_null(strstr(err, "inside"));
    FILE *f = fopen(path, "w");
    fputs("not a png", f);
    fclose(f);
    assert_null(exp_read_photo(path, CX, CY, R, 0, NULL, err, sizeof err));
    printf("not a PNG: %s\n", err);
    assert_non_null(strstr(err, path));
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_dark_powder), cmocka_unit_test(test_light_powder_inverted),
                                       cmocka_unit_test(test_bad_inputs)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
