// SPDX-License-Identifier: MIT
// The drum filled by bed volume has the fill degree's CSA; turned slowly, the
// resting bed first turns with the drum as a rigid body, so its surface angle
// grows at the drum's angular velocity (4 rpm = 24°/s) — an independent,
// kinematic check of the rotating wall, the measurement and the units. The
// start tilt turns the bed the same way, by its angle. Checking the turn's
// step against the bed's network leaves the run as it is. The MSER rule stops
// a run at the first sample where its own statement holds, and reports the
// mean from the start it names.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

#include <cmocka.h>

#include "exp_drum_config.h"
#include "exp_series.h"

// The shipped drum config with lambda and slice_depth set, its definitions,
// and its bed filled (the caller frees the config and the world).
static dem_world *filled_drum(char *lambda, char *slice_depth, exp_drum_yaml **y, exp_drum_def *d, exp_drum_run_opts *run)
{
    char path[1024], err[512];
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(path, sizeof path, "%s/configs/drum.yaml", src ? src : ".");
    char *sets[] = {lambda, slice_depth};
    *y = exp_drum_config_load(path, 2, sets, err, sizeof err);
    if (!*y) fail_msg("%s", err);
    if (exp_drum_config_defs(*y, d, run, err, sizeof err)) fail_msg("%s", err);
    dem_world *w = exp_drum_fill(d, NULL, NULL, err, sizeof err);
    if (!w) fail_msg("%s", err);
    return w;
}

static void test_fill_and_rigid_turn(void **state)
{
    (void)state;
    // A coarser bed than the shipped config (~460 granules in 3D instead of ~1140): what is
    // checked here (the fill degree, a level bed, rigid turning) does not depend on lambda.
    exp_drum_yaml *y;
    exp_drum_def d;
    exp_drum_run_opts run;
    dem_world *w = filled_drum("lambda=16384", "slice_depth=0.025", &y, &d, &run);
    double pixel = 0.25 * d.gsd.median_diameter * cbrt(d.lambda);
    exp_drum_measure m0, m1;
    assert_int_equal(exp_drum_measure_now(w, &d, pixel, d.closing_px, &m0), 0);
    printf("filled: %zu granules, CSA %.2f %% (fill degree %.0f %%), angle %.2f deg\n", dem_world_granules(w).count,
           m0.csa_percent, 100 * d.fill, m0.angle_deg);
    assert_true(fabs(m0.csa_percent - 100 * d.fill) < 1.5); // cut at centres, then settled
    // A level bed, at the resolution of its own granules: across the central
    // 60 % of the surface that the angle is fitted to (at most 0.6 D), the
    // fitted line rises less than the largest granule's diameter. At this
    // coarse lambda the largest granule (10.3 mm) is a tenth of the drum:
    // fills of seeds 1-5 gave 0.9-7.5 deg (seeds 1-3 with the previous order
    // of summation: 0.2-1.8 deg), all level to within a granule; a bed left
    // tilted or piled by a wrong fill would stand at tens of degrees.
    dem_granules_view g = dem_world_granules(w);
    double d_max = 0;
    for (size_t i = 0; i < g.count; ++i) d_max = fmax(d_max, 2 * g.radius[i]);
    const double level_deg = atan(d_max / (0.6 * d.diameter)) * 180 / DEM_PI;
    printf("level: %.2f deg, allowed %.2f deg (largest granule %.2f mm over 0.6 D)\n", m0.angle_deg, level_deg,
           1e3 * d_max);
    assert_true(m0.angle_deg < level_deg);
    // The start tilt (exp_drum_run_opts.start_tilt_deg) turns the bed rigidly
    // in the drum's own sense: the surface turns by as much as the turn below
    // does, the same way round, and the occupied area stays.
    dem_world *tilted = dem_world_clone(w);
    assert_non_null(tilted);
    const double tilt = exp_default_drum_run_opts().start_tilt_deg;
    assert_int_equal(exp_drum_tilt(tilted, tilt), DEM_OK);
    exp_drum_measure mt;
    assert_int_equal(exp_drum_measure_now(tilted, &d, pixel, d.closing_px, &mt), 0);
    printf("start tilt %.0f deg: surface turned %.2f deg, CSA %.2f %%\n", tilt, mt.angle_signed_deg - m0.angle_signed_deg,
           mt.csa_percent);
    assert_true(fabs(mt.angle_signed_deg - m0.angle_signed_deg - tilt) < 0.15 * tilt);
    assert_true(fabs(mt.csa_percent - m0.csa_percent) < 1.0);
    dem_world_destroy(tilted);
    assert_int_equal(dem_world_adopt_network_dt(w), DEM_OK);
    double omega = 4 * 2 * DEM_PI / 60, t = 0.4;
    dem_world_set_wall_spin(w, 0, omega);
    assert_int_equal(dem_world_step(w, (uint64_t)(t / dem_world_dt(w))), DEM_OK);
    assert_int_equal(exp_drum_measure_now(w, &d, pixel, d.closing_px, &m1), 0);
    double turned = m1.angle_signed_deg - m0.angle_signed_deg, rigid = omega * t * 180 / DEM_PI;
    printf("after %.1f s at 4 rpm: angle %.2f deg, turned %.2f deg (rigid body %.2f), CSA %.2f %%\n", t, m1.angle_deg,
           turned, rigid, m1.csa_percent);
    assert_true(fabs(turned - rigid) < 0.15 * rigid);
    assert_true(fabs(m1.csa_percent - m0.csa_percent) < 1.0);
    dem_world_destroy(w);
    exp_drum_config_free(y);
}

