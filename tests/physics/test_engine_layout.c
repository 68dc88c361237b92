// SPDX-License-Identifier: MIT
// The engine's memory layout is invisible to the physics (issue 7's levers):
//  - dem_world_sort_spatially moves granules, not physics: every granule keeps
//    its state by id, every spring its history (also a pair whose roles swap,
//    where the tangential spring must change sign), and the next steps give
//    bitwise the same forces for an isolated pair and rounding-level ones for
//    a loaded bed; contact partners end up close in memory;
//  - 1, 2 and 3 threads give the same bits (blocks of granules, crossing pairs
//    through slots, every granule summing in the serial order);
//  - the wall near-lists miss no contact: a granule thrown at a wall from
//    afar, across several list rebuilds, bounces; a wall added to a running
//    world acts at once;
//  - switching the tangential spring off and the rolling one on (same history
//    length) restarts the springs instead of reading one as the other;
//  - dem_world_rotate turns a loaded contact state rigidly: a pair sheared
//    against a spinning drum wall, turned about the drum axis, runs on as the
//    unturned one turned, to rounding; a refused rotation changes nothing.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>
#include <omp.h>

#include "dem_world.h"

// Index of granule `id` in a view (ids are unique), or SIZE_MAX.
static size_t index_of(const dem_granules_view *g, uint64_t id)
{
    for (size_t i = 0; i < g->count; ++i)
        if (g->id[i] == id) return i;
    return SIZE_MAX;
}

static void assert_vec_equal(dem_vec3 a, dem_vec3 b)
{
    assert_memory_equal(&a, &b, sizeof a);
}

// ------------------------------------------------------------- one pair ---

// A 2 cm box without gravity at a fixed 1 µs step, for one or two granules.
static dem_world *small_weightless_world(void)
{
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, 0);
    def.dt = 1e-6;
    def.domain_lo = dem_v3(-0.01, -0.01, -0.01);
    def.domain_hi = dem_v3(0.01, 0.01, 0.01);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    return w;
}

// Two granules pressed together and sheared, so that both springs carry load;
// the one added first lies further along the Morton curve, so sorting swaps
// their indices and with them the roles i and j of their pair.
static dem_world *sheared_pair(void)
{
    dem_world *w = small_weightless_world();
    const double r = 1e-3;
    // Centres 1.87 R apart (overlap 0.13 R), sliding past each other and spinning.
    assert_true(dem_world_add_granule(w, dem_v3(0.9 * r, 0.3 * r, 0.1 * r), dem_v3(-0.002, 0.003, 0), dem_v3(0, 0, 4),
                                      r, 1800) >= 0);
    assert_true(dem_world_add_granule(w, dem_v3(-0.9 * r, -0.2 * r, 0), dem_v3(0.002, -0.003, 0.001),
                                      dem_v3(1, 0, -3), r, 1800) >= 0);
    assert_int_equal(dem_world_step(w, 40), DEM_OK); // springs loaded
    return w;
}

static void test_sort_swaps_pair_roles_bitwise(void **state)
{
    (void)state;
    dem_world *a = sheared_pair(), *b = dem_world_clone(a);
    assert_non_null(b);
    dem_diagnostics da = dem_world_diagnose(a);
    assert_int_equal(da.contacts, 1);
    const uint64_t first = dem_world_granules(a).id[0];
    assert_int_equal(dem_world_sort_spatially(b), DEM_OK);
    dem_granules_view gb = dem_world_granules(b);
    assert_true(gb.id[0] != first); // the order really swapped
    dem_diagnostics db = dem_world_diagnose(b);
    assert_true(db.potential_elastic == da.potential_elastic); // springs kept, not restarted
    for (int s = 0; s < 3; ++s) {
        assert_int_equal(dem_world_step(a, 10), DEM_OK);
        assert_int_equal(dem_world_step(b, 10), DEM_OK);
        dem_granules_view ga = dem_world_granules(a);
        gb = dem_world_granules(b);
        for (size_t i = 0; i < ga.count; ++i) {
            size_t k = index_of(&gb, ga.id[i]);
            assert_true(k != SIZE_MAX);
            assert_vec_equal(ga.force[i], gb.force[k]);
            assert_vec_equal(ga.torque[i], gb.torque[k]);
            assert_vec_equal(ga.position[i], gb.position[k]);
            assert_vec_equal(ga.omega[i], gb.omega[k]);
        }
    }
    printf("sheared pair, sorted (indices swapped) and not: forces, torques, positions and spins bitwise equal "
           "for 30 steps; elastic energy %.6e J kept\n",
           db.potential_elastic);
    dem_world_destroy(a);
    dem_world_destroy(b);
}

