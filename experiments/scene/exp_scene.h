// SPDX-License-Identifier: MIT
/// @file exp_scene.h
/// Explicit scenes: granules and walls listed one by one in YAML (the
/// paper's verification test, Table A.1, is one). Loaded with libcyaml
/// against a schema, then checked field by field; errors name the file, the
/// line and the field.
#ifndef EXP_SCENE_H
#define EXP_SCENE_H

#include <stddef.h>

#include "dem_world.h"

/// Contact parameters as written in YAML.
typedef struct exp_contact_yaml {
    double k_n, k_s, k_r, xi, mu_s, mu_r;
    char *damping; ///< reading of eq. 4, optional (default "approaching")
} exp_contact_yaml;

typedef struct exp_wall_yaml {
    char *name;
    char *kind; ///< plane | disc | cylinder
    double point[3], normal[3], axis[3];
    double radius;
    double rpm; ///< spin about axis, revolutions per minute
    exp_contact_yaml contact;
} exp_wall_yaml;

typedef struct exp_granule_yaml {
    double position[3], velocity[3], omega[3];
    double radius, density;
} exp_granule_yaml;

/// An explicit scene.
typedef struct exp_scene {
    char *name;
    double duration;        ///< simulated time, s
    double dt;              ///< time step, s; 0 = the engine's stable choice
    double output_interval; ///< s between trajectory rows
    double gravity[3];
    double domain_lo[3], domain_hi[3];
    char *lever_arm;        ///< contact_point | radius (optional)
    exp_contact_yaml granule_contact;
    exp_wall_yaml *walls;
    unsigned walls_count;
    exp_granule_yaml *granules;
    unsigned granules_count;
} exp_scene;

/// Load and validate a scene file. Returns NULL with a message naming the
/// file, line and field in `err`.
exp_scene *exp_scene_load(const char *path, char *err, size_t err_len);
void exp_scene_free(exp_scene *s);

/// Build a world from a scene. Returns NULL with a message in `err`.
dem_world *exp_scene_build(const exp_scene *s, char *err, size_t err_len);

/// Convert contact parameters read from YAML; `where` prefixes messages.
int exp_contact_from_yaml(const exp_contact_yaml *y, dem_contact_params *out, const char *where, char *err,
                          size_t err_len);

#endif
