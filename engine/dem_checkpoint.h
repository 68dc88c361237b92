// SPDX-License-Identifier: MIT
/// @file dem_checkpoint.h
/// A world's whole state in one HDF5 file, to resume a long run after a kill:
/// granules, forces, contact springs, the neighbour list as it stands (so the
/// resumed run sums its forces in the same order), walls, time and step. A run
/// resumed from a checkpoint goes on bit for bit as the run that wrote it
/// would have, on the same build and thread count (what dem_world_clone
/// copies is what is saved).
///
/// The file is written under `<path>.tmp` and renamed into place, so a kill
/// while writing leaves the previous checkpoint whole. It is tied to the
/// build that wrote it: the world's memory layout is part of the file, and a
/// checkpoint of another layout is refused, never misread. The world's
/// definition is in it (its network check interval, each wall's prescribed
/// motion) with the steps since its last network check: a resumed run moves
/// its walls and checks its step where the run that wrote it would have. A
/// checkpoint of the layout before those (issue 38) is refused with the
/// message "written by another build of the engine", not loaded with
/// defaults: where its next check falls is not in it, and a run resumed
/// without it would not be the run that wrote it; the drum then turns afresh
/// (its note says why), ending as the uninterrupted run.
#ifndef DEM_CHECKPOINT_H
#define DEM_CHECKPOINT_H

#include <stddef.h>

#include "dem_world.h"

/// A caller's own numbers saved with the world (a run's measurements so far):
/// `count` doubles under `name` (letters, digits, '_'). On reading, `data`
/// is allocated (the caller frees it, also on failure) and `count` set.
typedef struct dem_checkpoint_array {
    const char *name;
    double *data;
    size_t count;
} dem_checkpoint_array;

/// Save @p w and the caller's arrays to @p path, labelled with @p key (the
/// text that defines the run: a checkpoint is resumed only by the same run).
/// 0, or non-zero with a message naming the file; the previous file at
/// @p path is then untouched.
int dem_checkpoint_write(const dem_world *w, const char *path, const char *key, const dem_checkpoint_array *extra,
                         int n_extra, char *err, size_t len);

/// Replace the whole state of @p w by the checkpoint at @p path, and read the
/// caller's arrays (by name). Returns 0; 1 if there is no file at @p path;
/// −1 if the file is there but cannot be resumed (another run's key, another
/// build's layout, damaged), with the reason in @p err. On non-zero @p w is
/// unchanged.
int dem_checkpoint_read(dem_world *w, const char *path, const char *key, dem_checkpoint_array *extra, int n_extra,
                        char *err, size_t len);

/// Remove the checkpoint at @p path and any temporary a killed write left
/// beside it (once the run's result is safe elsewhere).
void dem_checkpoint_remove(const char *path);

#endif