// ------------------------------------------------------------ a loaded bed ---

enum { BED_N = 600 };

// A box of granules added in a shuffled order (random in space, like a poured
// bed), settled under gravity so that springs carry load.
static dem_world *shuffled_bed(void)
{
    dem_world_def def = dem_default_world_def();
    def.domain_lo = dem_v3(-0.02, -0.001, -0.02);
    def.domain_hi = dem_v3(0.02, 0.1, 0.02);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .contact = def.granule, .name = "floor"};
    assert_true(dem_world_add_wall(w, &floor) >= 0);
    for (int a = 0; a < 2; ++a) { // side walls at ±7.5 mm: a column some 8 granules deep
        dem_wall_def side = floor;
        side.point = dem_v3(a ? 0.0075 : -0.0075, 0, 0);
        side.normal = dem_v3(a ? -1 : 1, 0, 0);
        side.name = a ? "right" : "left";
        assert_true(dem_world_add_wall(w, &side) >= 0);
        side.point = dem_v3(0, 0, a ? 0.0075 : -0.0075);
        side.normal = dem_v3(0, 0, a ? -1 : 1);
        assert_true(dem_world_add_wall(w, &side) >= 0);
    }
    int order[BED_N];
    for (int i = 0; i < BED_N; ++i) order[i] = i;
    uint64_t x = 12345;
    for (int i = BED_N - 1; i > 0; --i) { // Fisher–Yates with a fixed LCG
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        int k = (int)((x >> 33) % (uint64_t)(i + 1)), t = order[i];
        order[i] = order[k], order[k] = t;
    }
    for (int s = 0; s < BED_N; ++s) {
        int i = order[s];
        dem_vec3 p = dem_v3(0.0028 * (i % 5) - 0.0056, 0.0015 + 0.0028 * (i / 25), 0.0028 * ((i / 5) % 5) - 0.0056);
        // Lateral kicks so the stacked lattice collapses into a packing
        // instead of standing as chains (coordination 2).
        dem_vec3 v = dem_v3(0.05 * sin(1.7 * i), 0.0, 0.05 * cos(2.3 * i));
        assert_true(dem_world_add_granule(w, p, v, dem_v3(0, 0, 0), 1e-3 * (1 + 0.25 * sin(1.7 * i)), 1800) >= 0);
    }
    assert_int_equal(dem_world_prepare(w), DEM_OK); // fixes the step
    assert_int_equal(dem_world_step(w, (uint64_t)(0.4 / dem_world_dt(w))), DEM_OK); // falls 6.5 cm, settles
    return w;
}

// Mean |i − j| over touching pairs: how far apart in memory partners are.
static double mean_partner_distance(const dem_world *w)
{
    dem_granules_view g = dem_world_granules(w);
    double sum = 0;
    size_t pairs = 0;
    for (size_t i = 0; i < g.count; ++i)
        for (size_t j = i + 1; j < g.count; ++j) {
            dem_vec3 d = dem_v3_sub(g.position[j], g.position[i]);
            double reach = g.radius[i] + g.radius[j];
            if (dem_v3_norm2(d) < reach * reach) sum += (double)(j - i), pairs++;
        }
    return pairs ? sum / (double)pairs : 0;
}