// The turn's checks of its step against the bed's network (issue 21) read
// the bed only: a run checked at every sample is the run never checked, bit
// for bit, as long as no check lowers the step; and they report the margin.
static void test_network_checks_leave_the_run(void **state)
{
    (void)state;
    exp_drum_yaml *y;
    exp_drum_def d;
    exp_drum_run_opts run;
    dem_world *bed = filled_drum("lambda=65536", "slice_depth=0.04", &y, &d, &run);
    run.rpm = 40, run.max_time = 1.0, run.window = 0.25;
    exp_drum_result r[2];
    for (int checked = 0; checked < 2; ++checked) {
        dem_world *w = dem_world_clone(bed);
        assert_non_null(w);
        run.network_check_interval = checked ? run.sample_interval : 0;
        assert_int_equal(exp_drum_rotate(w, &d, &run, NULL, NULL, &r[checked]), DEM_OK);
        dem_world_destroy(w);
    }
    printf("checked every sample: margin at least %.3f, lowered %d times, %.3f s of checks; angle %.17g / %.17g\n",
           r[1].dt_margin_min, r[1].dt_lowered, r[1].network_check_wall_s, r[1].angle_deg, r[0].angle_deg);
    assert_true(isnan(r[0].dt_margin_min));
    assert_true(r[1].dt_margin_min > 1);
    assert_int_equal(r[1].dt_lowered, 0);
    assert_memory_equal(&r[1].angle_deg, &r[0].angle_deg, sizeof r[0].angle_deg);
    assert_memory_equal(&r[1].csa_percent, &r[0].csa_percent, sizeof r[0].csa_percent);
    assert_int_equal(r[1].particle_steps, r[0].particle_steps);
    dem_world_destroy(bed);
    exp_drum_config_free(y);
}

typedef struct samples {
    int n;
    double angle[512], csa[512];
} samples;

static void keep_sample(int index, const exp_drum_measure *m, void *ctx)
{
    samples *s = ctx;
    if (index < 512) s->angle[index] = m->angle_deg, s->csa[index] = m->csa_percent, s->n = index + 1;
}

// The rule's statement over the first n samples (exp_drum.h, EXP_STEADY_MSER:
// MSER-5, 10 batches, at least two windows averaged): the start, or -1.
static int rule_holds(const samples *s, int n, int per_window, const exp_drum_run_opts *o)
{
    if (n < 2 * per_window) return -1;
    int la, lc;
    const int a = exp_series_mser_start(s->angle, n, 5, &la), c = exp_series_mser_start(s->csa, n, 5, &lc);
    if (a < 0 || c < 0 || la || lc) return -1;
    const int start = a > c ? a : c;
    if (n - start < 2 * per_window) return -1;
    const int ok = exp_series_batch_se(s->angle + start, n - start, 10) <= o->se_angle_deg &&
                   exp_series_batch_se(s->csa + start, n - start, 10) <= o->se_csa_percent;
    return ok ? start : -1;
}

static void test_mser_rule_stops_where_it_says(void **state)
{
    (void)state;
    exp_drum_yaml *y;
    exp_drum_def d;
    exp_drum_run_opts run;
    dem_world *bed = filled_drum("lambda=65536", "slice_depth=0.04", &y, &d, &run);
    run.rpm = 40, run.max_time = 4.0, run.window = 0.25, run.average_time = 0;
    run.steady_rule = EXP_STEADY_MSER, run.se_angle_deg = 1.0, run.se_csa_percent = 0.5;
    const int per_window = (int)(run.window / run.sample_interval + 0.5);
    for (int reachable = 1; reachable >= 0; --reachable) {
        if (!reachable) run.se_angle_deg = 1e-6; // no run this short knows its angle that well
        samples s = {0};
        run.on_sample = keep_sample, run.sample_ctx = &s;
        dem_world *w = dem_world_clone(bed);
        assert_non_null(w);
        exp_drum_result r;
        assert_int_equal(exp_drum_rotate(w, &d, &run, NULL, NULL, &r), DEM_OK);
        dem_world_destroy(w);
        printf("MSER rule, angle target %g: %d samples, steady %d, angle %.3f over the last %.2f s\n", run.se_angle_deg,
               s.n, r.steady, r.angle_deg, r.averaged_time_s);
        assert_int_equal(r.steady, reachable);
        for (int n = 1; n < s.n; ++n) assert_int_equal(rule_holds(&s, n, per_window, &run), -1); // not before
        if (!reachable) {
            assert_true(s.n * run.sample_interval > run.max_time - run.sample_interval); // turned to the end
            continue;
        }
        const int start = rule_holds(&s, s.n, per_window, &run);
        assert_true(start >= 0);
        assert_true(s.n * run.sample_interval < run.max_time - run.sample_interval); // stopped by the rule
        assert_true(fabs(r.angle_deg - exp_series_mean(s.angle, start, s.n)) < 1e-9);
        assert_true(fabs(r.csa_percent - exp_series_mean(s.csa, start, s.n)) < 1e-9);
        assert_true(fabs(r.averaged_time_s - (s.n - start) * run.sample_interval) < 1e-9);
    }
    dem_world_destroy(bed);
    exp_drum_config_free(y);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_fill_and_rigid_turn),
                                       cmocka_unit_test(test_network_checks_leave_the_run),
                                       cmocka_unit_test(test_mser_rule_stops_where_it_says)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
