// SPDX-License-Identifier: MIT
// The force the granules exert on a wall (dem_world_wall_force), against
// statics: a column of granules at rest on a floor presses on it with its
// whole weight; a granule held on an incline by friction and rolling
// resistance presses on it with its weight as a vector (normal and
// tangential parts together); walls that nothing touches feel nothing. The
// total survives what rebuilds the walls' near lists without a new force
// evaluation (re-sorting), a clone, and a checkpoint.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "dem_checkpoint.h"
#include "dem_vec.h"
#include "dem_world.h"

static const double G = 9.81, RHO = 1800.0, R = 1e-3;

static dem_contact_params contact(double k, double xi, double mu_s, double mu_r)
{
    return (dem_contact_params){
        .k_n = k, .k_s = k, .k_r = k, .xi = xi, .mu_s = mu_s, .mu_r = mu_r, .damping = DEM_DAMPING_ALWAYS};
}

static dem_wall_def plane(dem_vec3 point, dem_vec3 normal, dem_contact_params c, const char *name)
{
    return (dem_wall_def){.kind = DEM_WALL_PLANE, .point = point, .normal = normal, .axis = {0, 0, 1},
                          .contact = c, .name = name};
}

static double total_mass(const dem_world *w) { return dem_world_diagnose(w).mass; }

static double kinetic(const dem_world *w)
{
    dem_diagnostics d = dem_world_diagnose(w);
    return d.ke_translational + d.ke_rotational;
}

