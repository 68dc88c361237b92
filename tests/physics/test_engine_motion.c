// SPDX-License-Identifier: MIT
// The engine owns a run's motion and its step safety (issue 38):
//  - a wall with a prescribed translation (dem_wall_def.motion) is where its
//    law says after N steps, one addition of its step displacement a step,
//    whether the N steps are one call (on the team of threads) or N calls,
//    and the bed under it is the same bits as a bed whose caller moved the
//    wall by hand before each single step (as the compression once did);
//    with no step displacement it moves at velocity × dt;
//  - the world's own network checks (dem_world_def.network_check_interval)
//    fall on the steps their schedule names, whatever the calls: a run
//    checked by the engine is the same bits as one whose caller checked by
//    hand at those steps (as the drum once did), on a bed whose stiffening
//    network lowers the step; the schedule goes through a checkpoint.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_checkpoint.h"
#include "dem_world.h"

#define R 1e-3
#define RHO 1800.0

static int same_granules(const dem_world *a, const dem_world *b)
{
    dem_granules_view x = dem_world_granules(a), y = dem_world_granules(b);
    return x.count == y.count && dem_world_time(a) == dem_world_time(b) && dem_world_dt(a) == dem_world_dt(b) &&
           memcmp(x.position, y.position, x.count * sizeof *x.position) == 0 &&
           memcmp(x.velocity, y.velocity, x.count * sizeof *x.velocity) == 0 &&
           memcmp(x.omega, y.omega, x.count * sizeof *x.omega) == 0;
}

// ------------------------------------------------------ prescribed motion ---

#define BED 900 // above the engine's threshold for a team of threads (512)

// A box of granules on a floor under a piston (wall 1) a little above them,
// on `threads` threads, prepared.
static dem_world *bed_under_piston(int threads)
{
    dem_world_def def = dem_default_world_def();
    def.domain_lo = dem_v3(-0.05, -0.01, -0.05), def.domain_hi = dem_v3(0.05, 0.1, 0.05);
    def.threads = threads;
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .normal = {0, 1, 0}, .axis = {0, 1, 0}, .contact = def.granule,
                          .name = "floor"};
    dem_wall_def piston = floor;
    piston.point = dem_v3(0, 0.0092, 0), piston.normal = dem_v3(0, -1, 0), piston.name = "piston";
    assert_int_equal(dem_world_add_wall(w, &floor), 0);
    assert_int_equal(dem_world_add_wall(w, &piston), 1);
    for (int i = 0; i < BED; ++i)
        assert_true(dem_world_add_granule(w, dem_v3(0.0022 * (i % 15) - 0.016, 0.0011 + 0.00215 * (i / 225),
                                                    0.0022 * ((i / 15) % 15) - 0.016),
                                          dem_v3(0.01 * sin(i), 0, 0.01 * cos(i)), dem_v3(0, 0, 0),
                                          R * (1 + 0.05 * sin(3.0 * i)), RHO) >= 0);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    return w;
}

static const double SPEED = 0.05;

// The piston's displacement per step as the compression computes it: its own
// product, which velocity × dt would round otherwise.
static double travel_of(const dem_world *w) { return 3.0 * (SPEED / 3.0 * dem_world_dt(w)); }

// N steps of the piston driven down by the engine, in calls of `per_call`.
static void drive_engine(dem_world *w, uint64_t n, uint64_t per_call)
{
    const double travel = travel_of(w);
    assert_int_equal(dem_world_set_wall_translation(w, 1, dem_v3(0, -SPEED, 0), dem_v3(0, -travel, 0)), DEM_OK);
    for (uint64_t done = 0; done < n; done += per_call) assert_int_equal(dem_world_step(w, per_call), DEM_OK);
}

// N single steps with the piston moved and given its velocity by hand.
static void drive_by_hand(dem_world *w, uint64_t n)
{
    const double travel = travel_of(w);
    dem_vec3 p = dem_world_wall(w, 1)->point;
    for (uint64_t s = 0; s < n; ++s) {
        p.y += -travel;
        assert_int_equal(dem_world_set_wall_point(w, 1, p), DEM_OK);
        assert_int_equal(dem_world_set_wall_velocity(w, 1, dem_v3(0, -SPEED, 0)), DEM_OK);
        assert_int_equal(dem_world_step(w, 1), DEM_OK);
    }
}

