// SPDX-License-Identifier: MIT
// The silo discharge benchmark as a YAML file: load, --set, validate. See
// exp_silo_config.h; its runner is exp_silo_runner.c.
#include "exp_silo_config.h"

#include <cyaml/cyaml.h>
#include <stdio.h>
#include <string.h>

#include "exp_contact_rules.h"
#include "exp_yaml.h"

typedef struct silo_yaml {
    char *experiment;
    double median_diameter, geometric_sd, truncation_sigmas, density;
    double k_n, k_s, wall_k_n, wall_k_s, xi, mu_s;
    int n_granules;
    double silo_radius, orifice_radius, plate_z, plate_sphere_radius;
    double dt, duration, sample_interval, fill_xi, fill_max_time;
    int seed;
} silo_yaml;

#define F(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_DEFAULT, silo_yaml, member)
static const cyaml_schema_field_t silo_fields[] = {
    CYAML_FIELD_STRING_PTR("experiment", CYAML_FLAG_POINTER, silo_yaml, experiment, 1, 16),
    F("median_diameter", median_diameter), F("geometric_sd", geometric_sd), F("truncation_sigmas", truncation_sigmas),
    F("density", density), F("k_n", k_n), F("k_s", k_s), F("wall_k_n", wall_k_n), F("wall_k_s", wall_k_s), F("xi", xi),
    F("mu_s", mu_s), CYAML_FIELD_INT("n_granules", CYAML_FLAG_DEFAULT, silo_yaml, n_granules),
    F("silo_radius", silo_radius), F("orifice_radius", orifice_radius), F("plate_z", plate_z),
    F("plate_sphere_radius", plate_sphere_radius), F("dt", dt), F("duration", duration),
    F("sample_interval", sample_interval), F("fill_xi", fill_xi), F("fill_max_time", fill_max_time),
    CYAML_FIELD_INT("seed", CYAML_FLAG_DEFAULT, silo_yaml, seed), CYAML_FIELD_END};
#undef F
static const cyaml_schema_value_t silo_schema = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, silo_yaml, silo_fields)};

int exp_is_silo_config(const char *path) { return exp_yaml_starts_with(path, "experiment: silo"); }

static void to_def(const silo_yaml *y, exp_silo_def *d)
{
    *d = exp_default_silo_def();
    d->gsd = dem_gsd_lognormal(y->median_diameter, y->geometric_sd, y->truncation_sigmas);
    d->density = y->density;
    // Table A.2: no rolling (k_r = μ_r = 0), one damping ratio for all contacts.
    d->granule = (dem_contact_params){.k_n = y->k_n, .k_s = y->k_s, .xi = y->xi, .mu_s = y->mu_s, .damping = EXP_DAMPING_DEFAULT};
    d->wall = (dem_contact_params){
        .k_n = y->wall_k_n, .k_s = y->wall_k_s, .xi = y->xi, .mu_s = y->mu_s, .damping = EXP_DAMPING_DEFAULT};
    d->n_granules = y->n_granules > 0 ? (size_t)y->n_granules : 0;
    d->silo_radius = y->silo_radius, d->orifice_radius = y->orifice_radius, d->plate_z = y->plate_z;
    d->plate_sphere_radius = y->plate_sphere_radius;
    d->dt = y->dt, d->duration = y->duration, d->sample_interval = y->sample_interval;
    d->fill_xi = y->fill_xi, d->fill_max_time = y->fill_max_time, d->seed = (uint64_t)y->seed;
}

static int apply_set(silo_yaml *y, const char *set, char *err, size_t len)
{
    const exp_set_key keys[] = {
        EXP_SET_NUMBER("k_n", &y->k_n), EXP_SET_NUMBER("mu_s", &y->mu_s), EXP_SET_NUMBER("xi", &y->xi),
        EXP_SET_NUMBER("dt", &y->dt), EXP_SET_NUMBER("duration", &y->duration),
        EXP_SET_NUMBER("orifice_radius", &y->orifice_radius), EXP_SET_NUMBER("silo_radius", &y->silo_radius),
        EXP_SET_NUMBER("plate_z", &y->plate_z), EXP_SET_INTEGER("n_granules", &y->n_granules),
        EXP_SET_INTEGER("seed", &y->seed), EXP_SET_REFUSED("mu_r", "the silo benchmark has no rolling resistance")};
    return exp_apply_set(set, keys, sizeof keys / sizeof *keys, err, len);
}

// The YAML key of a check's field: granule_contact.k_n is k_n,
// wall_contact.k_n is wall_k_n (the file keeps the two pairs flat).
static const char *yaml_key(const char *msg, char key[EXP_FIELD_LEN])
{
    char field[EXP_FIELD_LEN];
    const char *leaf = exp_message_field(msg, field);
    snprintf(key, EXP_FIELD_LEN, "%s%s", strncmp(field, "wall_contact", 12) == 0 ? "wall_" : "", leaf);
    return key;
}

int exp_silo_load(const char *path, int n_sets, char **sets, exp_silo_def *d, char *err, size_t len)
{
    silo_yaml *y = NULL;
    if (exp_yaml_load(path, &silo_schema, (void **)&y, "check the keys and value types against configs/silo.yaml", err,
                      len))
        return 1;
    int bad = 0;
    char msg[300], key[EXP_FIELD_LEN];
    for (int k = 0; k < n_sets && !bad; ++k) bad = apply_set(y, sets[k], err, len);
    if (!bad && strcmp(y->experiment, "silo") != 0)
        bad = exp_field_error(path, 0, NULL, "experiment", "must be silo", err, len);
    if (!bad && y->n_granules < 1) {
        snprintf(msg, sizeof msg, "n_granules = %d: must be >= 1", y->n_granules);
        bad = exp_field_error(path, n_sets, sets, "n_granules", msg, err, len);
    }
    if (!bad) bad = exp_seed_check(path, y->seed, err, len);
    if (!bad) {
        to_def(y, d);
        if (exp_silo_check(d, msg, sizeof msg))
            bad = exp_field_error(path, n_sets, sets, yaml_key(msg, key), msg, err, len);
    }
    exp_yaml_free(&silo_schema, y);
    return bad;
}
