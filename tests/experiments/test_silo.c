// SPDX-License-Identifier: MIT
// The silo discharge scene (Appendix A.2) checked by energy, which its own
// output does not contain: Table A.2 has no damping, so with the friction
// also off (μ_s = 0) the only forces left are gravity and linear springs, and
// kinetic + gravitational + elastic energy must be conserved through the
// discharge (velocity Verlet at Δt = 1e-3 s ≈ 0.02 Δt_crit); the fixed plate
// spheres do no work. With Table A.2's friction on, energy can only be lost.
// Also: the scene switches on only what it uses (no damping, no rolling),
// and a bad key of configs/silo.yaml is refused with its file and line.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "config_variant.h"
#include "exp_silo.h"
#include "exp_silo_config.h"

// Kinetic + gravitational (z up, g = 9.81) + elastic energy of the scene; the
// fixed spheres (ids below n_fixed) neither move nor count.
static double energy(const dem_world *w, size_t n_fixed)
{
    dem_granules_view g = dem_world_granules(w);
    double e = dem_world_diagnose(w).potential_elastic;
    for (size_t i = 0; i < g.count; ++i) {
        if (g.id[i] < n_fixed) continue;
        e += 0.5 * g.mass[i] * dem_v3_norm2(g.velocity[i]) + 0.5 * g.inertia[i] * dem_v3_norm2(g.omega[i]);
        e += g.mass[i] * 9.81 * g.position[i].z;
    }
    return e;
}

static void run(double mu_s, double *e0, double *e1, double *ke_peak, size_t *discharged, char *effects, size_t len)
{
    exp_silo_def d = exp_default_silo_def();
    d.n_granules = 100, d.duration = 3.0;
    d.granule.mu_s = d.wall.mu_s = mu_s;
    char err[512];
    size_t plate = 0;
    dem_world *w = exp_silo_prepare(&d, NULL, NULL, &plate, err, sizeof err);
    if (!w) fail_msg("%s", err);
    assert_int_equal(dem_world_prepare(w), DEM_OK);
    dem_world_describe_features(w, effects, len);
    *e0 = energy(w, plate);
    exp_silo_result r;
    assert_int_equal(exp_silo_discharge(w, &d, plate, NULL, NULL, &r), DEM_OK);
    *e1 = energy(w, plate);
    *ke_peak = 0;
    for (size_t k = 0; k < r.n_series; ++k)
        *ke_peak = fmax(*ke_peak, r.series[k].ke_translational + r.series[k].ke_rotational);
    *discharged = r.series[r.n_series - 1].discharged;
    exp_silo_result_free(&r);
    dem_world_destroy(w);
}

static void test_energy_of_the_discharge(void **state)
{
    (void)state;
    char effects[1024];
    double e0, e1, peak;
    size_t out;
    run(0.0, &e0, &e1, &peak, &out, effects, sizeof effects);
    printf("frictionless: E %.6g -> %.6g J (drift %.2g of the peak kinetic energy %.4g J), %zu discharged\n", e0, e1,
           (e1 - e0) / peak, peak, out);
    assert_true(out > 10);                         // it did discharge
    assert_true(fabs(e1 - e0) < 2e-3 * peak);      // conserved
    assert_non_null(strstr(effects, "granule-granule: damping off (approaching), tangential off, rolling off"));
    run(0.5, &e0, &e1, &peak, &out, effects, sizeof effects);
    printf("Table A.2 (mu_s 0.5): E %.6g -> %.6g J (lost %.3g of the peak kinetic energy), %zu discharged\n", e0, e1,
           (e0 - e1) / peak, out);
    assert_true(e1 < e0); // friction only dissipates
    assert_non_null(strstr(effects, "granule-granule: damping off (approaching), tangential on, rolling off"));
}

// A bad value in configs/silo.yaml: refused with the file, the line and the key.
static void refused_at_its_line(const char *key, const char *line)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    char path[1024], tmp[] = "/tmp/granucal_silo_XXXXXX", err[1024], want[128];
    snprintf(path, sizeof path, "%s/configs/silo.yaml", src ? src : ".");
    int bad_line = config_variant(path, key, line, tmp);
    assert_true(bad_line > 0);
    exp_silo_def d;
    assert_int_not_equal(exp_silo_load(tmp, 0, NULL, &d, err, sizeof err), 0);
    printf("%s\n", err);
    snprintf(want, sizeof want, "%s:%d: %.*s", tmp, bad_line, (int)strcspn(key, ":"), key);
    assert_non_null(strstr(err, want));
    remove(tmp);
}

static void test_bad_input_is_named(void **state)
{
    (void)state;
    refused_at_its_line("seed:", "seed: -1"); // a uint64_t seed would wrap
    refused_at_its_line("fill_max_time:", "fill_max_time: 0");
    refused_at_its_line("wall_k_n:", "wall_k_n: -5");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_energy_of_the_discharge),
                                       cmocka_unit_test(test_bad_input_is_named)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
