// SPDX-License-Identifier: MIT
/// @file exp_scene_runner.h
/// An explicit scene's runner (exp_scene.h): run a loaded scene and write
/// its trajectory, frame by frame.
#ifndef EXP_SCENE_RUNNER_H
#define EXP_SCENE_RUNNER_H

#include "exp_scene.h"

/// `granucal simulate SCENE.yaml [--out DIR]` once the scene is loaded
/// (exp_scene_load) from `path` (named in messages): build, run for its
/// duration, one frame every output_interval; `out_dir` (NULL:
/// results/runs/<scene name>) gets trajectory.csv (t,id,x,y,z,vx,vy,vz,
/// wx,wy,wz), result.h5 (the same frames with diagnostics) and result.json,
/// the summary also printed on stdout. 0, or 1 when the run failed or a file
/// could not be written.
int exp_scene_simulate(const exp_scene *s, const char *out_dir, const char *path);

#endif
