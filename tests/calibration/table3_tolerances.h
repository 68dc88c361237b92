// SPDX-License-Identifier: MIT
// Tolerances of the Table 3 comparison (test_table3.c), each with its reason.
//
// The ci tier (configs/calibration.yaml) turns a lambda = 32768 drum, where
// Table 3's pair piles 5.8 +- 2.5 deg steeper than the lab (four seeds of
// `granucal study fidelity`; README "What accuracy costs in time"); its
// angle_offset_deg takes that bias out, so the run checks the pipeline, not
// the coarse model's absolute angle. What the ci tier can then resolve is set
// by its search, fixed before any run was compared with Table 3:
//  - the initial design is a 2 x 2 grid at 1/4 and 3/4 of each axis of the
//    unit square (mu_s linear, mu_r log10), so any point of the square is at
//    most 1/4 of an axis from a grid point;
//  - COBYLA then starts at the best grid point with steps of 1/4 and the tier
//    allows it 2 evaluations: the start (already simulated) and one step.
// A calibrated value can therefore be off by a quarter of its axis even when
// every simulation were exact: 0.25 x 0.9 = 0.225 in mu_s (both bounds span
// 0.1-1), 0.25 x 2.70 = 0.68 decades in granule mu_r (1e-3 - 0.5) and
// 0.25 x 4.70 = 1.17 decades in wall mu_r (1e-5 - 0.5). These are the
// tolerances so far; none was changed after a run.
//
// The issue asks for tolerances from the tier's measured spread as well. The
// protocol, fixed here before its runs finished: the ci calibration is run at
// the config's seeds 2, 3 and 4 beside seed 1 (results/table3_ci/r3_misfit/);
// an entry's spread is its sample standard deviation over the four runs (mu_s
// as a value, mu_r and k_n in decades); its tolerance becomes the larger of
// the search resolution above and twice that spread. The replicate runs go to
// results/table3_ci/r3_seeds/.
static const tolerance tolerances[] = {
    // Inputs and rules: the table must carry them exactly.
    {"granule-granule", "*", "density", 0, 1e-9, "config input (section 3.1)"},
    {"granule-granule", "*", "xi", 0, 1e-9, "config input (Table 3)"},
    {"granule-boundary", "*", "xi", 0, 1e-9, "config input (Table 3)"},
    {"granule-granule", "*", "k_s", 1, 0.302, "k_s = k_n (Table 3): follows k_n"},
    {"granule-granule", "*", "k_r", 1, 0.302, "k_r = k_n (Table 3): follows k_n"},
    {"granule-boundary", "*", "k_n", 1, 0.302, "2 k_n, springs in series (Table 3): follows k_n"},
    {"granule-boundary", "*", "k_s", 1, 0.302, "2 k_n (Table 3): follows k_n"},
    {"granule-boundary", "*", "k_r", 1, 0.302, "2 k_n (Table 3): follows k_n"},
    // Calibrated.
    {"granule-granule", "*", "k_n", 1, 0.302,
     "one rung of the candidate ladder (factor 2): stage 1 can only land on a candidate"},
    {"granule-granule", "*", "mu_s", 0, 0.225, "ci search resolution: 1/4 of the mu_s axis (0.1-1)"},
    {"granule-granule", "*", "mu_r", 1, 0.68, "ci search resolution: 1/4 of the log mu_r axis (1e-3 - 0.5)"},
    {"granule-boundary", "*", "mu_s", 0, 0.225, "ci search resolution: 1/4 of the mu_s axis (0.1-1)"},
    {"granule-boundary", "*", "mu_r", 1, 1.17,
     "ci search resolution: 1/4 of the log mu_r axis (1e-5 - 0.5); the wall mu_r spans decades (Fig. 17)"},
};
