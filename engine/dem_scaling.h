// SPDX-License-Identifier: MIT
/// @file dem_scaling.h
/// Coarse graining, Tiscar et al. (2019) section 2.2, eq. 15–18: the one
/// module that owns the scaling laws. Nothing else in granucal rescales
/// radii, densities or stiffnesses; every caller goes through here.
///
/// The scale factor is λ = N^r/N^s = V^s/V^r = (R^s/R^r)³ (eq. 15), with
/// "r" the real and "s" the scaled system. λ = 1 is the real powder; λ must
/// be finite and ≥ 1 (a coarse granule is never smaller than a real one).
/// Every function here returns NaN (or NaN fields) for a λ that fails
/// dem_scale_check, so a bad λ is caught by the next parameter check rather
/// than silently producing a plausible-looking scene.
#ifndef DEM_SCALING_H
#define DEM_SCALING_H

#include <stddef.h>

#include "dem_contact.h"
#include "dem_gsd.h"

/// Check a scale factor: finite and ≥ 1. On error writes a message naming
/// λ into `msg` (if not NULL) and returns non-zero.
int dem_scale_check(double lambda, char *msg, size_t len);

/// Radius (or diameter) of the coarse granule: R^s = R^r·λ^(1/3) (eq. 15).
double dem_scale_radius(double r, double lambda);

/// Density of the coarse granule: ρ^s = ρ^r/λ (eq. 17), which keeps the
/// granule mass ρV unchanged (eq. 16).
double dem_scale_density(double rho, double lambda);

/// Spring stiffness of the coarse contact: k^s = k^r·λ^(−1/3) = k^r·R^r/R^s
/// (eq. 18), which keeps the relative overlap h/R under a given force.
/// Applies to k_n, k_s and k_r alike.
double dem_scale_stiffness(double k, double lambda);

/// Contact parameters of the coarse system, by the law's own rule: the
/// linear law's k_n, k_s, k_r scaled by eq. 18; Hertz–Mindlin's E* and G* by
/// (R^r/R^s)² = λ^(−2/3), which keeps eq. 18's relative overlap h/R under a
/// given force for a Hertz spring (derivation in dem_contact.c, hertz_scale),
/// and its k_r by eq. 18. Friction coefficients, damping ratio ξ, damping
/// reading and law unchanged.
dem_contact_params dem_scale_contact(const dem_contact_params *p, double lambda);

/// GSD of the coarse system: every diameter × λ^(1/3) (eq. 15), so the
/// median scales and the log-normal shape (σ_g, truncation) is unchanged.
dem_gsd dem_scale_gsd(const dem_gsd *g, double lambda);

#endif
