// SPDX-License-Identifier: MIT
/// @file dem_stability.h
/// The engine's own time-step limit. Eq. 14's dt_crit = sqrt(m_min/k_n) is
/// the reference, but it is not the limit: with k_s = k_n a sticking contact
/// moves a solid sphere's contact point 3.5× more easily than its centre
/// (1/m + R²/I = 3.5/m), so neighbours counter-rotating ("spin mode") vibrate
/// far faster than the normal mode, and the ξ = 0.7 dashpot, explicit in
/// velocity Verlet, tightens the limit further.
///
/// The limit is computed, not assumed: power iteration on the linearised,
/// mass-normalised stiffness (normal, sticking tangential and rolling
/// springs) and dashpot operators of a contact network gives the highest
/// angular frequency ω and damping rate c; velocity Verlet with a velocity
/// lagged by half a step is stable for ω·dt < 2(sqrt(1+ζ²) − ζ), which with
/// ζ ≤ c/(2ω) gives dt < 4 / (sqrt(4ω² + c²) + c). With the implicit dashpot
/// (dem_world_def.implicit_damping) the limit is that of the springs alone,
/// ω·dt < 2.
#ifndef DEM_STABILITY_H
#define DEM_STABILITY_H

#include "dem_world.h"

typedef struct dem_stability {
    double omega_max;    ///< highest angular frequency of the contact network, rad/s
    double damping_max;  ///< highest mass-normalised dashpot rate, 1/s
    double dt_limit;     ///< stable step limit, s
    double dt_crit;      ///< eq. 14: sqrt(m_min / k_n), s
    char why[200];       ///< what network the limit was computed for
} dem_stability;

/// Limit for the scene before it runs: a dense face-centred-cubic cluster
/// (12 contacts each, the most an equal sphere can have) of the scene's
/// lightest granules, with the stiffest of the granule and wall springs, all
/// sticking. Conservative: heavier neighbours only lower the frequencies.
dem_stability dem_stability_apriori(const dem_world *w);

/// Limit of the world's current contact network (e.g. a settled bed).
dem_stability dem_stability_current(dem_world *w);

/// Limit for the contacts of any world, used by both of the above.
dem_stability dem_stability_of_network(dem_world *w, double dt_crit);

#endif