static void test_sort_keeps_a_loaded_bed(void **state)
{
    (void)state;
    dem_world *a = shuffled_bed(), *b = dem_world_clone(a);
    assert_non_null(b);
    const double spread_before = mean_partner_distance(b);
    dem_diagnostics da = dem_world_diagnose(a);
    assert_int_equal(dem_world_sort_spatially(b), DEM_OK);
    dem_diagnostics db = dem_world_diagnose(b);
    const double spread_after = mean_partner_distance(b);
    // Same granules, same state, by id: a permutation, nothing else.
    dem_granules_view ga = dem_world_granules(a), gb = dem_world_granules(b);
    assert_int_equal(ga.count, gb.count);
    for (size_t i = 0; i < ga.count; ++i) {
        size_t k = index_of(&gb, ga.id[i]);
        assert_true(k != SIZE_MAX);
        assert_vec_equal(ga.position[i], gb.position[k]);
        assert_vec_equal(ga.velocity[i], gb.velocity[k]);
        assert_true(ga.radius[i] == gb.radius[k] && ga.mass[i] == gb.mass[k]);
    }
    // Springs kept: the same contacts and stored energy (summed in another order).
    assert_int_equal(da.contacts, db.contacts);
    assert_int_equal(da.wall_contacts, db.wall_contacts);
    assert_true(da.potential_elastic > 0);
    assert_true(fabs(db.potential_elastic - da.potential_elastic) <= 1e-12 * da.potential_elastic);
    // Then both run on: forces differ only in the order they are summed.
    const uint64_t steps = 200;
    assert_int_equal(dem_world_step(a, steps), DEM_OK);
    assert_int_equal(dem_world_step(b, steps), DEM_OK);
    ga = dem_world_granules(a), gb = dem_world_granules(b);
    double worst = 0;
    for (size_t i = 0; i < ga.count; ++i) {
        size_t k = index_of(&gb, ga.id[i]);
        double dx = dem_v3_norm(dem_v3_sub(ga.position[i], gb.position[k])) / ga.radius[i];
        worst = dx > worst ? dx : worst;
    }
    printf("bed of %zu granules, %zu contacts: mean |i - j| of partners %.1f shuffled, %.1f sorted; elastic energy "
           "%.9e vs %.9e J; after %llu more steps max |dx|/R %.2e\n",
           ga.count, da.contacts, spread_before, spread_after, da.potential_elastic, db.potential_elastic,
           (unsigned long long)steps, worst);
    assert_true(worst < 1e-9);
    // Sorted, partners are several times closer in memory.
    assert_true(spread_after < 0.25 * spread_before);
    dem_world_destroy(a);
    dem_world_destroy(b);
}

// A copy of `bed` stepped on `threads` OpenMP threads.
static dem_world *stepped_on(const dem_world *bed, int threads, uint64_t steps)
{
    dem_world *w = dem_world_clone(bed);
    assert_non_null(w);
    assert_int_equal(dem_world_set_threads(w, threads), DEM_OK);
    assert_int_equal(dem_world_step(w, steps), DEM_OK);
    return w;
}

static void test_threads_sum_in_the_serial_order(void **state)
{
    (void)state;
    // 600 granules: above DEM_OMP_MIN_GRANULES, so 2 and 3 threads split the
    // rows into blocks, and pairs cross the blocks' edges.
    // A deep column: most granules sum several forces, where a different
    // order would change the last bits.
    dem_world *bed = shuffled_bed();
    assert_int_equal(dem_world_sort_spatially(bed), DEM_OK);
    const int saved = omp_get_max_threads();
    dem_world *one = stepped_on(bed, 1, 1000), *two = stepped_on(bed, 2, 1000), *three = stepped_on(bed, 3, 1000);
    omp_set_num_threads(saved);
    dem_granules_view a = dem_world_granules(one), b = dem_world_granules(two), c = dem_world_granules(three);
    printf("sorted bed, %zu contacts, 1000 steps on 1, 2 and 3 threads: positions and spins %s\n",
           dem_world_diagnose(one).contacts,
           memcmp(a.position, b.position, a.count * sizeof *a.position) == 0 &&
                   memcmp(a.position, c.position, a.count * sizeof *a.position) == 0
               ? "bitwise identical"
               : "DIFFERENT");
    assert_memory_equal(a.position, b.position, a.count * sizeof *a.position);
    assert_memory_equal(a.position, c.position, a.count * sizeof *a.position);
    assert_memory_equal(a.omega, b.omega, a.count * sizeof *a.omega);
    assert_memory_equal(a.omega, c.omega, a.count * sizeof *a.omega);
    dem_world_destroy(one), dem_world_destroy(two), dem_world_destroy(three), dem_world_destroy(bed);
}

// ------------------------------------------------------- wall near-lists ---

static dem_world *one_granule_and_floor(double height, double vy)
{
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, 0);
    def.domain_lo = dem_v3(-0.01, -0.01, -0.01);
    def.domain_hi = dem_v3(0.01, 0.05, 0.01);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    assert_true(dem_world_add_granule(w, dem_v3(0, height, 0), dem_v3(0, vy, 0), dem_v3(0, 0, 0), 1e-3, 1800) >= 0);
    return w;
}

