// SPDX-License-Identifier: MIT
// The poured cylinder (section 4.1) as a YAML scene: load, --set, validate.
// See exp_cylinder_config.h; its runner is exp_cylinder_runner.c.
#include "exp_cylinder_config.h"

#include <cyaml/cyaml.h>
#include <stdio.h>
#include <string.h>

#include "exp_contact_rules.h"
#include "exp_yaml.h"

typedef struct cylinder_yaml {
    char *experiment;
    double diameter, depth, density, median_diameter, geometric_sd, truncation_sigmas, lambda;
    double k_n, xi, mu_s, mu_r;
    char *damping;
    int seed;
} cylinder_yaml;

#define F(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_DEFAULT, cylinder_yaml, member)
static const cyaml_schema_field_t cylinder_fields[] = {
    CYAML_FIELD_STRING_PTR("experiment", CYAML_FLAG_POINTER, cylinder_yaml, experiment, 1, 16),
    F("diameter", diameter), F("depth", depth), F("density", density), F("median_diameter", median_diameter),
    F("geometric_sd", geometric_sd), F("truncation_sigmas", truncation_sigmas), F("lambda", lambda), F("k_n", k_n),
    F("xi", xi), F("mu_s", mu_s), F("mu_r", mu_r),
    CYAML_FIELD_STRING_PTR("damping", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cylinder_yaml, damping, 1, 32),
    CYAML_FIELD_INT("seed", CYAML_FLAG_DEFAULT, cylinder_yaml, seed), CYAML_FIELD_END};
#undef F
static const cyaml_schema_value_t cylinder_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, cylinder_yaml, cylinder_fields)};

int exp_is_cylinder_config(const char *path) { return exp_yaml_starts_with(path, "experiment: cylinder"); }

static int to_def(const cylinder_yaml *y, exp_cylinder_def *d, char *err, size_t len)
{
    *d = exp_default_cylinder_def();
    d->diameter = y->diameter, d->depth = y->depth, d->density = y->density, d->lambda = y->lambda;
    d->gsd = dem_gsd_lognormal(y->median_diameter, y->geometric_sd, y->truncation_sigmas);
    dem_damping_mode mode;
    if (exp_damping_from_name(y->damping, "damping", &mode, err, len)) return 1;
    // The container's friction is the granules' (as in the calibration's
    // stage 1); exp_cylinder_run gives it Table 3's boundary stiffness.
    d->granule = exp_granule_pair(y->k_n, y->xi, y->mu_s, y->mu_r, mode);
    d->wall = d->granule;
    d->seed = (uint64_t)y->seed;
    return 0;
}

static int apply_set(cylinder_yaml *y, const char *set, char *err, size_t len)
{
    const exp_set_key keys[] = {
        EXP_SET_NUMBER("k_n", &y->k_n), EXP_SET_NUMBER("mu_s", &y->mu_s), EXP_SET_NUMBER("mu_r", &y->mu_r),
        EXP_SET_NUMBER("xi", &y->xi), EXP_SET_NUMBER("lambda", &y->lambda), EXP_SET_INTEGER("seed", &y->seed),
        EXP_SET_NUMBER("diameter", &y->diameter), EXP_SET_NUMBER("depth", &y->depth),
        EXP_SET_NUMBER("density", &y->density)};
    return exp_apply_set(set, keys, sizeof keys / sizeof *keys, err, len);
}

int exp_cylinder_load(const char *path, int n_sets, char **sets, exp_cylinder_def *d, char *err, size_t len)
{
    cylinder_yaml *y = NULL;
    if (exp_yaml_load(path, &cylinder_schema, (void **)&y, "check the keys and value types against configs/cylinder.yaml",
                      err, len))
        return 1;
    char msg[300];
    int bad = 0;
    for (int k = 0; k < n_sets && !bad; ++k) bad = apply_set(y, sets[k], err, len);
    if (!bad && strcmp(y->experiment, "cylinder") != 0)
        bad = exp_field_error(path, 0, NULL, "experiment", "must be cylinder", err, len);
    if (!bad) bad = exp_seed_check(path, y->seed, err, len);
    if (!bad && (to_def(y, d, msg, sizeof msg) || exp_cylinder_check(d, msg, sizeof msg))) {
        // Messages start with the field: "depth = ...", "granule_contact.mu_s = ...",
        // "gsd.geometric_sd = ..."; the YAML key is the last part.
        char field[EXP_FIELD_LEN];
        bad = exp_field_error(path, n_sets, sets, exp_message_field(msg, field), msg, err, len);
    }
    exp_yaml_free(&cylinder_schema, y);
    return bad;
}
