// SPDX-License-Identifier: MIT
/// @file exp_contact_rules.h
/// The paper's rules for a scene's contact pairs, each written once: section
/// 3.2's k_n = k_s = k_r; Table 3's boundary springs at twice the granules'
/// (a granule pair's k_n is two granules' own springs of 2 k_n in series; a
/// granule on a rigid boundary has only its own, 2 k_n); and the damping
/// reading a config gets when it names none.
#ifndef EXP_CONTACT_RULES_H
#define EXP_CONTACT_RULES_H

#include <stddef.h>

#include "dem_contact.h"

/// The reading of eq. 4's dashpot a config gets when it names none (docs/model.md,
/// "The contact model": damped while approaching, never pulling granules together).
#define EXP_DAMPING_DEFAULT DEM_DAMPING_APPROACHING

/// A config's optional damping name (NULL: EXP_DAMPING_DEFAULT) into *out;
/// 0, or 1 with a message naming `field` and the readings there are.
int exp_damping_from_name(const char *name, const char *field, dem_damping_mode *out, char *err, size_t len);

/// Section 3.2's granule pair: one stiffness for the normal, tangential and
/// rolling springs.
dem_contact_params exp_granule_pair(double k_n, double xi, double mu_s, double mu_r, dem_damping_mode damping);

/// Table 3: a boundary's stiffness (k_n = k_s = k_r) from the granules' k_n.
double exp_boundary_stiffness(double granule_k_n);

/// Table 3's granule–boundary pair: the boundary's stiffness for all three
/// springs, the granule pair's ξ and damping, the boundary's own friction.
dem_contact_params exp_boundary_pair(const dem_contact_params *granule, double mu_s, double mu_r);

#endif
