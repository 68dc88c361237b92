// SPDX-License-Identifier: MIT
/// @file exp_cost.h
/// What a scene will cost, predicted before it runs (a calibration's plan, and
/// refusing a tier that cannot fit the machine or the budget): the figures the
/// drum and the cylinder predictions share, each in one place.
#ifndef EXP_COST_H
#define EXP_COST_H

#include "dem_gsd.h"

/// The fraction of eq. 14's dt_crit the engine steps at while a bed is poured:
/// the a-priori bound of the densest (FCC) cluster (dem_stability_apriori) for
/// Table 3's contact, ξ = 0.7; other dashpots move it a little, and a
/// prediction takes this one number.
#define EXP_POUR_STEP_FRACTION 0.165

/// Eq. 14's critical step, sqrt(m/k_n), of the lightest granule of a real GSD
/// coarse-grained by λ (eq. 15-18): what a scene's step is a fraction of.
double exp_lightest_dt_crit(const dem_gsd *real_gsd, double real_density, double real_k_n, double lambda);

/// One simulation's peak resident memory (MB) with `granules` granules on one
/// thread: a fixed part and a part per granule, fitted to the records of two
/// drums (305 granules: 10.1 MB; 3633: 17.1 MB).
double exp_predicted_peak_memory_mb(double granules);

#endif