static dem_wall_def floor_def(void)
{
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .contact = dem_default_world_def().granule, .name = "floor"};
    return floor;
}

static void test_wall_reached_across_rebuilds(void **state)
{
    (void)state;
    // 20 radii away, flying at the floor: the near list is rebuilt on the way
    // (every 0.2 R of travel) and must pick the granule up in time.
    dem_world *w = one_granule_and_floor(0.021, -0.5);
    dem_wall_def floor = floor_def();
    assert_true(dem_world_add_wall(w, &floor) >= 0);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    assert_int_equal(dem_world_step(w, (uint64_t)(0.12 / dem_world_dt(w))), DEM_OK);
    dem_granules_view g = dem_world_granules(w);
    dem_diagnostics d = dem_world_diagnose(w);
    printf("granule thrown at the floor from 20 R: after %llu rebuilds, y %.4f m, vy %+.3f m/s (bounced)\n",
           (unsigned long long)d.list_rebuilds, g.position[0].y, g.velocity[0].y);
    assert_true(d.list_rebuilds > 10);
    assert_true(g.velocity[0].y > 0.1 && g.position[0].y > 1e-3); // going up, above the floor
    dem_world_destroy(w);
}

static void test_wall_added_to_running_world(void **state)
{
    (void)state;
    // Resting on y = 0 with a small overlap, no wall yet: nothing pushes it.
    dem_world *w = one_granule_and_floor(0.99e-3, 0.0);
    assert_int_equal(dem_world_step(w, 10), DEM_OK);
    assert_true(dem_world_granules(w).force[0].y == 0.0);
    dem_wall_def floor = floor_def();
    assert_true(dem_world_add_wall(w, &floor) >= 0);
    assert_int_equal(dem_world_step(w, 1), DEM_OK);
    dem_granules_view g = dem_world_granules(w);
    printf("wall added to a running world: force on the overlapping granule %.4e N (k_n h = %.4e N)\n",
           g.force[0].y, floor.contact.k_n * (1e-3 - g.position[0].y));
    assert_true(g.force[0].y > 0.0);
    dem_world_destroy(w);
}

static void test_moved_wall_reaches_granules_off_its_list(void **state)
{
    (void)state;
    // At rest 4 mm above the floor (skin 0.4 mm: not on the floor's near
    // list). The floor is then moved up under it in one call, 0.2 mm into
    // it: the lists must be rebuilt for the wall's travel, and push it up.
    dem_world *w = one_granule_and_floor(5e-3, 0.0);
    dem_wall_def floor = floor_def();
    assert_true(dem_world_add_wall(w, &floor) >= 0);
    assert_int_equal(dem_world_step(w, 10), DEM_OK);
    const uint64_t rebuilds = dem_world_diagnose(w).list_rebuilds;
    assert_int_equal(dem_world_set_wall_point(w, 0, dem_v3(0, 4.2e-3, 0)), DEM_OK);
    assert_true(dem_world_wall(w, 0)->point.y == 4.2e-3);
    assert_int_equal(dem_world_step(w, 2), DEM_OK);
    dem_granules_view g = dem_world_granules(w);
    printf("floor moved 4.2 mm up into a granule off its near list: %llu rebuild(s), vy %+.4f m/s\n",
           (unsigned long long)(dem_world_diagnose(w).list_rebuilds - rebuilds), g.velocity[0].y);
    assert_true(dem_world_diagnose(w).list_rebuilds > rebuilds);
    assert_true(g.velocity[0].y > 0.0);
    assert_int_equal(dem_world_set_wall_point(w, 1, dem_v3(0, 0, 0)), DEM_ERR_INVALID);
    assert_null(dem_world_wall(w, 1));
    dem_world_destroy(w);
}

// ------------------------------------------------------ fixed granules ---