static void test_a_driven_wall_is_where_its_law_says(void **state)
{
    (void)state;
    for (int threads = 1; threads <= 2; ++threads) {
        dem_world *one_call = bed_under_piston(threads), *single = bed_under_piston(threads),
                  *by_hand = bed_under_piston(threads);
        // 1.5 mm of travel: onto the bed (settling, its top falls from 8.6 to
        // about 8.1 mm), and several list rebuilds (half a skin is 0.19 mm).
        const uint64_t n = (uint64_t)(1.5e-3 / (SPEED * dem_world_dt(one_call)));
        const double y0 = dem_world_wall(one_call, 1)->point.y, travel = travel_of(one_call);
        drive_engine(one_call, n, n);
        drive_engine(single, n, 1);
        drive_by_hand(by_hand, n);
        double y = y0; // the law: a running sum, one addition a step
        for (uint64_t s = 0; s < n; ++s) y += -travel;
        const dem_wall_def *a = dem_world_wall(one_call, 1), *b = dem_world_wall(single, 1),
                           *c = dem_world_wall(by_hand, 1);
        printf("%d thread(s): piston from %.9g to %.9g m after %llu steps (law %.9g); wall force %.6g N; list "
               "rebuilds %llu\n",
               threads, y0, a->point.y, (unsigned long long)n, y, dem_world_wall_force(one_call, 1).y,
               (unsigned long long)dem_world_diagnose(one_call).list_rebuilds);
        assert_memory_equal(&a->point, &c->point, sizeof a->point);
        assert_memory_equal(&b->point, &c->point, sizeof b->point);
        assert_true(a->point.y == y && a->point.x == 0 && a->point.z == 0);
        assert_true(a->velocity.y == -SPEED);
        assert_true(dem_world_wall_force(one_call, 1).y > 0); // the piston has met the bed
        assert_true(same_granules(one_call, by_hand));
        assert_true(same_granules(single, by_hand));
        dem_vec3 fa = dem_world_wall_force(one_call, 1), fc = dem_world_wall_force(by_hand, 1);
        assert_memory_equal(&fa, &fc, sizeof fa);
        // Stopped, it stays.
        assert_int_equal(dem_world_stop_wall(one_call, 1), DEM_OK);
        assert_int_equal(dem_world_step(one_call, 50), DEM_OK);
        assert_true(dem_world_wall(one_call, 1)->point.y == y);
        assert_true(dem_world_wall(one_call, 1)->velocity.y == 0 && !signbit(dem_world_wall(one_call, 1)->velocity.y));
        dem_world_destroy(one_call), dem_world_destroy(single), dem_world_destroy(by_hand);
    }
}

static void test_a_law_without_a_step_displacement_moves_at_velocity_dt(void **state)
{
    (void)state;
    dem_world *w = bed_under_piston(1);
    const dem_vec3 v = dem_v3(0, 0.01, 0); // up, away from the bed
    dem_vec3 p = dem_world_wall(w, 1)->point;
    assert_int_equal(dem_world_set_wall_translation(w, 1, v, dem_v3(0, 0, 0)), DEM_OK);
    assert_int_equal(dem_world_step(w, 100), DEM_OK);
    for (int s = 0; s < 100; ++s) p.y += v.y * dem_world_dt(w);
    assert_memory_equal(&p, &dem_world_wall(w, 1)->point, sizeof p);
    // A bad law is refused, the wall left as it was.
    assert_int_equal(dem_world_set_wall_translation(w, 1, v, dem_v3(NAN, 0, 0)), DEM_ERR_INVALID);
    assert_int_equal(dem_world_set_wall_translation(w, 2, v, dem_v3(0, 0, 0)), DEM_ERR_INVALID);
    assert_int_equal(dem_world_stop_wall(w, 5), DEM_ERR_INVALID);
    dem_world_destroy(w);
}

// ------------------------------------------------- scheduled network checks ---

