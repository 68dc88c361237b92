// SPDX-License-Identifier: MIT
/// @file exp_compress.h
/// The confined compression test of sections 3.2.1 and 4.1: a cylindrical
/// die 76 mm across and 15 mm deep, granules poured in and struck off at the
/// rim, then a flat piston driven down and up at a constant, quasi-static
/// speed, reversing when the stress on it reaches σ_max (loading) or σ_min
/// (unloading): loading–unloading cycles between two pressures, as the
/// Instron test of Fig. 4 does. The confined modulus E' (eq. 19) comes from
/// the last cycle.
///
/// Effects: no rolling resistance (μ_r = 0 for granules and walls, so the
/// engine switches the rolling spring off); tangential friction and the
/// normal dashpot on. Section 4.1 sets the granule–die friction to 0.2.
///
/// The physics only: exp_compress_config.h loads a definition from YAML,
/// exp_compress_runner.h runs it and writes its files.
#ifndef EXP_COMPRESS_H
#define EXP_COMPRESS_H

#include <stddef.h>
#include <stdint.h>

#include "dem_gsd.h"
#include "dem_world.h"
#include "exp_common.h"

#define EXP_COMPRESS_MAX_CYCLES 32

/// Definition of a compression run. Powder and contacts are for the REAL
/// powder; eq. 15–18 are applied with `lambda`. The pressures are applied
/// to the simulated (coarse) bed as they are (see docs/experiments.md: E' of a coarse bed
/// at a fixed real k scales as λ^(−2/3)).
typedef struct exp_compress_def {
    double diameter;     ///< die inner diameter, m (0.076)
    double depth;        ///< die depth, m (0.015): the bed is poured to the rim
    double lambda;       ///< coarse-graining scale factor (eq. 15)
    dem_gsd gsd;         ///< real GSD
    double density;      ///< real density, kg/m³
    dem_contact_params granule; ///< real granule–granule contact; mu_r must be 0 (no rolling here)
    dem_contact_params wall;    ///< real granule–die/piston contact; stiffness set to 2 k_n (Table 3), mu_r 0
    double sigma_min, sigma_max; ///< pressures between which the piston cycles, Pa
    double piston_speed; ///< m/s, loading and unloading
    int cycles;          ///< loading–unloading cycles (≥ 2: E' from the last, stability from the last two)
    double max_time;     ///< s of piston motion at most
    uint64_t seed;
    int stop_at_last_turn; ///< stop at the last cycle's σ_max (the bed under load; for tests), 0: complete it
} exp_compress_def;

exp_compress_def exp_default_compress_def(void);

/// Check a definition; a message names the field.
int exp_compress_check(const exp_compress_def *d, char *msg, size_t len);

/// One sample of the force–displacement curve.
typedef struct exp_compress_sample {
    double t;            ///< s since the piston started
    double piston_y;     ///< piston height above the die floor, m
    double displacement; ///< piston travel from where σ first reached σ_min, m (> 0 down)
    double strain;       ///< displacement / bed height at that point
    double f_top;        ///< spring force of the granules on the piston, N (Σ k h: what σ is)
    double f_bottom;     ///< ... on the die floor, N
    double f_side;       ///< sum of normal forces on the die's side wall, N
    /// The whole force of the granules along the die's axis (−y is down, so
    /// a wall pushed outwards by the bed reads +y for the piston, −y for the
    /// floor), as the engine computed it (dem_world_wall_force: springs,
    /// dashpots and friction): on the piston, the floor, and the side wall
    /// (there only friction has an axial part: the load the die wall carries).
    double f_piston_axial, f_floor_axial, f_side_axial;
    double sigma;        ///< f_top / die area, Pa
    double ke_over_elastic; ///< kinetic over elastic energy of the bed (quasi-static when small)
    int cycle;           ///< 1-based
    int loading;         ///< 1 while the piston moves down
} exp_compress_sample;

/// One loading–unloading cycle: start (σ_min on loading, or the end of the
/// previous unloading), turn (σ_max), end (σ_min on unloading).
typedef struct exp_compress_cycle {
    double sigma_start, strain_start, sigma_turn, strain_turn, sigma_end, strain_end;
    double e_loading;    ///< eq. 19 on the loading branch, Pa
    double e_unloading;  ///< eq. 19 on the unloading branch, Pa
    double permanent_strain; ///< strain_end − strain_start
    double work_in, work_out; ///< J: piston work while loading, returned while unloading
} exp_compress_cycle;

typedef struct exp_compress_result {
    size_t granules;
    double bed_height;        ///< piston height where σ first reached σ_min, m (the strain reference)
    double solid_fraction;    ///< solid volume over the die volume below bed_height
    double coordination_turn; ///< granule–granule coordination at the last σ_max
    int n_cycles;
    exp_compress_cycle cycle[EXP_COMPRESS_MAX_CYCLES];
    double e_confined;        ///< E' (eq. 19) of the last cycle, unloading branch, Pa
    double e_confined_loading;///< the same on its loading branch, Pa
    int stable;               ///< last cycle: permanent strain < 5 % of its elastic strain, E' within 5 % of the previous cycle's
    double max_ke_over_elastic; ///< largest KE/elastic energy while the piston touched the bed
    double fill_time_s, simulated_time_s; ///< s of simulated time: fill + settle, piston motion
    unsigned long long particle_steps;
    exp_compress_sample *curve; ///< samples (owned; exp_compress_result_free)
    size_t n_curve;
} exp_compress_result;

void exp_compress_result_free(exp_compress_result *r);

/// Pour, strike off at the rim, settle, and cycle the piston. Returns the
/// world at the end (the bed at σ_min after the last unloading) or NULL
/// with a message. The piston is the world's wall 2, the floor wall 1, the
/// side wall 0.
dem_world *exp_compress_run(const exp_compress_def *d, exp_progress_fn progress, void *ctx, exp_compress_result *out,
                            char *err, size_t len);

#endif
