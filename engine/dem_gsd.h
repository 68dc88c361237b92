// SPDX-License-Identifier: MIT
/// @file dem_gsd.h
/// Granule size distribution (GSD): a log-normal number distribution of
/// diameters, truncated symmetrically in log space (Tiscar et al. 2019,
/// section 3.1: number median 200 µm, geometric deviation 1.43).
///
/// Sampling uses GSL's Mersenne Twister seeded from a 64-bit seed, so a seed
/// names one sequence of diameters, bit for bit, on a given build.
#ifndef DEM_GSD_H
#define DEM_GSD_H

#include <stddef.h>
#include <stdint.h>

/// Parameters of a truncated log-normal number distribution of diameters.
typedef struct dem_gsd {
    double median_diameter; ///< number median d_50, m (> 0)
    double geometric_sd;    ///< geometric standard deviation σ_g (≥ 1; 1 = monodisperse)
    /// Diameters outside median·σ_g^(±truncation_sigmas) are rejected and
    /// redrawn (≥ 0.5). Symmetric in log space, so the median is unchanged.
    double truncation_sigmas;
} dem_gsd;

/// The paper's powder: median 200 µm, σ_g = 1.43, truncated at ±2σ
/// (98–409 µm).
dem_gsd dem_default_gsd(void);

/// Check a GSD; on error writes a message naming the field into `msg` (if
/// not NULL) and returns non-zero.
int dem_gsd_check(const dem_gsd *g, char *msg, size_t len);

/// Smallest and largest diameter a draw can have, m (the truncation bounds,
/// median·σ_g^(∓truncation_sigmas)).
double dem_gsd_min_diameter(const dem_gsd *g);
double dem_gsd_max_diameter(const dem_gsd *g);

/// Draw `n` diameters (m) into `diameters`. The same seed gives the same
/// diameters bit for bit, and the first k of n draws equal a draw of k.
/// Returns 0, DEM_ERR_INVALID (bad GSD, or NULL with n > 0) or
/// DEM_ERR_NOMEM (see dem_world.h).
int dem_gsd_sample(const dem_gsd *g, uint64_t seed, size_t n, double *diameters);

/// Mean granule volume π/6·E[d³] of the truncated number distribution, m³,
/// from the analytic truncated log-normal moment (no sampling). NaN for an
/// invalid GSD.
double dem_gsd_mean_volume(const dem_gsd *g);

/// Number of granules whose expected total volume first reaches
/// `solid_volume` (m³), i.e. ceil(solid_volume / mean volume), with a
/// round-off allowance so that an exact multiple is not counted one over.
/// 0 for an invalid GSD or a volume that is not finite and > 0; SIZE_MAX if
/// the count does not fit.
size_t dem_gsd_count_for_volume(const dem_gsd *g, double solid_volume);

#endif
