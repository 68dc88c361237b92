// SPDX-License-Identifier: MIT
/// @file dem_output.h
/// Simulation state to HDF5, with an XDMF sidecar that ParaView opens as a
/// time series of point clouds.
///
/// Layout of the HDF5 file:
///
///     /                       root attributes from dem_h5_write_attribute_string
///     /frames/NNNNNN          one group per frame (000000, 000001, ...); attributes
///                             time, step, granules, contacts, wall_contacts,
///                             coordination, coordination_walls, ke_translational,
///                             ke_rotational, max_overlap_ratio, potential_elastic
///         position  N×3 float64, m
///         velocity  N×3 float64, m/s
///         omega     N×3 float64, rad/s
///         radius    N   float64, m
///         id        N   uint64, stable granule id
///     /diagnostics            frames×11 float64, one row per frame; attribute
///                             `columns` names the columns, `units` their units
///
/// Both files are written under temporary names (`<h5 path>.tmp`, `<xmf
/// path>.tmp`) and renamed into place by dem_h5_close, so a run killed part
/// way never leaves a half-written file under the final name. The sidecar is
/// `<h5 path without .h5>.xmf` and refers to the HDF5 file by its base name,
/// so the pair can be moved together.
///
/// HDF5's automatic error printing is silenced inside these functions (and
/// restored on return); failures come back as a status and a message.
///
/// Serial HDF5 is not thread-safe: a parallel driver must serialise all HDF5
/// use in the process (these functions and any other HDF5 user) with a lock.
#ifndef DEM_OUTPUT_H
#define DEM_OUTPUT_H

#include <stddef.h>

#include "dem_world.h"

/// An open HDF5 output file.
typedef struct dem_h5_writer dem_h5_writer;

/// Create (or replace, on close) the HDF5 file `h5_path`. Returns NULL on
/// failure; then `err`, if not NULL, receives a message naming the file.
dem_h5_writer *dem_h5_open(const char *h5_path, char *err, size_t err_len);

/// Append one frame: the granules in `g` and the diagnostics `d` (both
/// required). `time` is the frame's time (normally d->time) and is what the
/// frame attribute, the diagnostics row and the XDMF time step carry.
/// Returns 0, or non-zero with the message in dem_h5_error(). After a
/// failure the writer refuses further frames and dem_h5_close discards the
/// files.
int dem_h5_write_frame(dem_h5_writer *w, double time, const dem_granules_view *g, const dem_diagnostics *d);

/// Set a string attribute on the root group (engine version, feature list,
/// time-step report...). Setting a name again replaces its value. Returns 0
/// or non-zero with the message in dem_h5_error().
int dem_h5_write_attribute_string(dem_h5_writer *w, const char *name, const char *value);

/// Message of the last failure, "" if none.
const char *dem_h5_error(const dem_h5_writer *w);

/// Write the XDMF sidecar, close the HDF5 file and rename both into place;
/// always frees `w` (NULL is a no-op returning 0). Returns 0, or non-zero
/// with a message naming the file in `err` (if not NULL). On failure, and
/// after any earlier failed write, the temporary files are removed; a final
/// name is only ever replaced by a complete file.
int dem_h5_close(dem_h5_writer *w, char *err, size_t err_len);

#endif
