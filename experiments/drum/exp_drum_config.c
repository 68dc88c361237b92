// SPDX-License-Identifier: MIT
// Drum experiment config: libcyaml schema, overrides, validation.
#include "exp_drum_config.h"
#include "exp_yaml.h"

#include <cyaml/cyaml.h>

#include "exp_common.h"
#include "exp_contact_rules.h"
#include "exp_gsd_table.h"
#include <errno.h>
#include <libgen.h>
#include <stdarg.h>
#include <stdio.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const cyaml_schema_field_t material_fields[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_POINTER, exp_material_yaml, name, 1, 31),
    CYAML_FIELD_FLOAT("mu_s", CYAML_FLAG_DEFAULT, exp_material_yaml, mu_s),
    CYAML_FIELD_FLOAT("mu_r", CYAML_FLAG_DEFAULT, exp_material_yaml, mu_r), CYAML_FIELD_END};
static const cyaml_schema_value_t material_entry = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, exp_material_yaml, material_fields)};

#define REQ_FLOAT(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_DEFAULT, exp_drum_yaml, member)
#define OPT_FLOAT(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_OPTIONAL, exp_drum_yaml, member)
static const cyaml_schema_field_t drum_fields[] = {
    CYAML_FIELD_STRING_PTR("experiment", CYAML_FLAG_POINTER, exp_drum_yaml, experiment, 1, 16),
    REQ_FLOAT("diameter", diameter), REQ_FLOAT("depth", depth), REQ_FLOAT("fill", fill),
    CYAML_FIELD_BOOL("periodic", CYAML_FLAG_DEFAULT, exp_drum_yaml, periodic), OPT_FLOAT("slice_depth", slice_depth),
    REQ_FLOAT("density", density), OPT_FLOAT("median_diameter", median_diameter),
    OPT_FLOAT("geometric_sd", geometric_sd), OPT_FLOAT("truncation_sigmas", truncation_sigmas),
    CYAML_FIELD_STRING_PTR("gsd_table", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_drum_yaml, gsd_table, 1, 1000),
    CYAML_FIELD_STRING_PTR("gsd_basis", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_drum_yaml, gsd_basis, 1, 16),
    REQ_FLOAT("lambda", lambda), REQ_FLOAT("k_n", k_n), REQ_FLOAT("xi", xi), REQ_FLOAT("mu_s", mu_s),
    REQ_FLOAT("mu_r", mu_r),
    CYAML_FIELD_STRING_PTR("damping", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_drum_yaml, damping, 1, 32),
    CYAML_FIELD_STRING_PTR("fill_method", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_drum_yaml, fill_method, 1, 16),
    CYAML_FIELD_STRING_PTR("wall", CYAML_FLAG_POINTER, exp_drum_yaml, wall, 1, 31),
    CYAML_FIELD_SEQUENCE("materials", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_drum_yaml, materials,
                         &material_entry, 0, 16),
    REQ_FLOAT("rpm", rpm), REQ_FLOAT("max_time", max_time), OPT_FLOAT("window", window),
    OPT_FLOAT("sample_interval", sample_interval), OPT_FLOAT("pixel", pixel),
    CYAML_FIELD_FLOAT_PTR("start_tilt_deg", CYAML_FLAG_OPTIONAL, exp_drum_yaml, start_tilt_deg),
    CYAML_FIELD_INT("closing_px", CYAML_FLAG_OPTIONAL, exp_drum_yaml, closing_px),
    CYAML_FIELD_INT("seed", CYAML_FLAG_OPTIONAL, exp_drum_yaml, seed), CYAML_FIELD_END};
static const cyaml_schema_value_t drum_schema = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, exp_drum_yaml, drum_fields)};


int exp_is_drum_config(const char *path) { return exp_yaml_starts_with(path, "experiment: drum"); }

static char *dup_string(const char *s)
{
    char *d = malloc(strlen(s) + 1);
    if (d) strcpy(d, s);
    return d;
}

