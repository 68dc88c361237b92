// SPDX-License-Identifier: MIT
// The sphere on an inclined plane as a YAML file: load, --set, validate. See
// exp_incline_config.h; its runner is exp_incline_runner.c.
#include "exp_incline_config.h"

#include <cyaml/cyaml.h>
#include <stdio.h>
#include <string.h>

#include "exp_common.h"
#include "exp_contact_rules.h"
#include "exp_yaml.h"

typedef struct incline_yaml {
    char *experiment;
    double angle_deg, diameter, density, gravity;
    double k_n, xi, mu_s, mu_r;
    char *damping;
    double duration, sample_interval, skip_fraction;
} incline_yaml;

#define F(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_DEFAULT, incline_yaml, member)
static const cyaml_schema_field_t incline_fields[] = {
    CYAML_FIELD_STRING_PTR("experiment", CYAML_FLAG_POINTER, incline_yaml, experiment, 1, 16),
    F("angle_deg", angle_deg), F("diameter", diameter), F("density", density), F("gravity", gravity),
    F("k_n", k_n), F("xi", xi), F("mu_s", mu_s), F("mu_r", mu_r),
    CYAML_FIELD_STRING_PTR("damping", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, incline_yaml, damping, 1, 32),
    F("duration", duration), F("sample_interval", sample_interval), F("skip_fraction", skip_fraction),
    CYAML_FIELD_END};
#undef F
static const cyaml_schema_value_t incline_schema = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, incline_yaml, incline_fields)};

int exp_is_incline_config(const char *path) { return exp_yaml_starts_with(path, "experiment: incline"); }

static int to_def(const incline_yaml *y, exp_incline_def *d, char *err, size_t len)
{
    *d = exp_default_incline_def();
    d->angle_deg = y->angle_deg, d->diameter = y->diameter, d->density = y->density, d->gravity = y->gravity;
    dem_damping_mode mode;
    if (exp_damping_from_name(y->damping, "damping", &mode, err, len)) return 1;
    d->contact = exp_granule_pair(y->k_n, y->xi, y->mu_s, y->mu_r, mode); // k_n = k_s = k_r, as Table 3
    d->duration = y->duration, d->sample_interval = y->sample_interval, d->skip_fraction = y->skip_fraction;
    return 0;
}

static int apply_set(incline_yaml *y, const char *set, char *err, size_t len)
{
    const exp_set_key keys[] = {
        EXP_SET_NUMBER("angle_deg", &y->angle_deg), EXP_SET_NUMBER("mu_s", &y->mu_s),
        EXP_SET_NUMBER("mu_r", &y->mu_r), EXP_SET_NUMBER("k_n", &y->k_n), EXP_SET_NUMBER("xi", &y->xi),
        EXP_SET_NUMBER("diameter", &y->diameter), EXP_SET_NUMBER("density", &y->density),
        EXP_SET_NUMBER("duration", &y->duration)};
    return exp_apply_set(set, keys, sizeof keys / sizeof *keys, err, len);
}

int exp_incline_load(const char *path, int n_sets, char **sets, exp_incline_def *d, char *err, size_t len)
{
    incline_yaml *y = NULL;
    if (exp_yaml_load(path, &incline_schema, (void **)&y, "check the keys and value types against configs/incline.yaml",
                      err, len))
        return 1;
    char msg[300];
    int bad = 0;
    for (int k = 0; k < n_sets && !bad; ++k) bad = apply_set(y, sets[k], err, len);
    if (!bad && strcmp(y->experiment, "incline") != 0)
        bad = exp_field_error(path, 0, NULL, "experiment", "must be incline", err, len);
    if (!bad && (to_def(y, d, msg, sizeof msg) || exp_incline_check(d, msg, sizeof msg))) {
        // Messages start with the field: "angle_deg = ...", "contact.mu_s = ...";
        // the YAML key is the last part.
        char field[EXP_FIELD_LEN];
        bad = exp_field_error(path, n_sets, sets, exp_message_field(msg, field), msg, err, len);
    }
    exp_yaml_free(&incline_schema, y);
    return bad;
}
