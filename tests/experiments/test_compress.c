// SPDX-License-Identifier: MIT
// The confined compression test (sections 3.2.1, 4.1) at the shipped config,
// checked against what does not come from its own output:
//  - E' (eq. 19) against the affine (Voigt) estimate of the bed's own contact
//    network at σ_max, M_V = (1/V) Σ_c l_c² [k_n n_y⁴ + k_t (n_y² − n_y⁴)],
//    which for linear springs that stick is an upper bound of the network's
//    stiffness (minimum of the elastic energy); a disordered frictional bed
//    relaxes non-affinely and loses contacts while unloading, so E' must come
//    out below it and within a factor of it;
//  - the force balance of the die at rest: the piston force and the weight
//    less the floor force is carried by the side wall's friction, so it is at
//    most μ_wall × the side wall's normal force (Janssen);
//  - the hysteresis of every cycle has the dissipative sign (work put in by
//    the piston while loading ≥ work returned while unloading), and the
//    permanent strain of the first cycle (rearrangement) exceeds the last;
//  - bad input in the YAML is named by file, line and field.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "config_variant.h"
#include "dem_scaling.h"
#include "exp_compress.h"
#include "exp_compress_config.h"

static void shipped_config(char *path, size_t len)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    snprintf(path, len, "%s/configs/compression.yaml", src ? src : ".");
}

// Affine estimate of the confined modulus from granule–granule contacts
// (own contact search, O(N²): no engine code).
static double voigt_modulus(const dem_granules_view *g, double k_n, double k_t, double volume, double *coordination)
{
    double sum = 0;
    size_t contacts = 0;
    for (size_t i = 0; i < g->count; ++i)
        for (size_t j = i + 1; j < g->count; ++j) {
            dem_vec3 d = dem_v3_sub(g->position[j], g->position[i]);
            double l = dem_v3_norm(d);
            if (l >= g->radius[i] + g->radius[j]) continue;
            double ny2 = d.y * d.y / (l * l);
            sum += l * l * (k_n * ny2 * ny2 + k_t * (ny2 - ny2 * ny2));
            contacts++;
        }
    *coordination = 2.0 * (double)contacts / (double)g->count;
    return sum / volume;
}

