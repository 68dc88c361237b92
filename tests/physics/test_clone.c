// SPDX-License-Identifier: MIT
// A cloned world is the same world: stepped alike, the copy and the original
// stay bitwise identical (contact history included), and neither disturbs the
// other. The drum uses this to turn one settled bed at several speeds.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "dem_world.h"

static dem_world *small_bed(void)
{
    dem_world_def def = dem_default_world_def();
    def.domain_lo = dem_v3(-0.05, -0.01, -0.05);
    def.domain_hi = dem_v3(0.05, 0.2, 0.05);
    dem_world *w = dem_world_create(&def, NULL, 0);
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .spin = 3.0, .contact = def.granule, .name = "floor"};
    floor.contact.k_n = floor.contact.k_s = floor.contact.k_r = 400;
    dem_world_add_wall(w, &floor);
    for (int i = 0; i < 200; ++i)
        dem_world_add_granule(w, dem_v3(0.004 * (i % 10) - 0.02, 0.002 + 0.0035 * (i / 50), 0.004 * ((i / 10) % 5) - 0.01),
                              dem_v3(0.01 * sin(i), 0, 0.01 * cos(i)), dem_v3(0, 0, 0), 1e-3 * (1 + 0.3 * sin(3.0 * i)), 1800);
    return w;
}

static int same(const dem_world *a, const dem_world *b)
{
    dem_granules_view x = dem_world_granules(a), y = dem_world_granules(b);
    return x.count == y.count && memcmp(x.position, y.position, x.count * sizeof *x.position) == 0 &&
           memcmp(x.velocity, y.velocity, x.count * sizeof *x.velocity) == 0 &&
           memcmp(x.omega, y.omega, x.count * sizeof *x.omega) == 0;
}

static void test_clone_steps_identically(void **state)
{
    (void)state;
    dem_world *w = small_bed();
    assert_int_equal(dem_world_step(w, 20000), DEM_OK); // in contact, springs loaded
    dem_world *c = dem_world_clone(w);
    assert_non_null(c);
    assert_true(same(w, c));
    assert_int_equal(dem_world_step(c, 5000), DEM_OK);
    assert_int_equal(dem_world_step(w, 5000), DEM_OK);
    dem_diagnostics d = dem_world_diagnose(w);
    printf("after 5000 more steps each: %zu contacts, %zu wall contacts; identical: %s\n", d.contacts,
           d.wall_contacts, same(w, c) ? "yes" : "no");
    assert_true(d.contacts > 0 && d.wall_contacts > 0);
    assert_true(same(w, c));
    // Per-granule counts follow the diagnostics' rule: they sum to 2C.
    unsigned counts[200], sum = 0;
    dem_world_contact_counts(w, counts);
    for (int i = 0; i < 200; ++i) sum += counts[i];
    assert_int_equal(sum, 2 * d.contacts);
    dem_world_destroy(w); // the clone owns its own memory
    assert_int_equal(dem_world_step(c, 100), DEM_OK);
    dem_world_destroy(c);
}

// The cost figure: each step counts the granules it moved (200 for 300
// steps, then 201 for 40), a clone starts from its source's count, and the
// count moves with neither the other's steps.
static void test_particle_steps_counted(void **state)
{
    (void)state;
    dem_world *w = small_bed();
    assert_true(dem_world_particle_steps(w) == 0);
    assert_int_equal(dem_world_step(w, 300), DEM_OK);
    assert_true(dem_world_particle_steps(w) == 300u * 200u);
    dem_world_add_granule(w, dem_v3(0, 0.1, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), 1e-3, 1800);
    assert_int_equal(dem_world_step(w, 40), DEM_OK);
    const uint64_t counted = 300u * 200u + 40u * 201u;
    assert_true(dem_world_particle_steps(w) == counted);
    dem_world *c = dem_world_clone(w);
    assert_non_null(c);
    assert_true(dem_world_particle_steps(c) == counted);
    assert_int_equal(dem_world_step(c, 10), DEM_OK);
    assert_true(dem_world_particle_steps(c) == counted + 10u * 201u);
    assert_true(dem_world_particle_steps(w) == counted);
    dem_world_destroy(c);
    dem_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_clone_steps_identically),
                                       cmocka_unit_test(test_particle_steps_counted)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
