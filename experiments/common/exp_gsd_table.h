// SPDX-License-Identifier: MIT
/// @file exp_gsd_table.h
/// A measured size distribution from a CSV file, for the configs' `gsd_table`
/// key. The file:
///
///     # comments and blank lines are skipped
///     size_um,cumulative_percent
///     60,0
///     ...
///     600,100
///
/// sizes in micrometres, strictly increasing; the cumulative percentage below
/// each size, never decreasing, 0 on the first row and 100 on the last. The
/// config's `gsd_basis` says what it counts: `volume` (laser diffraction,
/// sieving: converted to numbers) or `number`. The rules and the conversion
/// are dem_gsd_from_table's (engine/dem_gsd.c); this file reads and locates.
#ifndef EXP_GSD_TABLE_H
#define EXP_GSD_TABLE_H

#include <stddef.h>

#include "dem_gsd.h"

/// "volume" or "number" to a basis; non-zero for anything else.
int exp_gsd_basis_from_name(const char *name, dem_gsd_basis *out);

/// Read `path` on `basis_name` into *out. 0 on success; else 1 with
/// "PATH:LINE: FIELD: what is wrong" (or "PATH: ..." for the file as a whole) in err.
int exp_gsd_table_load(const char *path, const char *basis_name, dem_gsd *out, char *err, size_t len);

#endif
