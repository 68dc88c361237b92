// SPDX-License-Identifier: MIT
// The confined compression test as a YAML file: load, --set, validate. See
// exp_compress_config.h; its runner is exp_compress_runner.c.
#include "exp_compress_config.h"

#include <cyaml/cyaml.h>
#include <stdio.h>
#include <string.h>

#include "exp_contact_rules.h"
#include "exp_yaml.h"

typedef struct compress_yaml {
    char *experiment;
    double diameter, depth, density, median_diameter, geometric_sd, truncation_sigmas, lambda;
    double k_n, xi, mu_s, wall_mu_s;
    char *damping;
    double sigma_min, sigma_max, piston_speed, max_time;
    int cycles, seed;
} compress_yaml;

#define F(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_DEFAULT, compress_yaml, member)
static const cyaml_schema_field_t compress_fields[] = {
    CYAML_FIELD_STRING_PTR("experiment", CYAML_FLAG_POINTER, compress_yaml, experiment, 1, 16),
    F("diameter", diameter), F("depth", depth), F("density", density), F("median_diameter", median_diameter),
    F("geometric_sd", geometric_sd), F("truncation_sigmas", truncation_sigmas), F("lambda", lambda), F("k_n", k_n),
    F("xi", xi), F("mu_s", mu_s), F("wall_mu_s", wall_mu_s),
    CYAML_FIELD_STRING_PTR("damping", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, compress_yaml, damping, 1, 32),
    F("sigma_min", sigma_min), F("sigma_max", sigma_max), F("piston_speed", piston_speed), F("max_time", max_time),
    CYAML_FIELD_INT("cycles", CYAML_FLAG_DEFAULT, compress_yaml, cycles),
    CYAML_FIELD_INT("seed", CYAML_FLAG_DEFAULT, compress_yaml, seed), CYAML_FIELD_END};
#undef F
static const cyaml_schema_value_t compress_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, compress_yaml, compress_fields)};

int exp_is_compress_config(const char *path) { return exp_yaml_starts_with(path, "experiment: compression"); }

static int to_def(const compress_yaml *y, exp_compress_def *d, char *err, size_t len)
{
    *d = exp_default_compress_def();
    d->diameter = y->diameter, d->depth = y->depth, d->density = y->density, d->lambda = y->lambda;
    d->gsd = dem_gsd_lognormal(y->median_diameter, y->geometric_sd, y->truncation_sigmas);
    dem_damping_mode mode;
    if (exp_damping_from_name(y->damping, "damping", &mode, err, len)) return 1;
    d->granule = exp_granule_pair(y->k_n, y->xi, y->mu_s, 0, mode); // no rolling here (μ_r = 0 switches it off)
    d->wall = d->granule;
    d->wall.mu_s = y->wall_mu_s;
    d->sigma_min = y->sigma_min, d->sigma_max = y->sigma_max, d->piston_speed = y->piston_speed;
    d->max_time = y->max_time, d->cycles = y->cycles, d->seed = (uint64_t)y->seed;
    return 0;
}

static int apply_set(compress_yaml *y, const char *set, char *err, size_t len)
{
    const exp_set_key keys[] = {
        EXP_SET_NUMBER("k_n", &y->k_n), EXP_SET_NUMBER("mu_s", &y->mu_s), EXP_SET_NUMBER("wall_mu_s", &y->wall_mu_s),
        EXP_SET_NUMBER("xi", &y->xi), EXP_SET_NUMBER("lambda", &y->lambda), EXP_SET_INTEGER("seed", &y->seed),
        EXP_SET_NUMBER("sigma_min", &y->sigma_min), EXP_SET_NUMBER("sigma_max", &y->sigma_max),
        EXP_SET_NUMBER("piston_speed", &y->piston_speed), EXP_SET_INTEGER("cycles", &y->cycles),
        EXP_SET_NUMBER("max_time", &y->max_time),
        EXP_SET_REFUSED("mu_r", "the compression test has no rolling resistance")};
    return exp_apply_set(set, keys, sizeof keys / sizeof *keys, err, len);
}

int exp_compress_load(const char *path, int n_sets, char **sets, exp_compress_def *d, char *err, size_t len)
{
    compress_yaml *y = NULL;
    if (exp_yaml_load(path, &compress_schema, (void **)&y,
                      "check the keys and value types against configs/compression.yaml", err, len))
        return 1;
    char msg[300];
    int bad = 0;
    for (int k = 0; k < n_sets && !bad; ++k) bad = apply_set(y, sets[k], err, len);
    if (!bad && strcmp(y->experiment, "compression") != 0)
        bad = exp_field_error(path, 0, NULL, "experiment", "must be compression", err, len);
    if (!bad) bad = exp_seed_check(path, y->seed, err, len);
    if (!bad && (to_def(y, d, msg, sizeof msg) || exp_compress_check(d, msg, sizeof msg))) {
        // Messages start with the field ("sigma_max = ...", "granule_contact.mu_s = ...").
        char field[EXP_FIELD_LEN];
        bad = exp_field_error(path, n_sets, sets, exp_message_field(msg, field), msg, err, len);
    }
    exp_yaml_free(&compress_schema, y);
    return bad;
}