// A granule dropped onto a fixed one, under gravity: the fixed one stays
// where it was, bit for bit, through a spatial sort and a clone; the other
// comes to rest on it.
static void test_fixed_granule_holds(void **state)
{
    (void)state;
    dem_world_def def = dem_default_world_def();
    def.domain_lo = dem_v3(-0.01, -0.01, -0.01);
    def.domain_hi = dem_v3(0.01, 0.05, 0.01);
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    const dem_vec3 base = dem_v3(1e-4, 0, 0);
    assert_true(dem_world_add_granule(w, dem_v3(0, 3e-3, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), 1e-3, 1800) >= 0);
    assert_true(dem_world_add_granule(w, base, dem_v3(0, 0.1, 0), dem_v3(0, 0, 1), 1e-3, 1800) >= 0);
    assert_int_equal(dem_world_set_granule_fixed(w, 1, 1), DEM_OK);
    assert_true(dem_world_granule_fixed(w, 1) && !dem_world_granule_fixed(w, 0));
    assert_int_equal(dem_world_set_granule_fixed(w, 2, 1), DEM_ERR_INVALID);
    assert_int_equal(dem_world_sort_spatially(w), DEM_OK);
    assert_int_equal(dem_world_step(w, (uint64_t)(0.05 / dem_world_dt(w))), DEM_OK);
    dem_world *c = dem_world_clone(w);
    assert_non_null(c);
    assert_int_equal(dem_world_step(c, (uint64_t)(0.05 / dem_world_dt(c))), DEM_OK);
    dem_granules_view g = dem_world_granules(c);
    const size_t f = index_of(&g, 1), m = index_of(&g, 0);
    printf("granule dropped on a fixed one: fixed at (%g, %g, %g), speed %g; the other at y = %.4e m, vy %+.2e m/s\n",
           g.position[f].x, g.position[f].y, g.position[f].z, dem_v3_norm(g.velocity[f]), g.position[m].y,
           g.velocity[m].y);
    assert_true(dem_world_granule_fixed(c, f));
    assert_vec_equal(g.position[f], base);
    assert_vec_equal(g.velocity[f], dem_v3(0, 0, 0));
    assert_vec_equal(g.omega[f], dem_v3(0, 0, 0));
    assert_true(g.position[m].y > 1.5e-3 && fabs(g.velocity[m].y) < 0.05); // resting on it
    dem_world_destroy(c);
    dem_world_destroy(w);
}

static void test_fixed_granules_refuse_implicit_springs(void **state)
{
    (void)state;
    dem_world_def def = dem_default_world_def();
    def.implicit_springs = 1;
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    assert_true(dem_world_add_granule(w, dem_v3(0, 0, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), 1e-3, 1800) >= 0);
    assert_int_equal(dem_world_set_granule_fixed(w, 0, 1), DEM_OK);
    assert_int_equal(dem_world_prepare(w), DEM_ERR_INVALID);
    printf("fixed granule, implicit springs asked for: %s\n", dem_world_error(w));
    assert_int_equal(dem_world_set_granule_fixed(w, 0, 0), DEM_OK);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    dem_world_destroy(w);
}

// ------------------------------------------------------ spring layout swap ---

// Rolling spring energy of the pair: the elastic energy less the normal spring's.
static double rolling_energy(const dem_world *w, double k_n)
{
    dem_granules_view g = dem_world_granules(w);
    const double h = g.radius[0] + g.radius[1] - dem_v3_norm(dem_v3_sub(g.position[1], g.position[0]));
    return dem_world_diagnose(w).potential_elastic - 0.5 * k_n * h * h;
}

static void test_tangential_to_rolling_restarts_springs(void **state)
{
    (void)state;
    dem_world *w = sheared_pair();
    dem_contact_params p = dem_default_world_def().granule;
    p.mu_r = 0; // tangential only: 3 doubles of history
    assert_int_equal(dem_world_set_granule_contact(w, &p), DEM_OK);
    assert_int_equal(dem_world_step(w, 20), DEM_OK);
    const double tangential = rolling_energy(w, p.k_n); // here: the tangential spring's energy
    p.mu_r = 0.2, p.mu_s = 0; // rolling only: also 3 doubles, another spring
    assert_int_equal(dem_world_set_granule_contact(w, &p), DEM_OK);
    dem_granules_view g = dem_world_granules(w);
    // A restarted rolling spring holds at most |v_rel,r| Δt after one step (eq. 12).
    const double reduced = g.radius[0] * g.radius[1] / (g.radius[0] + g.radius[1]);
    const double stretch = reduced * dem_v3_norm(dem_v3_sub(g.omega[0], g.omega[1])) * dem_world_dt(w);
    assert_int_equal(dem_world_step(w, 1), DEM_OK);
    const double rolling = rolling_energy(w, p.k_n), bound = 0.5 * p.k_r * (2 * stretch) * (2 * stretch);
    printf("tangential-only then rolling-only: tangential spring %.3e J; rolling spring one step later %.3e J "
           "(a restarted spring holds at most %.3e J)\n",
           tangential, rolling, bound);
    assert_true(tangential > 100 * bound); // the old spring would be seen
    assert_true(rolling <= bound);
    dem_world_destroy(w);
}

