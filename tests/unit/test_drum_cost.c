// SPDX-License-Identifier: MIT
// exp_drum_predict_cost against what drum runs measured: the records of
// three drums in committed stores (granules, the turn's step, peak memory),
// at Table 3's pair, drum lined with granules. A prediction is for refusing a
// tier before it runs, so it must be right to a fraction, not exactly.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include <cmocka.h>

#include "exp_cylinder.h"
#include "exp_drum.h"

typedef struct measured {
    const char *where;
    double lambda, slice_depth;
    double granules, dt_s, peak_rss_mb; ///< the record's
} measured;

static const measured runs[] = {
    // results/twin_ci/r4_ci_test/store/41bc29ee928c18f2.yaml (ci tier, 40 rpm, seed 1)
    {"ci, 30 mm slice", 32768, 0.03, 305, 4.100e-6, 10.09},
    // results/fidelity_ladder/store, L4096-slice15-avg8 records (two seeds)
    {"lambda 4096, 15 mm slice", 4096, 0.015, 1135, 2.784e-6, 14.68},
    // results/fidelity_ladder/store, L1000-slice12-avg8 records at 4 rpm (seeds 2, 3)
    {"lambda 1000, 12 mm slice", 1000, 0.012, 3633, 2.085e-6, 17.05},
};

static void predictions_within_a_fraction_of_records(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof runs / sizeof *runs; ++k) {
        const measured *m = &runs[k];
        exp_drum_def d = exp_default_drum_def();
        d.lambda = m->lambda, d.depth = m->slice_depth, d.periodic = 1;
        d.granule.k_n = 200; // Table 3
        exp_drum_cost c = exp_drum_predict_cost(&d, 1.0);
        double dt = c.granules / c.turn_particle_steps; // one simulated second at the turn's step
        printf("%s: granules %.0f (record %.0f), turn step %.3g s (%.3g), memory %.1f MB (%.1f)\n", m->where, c.granules,
               m->granules, dt, m->dt_s, c.memory_mb, m->peak_rss_mb);
        assert_true(fabs(c.granules / m->granules - 1) < 0.1);
        assert_true(fabs(dt / m->dt_s - 1) < 0.2);
        assert_true(fabs(c.memory_mb / m->peak_rss_mb - 1) < 0.25);
        assert_true(c.fill_particle_steps > 0);
    }
}

// The standard tier's stage 1 (results/calibration-standard-affine/store): poured
// cylinders at λ 32768, seed 1 of each stiffness (the other seeds lie within
// 3 % in granules and step).
typedef struct measured_cylinder {
    double k_n, granules, dt_s, simulated_time_s, peak_rss_mb;
} measured_cylinder;

static const measured_cylinder cylinders[] = {
    {50, 826, 4.018e-6, 3.001, 10.27}, {100, 825, 2.841e-6, 3.001, 10.26}, {200, 831, 2.009e-6, 3.050, 10.29},
    {400, 831, 1.420e-6, 3.050, 10.29}, {800, 837, 1.004e-6, 3.050, 10.19},
};

static void cylinder_predictions_within_a_fraction_of_records(void **state)
{
    (void)state;
    for (size_t k = 0; k < sizeof cylinders / sizeof *cylinders; ++k) {
        const measured_cylinder *m = &cylinders[k];
        exp_cylinder_def d = exp_default_cylinder_def();
        d.lambda = 32768, d.granule.k_n = m->k_n;
        exp_cylinder_cost c = exp_cylinder_predict_cost(&d);
        double steps = m->simulated_time_s / m->dt_s, predicted_steps = c.particle_steps / c.granules;
        printf("cylinder k_n %g: granules %.0f (record %.0f), steps %.3g (%.3g), memory %.1f MB (%.1f)\n", m->k_n,
               c.granules, m->granules, predicted_steps, steps, c.memory_mb, m->peak_rss_mb);
        assert_true(fabs(c.granules / m->granules - 1) < 0.1);
        assert_true(fabs(predicted_steps / steps - 1) < 0.2);
        assert_true(fabs(c.memory_mb / m->peak_rss_mb - 1) < 0.25);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(predictions_within_a_fraction_of_records),
                                       cmocka_unit_test(cylinder_predictions_within_a_fraction_of_records)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
