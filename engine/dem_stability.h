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

/// One contact of a network, linearised about its current geometry: granule
/// i against granule j, or against a wall (j = SIZE_MAX: a partner of
/// infinite mass); unit normal n from i towards the partner, lever arms ai
/// and aj, R*, m*, the contact's parameters (k_n, k_s, k_r, ξ) and its
/// overlap h, at which a law whose springs stiffen with the overlap
/// (Hertz–Mindlin) is linearised (dem_contact_model.stiffness_at).
typedef struct dem_network_contact {
    size_t i, j;
    dem_vec3 n;
    double ai, aj, rstar, mstar;
    const dem_contact_params *p;
    double overlap;
} dem_network_contact;

/// A contact network: the granules' masses and moments of inertia, and the
/// contacts between them. Its limit depends on the order of the contacts in
/// its last bits (the power iteration sums them in that order).
typedef struct dem_contact_network {
    size_t granules;
    const double *mass, *inertia;
    size_t count;
    const dem_network_contact *contact;
} dem_contact_network;

/// How the network is integrated: the limit differs.
typedef struct dem_integration {
    int implicit_damping;  ///< dem_world_def.implicit_damping
    int implicit_springs;  ///< as decided (never auto)
    int dashpot_switches;  ///< some dashpot is switched on and off within a contact
} dem_integration;

/// Limit of a network: a pure function of it.
dem_stability dem_stability_of_network(const dem_contact_network *net, const dem_integration *how, double dt_crit);

/// Limit of the densest cluster of equal granules of mass m_min and radius
/// r_min (face-centred cubic, 12 contacts each, the most an equal sphere can
/// have) with contact parameters p, all springs sticking; lever_factor 1 for
/// the contact-point lever arm, 0 for R.
dem_stability dem_stability_fcc(const dem_contact_params *p, double lever_factor, const dem_integration *how,
                                double m_min, double r_min, double dt_crit);

/// The Rayleigh time of the smallest granules, the reference step of a
/// Hertz–Mindlin contact (its eq. 14): t_R = π R √(ρ/G) / (0.1631 ν +
/// 0.8766), the time a Rayleigh surface wave takes across a granule
/// (Li, Xu & Thornton 2005, Powder Technol. 160:219; Thornton 2015,
/// "Granular Dynamics, Contact Mechanics and Particle System Simulations",
/// sec. 2.6), with ρ from m_min and r_min and ν and G from E* and G* read as
/// two granules of one material (see material_of in dem_stability.c).
double dem_rayleigh_time(const dem_contact_params *p, double m_min, double r_min);

/// A Hertz–Mindlin contact's stiffness grows with the overlap, so no
/// a-priori cluster has one frequency: the limit before a run is instead a
/// fraction of the Rayleigh time, the DEM literature's rule for Hertzian
/// contacts (0.2–0.4 t_R is the usual range; Li et al. 2005). The limit of a
/// current network (dem_stability_current) is the power iteration at each
/// contact's own overlap.
#define DEM_RAYLEIGH_FRACTION 0.2
dem_stability dem_stability_rayleigh(const dem_contact_params *p, double m_min, double r_min);

/// Limit for the scene before it runs: dem_stability_fcc of the scene's
/// lightest granules, with the stiffest of the granule and wall springs.
/// Conservative: heavier neighbours only lower the frequencies.
dem_stability dem_stability_apriori(const dem_world *w);

/// Limit of the world's current contact network (e.g. a settled bed).
dem_stability dem_stability_current(dem_world *w);

#endif
