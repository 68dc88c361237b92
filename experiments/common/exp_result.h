// SPDX-License-Identifier: MIT
/// @file exp_result.h
/// The files every experiment's run leaves in its output folder (`granucal
/// simulate SCENE --out DIR`), written here and nowhere else:
///  - DIR/result.h5, the world's final state as one frame with its
///    diagnostics and the engine's account of its time step (ParaView reads
///    it through DIR/result.xmf). Written whole or not at all (dem_h5_close
///    renames it into place).
///  - DIR/result.json, the run's one-line JSON summary, which the experiment
///    formats (its fields are its own) and this writes whole or not at all
///    (a temporary file, flushed to disk, renamed).
///  - on stdout, the JSON of a run that failed before it had a result.
/// And the way every other file of a run is written whole or not at all
/// (curve.csv, series.csv, trajectory.csv, ...): exp_atomic_file.
#ifndef EXP_RESULT_H
#define EXP_RESULT_H

#include <stddef.h>
#include <stdio.h>

#include "dem_output.h"
#include "dem_world.h"

/// Returns 0, or non-zero with a message naming the file in err.
int exp_result_write_h5(const char *dir, const dem_world *w, char *err, size_t len);

/// DIR/result.h5 for a run that writes several frames (an explicit scene's
/// trajectory): exp_result_h5_frame for each, dem_h5_close at the end. NULL
/// with a message.
dem_h5_writer *exp_result_h5_open(const char *dir, char *err, size_t len);

/// The world now as one frame with its diagnostics. 0, or non-zero (the
/// writer's message: dem_h5_error).
int exp_result_h5_frame(dem_h5_writer *h5, const dem_world *w);

/// Formats an experiment's JSON summary on `f` (a file or stdout): the same
/// function writes result.json and the copy on stdout, so the two agree.
typedef void (*exp_result_json_fn)(FILE *f, const void *ctx);

/// DIR/result.json from `write(f, ctx)`. 0, or 1 with a message naming the file.
int exp_result_write_json(const char *dir, exp_result_json_fn write, const void *ctx, char *err, size_t len);

/// One line on stdout for a run that failed before it had a result:
/// {"experiment": NAME, "status": "failed", "error": ERR}, the error escaped
/// as a JSON string.
void exp_result_print_failure(const char *experiment, const char *err);

#endif
