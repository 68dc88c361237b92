// SPDX-License-Identifier: MIT
// A world saved to a checkpoint and restored goes on bit for bit as the world
// that wrote it (contact springs, neighbour list and all), on 1 and on 2
// threads; a checkpoint of another run, of another build's layout, or a
// damaged file is refused with a reason and leaves the world as it was.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <hdf5_hl.h>

#include "dem_checkpoint.h"
#include "dem_world.h"

// Granules on a spinning floor between two side walls, rolling resistance on, with a periodic axis
// (z): springs loaded, walls and periodic pairs in the list.
static dem_world *bed(int granules, int threads)
{
    dem_world_def def = dem_default_world_def();
    def.domain_lo = dem_v3(-0.05, -0.01, 0);
    def.domain_hi = dem_v3(0.05, 0.3, 0.04);
    def.periodic_axis = 2;
    def.threads = threads;
    dem_world *w = dem_world_create(&def, NULL, 0);
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .spin = 3.0, .contact = def.granule, .name = "floor"};
    floor.contact.k_n = floor.contact.k_s = floor.contact.k_r = 400;
    dem_world_add_wall(w, &floor);
    dem_wall_def left = {.kind = DEM_WALL_PLANE, .point = {-0.048, 0, 0}, .normal = {1, 0, 0}, .axis = {1, 0, 0},
                         .contact = floor.contact, .name = "left"};
    dem_wall_def right = left;
    right.point = dem_v3(0.048, 0, 0), right.normal = dem_v3(-1, 0, 0), right.name = "right";
    dem_world_add_wall(w, &left), dem_world_add_wall(w, &right);
    for (int i = 0; i < granules; ++i)
        dem_world_add_granule(w, dem_v3(0.0045 * (i % 10) - 0.02, 0.002 + 0.0035 * (i / 50), 0.0045 * ((i / 10) % 5) + 0.01),
                              dem_v3(0.01 * sin(i), 0, 0.01 * cos(i)), dem_v3(0, 0, 0), 1e-3 * (1 + 0.3 * sin(3.0 * i)), 1800);
    return w;
}

static int same(const dem_world *a, const dem_world *b)
{
    dem_granules_view x = dem_world_granules(a), y = dem_world_granules(b);
    return x.count == y.count && dem_world_time(a) == dem_world_time(b) &&
           memcmp(x.position, y.position, x.count * sizeof *x.position) == 0 &&
           memcmp(x.velocity, y.velocity, x.count * sizeof *x.velocity) == 0 &&
           memcmp(x.omega, y.omega, x.count * sizeof *x.omega) == 0;
}

static const char *temp_path(const char *name)
{
    static char path[512];
    const char *dir = getenv("GRANUCAL_BINARY_DIR");
    snprintf(path, sizeof path, "%s/%s", dir ? dir : ".", name);
    return path;
}

static void resumes_bit_for_bit(int granules, int threads)
{
    char err[1024];
    const char *path = temp_path("test_checkpoint.h5");
    dem_world *w = bed(granules, threads);
    assert_int_equal(dem_world_step(w, 6000), DEM_OK);
    double history[3] = {1.5, -2.0, 3.25};
    dem_checkpoint_array extra = {"history", history, 3};
    assert_int_equal(dem_checkpoint_write(w, path, "the run", &extra, 1, err, sizeof err), 0);
    // The writer goes on; a fresh world of another shape takes the saved state.
    assert_int_equal(dem_world_step(w, 6000), DEM_OK);
    dem_world *r = bed(7, 1);
    dem_checkpoint_array back = {"history", NULL, 0};
    assert_int_equal(dem_checkpoint_read(r, path, "the run", &back, 1, err, sizeof err), 0);
    assert_int_equal(back.count, 3);
    assert_memory_equal(back.data, history, sizeof history);
    free(back.data);
    assert_int_equal(dem_world_step(r, 6000), DEM_OK);
    dem_diagnostics d = dem_world_diagnose(w);
    printf("%d granules, %d thread(s): %zu contacts, %zu wall contacts after 12000 steps; resumed identical: %s\n",
           granules, threads, d.contacts, d.wall_contacts, same(w, r) ? "yes" : "no");
    assert_true(d.contacts > 0 && d.wall_contacts > 0);
    assert_true(same(w, r));
    // The restored world is a world like any other: it grows and steps on.
    assert_true(dem_world_add_granule(r, dem_v3(0, 0.2, 0.02), dem_v3(0, 0, 0), dem_v3(0, 0, 0), 1e-3, 1800) >= 0);
    assert_int_equal(dem_world_step(r, 200), DEM_OK);
    dem_world_destroy(w), dem_world_destroy(r);
    remove(path);
}

static void test_resumes_bit_for_bit(void **state)
{
    (void)state;
    resumes_bit_for_bit(200, 1);
}

// Above DEM_OMP_MIN_GRANULES: the threaded step, its blocks and crossing pairs.
static void test_resumes_bit_for_bit_on_two_threads(void **state)
{
    (void)state;
    resumes_bit_for_bit(700, 2);
}

static void assert_refused(dem_world *w, const char *path, const char *key, const char *why)
{
    char err[1024] = "";
    dem_granules_view before = dem_world_granules(w);
    size_t n = before.count;
    double t = dem_world_time(w);
    assert_int_equal(dem_checkpoint_read(w, path, key, NULL, 0, err, sizeof err), -1);
    printf("refused: %s\n", err);
    assert_non_null(strstr(err, why));
    assert_int_equal(dem_world_granules(w).count, n);
    assert_true(dem_world_time(w) == t);
}

static void test_refuses_what_it_cannot_resume(void **state)
{
    (void)state;
    char err[1024];
    const char *path = temp_path("test_checkpoint_bad.h5");
    dem_world *w = bed(50, 1);
    assert_int_equal(dem_world_step(w, 100), DEM_OK);
    remove(path);
    assert_int_equal(dem_checkpoint_read(w, path, "k", NULL, 0, err, sizeof err), 1); // none yet: start afresh
    assert_int_equal(dem_checkpoint_write(w, path, "run A", NULL, 0, err, sizeof err), 0);
    assert_refused(w, path, "run B", "another run");
    // Another build's layout (as a changed struct dem_world would write).
    hid_t f = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
    assert_true(f >= 0);
    assert_true(H5LTset_attribute_string(f, "/", "layout", "granucal checkpoint format 0") >= 0);
    H5Fclose(f);
    assert_refused(w, path, "run A", "another build");
    // Not HDF5 at all (a file cut short, or another file under the name).
    FILE *junk = fopen(path, "w");
    fputs("not a checkpoint\n", junk);
    fclose(junk);
    assert_refused(w, path, "run A", "cannot open");
    // An unwritable place: the write fails with the file named, nothing left behind.
    assert_int_not_equal(dem_checkpoint_write(w, "/proc/granucal/ck.h5", "run A", NULL, 0, err, sizeof err), 0);
    assert_non_null(strstr(err, "/proc/granucal/ck.h5"));
    assert_int_equal(dem_world_step(w, 100), DEM_OK);
    dem_world_destroy(w);
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_resumes_bit_for_bit),
                                       cmocka_unit_test(test_resumes_bit_for_bit_on_two_threads),
                                       cmocka_unit_test(test_refuses_what_it_cannot_resume)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