// -------------------------------------------------------- rigid rotation ---

static dem_vec3 turned_about_z(dem_vec3 v, double angle)
{
    return dem_v3(v.x * cos(angle) - v.y * sin(angle), v.x * sin(angle) + v.y * cos(angle), v.z);
}

// A pair pressed together and sheared, the outer granule also pressed against
// a spinning drum wall (axis z) and sliding along it: granule and wall
// springs, tangential and rolling, all loaded. No gravity, which would not turn.
static dem_world *pair_against_drum(void)
{
    dem_world *w = small_weightless_world();
    const dem_contact_params table3 = dem_default_world_def().granule;
    const double r = 1e-3;
    dem_wall_def drum = {.kind = DEM_WALL_CYLINDER, .point = {0, 0, 0}, .axis = {0, 0, 1}, .radius = 5 * r,
                         .contact = table3, .name = "drum"};
    drum.contact.k_n = drum.contact.k_s = drum.contact.k_r = 2 * table3.k_n;
    assert_true(dem_world_add_wall(w, &drum) >= 0);
    dem_world_set_wall_spin(w, 0, 2.0);
    assert_true(dem_world_add_granule(w, dem_v3(4.1 * r, 0, 0), dem_v3(0.001, 0.01, 0.003), dem_v3(0, 0, 4), r, 1800) >= 0);
    assert_true(dem_world_add_granule(w, dem_v3(2.2 * r, 0.3 * r, 0.1 * r), dem_v3(0.002, -0.003, 0.001),
                                      dem_v3(1, 0, -3), r, 1800) >= 0);
    assert_int_equal(dem_world_step(w, 40), DEM_OK); // springs loaded
    dem_diagnostics d = dem_world_diagnose(w);
    assert_int_equal(d.contacts, 1);
    assert_int_equal(d.wall_contacts, 1);
    return w;
}

// Largest gap between `turned` and `plain` turned by `angle`, over positions
// (in radii), velocities and spins (relative to the largest of each).
static double gap_after_turn(const dem_world *plain, const dem_world *turned, double angle)
{
    dem_granules_view a = dem_world_granules(plain), b = dem_world_granules(turned);
    double v_scale = 0, w_scale = 0, worst = 0;
    for (size_t i = 0; i < a.count; ++i)
        v_scale = fmax(v_scale, dem_v3_norm(a.velocity[i])), w_scale = fmax(w_scale, dem_v3_norm(a.omega[i]));
    for (size_t i = 0; i < a.count; ++i) {
        worst = fmax(worst, dem_v3_norm(dem_v3_sub(turned_about_z(a.position[i], angle), b.position[i])) / a.radius[i]);
        worst = fmax(worst, dem_v3_norm(dem_v3_sub(turned_about_z(a.velocity[i], angle), b.velocity[i])) / v_scale);
        worst = fmax(worst, dem_v3_norm(dem_v3_sub(turned_about_z(a.omega[i], angle), b.omega[i])) / w_scale);
    }
    return worst;
}

static void test_rotation_turns_the_springs_with_the_bed(void **state)
{
    (void)state;
    const double angle = 0.7;
    const uint64_t steps = 300;
    dem_world *plain = pair_against_drum(), *turned = dem_world_clone(plain), *restarted = dem_world_clone(plain);
    assert_non_null(turned);
    assert_non_null(restarted);
    const double stored = dem_world_diagnose(plain).potential_elastic;
    assert_int_equal(dem_world_rotate(turned, dem_v3(0, 0, 0), dem_v3(0, 0, 2), angle), DEM_OK);
    assert_true(fabs(dem_world_diagnose(turned).potential_elastic - stored) <= 1e-12 * stored);
    // Control: the same pair with its springs restarted (tangential off and
    // on again), to show that the gap below would see a spring left unturned.
    dem_contact_params p = dem_default_world_def().granule, no_slide = p;
    no_slide.mu_s = 0;
    assert_int_equal(dem_world_set_granule_contact(restarted, &no_slide), DEM_OK);
    assert_int_equal(dem_world_set_granule_contact(restarted, &p), DEM_OK);
    assert_int_equal(dem_world_step(plain, steps), DEM_OK);
    assert_int_equal(dem_world_step(turned, steps), DEM_OK);
    assert_int_equal(dem_world_step(restarted, steps), DEM_OK);
    const double gap = gap_after_turn(plain, turned, angle), control = gap_after_turn(plain, restarted, 0.0);
    printf("turned by %.2f rad about the drum axis, then %llu steps: largest gap to the plain run turned %.2e; "
           "springs restarted instead: %.2e\n",
           angle, (unsigned long long)steps, gap, control);
    assert_true(gap < 1e-9);
    assert_true(control > 1e3 * 1e-9);
    dem_world_destroy(plain), dem_world_destroy(turned), dem_world_destroy(restarted);
}