// A granule resting on a floor and a second one falling onto it (as
// tests/stability/test_network_check.c): at dt_safety 0.99 of the first
// network's limit, the stack's stiffer network needs a lower step.
static dem_world *rest_and_incoming_at(double dt_safety)
{
    dem_world_def def = dem_default_world_def();
    def.dt_safety = dt_safety;
    def.domain_lo = dem_v3(-0.02, -0.001, -0.02);
    def.domain_hi = dem_v3(0.02, 0.04, 0.02);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .normal = {0, 1, 0}, .contact = def.granule, .name = "floor"};
    assert_true(dem_world_add_wall(w, &floor) >= 0);
    assert_true(dem_world_add_granule(w, dem_v3(0, 0.999 * R, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO) >= 0);
    assert_true(dem_world_add_granule(w, dem_v3(0, 3.5 * R, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), R, RHO) >= 0);
    assert_int_equal(dem_world_adopt_network_dt(w), DEM_OK);
    return w;
}

static dem_world *rest_and_incoming(void) { return rest_and_incoming_at(0.99); }

// A chunk of simulated time (the drum's sample) and the interval, 4 chunks.
static const double CHUNK_S = 4e-4, INTERVAL_S = 1.6e-3;

static uint64_t chunk_steps(const dem_world *w) { return (uint64_t)(CHUNK_S / dem_world_dt(w) + 0.5); }

// The schedule by hand, as the drum kept it: a check after every 4th chunk,
// the chunk re-derived from the step after a lowering.
static int run_checked_by_hand(dem_world *w, int chunks)
{
    int lowered = 0;
    for (int k = 1; k <= chunks; ++k) {
        assert_int_equal(dem_world_step(w, chunk_steps(w)), DEM_OK);
        if (k % 4) continue;
        dem_network_dt_check c;
        assert_int_equal(dem_world_check_network_dt(w, &c), DEM_OK);
        lowered += c.lowered;
    }
    return lowered;
}

static void test_the_world_checks_its_step_on_schedule(void **state)
{
    (void)state;
    const int chunks = 120; // ~ 0.05 s: the falling granule lands (~ 0.03 s)
    dem_world *by_hand = rest_and_incoming(), *engine = rest_and_incoming(), *ragged = rest_and_incoming();
    const double dt0 = dem_world_dt(engine);
    const int lowered = run_checked_by_hand(by_hand, chunks);
    assert_int_equal(dem_world_set_network_check(engine, INTERVAL_S, CHUNK_S), DEM_OK);
    assert_int_equal(dem_world_set_network_check(ragged, INTERVAL_S, CHUNK_S), DEM_OK);
    for (int k = 0; k < chunks; ++k) assert_int_equal(dem_world_step(engine, chunk_steps(engine)), DEM_OK);
    // The same steps in calls that ignore the chunks: the checks fall on the
    // same steps (the call is cut where one is due), lowerings and all. Each
    // call's steps at the step of the engine world at the same moment.
    dem_world *pace = rest_and_incoming();
    assert_int_equal(dem_world_set_network_check(pace, INTERVAL_S, CHUNK_S), DEM_OK);
    uint64_t total = 0;
    for (int k = 0; k < chunks; ++k) {
        const uint64_t c = chunk_steps(pace);
        assert_int_equal(dem_world_step(pace, c), DEM_OK);
        total += c;
    }
    for (uint64_t done = 0, call = 7; done < total; done += call, call = call % 13 + 5)
        assert_int_equal(dem_world_step(ragged, call < total - done ? call : total - done), DEM_OK);
    const dem_network_checks k = dem_world_network_checks(engine);
    printf("step %.4g s -> %.4g s; %llu checks, %llu lowered (by hand: %d), least margin %.3f, %.3g s in checks\n",
           dt0, dem_world_dt(engine), (unsigned long long)k.checks, (unsigned long long)k.lowered, lowered,
           k.margin_min, k.wall_s);
    assert_true(lowered >= 1);
    assert_int_equal((int)k.lowered, lowered);
    assert_int_equal((int)k.checks, chunks / 4);
    assert_true(k.margin_min < 1);
    assert_true(dem_world_dt(engine) < dt0);
    assert_true(same_granules(engine, by_hand));
    assert_true(same_granules(ragged, by_hand));
    assert_true(same_granules(pace, by_hand));
    dem_world_destroy(by_hand), dem_world_destroy(engine), dem_world_destroy(ragged), dem_world_destroy(pace);
}

