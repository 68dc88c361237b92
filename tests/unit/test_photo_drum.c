// SPDX-License-Identifier: MIT
// Frames of granucal's own simulated drum rendered as pictures
// (exp_render_drum_png: granules coloured by size, the drum circle drawn
// dark on white), measured by the photograph path, against the raster the
// simulation measures itself on: a small settled bed, level and turned
// rigidly to steeper angles, so every frame has a known raster answer.
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

#include "exp_drum_config.h"
#include "exp_image.h"
#include "exp_photo.h"

#define FRAME_PX 480

static void test_rendered_frames_match_the_raster(void **state)
{
    (void)state;
    char config[1024], err[1024], dir[] = "/tmp/granucal_photo_drum_XXXXXX";
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(config, sizeof config, "%s/configs/drum.yaml", src ? src : ".");
    // The coarse bed of tests/experiments/test_drum.c (a few hundred granules), packed rather than
    // poured: filled and settled in seconds (half the pour's time).
    char *sets[] = {"lambda=16384", "slice_depth=0.025", "fill_method=pack"};
    exp_drum_yaml *y = exp_drum_config_load(config, 3, sets, err, sizeof err);
    if (!y) fail_msg("%s", err);
    exp_drum_def d;
    exp_drum_run_opts run;
    assert_int_equal(exp_drum_config_defs(y, &d, &run, err, sizeof err), 0);
    dem_world *w = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
    if (!w) fail_msg("%s", err);
    assert_non_null(mkdtemp(dir));
    // The picture's scale (exp_render_drum_png draws 2.1 drum radii across FRAME_PX).
    double radius_m = 0.5 * d.diameter, scale = FRAME_PX / (2.1 * radius_m), pixel = 0.25 * d.gsd.median_diameter * cbrt(d.lambda);
    // Closing as the simulation's raster: closing_px of its pixels, in the picture's pixels.
    exp_photo_opts o = exp_default_photo_opts();
    o.closing_px = (int)lround(d.closing_px * pixel * scale);
    o.max_sd_fraction = 0.15; // granules a tenth of the drum across: the surface is as rough as they are
    const double tilts[] = {0, 20, 35};
    for (int k = 0; k < 3; ++k) {
        dem_world *frame = dem_world_clone(w);
        assert_non_null(frame);
        assert_int_equal(exp_drum_tilt(frame, tilts[k]), DEM_OK);
        exp_drum_measure raster;
        assert_int_equal(exp_drum_measure_now(frame, &d, pixel, d.closing_px, &raster), 0);
        char path[1100];
        snprintf(path, sizeof path, "%s/frame%d.png", dir, k);
        if (exp_render_drum_png(path, frame, radius_m, FRAME_PX, EXP_COLOUR_SIZE, err, sizeof err)) fail_msg("%s", err);
        exp_circle given = {0.5 * FRAME_PX, 0.5 * FRAME_PX, scale * radius_m, 0};
        exp_photo_result found, refined;
        int rc_found = exp_photo_measure(path, NULL, &o, &found, err, sizeof err);
        if (rc_found) fail_msg("%s", err);
        if (exp_photo_measure(path, &given, &o, &refined, err, sizeof err)) fail_msg("%s", err);
        printf("tilt %2.0f deg: raster %6.2f deg CSA %5.2f %% | photo (circle given) %6.2f deg CSA %5.2f %% | photo "
               "(found, r %.1f of %.1f px) %6.2f deg CSA %5.2f %%, surface sd %.1f px\n",
               tilts[k], raster.angle_signed_deg, raster.csa_percent, refined.angle_deg, refined.csa_percent,
               found.circle.r, given.r, found.angle_deg, found.csa_percent, found.surface_sd_px);
        const char *keep = getenv("GRANUCAL_PHOTO_KEEP"); // DIR: the frames and their masks stay there
        if (keep) {
            char copy[1100];
            snprintf(copy, sizeof copy, "%s/drum_frame%d_mask.png", keep, k);
            assert_int_equal(exp_photo_write_mask(copy, &found, err, sizeof err), 0);
            snprintf(copy, sizeof copy, "%s/drum_frame%d.png", keep, k);
            assert_int_equal(exp_render_drum_png(copy, frame, radius_m, FRAME_PX, EXP_COLOUR_SIZE, err, sizeof err), 0);
        }
        assert_true(fabs(refined.angle_deg - raster.angle_signed_deg) < 1.0);
        assert_true(fabs(found.angle_deg - raster.angle_signed_deg) < 1.0);
        assert_true(fabs(refined.csa_percent - raster.csa_percent) < 1.0);
        assert_true(fabs(found.csa_percent - raster.csa_percent) < 1.0);
        exp_photo_result_free(&found), exp_photo_result_free(&refined);
        dem_world_destroy(frame);
        remove(path);
    }
    rmdir(dir);
    dem_world_destroy(w);
    exp_drum_config_free(y);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_rendered_frames_match_the_raster)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
