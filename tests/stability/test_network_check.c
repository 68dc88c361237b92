// SPDX-License-Identifier: MIT
// The step checked against the network while a world runs
// (dem_world_check_network_dt; issue 21: a turning bed's contacts change, and
// the step chosen from the settled bed must stay within the limit).
//  - A check reads the world only: a run checked every few steps is the same
//    run, bit for bit, as one never checked.
//  - A network that stiffens (a granule lands on one resting on the floor: the
//    bottom one then has two springs) lowers an engine-chosen step to dt_safety of the
//    new limit. (A configured step has passed the a-priori bound of the densest
//    cluster, which no network exceeds.)
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "dem_world.h"

#define R 1e-3
#define RHO 1800.0

// A granule resting on a floor (one wall contact) and a second one falling
// onto it: the stack's bottom granule then has two springs.
static dem_world *rest_and_incoming(double dt_safety)
{
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, -9.81, 0);
    def.dt_safety = dt_safety;
    def.domain_lo = dem_v3(-0.02, -0.001, -0.02);
    def.domain_hi = dem_v3(0.02, 0.04, 0.02);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .contact = def.granule, .name = "floor"};
    floor.point = dem_v3(0, 0, 0), floor.normal = dem_v3(0, 1, 0);
    assert_true(dem_world_add_wall(w, &floor) >= 0);
    assert_true(dem_world_add_granule(w, dem_v3(0, 0.999 * R, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO) >= 0);
    assert_true(dem_world_add_granule(w, dem_v3(0, 3.5 * R, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO) >= 0);
    return w;
}

static unsigned contacts(const dem_world *w) { return (unsigned)dem_world_diagnose(w).contacts; }

// The step for the granule on the floor alone (the other one still falling).
static void adopt_first_network(dem_world *w)
{
    dem_status st = dem_world_adopt_network_dt(w);
    if (st != DEM_OK) fail_msg("%s", dem_world_error(w));
    assert_int_equal(contacts(w), 0);
    assert_int_equal((int)dem_world_diagnose(w).wall_contacts, 1);
}

static void test_a_check_reads_only(void **state)
{
    (void)state;
    // At half the limit: room for the stack's stiffer network (margin 0.66 at 0.99).
    dem_world *checked = rest_and_incoming(0.5), *plain = rest_and_incoming(0.5);
    adopt_first_network(checked), adopt_first_network(plain);
    double least = INFINITY;
    for (int k = 0; k < 400; ++k) {
        assert_int_equal(dem_world_step(checked, 25), DEM_OK);
        assert_int_equal(dem_world_step(plain, 25), DEM_OK);
        dem_network_dt_check c;
        assert_int_equal(dem_world_check_network_dt(checked, &c), DEM_OK);
        assert_false(isnan(c.margin));
        least = fmin(least, c.margin);
        assert_int_equal(c.lowered, 0);
    }
    printf("least margin over the run at dt_safety 0.5: %.3f\n", least);
    assert_true(least > 1);
    dem_granules_view a = dem_world_granules(checked), b = dem_world_granules(plain);
    assert_memory_equal(a.position, b.position, a.count * sizeof *a.position);
    assert_memory_equal(a.velocity, b.velocity, a.count * sizeof *a.velocity);
    assert_memory_equal(a.omega, b.omega, a.count * sizeof *a.omega);
    dem_world_destroy(checked), dem_world_destroy(plain);
}

// Step until the falling granule lands: the bottom one between two springs.
static void step_into_stack(dem_world *w)
{
    for (int k = 0; k < 100000 && contacts(w) < 1; ++k) assert_int_equal(dem_world_step(w, 1), DEM_OK);
    assert_int_equal(contacts(w), 1);
    assert_int_equal((int)dem_world_diagnose(w).wall_contacts, 1);
}

static void test_a_stiffer_network_lowers_the_step(void **state)
{
    (void)state;
    dem_world *w = rest_and_incoming(0.99); // near one contact's limit: no room for a stiffer network
    adopt_first_network(w);
    double dt_one = dem_world_dt(w);
    step_into_stack(w);
    dem_network_dt_check c;
    assert_int_equal(dem_world_check_network_dt(w, &c), DEM_OK);
    printf("one-contact step %.4g s; stack: margin %.3f, lowered %d, step now %.4g s (limit %.4g s)\n", dt_one, c.margin,
           c.lowered, dem_world_dt(w), dem_world_dt_limit(w));
    assert_true(c.margin < 1);
    assert_int_equal(c.lowered, 1);
    assert_float_equal(dem_world_dt(w), 0.99 * dem_world_dt_limit(w), 1e-12 * dt_one);
    assert_float_equal(dem_world_dt(w), 0.99 * c.margin * dt_one, 1e-12 * dt_one);
    assert_int_equal(dem_world_step(w, 2000), DEM_OK); // runs on at the new step
    assert_int_equal(dem_world_check_network_dt(w, &c), DEM_OK);
    assert_int_equal(c.lowered, 0);
    dem_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_a_check_reads_only),
                                       cmocka_unit_test(test_a_stiffer_network_lowers_the_step)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
