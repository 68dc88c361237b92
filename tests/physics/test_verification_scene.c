// SPDX-License-Identifier: MIT
// The paper's verification test (Appendix A.1, Table A.1), as the scene file
// configs/scenes/verification_two_particles.yaml, run by the engine and
// compared every 0.01 s with an independent integration of eq. 1–14
// (tests/support/ref_two_particles.c, which shares no code with engine/).
// Same equations and time discretisation, separate implementations: they
// must agree to far below the scale of the motion.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "exp_scene.h"
#include "ref_two_particles.c" // test support compiled into this test only

#define POSITION_TOL 1e-9 // m; the particles travel ~2 m
#define VELOCITY_TOL 1e-8 // m/s
#define SPIN_TOL 1e-6     // rad/s; particle 1 starts at 300 rad/s

static char scene_path[1024];

/// The scene as shipped, or with its lever arm replaced when `lever` is not NULL.
static dem_world *build_variant(exp_scene *s, const char *lever, dem_damping_mode damping)
{
    char *saved = s->lever_arm;
    if (lever) s->lever_arm = (char *)lever;
    char err[512];
    dem_world *w = exp_scene_build(s, err, sizeof err);
    s->lever_arm = saved;
    assert_non_null(w);
    dem_contact_params p;
    assert_int_equal(exp_contact_from_yaml(&s->granule_contact, &p, "granule_contact", err, sizeof err), 0);
    p.damping = damping;
    assert_int_equal(dem_world_set_granule_contact(w, &p), 0);
    assert_int_equal(exp_contact_from_yaml(&s->walls[0].contact, &p, "walls[0].contact", err, sizeof err), 0);
    p.damping = damping;
    assert_int_equal(dem_world_set_wall_contact(w, 0, &p), 0);
    return w;
}

static double max3(const double a[3], dem_vec3 b)
{
    return fmax(fabs(a[0] - b.x), fmax(fabs(a[1] - b.y), fabs(a[2] - b.z)));
}

/// `lever` NULL runs the scene's own lever arm, which must then be the
/// reference's `lever_option`.
static void compare(const char *lever, int lever_option, dem_damping_mode damping)
{
    char err[512];
    exp_scene *s = exp_scene_load(scene_path, err, sizeof err);
    if (!s) fail_msg("%s", err);
    if (!lever) {
        assert_non_null(s->lever_arm);
        lever = s->lever_arm;
        assert_int_equal(strcmp(lever, "radius") == 0 ? REF_LEVER_RADIUS : REF_LEVER_CONTACT_POINT, lever_option);
    }
    dem_world *w = build_variant(s, lever, damping);
    ref_options opt = ref_default_options();
    opt.lever = lever_option;
    opt.damping = (int)damping;
    opt.dt = s->dt;
    opt.duration = s->duration;
    int nframes = ref_frame_count(opt.duration);
    ref_frame *frames = calloc((size_t)nframes, sizeof *frames);
    assert_int_equal(ref_two_particles_run(&opt, frames, nframes), nframes);
    uint64_t per_frame = (uint64_t)(REF_FRAME_INTERVAL / s->dt + 0.5);
    double dx = 0, dv = 0, dw = 0;
    for (int f = 0; f < nframes; ++f) {
        if (f > 0) assert_int_equal(dem_world_step(w, per_frame), DEM_OK);
        dem_granules_view g = dem_world_granules(w);
        for (int p = 0; p < 2; ++p) {
            dx = fmax(dx, max3(frames[f].x[p], g.position[p]));
            dv = fmax(dv, max3(frames[f].v[p], g.velocity[p]));
            dw = fmax(dw, max3(frames[f].w[p], g.omega[p]));
        }
    }
    dem_granules_view g = dem_world_granules(w);
    printf("lever %-13s damping %-11s: final x1 = %.10f (reference %.10f); max |dx| %.2e m, |dv| %.2e m/s, "
           "|dw| %.2e rad/s over %d frames\n",
           lever, dem_damping_mode_name(damping), g.position[0].x, frames[nframes - 1].x[0][0], dx, dv, dw, nframes);
    assert_true(dx < POSITION_TOL);
    assert_true(dv < VELOCITY_TOL);
    assert_true(dw < SPIN_TOL);
    free(frames);
    dem_world_destroy(w);
    exp_scene_free(s);
}

/// Table A.1 as shipped: eq. 7 and 9's lever arm R_i, taken from the scene
/// file itself (the paper's verification scene verifies the paper's equations).
static void test_scene_as_shipped(void **state)
{
    (void)state;
    compare(NULL, REF_LEVER_RADIUS, DEM_DAMPING_APPROACHING);
}

static void test_other_damping_readings(void **state)
{
    (void)state;
    compare("radius", REF_LEVER_RADIUS, DEM_DAMPING_ALWAYS);
    compare("radius", REF_LEVER_RADIUS, DEM_DAMPING_SEPARATING);
    compare("radius", REF_LEVER_RADIUS, DEM_DAMPING_NO_TENSION);
}

/// The drum scenes' objective lever arm (contact point), every damping reading.
static void test_contact_point_lever_arm(void **state)
{
    (void)state;
    compare("contact_point", REF_LEVER_CONTACT_POINT, DEM_DAMPING_APPROACHING);
    compare("contact_point", REF_LEVER_CONTACT_POINT, DEM_DAMPING_ALWAYS);
    compare("contact_point", REF_LEVER_CONTACT_POINT, DEM_DAMPING_SEPARATING);
    compare("contact_point", REF_LEVER_CONTACT_POINT, DEM_DAMPING_NO_TENSION);
}

int main(void)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(scene_path, sizeof scene_path, "%s/configs/scenes/verification_two_particles.yaml", src ? src : ".");
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_scene_as_shipped),
                                       cmocka_unit_test(test_other_damping_readings),
                                       cmocka_unit_test(test_contact_point_lever_arm)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