// Five granules stacked on the floor y = 0 (slightly apart), a lid far above
// and a side wall off to one side; settled by the dashpot.
static dem_world *column(int threads)
{
    dem_world_def def = dem_default_world_def();
    def.granule = contact(500, 0.7, 0.5, 0.1);
    def.domain_lo = dem_v3(-0.05, -0.01, -0.05), def.domain_hi = dem_v3(0.05, 0.1, 0.05);
    def.threads = threads;
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    dem_contact_params wc = contact(1000, 0.7, 0.5, 0.1);
    const dem_wall_def bottom = plane(dem_v3(0, 0, 0), dem_v3(0, 1, 0), wc, "floor"),
                       lid = plane(dem_v3(0, 0.05, 0), dem_v3(0, -1, 0), wc, "lid"),
                       side = plane(dem_v3(-0.01, 0, 0), dem_v3(1, 0, 0), wc, "side");
    assert_int_equal(dem_world_add_wall(w, &bottom), 0);
    assert_int_equal(dem_world_add_wall(w, &lid), 1);
    assert_int_equal(dem_world_add_wall(w, &side), 2);
    for (int k = 0; k < 5; ++k)
        assert_true(dem_world_add_granule(w, dem_v3(0, R * (1.0 + 2.02 * k), 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R,
                                          RHO) >= 0);
    return w;
}

static void settle(dem_world *w, double seconds)
{
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    assert_int_equal(dem_world_step(w, (uint64_t)(seconds / dem_world_dt(w))), DEM_OK);
}

static void assert_vec_equal(dem_vec3 a, dem_vec3 b)
{
    assert_true(a.x == b.x && a.y == b.y && a.z == b.z);
}

static void test_column_floor_carries_the_weight(void **state)
{
    (void)state;
    dem_world *w = column(1);
    dem_vec3 f0 = dem_world_wall_force(w, 0);
    assert_true(f0.x == 0 && f0.y == 0 && f0.z == 0); // before any evaluation
    settle(w, 0.5);
    const double weight = total_mass(w) * G;
    dem_vec3 on_floor = dem_world_wall_force(w, 0), lid = dem_world_wall_force(w, 1), side = dem_world_wall_force(w, 2);
    printf("column of 5 at rest (KE %.3g J): floor force (%.6g, %.9g, %.6g) N, weight %.9g N, relative error %.2g\n",
           kinetic(w), on_floor.x, on_floor.y, on_floor.z, weight, fabs(-on_floor.y - weight) / weight);
    assert_true(kinetic(w) < 1e-12);
    assert_true(fabs(-on_floor.y - weight) < 1e-9 * weight); // pushes down with the whole weight
    assert_true(fabs(on_floor.x) < 1e-12 * weight && fabs(on_floor.z) < 1e-12 * weight);
    assert_true(lid.x == 0 && lid.y == 0 && lid.z == 0); // untouched
    assert_true(side.x == 0 && side.y == 0 && side.z == 0);
    dem_vec3 none = dem_world_wall_force(w, 3);
    assert_true(isnan(none.x) && isnan(none.y) && isnan(none.z));
    dem_world_destroy(w);
}

// The sum is the same bits on two threads (the column is too small for the
// engine to split it, so this also asks nothing of the thread blocks; the
// bench's N = 20 000 drum does), after re-sorting (its near lists are rebuilt
// with no new evaluation), in a clone, and from a checkpoint.
static void test_total_survives_sort_clone_checkpoint(void **state)
{
    (void)state;
    dem_world *w = column(1), *w2 = column(2);
    settle(w, 0.2), settle(w2, 0.2);
    const dem_vec3 f = dem_world_wall_force(w, 0);
    assert_vec_equal(dem_world_wall_force(w2, 0), f);
    assert_int_equal(dem_world_sort_spatially(w), DEM_OK);
    assert_vec_equal(dem_world_wall_force(w, 0), f);
    dem_world *c = dem_world_clone(w);
    assert_non_null(c);
    assert_vec_equal(dem_world_wall_force(c, 0), f);
    char path[128];
    snprintf(path, sizeof path, "test_wall_forces_%ld.h5", (long)getpid()); // in the test's working folder
    char err[512];
    assert_int_equal(dem_checkpoint_write(w, path, "column", NULL, 0, err, sizeof err), 0);
    dem_world *r = column(1); // its state is replaced by the checkpoint's
    assert_int_equal(dem_checkpoint_read(r, path, "column", NULL, 0, err, sizeof err), 0);
    unlink(path);
    assert_vec_equal(dem_world_wall_force(r, 0), f);
    // Stepped on, all three stay the same run.
    assert_int_equal(dem_world_step(w, 100), DEM_OK);
    assert_int_equal(dem_world_step(c, 100), DEM_OK);
    assert_int_equal(dem_world_step(r, 100), DEM_OK);
    assert_vec_equal(dem_world_wall_force(c, 0), dem_world_wall_force(w, 0));
    assert_vec_equal(dem_world_wall_force(r, 0), dem_world_wall_force(w, 0));
    dem_world_destroy(r), dem_world_destroy(c), dem_world_destroy(w), dem_world_destroy(w2);
}

// One granule on a plane tilted by 10°, held by sliding friction (μ_s = 0.8
// > tan 10°) and rolling resistance (μ_r = 0.5): the plane carries the
// weight as a vector, m g straight down, its tangential part m g sin 10°
// (the friction) as well as its normal part m g cos 10°. The tangential and
// rolling springs have no dashpot, so the granule keeps a small undamped
// oscillation about rest: the force is averaged over 0.05 s (~100 periods),
// sampled every step.
static void test_incline_carries_the_weight_vector(void **state)
{
    (void)state;
    const double th = 10.0 * DEM_PI / 180.0;
    dem_world_def def = dem_default_world_def();
    def.granule = contact(500, 0.7, 0.8, 0.5);
    def.domain_lo = dem_v3(-0.05, -0.05, -0.05), def.domain_hi = dem_v3(0.05, 0.05, 0.05);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    const dem_vec3 n = dem_v3(-sin(th), cos(th), 0);
    const dem_wall_def incline = plane(dem_v3(0, 0, 0), n, contact(1000, 0.7, 0.8, 0.5), "incline");
    assert_int_equal(dem_world_add_wall(w, &incline), 0);
    assert_true(dem_world_add_granule(w, dem_v3_scale(n, R), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO) >= 0);
    settle(w, 0.5);
    const dem_vec3 p0 = dem_world_granules(w).position[0];
    const uint64_t steps = (uint64_t)(0.05 / dem_world_dt(w));
    dem_vec3 f = dem_v3(0, 0, 0);
    for (uint64_t s = 0; s < steps; ++s) {
        assert_int_equal(dem_world_step(w, 1), DEM_OK);
        f = dem_v3_add(f, dem_world_wall_force(w, 0));
    }
    f = dem_v3_scale(f, 1.0 / (double)steps);
    const double m = total_mass(w), mg = m * G;
    const double slid = dem_v3_norm(dem_v3_sub(dem_world_granules(w).position[0], p0));
    const double tangential = dem_v3_dot(f, dem_v3(cos(th), sin(th), 0)), normal = -dem_v3_dot(f, n);
    printf("incline 10 deg (moved %.2g m in 0.05 s): mean force on it (%.6g, %.6g, %.3g) N against m g = %.6g N; "
           "normal %.6g (m g cos = %.6g), tangential %.6g (-m g sin = %.6g)\n",
           slid, f.x, f.y, f.z, mg, normal, mg * cos(th), tangential, -mg * sin(th));
    assert_true(slid < 1e-4 * R); // held: only the oscillation (1e-5 R measured)
    assert_true(fabs(f.z) < 1e-12 * mg);
    assert_true(dem_v3_norm(dem_v3_sub(f, dem_v3(0, -mg, 0))) < 2e-3 * mg); // 7e-4 measured: the mean of the oscillation
    assert_true(fabs(tangential + mg * sin(th)) < 2e-3 * mg); // the friction is in it
    dem_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_column_floor_carries_the_weight),
        cmocka_unit_test(test_total_survives_sort_clone_checkpoint),
        cmocka_unit_test(test_incline_carries_the_weight_vector),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