// One "key=value" override; strings are owned by libcyaml's allocator
// (plain malloc/free via cyaml_mem), so a replaced string is freed with free.
static int apply_set(exp_drum_yaml *y, const char *set, char *err, size_t len)
{
    char key[32];
    const char *value = NULL;
    if (exp_split_set(set, key, &value, err, len)) return 1;
    char **text = strcmp(key, "wall") == 0 ? &y->wall : strcmp(key, "fill_method") == 0 ? &y->fill_method : NULL;
    if (text) {
        char *copy = dup_string(value);
        if (!copy) return exp_fail(err, len, "out of memory");
        free(*text);
        *text = copy;
        return 0;
    }
    double tilt = NAN; // optional in the file: allocated only when given
    const exp_set_key keys[] = {
        EXP_SET_NUMBER("rpm", &y->rpm), EXP_SET_NUMBER("mu_s", &y->mu_s), EXP_SET_NUMBER("mu_r", &y->mu_r),
        EXP_SET_NUMBER("k_n", &y->k_n), EXP_SET_NUMBER("xi", &y->xi), EXP_SET_NUMBER("lambda", &y->lambda),
        EXP_SET_INTEGER("seed", &y->seed), EXP_SET_NUMBER("fill", &y->fill),
        EXP_SET_NUMBER("slice_depth", &y->slice_depth), EXP_SET_NUMBER("max_time", &y->max_time),
        EXP_SET_NUMBER("start_tilt_deg", &tilt)};
    const size_t n = sizeof keys / sizeof *keys;
    int found = exp_set_key_value(keys, n, key, value, err, len);
    if (found < 0) return exp_set_unknown(keys, n, "wall, fill_method", key, err, len);
    if (found == 0 && !isnan(tilt)) {
        if (!y->start_tilt_deg && !(y->start_tilt_deg = malloc(sizeof *y->start_tilt_deg)))
            return exp_fail(err, len, "out of memory");
        *y->start_tilt_deg = tilt;
    }
    return found;
}

static const exp_material_yaml *find_material(const exp_drum_yaml *y, const char *name)
{
    for (unsigned k = 0; k < y->materials_count; ++k)
        if (strcmp(y->materials[k].name, name) == 0) return &y->materials[k];
    return NULL;
}

/// Where a config's values came from: the file, then its --set overrides.
typedef struct source {
    const char *path;
    int n_sets;
    char **sets;
} source;

static int located(const source *from, const char *field, char *err, size_t len, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return exp_field_error(from->path, from->n_sets, from->sets, field, msg, err, len);
}

int exp_drum_config_defs(const exp_drum_yaml *y, exp_drum_def *def, exp_drum_run_opts *run, char *err, size_t len)
{
    *run = exp_default_drum_run_opts();
    exp_drum_physics p = {.diameter = y->diameter, .periodic = y->periodic, .depth = y->depth,
                          .slice_depth = y->slice_depth, .fill = y->fill, .lambda = y->lambda,
                          .gsd = y->gsd,
                          .density = y->density, .k_n = y->k_n, .xi = y->xi, .mu_s = y->mu_s, .mu_r = y->mu_r,
                          .fill_method = exp_default_drum_def().fill_method, .seed = (uint64_t)y->seed};
    if (exp_damping_from_name(y->damping, "damping", &p.damping, err, len)) return 1;
    // "granules": a lining of granules is a granular surface (assumption iii)
    p.wall_mu_s = y->mu_s, p.wall_mu_r = y->mu_r;
    if (strcmp(y->wall, "granules") != 0) {
        const exp_material_yaml *m = find_material(y, y->wall);
        if (!m) { // the linings this file defines, so the user can pick one
            char names[512] = "granules";
            for (unsigned k = 0; k < y->materials_count; ++k)
                snprintf(names + strlen(names), sizeof names - strlen(names), ", %s", y->materials[k].name);
            return exp_fail(err, len, "wall = '%s': not 'granules' nor a name under materials; the walls are: %s", y->wall,
                            names);
        }
        p.wall_mu_s = m->mu_s, p.wall_mu_r = m->mu_r;
    }
    if (y->fill_method && exp_drum_fill_method_from_name(y->fill_method, &p.fill_method))
        return exp_fail(err, len, "fill_method = '%s': use pour or pack", y->fill_method);
    *def = exp_drum_def_from_physics(&p);
    if (y->pixel > 0) def->pixel = y->pixel;
    if (y->closing_px > 0) def->closing_px = y->closing_px;
    run->rpm = y->rpm, run->max_time = y->max_time;
    if (y->window > 0) run->window = y->window;
    if (y->sample_interval > 0) run->sample_interval = y->sample_interval;
    if (y->start_tilt_deg) run->start_tilt_deg = *y->start_tilt_deg;
    return 0;
}