static void test_refused_rotation_changes_nothing(void **state)
{
    (void)state;
    dem_world *w = pair_against_drum(), *copy = dem_world_clone(w);
    assert_non_null(copy);
    // About a line far from the drum: the pair would leave the 2 cm box.
    assert_int_equal(dem_world_rotate(w, dem_v3(0.009, 0.009, 0), dem_v3(0, 0, 1), 3.0), DEM_ERR_INVALID);
    printf("refused: %s\n", dem_world_error(w));
    assert_int_equal(dem_world_rotate(w, dem_v3(0, 0, 0), dem_v3(0, 0, 0), 1.0), DEM_ERR_INVALID);
    dem_granules_view a = dem_world_granules(w), b = dem_world_granules(copy);
    for (size_t i = 0; i < a.count; ++i) {
        assert_vec_equal(a.position[i], b.position[i]);
        assert_vec_equal(a.velocity[i], b.velocity[i]);
    }
    assert_int_equal(dem_world_step(w, 10), DEM_OK);
    assert_int_equal(dem_world_step(copy, 10), DEM_OK);
    a = dem_world_granules(w), b = dem_world_granules(copy);
    for (size_t i = 0; i < a.count; ++i) assert_vec_equal(a.position[i], b.position[i]);
    // A periodic world turns only about its periodic axis.
    dem_world_def def = dem_default_world_def();
    def.periodic_axis = 2;
    dem_world *slab = dem_world_create(&def, NULL, 0);
    assert_non_null(slab);
    assert_int_equal(dem_world_rotate(slab, dem_v3(0, 0, 0), dem_v3(1, 0, 0), 0.1), DEM_ERR_INVALID);
    assert_int_equal(dem_world_rotate(slab, dem_v3(0, 0, 0), dem_v3(0, 0, -1), 0.1), DEM_OK);
    dem_world_destroy(w), dem_world_destroy(copy), dem_world_destroy(slab);
}

// A world's thread count is its own: creating one leaves OpenMP's
// process-wide setting alone (a caller running worlds side by side, as the
// calibration does, keeps its own), and it can be changed for one world.
static void test_world_threads_are_its_own(void **state)
{
    (void)state;
    const int before = omp_get_max_threads();
    dem_world_def def = dem_default_world_def();
    def.threads = before + 2;
    dem_world *w = dem_world_create(&def, NULL, 0);
    assert_non_null(w);
    assert_int_equal(omp_get_max_threads(), before);
    assert_int_equal(dem_world_threads(w), before + 2);
    assert_int_equal(dem_world_set_threads(w, 0), DEM_OK);
    assert_int_equal(dem_world_threads(w), before);
    assert_int_equal(dem_world_set_threads(w, -1), DEM_ERR_INVALID);
    dem_world_destroy(w);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sort_swaps_pair_roles_bitwise),
        cmocka_unit_test(test_sort_keeps_a_loaded_bed),
        cmocka_unit_test(test_threads_sum_in_the_serial_order),
        cmocka_unit_test(test_wall_reached_across_rebuilds),
        cmocka_unit_test(test_wall_added_to_running_world),
        cmocka_unit_test(test_tangential_to_rolling_restarts_springs),
        cmocka_unit_test(test_rotation_turns_the_springs_with_the_bed),
        cmocka_unit_test(test_refused_rotation_changes_nothing),
        cmocka_unit_test(test_world_threads_are_its_own),
        cmocka_unit_test(test_moved_wall_reaches_granules_off_its_list),
        cmocka_unit_test(test_fixed_granule_holds),
        cmocka_unit_test(test_fixed_granules_refuse_implicit_springs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