static void test_cycles_against_independent_estimates(void **state)
{
    (void)state;
    char path[1024], err[1024];
    shipped_config(path, sizeof path);
    exp_compress_def d;
    char cycles[] = "cycles=3", *sets[] = {cycles};
    if (exp_compress_load(path, 1, sets, &d, err, sizeof err)) fail_msg("%s", err);
    // Half the die's diameter (a quarter of the granules) keeps the test
    // within CI's few minutes; the shipped die is docs/experiments.md's run.
    d.diameter *= 0.5;
    exp_compress_result r;
    dem_world *w = exp_compress_run(&d, NULL, NULL, &r, err, sizeof err);
    if (!w) fail_msg("%s", err);
    assert_int_equal(r.n_cycles, d.cycles);
    // Rolling is off in this scene, tangential friction and the dashpot on.
    char effects[1024];
    dem_world_describe_features(w, effects, sizeof effects);
    assert_non_null(strstr(effects, "granule-granule: damping on (approaching), tangential on, rolling off"));
    assert_false(dem_world_features(w) & DEM_FEAT_ROLLING);

    dem_granules_view g = dem_world_granules(w);
    double k = dem_scale_stiffness(d.granule.k_n, d.lambda), kw = dem_scale_stiffness(2 * d.granule.k_n, d.lambda);
    double rd = 0.5 * d.diameter, area = DEM_PI * rd * rd;
    const exp_compress_sample *last = &r.curve[r.n_curve - 1];
    double z, mv_min = voigt_modulus(&g, k, k, area * last->piston_y, &z);
    // The same run again (deterministic), stopped at the last σ_max: the
    // network the unloading of eq. 19 starts from.
    exp_compress_def d2 = d;
    d2.stop_at_last_turn = 1;
    exp_compress_result r2;
    dem_world *w2 = exp_compress_run(&d2, NULL, NULL, &r2, err, sizeof err);
    if (!w2) fail_msg("%s", err);
    dem_granules_view g2 = dem_world_granules(w2);
    double z2, mv = voigt_modulus(&g2, k, k, area * r2.curve[r2.n_curve - 1].piston_y, &z2);
    assert_true(fabs(r2.curve[r2.n_curve - 1].sigma - r.cycle[r.n_cycles - 1].sigma_turn) < 1e-9 * d.sigma_max);
    const exp_compress_cycle *c = &r.cycle[r.n_cycles - 1], *c1 = &r.cycle[0];
    printf("%zu granules, bed %.2f mm, solid fraction %.3f, coordination %.2f at sigma_min (%.2f at sigma_max)\n",
           r.granules, 1e3 * r.bed_height, r.solid_fraction, z, r.coordination_turn);
    for (int k2 = 0; k2 < r.n_cycles; ++k2)
        printf("cycle %d: E' loading %.4g Pa, unloading %.4g Pa, permanent strain %.3g, work in %.3g J out %.3g J\n",
               k2 + 1, r.cycle[k2].e_loading, r.cycle[k2].e_unloading, r.cycle[k2].permanent_strain,
               r.cycle[k2].work_in, r.cycle[k2].work_out);
    printf("E' (last cycle, unloading) %.4g Pa; affine estimate of the network at sigma_max %.4g Pa (coordination "
           "%.2f): ratio %.3f; at sigma_min %.4g Pa: ratio %.3f; stable %d; max KE/elastic %.2g\n",
           r.e_confined, mv, z2, r.e_confined / mv, mv_min, r.e_confined / mv_min, r.stable, r.max_ke_over_elastic);
    // Below the affine bound of the network the unloading starts from (10 %
    // allowance: the bound ignores the walls' own springs and the prestress
    // terms), and within a factor 10 of it.
    assert_true(r.e_confined < 1.1 * mv);
    assert_true(r.e_confined > 0.1 * mv);
    exp_compress_result_free(&r2);
    dem_world_destroy(w2);

    // Force balance of the die at rest, from the positions (own overlaps).
    double top = 0, bottom = 0, side = 0, weight = 0;
    for (size_t i = 0; i < g.count; ++i) {
        double ri = g.radius[i], y = g.position[i].y;
        double rho = sqrt(g.position[i].x * g.position[i].x + g.position[i].z * g.position[i].z);
        top += fmax(0, ri - (last->piston_y - y)) * kw;
        bottom += fmax(0, ri - y) * kw;
        side += fmax(0, ri + rho - rd) * kw;
        weight += g.mass[i] * 9.81;
    }
    printf("at rest: piston %.4g N, floor %.4g N, weight %.3g N, side wall normal %.4g N (friction limit %.4g N)\n",
           top, bottom, weight, side, d.wall.mu_s * side);
    assert_true(fabs(top + weight - bottom) <= 1.05 * d.wall.mu_s * side + 0.02 * top);
    // The same balance from the engine's own wall totals (springs, dashpots
    // and friction: dem_world_wall_force), which name the side wall's share:
    // piston + floor + side = −weight along y, up to the bed's own m·a
    // (quasi-static); the side wall's share within its friction limit.
    const double fp = last->f_piston_axial, ff = last->f_floor_axial, fs = last->f_side_axial;
    printf("engine's totals at rest: piston %.4g N, floor %.4g N, side (friction) %.4g N; sum + weight %.3g N\n", fp,
           ff, fs, fp + ff + fs + weight);
    assert_true(fabs(fp + ff + fs + weight) < 0.01 * fabs(ff));
    assert_true(fabs(fs) <= 1.05 * d.wall.mu_s * side);
    assert_true(fabs(fp - top) < 0.05 * top); // the spring sum is most of it at rest

    // Dissipative hysteresis in every cycle; rearrangement dies out.
    for (int k2 = 0; k2 < r.n_cycles; ++k2) assert_true(r.cycle[k2].work_in >= r.cycle[k2].work_out);
    assert_true(c1->permanent_strain > c->permanent_strain);
    assert_true(c->e_unloading >= c->e_loading); // unloading is stiffer (elastic recovery only)
    assert_true(r.max_ke_over_elastic < 0.05);   // quasi-static
    exp_compress_result_free(&r);
    dem_world_destroy(w);
}

static void test_bad_input_is_named(void **state)
{
    (void)state;
    char path[1024], tmp[] = "/tmp/granucal_compress_XXXXXX", err[1024];
    shipped_config(path, sizeof path);
    int bad_line = config_variant(path, "sigma_max:", "sigma_max: 5", tmp);
    assert_true(bad_line > 0);
    exp_compress_def d;
    assert_int_not_equal(exp_compress_load(tmp, 0, NULL, &d, err, sizeof err), 0);
    char want[64];
    snprintf(want, sizeof want, ":%d: sigma_max", bad_line);
    printf("%s\n", err);
    assert_non_null(strstr(err, tmp));
    assert_non_null(strstr(err, want));
    char *set = "mu_r=0.1";
    assert_int_not_equal(exp_compress_load(path, 1, &set, &d, err, sizeof err), 0);
    assert_non_null(strstr(err, "rolling"));
    // A bad value given by --set is blamed on the --set, not on the file's line.
    set = "sigma_max=5";
    assert_int_not_equal(exp_compress_load(path, 1, &set, &d, err, sizeof err), 0);
    printf("%s\n", err);
    assert_non_null(strstr(err, "--set sigma_max=5"));
    remove(tmp);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_bad_input_is_named),
                                       cmocka_unit_test(test_cycles_against_independent_estimates)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