// The size distribution into y->gsd: the log-normal's three keys, or a
// measured table (gsd_table, relative to the config file, on gsd_basis), not both.
static int load_gsd(const source *from, exp_drum_yaml *y, char *err, size_t len)
{
    if (!y->gsd_table) {
        if (y->gsd_basis) return located(from, "gsd_basis", err, len, "given without gsd_table");
        y->gsd = dem_gsd_lognormal(y->median_diameter, y->geometric_sd, y->truncation_sigmas);
        return 0; // its values are checked with the drum (exp_drum_check)
    }
    const struct { const char *key; double v; } lognormal[] = {
        {"median_diameter", y->median_diameter}, {"geometric_sd", y->geometric_sd},
        {"truncation_sigmas", y->truncation_sigmas}};
    for (size_t k = 0; k < sizeof lognormal / sizeof *lognormal; ++k)
        if (lognormal[k].v != 0)
            return located(from, lognormal[k].key, err, len,
                           "gsd_table gives the size distribution: remove the log-normal's keys (give one or the other)");
    dem_gsd_basis basis;
    if (exp_gsd_basis_from_name(y->gsd_basis, &basis))
        return located(from, "gsd_basis", err, len, "'%s': say what the table's percentages count: volume (laser "
                       "diffraction, sieving) or number", y->gsd_basis ? y->gsd_basis : "absent");
    char dir[1024], path[2048];
    snprintf(dir, sizeof dir, "%s", from->path);
    if (y->gsd_table[0] == '/') snprintf(path, sizeof path, "%s", y->gsd_table);
    else snprintf(path, sizeof path, "%s/%s", dirname(dir), y->gsd_table);
    return exp_gsd_table_load(path, y->gsd_basis, &y->gsd, err, len);
}

static int validate(const source *from, exp_drum_yaml *y, char *err, size_t len)
{
    if (strcmp(y->experiment, "drum") != 0) return located(from, "experiment", err, len, "must be drum");
    // libcyaml reads inf and nan as numbers; the range checks below let inf through.
    const struct { const char *key; double v; } numbers[] = {
        {"diameter", y->diameter}, {"depth", y->depth}, {"fill", y->fill}, {"slice_depth", y->slice_depth},
        {"density", y->density}, {"median_diameter", y->median_diameter}, {"geometric_sd", y->geometric_sd},
        {"truncation_sigmas", y->truncation_sigmas}, {"lambda", y->lambda}, {"k_n", y->k_n}, {"xi", y->xi},
        {"mu_s", y->mu_s}, {"mu_r", y->mu_r}, {"rpm", y->rpm}, {"max_time", y->max_time}, {"window", y->window},
        {"sample_interval", y->sample_interval}, {"pixel", y->pixel}};
    for (size_t k = 0; k < sizeof numbers / sizeof *numbers; ++k)
        if (!isfinite(numbers[k].v))
            return located(from, numbers[k].key, err, len, "%g must be a finite number", numbers[k].v);
    if (load_gsd(from, y, err, len)) return 1;
    if (y->start_tilt_deg && !(*y->start_tilt_deg >= 0 && *y->start_tilt_deg <= 90))
        return located(from, "start_tilt_deg", err, len, "%g must be in [0, 90] degrees", *y->start_tilt_deg);
    if (y->window < 0) return located(from, "window", err, len, "%g must be >= 0 (0 or absent: 1 s)", y->window);
    if (y->sample_interval < 0)
        return located(from, "sample_interval", err, len, "%g must be >= 0 (0 or absent: 0.05 s)", y->sample_interval);
    if (!(y->rpm >= 0 && y->rpm <= 1000)) return located(from, "rpm", err, len, "%g must be in [0, 1000]", y->rpm);
    if (!(y->max_time > 0)) return located(from, "max_time", err, len, "%g must be > 0", y->max_time);
    if (y->periodic && !(y->slice_depth > 0))
        return located(from, "slice_depth", err, len, "%g must be > 0 for a periodic slice", y->slice_depth);
    if (!(y->k_n > 0)) return located(from, "k_n", err, len, "%g must be > 0", y->k_n);
    for (unsigned k = 0; k < y->materials_count; ++k)
        if (!(isfinite(y->materials[k].mu_s) && y->materials[k].mu_s >= 0) ||
            !(isfinite(y->materials[k].mu_r) && y->materials[k].mu_r >= 0))
            return located(from, "materials", err, len, "'%s': friction must be finite and >= 0", y->materials[k].name);
    exp_drum_def def;
    exp_drum_run_opts run;
    char msg[300];
    if (exp_drum_config_defs(y, &def, &run, msg, sizeof msg) || exp_drum_check(&def, msg, sizeof msg)) {
        char field[EXP_FIELD_LEN];
        return located(from, exp_message_field(msg, field), err, len, "%s", msg);
    }
    return 0;
}

exp_drum_yaml *exp_drum_config_load(const char *path, int n_sets, char **sets, char *err, size_t len)
{
    exp_drum_yaml *y = NULL;
    if (exp_yaml_load(path, &drum_schema, (void **)&y, "check the keys and value types against configs/drum.yaml", err,
                      len))
        return NULL;
    for (int k = 0; k < n_sets; ++k)
        if (apply_set(y, sets[k], err, len)) {
            exp_drum_config_free(y);
            return NULL;
        }
    if (validate(&(source){path, n_sets, sets}, y, err, len)) {
        exp_drum_config_free(y);
        return NULL;
    }
    return y;
}

void exp_drum_config_free(exp_drum_yaml *y)
{
    exp_yaml_free(&drum_schema, y);
}
