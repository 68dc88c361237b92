// SPDX-License-Identifier: MIT
/// @file cal_export.h
/// The calibrated table as input for other DEM codes: LIGGGHTS 3.8
/// (`liggghts_parameters.in`) and LAMMPS `pair_style granular`
/// (`lammps_parameters.in`), with what each leaves out of the paper's model;
/// and complete decks of the calibration's drum at its tier that include them
/// and run as written (`liggghts_drum.in`, `lammps_drum.in`: geometry, the
/// GSD at lambda, granucal's time step and why, pour, cut to the fill degree,
/// turn, dumps).
#ifndef CAL_EXPORT_H
#define CAL_EXPORT_H

#include <stdio.h>

#include "cal_report.h"

/// Write the export files into dir (the decks only when the table has a wall
/// material to line the drum with). 0 on success, else 1 with a message.
int cal_export_write(const char *dir, const cal_outcome *o, char *err, size_t len);

/// The report's section on the exports: what they leave out, and the peers
/// check of dir/peers when one was run on this table.
void cal_export_report(FILE *f, const char *dir);

#endif
