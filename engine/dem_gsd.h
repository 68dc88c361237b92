// SPDX-License-Identifier: MIT
/// @file dem_gsd.h
/// Granule size distribution (GSD): a log-normal number distribution of
/// diameters, truncated symmetrically in log space (Tiscar et al. 2019,
/// section 3.1: number median 200 µm, geometric deviation 1.43), or a
/// measured table (laser diffraction, sieving) converted to the number
/// distribution the engine samples (dem_gsd_from_table).
///
/// Sampling uses GSL's Mersenne Twister seeded from a 64-bit seed, so a seed
/// names one sequence of diameters, bit for bit, on a given build.
#ifndef DEM_GSD_H
#define DEM_GSD_H

#include <stddef.h>
#include <stdint.h>

/// Most rows a measured table may have (a laser diffraction instrument
/// reports up to ~100 size classes).
#define DEM_GSD_TABLE_MAX_ROWS 256

/// A tabulated number distribution: the cumulative number fraction at each
/// diameter, read as uniform in ln d between rows (each size class spread
/// evenly over the logarithm of its size, the usual reading of a table of
/// geometric size classes). Built by dem_gsd_from_table only.
typedef struct dem_gsd_table {
    int rows;                                   ///< 0: no table, the log-normal
    double diameter[DEM_GSD_TABLE_MAX_ROWS];    ///< m, strictly increasing
    double cumulative[DEM_GSD_TABLE_MAX_ROWS];  ///< number fraction ≤ diameter: 0 first, 1 last, non-decreasing
} dem_gsd_table;

/// A granule size distribution: a truncated log-normal number distribution
/// of diameters, or (table.rows > 0) a tabulated one.
typedef struct dem_gsd {
    /// Number median d_50, m (> 0). With a table: the table's number median
    /// (derived, for the length scales that use a typical diameter).
    double median_diameter;
    /// Geometric standard deviation σ_g (≥ 1; 1 = monodisperse). With a
    /// table: exp of the table's standard deviation of ln d (derived, shown).
    double geometric_sd;
    /// Diameters outside median·σ_g^(±truncation_sigmas) are rejected and
    /// redrawn (≥ 0.5). Symmetric in log space, so the median is unchanged.
    /// With a table: 0 (the table's first and last rows bound the sizes).
    double truncation_sigmas;
    /// A measured distribution (rows > 0) replaces the log-normal above.
    dem_gsd_table table;
} dem_gsd;

/// The truncated log-normal with these parameters (no table).
dem_gsd dem_gsd_lognormal(double median_diameter, double geometric_sd, double truncation_sigmas);

/// What a table's cumulative column counts.
typedef enum dem_gsd_basis {
    DEM_GSD_NUMBER, ///< fraction of granules (counting, image analysis)
    DEM_GSD_VOLUME, ///< fraction of volume, i.e. of mass (laser diffraction, sieving)
} dem_gsd_basis;

/// Build a tabulated GSD from a measured table: `rows` diameters (m,
/// strictly increasing) and the cumulative percentage (0–100,
/// non-decreasing, 0 on the first row and 100 on the last: the table must
/// bound the sizes, since the smallest granule sets the time step) on
/// `basis`. A volume-based table is converted to numbers (see dem_gsd.c).
/// Rows below the last 0 % and above the first 100 % are dropped. On error
/// returns non-zero, sets *bad_row to the 0-based row at fault (-1: the
/// table as a whole) and writes "field: what is wrong" into msg.
int dem_gsd_from_table(const double *diameter, const double *cumulative_percent, int rows, dem_gsd_basis basis,
                       dem_gsd *out, int *bad_row, char *msg, size_t len);

/// The diameter below which a number fraction p (0–1) of the granules lie
/// (the number distribution's quantile), m; NaN for an invalid GSD or p.
double dem_gsd_quantile(const dem_gsd *g, double p);

/// The distribution in at most `max` size classes, for a deck that inserts
/// granules class by class (LIGGGHTS particletemplate/particledistribution,
/// LAMMPS fix pour): each class's number fraction (summing to 1) and the
/// diameter of its mean granule volume, cbrt(E[d³ | class]), so that granules
/// drawn from the classes carry the distribution's mean volume. A log-normal:
/// `max` classes equally wide in ln d over the truncated range. A table: its
/// own classes (rows) holding granules, consecutive ones merged into `max`
/// groups when there are more. Returns the number of classes, 0 for an
/// invalid GSD or max < 1.
int dem_gsd_classes(const dem_gsd *g, int max, double *diameter, double *fraction);

/// A 64-bit fingerprint of a table's rows (0 without a table): part of a
/// stored simulation's key, so that another table is another simulation.
uint64_t dem_gsd_table_fingerprint(const dem_gsd *g);

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
