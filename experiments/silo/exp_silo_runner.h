// SPDX-License-Identifier: MIT
/// @file exp_silo_runner.h
/// The silo discharge benchmark's runner (exp_silo.h): run a definition
/// (exp_silo_config.h loads one) and write its files.
#ifndef EXP_SILO_RUNNER_H
#define EXP_SILO_RUNNER_H

#include <stddef.h>

#include "exp_silo.h"

/// Write the world's state as a LIGGGHTS data file (atom_style granular:
/// id type diameter density x y z; flowing granules type 1, plate type 2).
int exp_silo_write_liggghts_data(const char *path, const dem_world *w, const exp_silo_def *d, size_t plate_spheres,
                                 char *err, size_t len);

/// Time series as CSV (t_s,contacts,wall_contacts,ke_translational_J,
/// ke_rotational_J,ke_total_J,discharged,discharged_mass_kg) and PNGs of
/// contacts and kinetic energy over time (png_prefix + "contacts.png",
/// "kinetic_energy.png"; NULL for none).
int exp_silo_write_series(const exp_silo_result *r, const char *csv_path, const char *png_prefix, char *err,
                          size_t len);

/// `granucal simulate configs/silo.yaml [--set k=v ...] [--out DIR]` once
/// the config is loaded into `d`: fill, discharge, JSON on stdout; `out_dir`
/// (NULL: results/runs/silo) gets result.json, result.h5 (final frame),
/// series.csv, contacts.png, kinetic_energy.png and silo_initial.data (the
/// t = 0 state, for LIGGGHTS). 0, or 1 when the run failed or a file could
/// not be written.
int exp_silo_simulate(const exp_silo_def *d, const char *out_dir);

#endif
