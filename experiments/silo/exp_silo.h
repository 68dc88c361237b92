// SPDX-License-Identifier: MIT
/// @file exp_silo.h
/// The silo discharge benchmark of Appendix A.2 (Table A.2): granules of
/// d50 = 1 m, σ_geo = 1.1, ρ = 500 kg/m³, k_n = k_s = 50 000 N/m (walls
/// 100 000), no damping, μ_s = 0.5, no rolling, Δt = 1e-3 s, 120 s; a
/// flat-bottomed silo discharging into a vessel. The paper compares the number
/// of contacts and the kinetic energy over time with LIGGGHTS (Fig. A.4, A.5).
///
/// Geometry (the paper states none beyond Fig. A.3; assumptions, z up):
///  - one vertical cylinder of radius `silo_radius` is the wall of both the
///    silo and the vessel below it (same cross-section), the vessel floor is
///    the plane z = 0;
///  - the silo's flat bottom at z = `plate_z` is a plate of fixed spheres of
///    radius `plate_sphere_radius` on concentric rings (just not touching; the
///    holes between them pass no granule), open in the centre: the clear
///    orifice radius is about `orifice_radius`. The engine's walls are planes,
///    discs and infinite cylinders, and a disc pushes every granule in its
///    footprint below it, so a plate with a hole cannot be a wall; fixed
///    spheres are what LIGGGHTS gets too (a frozen atom group), so both codes
///    see the same bumpy plate. Fixed spheres are the engine's fixed granules
///    (dem_world_set_granule_fixed), at the granules' density: LIGGGHTS
///    integrates only the `flow` group, which holds its plate still alike.
///  - fill: granules on a lattice above the plate, the orifice closed by a
///    gate of more fixed spheres, settled with a temporary dashpot (ξ_fill)
///    until at rest; then the discharge starts from that state in a fresh
///    world (no contact history, zero velocities) with Table A.2's contact,
///    gate removed — exactly the state written for LIGGGHTS.
///
/// The physics only: exp_silo_config.h loads a definition from YAML,
/// exp_silo_runner.h runs it and writes its files.
#ifndef EXP_SILO_H
#define EXP_SILO_H

#include <stddef.h>
#include <stdint.h>

#include "dem_gsd.h"
#include "dem_world.h"
#include "exp_common.h"

typedef struct exp_silo_def {
    dem_gsd gsd;            ///< d50 1 m, σ_g 1.1, truncated at ±2σ (Table A.2)
    double density;         ///< 500 kg/m³
    dem_contact_params granule, wall; ///< Table A.2
    size_t n_granules;      ///< flowing granules
    double silo_radius;     ///< m
    double orifice_radius;  ///< clear radius of the orifice, m
    double plate_z;         ///< height of the plate spheres' centres, m
    double plate_sphere_radius; ///< m
    double dt;              ///< 1e-3 s (Table A.2)
    double duration;        ///< 120 s (Table A.2)
    double sample_interval; ///< s between samples of the time series
    double fill_xi;         ///< damping ratio while filling only
    double fill_max_time;   ///< s
    uint64_t seed;
} exp_silo_def;

exp_silo_def exp_default_silo_def(void);
int exp_silo_check(const exp_silo_def *d, char *msg, size_t len);

/// The orifice's clear radius the plate's rings leave (m): the innermost
/// ring's radius less a plate sphere's, about d->orifice_radius.
double exp_silo_orifice_clear_radius(const exp_silo_def *d);

typedef struct exp_silo_sample {
    double t;
    size_t contacts;       ///< sphere–sphere contacts (granule–granule and granule–plate)
    size_t wall_contacts;  ///< granule–wall (cylinder, floor) contacts
    double ke_translational, ke_rotational; ///< J, flowing granules only
    size_t discharged;     ///< flowing granules below the plate
    double discharged_mass; ///< kg
} exp_silo_sample;

typedef struct exp_silo_result {
    size_t granules, plate_spheres;
    double fill_time_s;
    exp_silo_sample *series;
    size_t n_series;
    double wall_time_s;
    unsigned long long particle_steps;
} exp_silo_result;

void exp_silo_result_free(exp_silo_result *r);

/// Build the discharge world at t = 0 (filled, settled, gate removed): the
/// plate spheres come first (ids 0..plate_spheres−1). NULL with a message.
dem_world *exp_silo_prepare(const exp_silo_def *d, exp_progress_fn progress, void *ctx, size_t *plate_spheres,
                            char *err, size_t len);

/// Run the discharge for d->duration, sampling every d->sample_interval.
/// Returns the engine status; the series so far is kept on a fault.
dem_status exp_silo_discharge(dem_world *w, const exp_silo_def *d, size_t plate_spheres, exp_progress_fn progress,
                              void *ctx, exp_silo_result *out);

#endif