static void test_checks_off_by_default_and_bad_ones_refused(void **state)
{
    (void)state;
    dem_world *w = rest_and_incoming(), *plain = rest_and_incoming();
    assert_int_equal(dem_world_step(w, 5000), DEM_OK);
    assert_int_equal(dem_world_step(plain, 5000), DEM_OK);
    dem_network_checks k = dem_world_network_checks(w);
    assert_int_equal((int)k.checks, 0);
    assert_true(isnan(k.margin_min));
    assert_int_equal(dem_world_set_network_check(w, -1, 0), DEM_ERR_INVALID);
    assert_int_equal(dem_world_set_network_check(w, 1e-3, INFINITY), DEM_ERR_INVALID);
    dem_world_def def = dem_default_world_def();
    def.network_check_interval = -0.5;
    char err[256];
    assert_null(dem_world_create(&def, err, sizeof err));
    assert_non_null(strstr(err, "network_check_interval"));
    // Checks every step in a chunk of 0 (one step), at a step with room to
    // spare for the stack (half the first network's limit): they read the
    // world only.
    dem_world *checked = rest_and_incoming_at(0.5), *unchecked = rest_and_incoming_at(0.5);
    assert_int_equal(dem_world_set_network_check(checked, dem_world_dt(checked), 0), DEM_OK);
    assert_int_equal(dem_world_step(checked, 300), DEM_OK);
    assert_int_equal(dem_world_step(unchecked, 300), DEM_OK);
    assert_int_equal((int)dem_world_network_checks(checked).checks, 300);
    assert_int_equal((int)dem_world_network_checks(checked).lowered, 0);
    assert_true(dem_world_network_checks(checked).margin_min > 1);
    assert_true(same_granules(checked, unchecked));
    dem_world_destroy(w), dem_world_destroy(plain), dem_world_destroy(checked), dem_world_destroy(unchecked);
}

// A checkpoint written between two checks resumes on the same schedule.
static void test_the_schedule_goes_through_a_checkpoint(void **state)
{
    (void)state;
    const char *dir = getenv("GRANUCAL_BINARY_DIR");
    char path[512];
    snprintf(path, sizeof path, "%s/test_engine_motion.checkpoint.h5", dir ? dir : ".");
    dem_world *a = rest_and_incoming(), *b = rest_and_incoming();
    assert_int_equal(dem_world_set_network_check(a, INTERVAL_S, CHUNK_S), DEM_OK);
    for (int k = 0; k < 62; ++k) assert_int_equal(dem_world_step(a, chunk_steps(a)), DEM_OK); // mid-interval
    char err[512];
    assert_int_equal(dem_checkpoint_write(a, path, "motion", NULL, 0, err, sizeof err), 0);
    assert_int_equal(dem_checkpoint_read(b, path, "motion", NULL, 0, err, sizeof err), 0);
    dem_checkpoint_remove(path);
    for (int k = 0; k < 58; ++k) {
        assert_int_equal(dem_world_step(a, chunk_steps(a)), DEM_OK);
        assert_int_equal(dem_world_step(b, chunk_steps(b)), DEM_OK);
    }
    dem_network_checks ka = dem_world_network_checks(a), kb = dem_world_network_checks(b);
    assert_int_equal((int)ka.checks, 30);
    assert_true(ka.checks == kb.checks && ka.lowered == kb.lowered && ka.margin_min == kb.margin_min);
    assert_true(same_granules(a, b));
    dem_world_destroy(a), dem_world_destroy(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_driven_wall_is_where_its_law_says),
        cmocka_unit_test(test_a_law_without_a_step_displacement_moves_at_velocity_dt),
        cmocka_unit_test(test_the_world_checks_its_step_on_schedule),
        cmocka_unit_test(test_checks_off_by_default_and_bad_ones_refused),
        cmocka_unit_test(test_the_schedule_goes_through_a_checkpoint),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
