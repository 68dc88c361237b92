// SPDX-License-Identifier: MIT
/// @file exp_cylinder.h
/// The poured cylinder of section 4.1: granules poured from above into a
/// metallic container 100 mm across and 40 mm deep, and the mean
/// coordination number of the bed at rest — the measure stage 1 of the
/// calibration sweeps against the contact stiffness (Fig. 12).
#ifndef EXP_CYLINDER_H
#define EXP_CYLINDER_H

#include <stdint.h>

#include "dem_gsd.h"
#include "dem_world.h"
#include "exp_common.h"

typedef struct exp_cylinder_def {
    double diameter;         ///< m (0.1)
    double depth;            ///< m (0.04): the bed is poured to the rim
    double lambda;           ///< coarse-graining scale factor (eq. 15)
    dem_gsd gsd;             ///< real GSD
    double density;          ///< real density, kg/m³
    dem_contact_params granule; ///< real granule–granule contact
    dem_contact_params wall;    ///< real granule–container contact; its stiffness is set to 2 k_n (Table 3)
    uint64_t seed;
} exp_cylinder_def;

exp_cylinder_def exp_default_cylinder_def(void);

/// Every field of a definition exp_cylinder_run would pour, or 1 with a
/// message that starts with the field ("lambda = ...", "granule_contact.mu_s = ...").
int exp_cylinder_check(const exp_cylinder_def *d, char *msg, size_t len);

/// Coordination numbers of a poured bed at rest: the cylinder's, or the
/// drum's own bed (exp_drum_bed.h), counted by one rule (exp_count_bed_contacts).
typedef struct exp_cylinder_result {
    size_t granules;
    double coordination;          ///< granule–granule contacts per granule, 2C/N (walls not counted)
    double coordination_interior; ///< the same over granules at least d_max from walls and free surface
    double wall_contacts_per_granule; ///< granule–wall contacts per granule, stated separately
    double solid_fraction;        ///< solid volume over the bed's volume (the cylinder's: the container below the rim)
    double simulated_time_s;
    double particle_steps; ///< granule-steps of the pour and settling (dem_world_particle_steps)
} exp_cylinder_result;

/// What a poured cylinder is expected to cost, before it runs (for the
/// calibration's plan): granules from the container's volume at the solid
/// fraction the pours reach (0.53-0.54), steps from eq. 14's dt_crit of the
/// lightest scaled granule at the fraction the engine pours at
/// (EXP_POUR_STEP_FRACTION), over the 3 s a pour and settling takes (2.9-3.05 s in the 15
/// records of results/calibration-standard/store, λ 32768, k 50-800 N/m).
typedef struct exp_cylinder_cost {
    double granules;
    double particle_steps;
    double memory_mb; ///< peak resident memory (exp_predicted_peak_memory_mb)
} exp_cylinder_cost;

exp_cylinder_cost exp_cylinder_predict_cost(const exp_cylinder_def *d);

/// Whether a granule at p is interior: at least dmax (the largest diameter)
/// from every wall and below the free surface (top: the highest granule
/// centre) by dmax. ctx: the scene's definition.
typedef int (*exp_interior_fn)(dem_vec3 p, double top, double dmax, const void *ctx);

/// Count the contacts of a bed at rest, the one rule of every stage-1 scene:
/// granules, coordination (2C/N granule-granule, dem_world_diagnose), wall
/// contacts per granule, and the interior coordination over the granules
/// `interior` accepts (NAN: none); *solid_volume: the granules' volume. The
/// scene sets solid_fraction and simulated_time_s. 1 when out of memory.
int exp_count_bed_contacts(const dem_world *w, double dmax, exp_interior_fn interior, const void *ctx,
                           exp_cylinder_result *out, double *solid_volume);

/// Pour, cut at the rim, settle, and count contacts. NULL world on error.
dem_world *exp_cylinder_run(const exp_cylinder_def *d, exp_progress_fn progress, void *ctx, exp_cylinder_result *out,
                            char *err, size_t len);

#endif
