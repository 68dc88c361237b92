// SPDX-License-Identifier: MIT
/// @file exp_result.h
/// The state file an experiment's run leaves in its output folder (`granucal
/// simulate SCENE --out DIR`): DIR/result.h5, the world's final state as one
/// frame with its diagnostics and the engine's account of its time step
/// (ParaView reads it through DIR/result.xmf). Written whole or not at all
/// (dem_h5_close renames it into place).
#ifndef EXP_RESULT_H
#define EXP_RESULT_H

#include <stddef.h>

#include "dem_world.h"

/// Returns 0, or non-zero with a message naming the file in err.
int exp_result_write_h5(const char *dir, const dem_world *w, char *err, size_t len);

#endif
