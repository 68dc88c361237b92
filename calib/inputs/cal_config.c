// SPDX-License-Identifier: MIT
// Calibration config: libcyaml schema and field-by-field validation.
#include "cal_config.h"
#include "exp_drum.h"

#include <cyaml/cyaml.h>
#include <libgen.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_contact.h"
#include "exp_common.h"
#include "exp_gsd_table.h"
#include "exp_yaml.h"

static const cyaml_schema_value_t float_entry = {CYAML_VALUE_FLOAT(CYAML_FLAG_DEFAULT, double)};

static const cyaml_schema_field_t material_fields[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_POINTER, cal_material, name, 1, 31),
    CYAML_FIELD_STRING_PTR("surface", CYAML_FLAG_POINTER, cal_material, surface, 1, 47), CYAML_FIELD_END};
static const cyaml_schema_value_t material_entry = {CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cal_material, material_fields)};

// A strict yes/no: libcyaml's bool reads any word but a few as true.
static const cyaml_strval_t yes_no[] = {{"false", 0}, {"true", 1}, {"no", 0}, {"yes", 1}};
static const cyaml_strval_t corrections[] = {{"kriging", CAL_MF_KRIGING}, {"affine", CAL_MF_AFFINE}};
static const cyaml_strval_t purposes[] = {{"calibration", 0}, {"demonstration", 1}};
static const cyaml_strval_t stiffness_scenes[] = {{"cylinder", 0}, {"drum", 1}};

// A calibration tier and a fidelity rung: one schema. The drum's knobs come
// first; a tier's own keys are optional here, so that a rung reads without
// them, and are required or refused by check_tier and check_fidelity.
#define TIER_FLOAT(key, member, flag) CYAML_FIELD_FLOAT(key, flag, cal_tier, member)
static const cyaml_schema_field_t tier_fields[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_POINTER, cal_tier, name, 1, 31),
    TIER_FLOAT("lambda", lambda, CYAML_FLAG_DEFAULT),
    TIER_FLOAT("slice_depth", slice_depth, CYAML_FLAG_DEFAULT),
    TIER_FLOAT("max_time", max_time, CYAML_FLAG_DEFAULT),
    TIER_FLOAT("window", window, CYAML_FLAG_DEFAULT),
    TIER_FLOAT("sample_interval", sample_interval, CYAML_FLAG_OPTIONAL),
    TIER_FLOAT("steady_angle_tol_deg", steady_angle_tol_deg, CYAML_FLAG_OPTIONAL),
    TIER_FLOAT("steady_csa_tol_percent", steady_csa_tol_percent, CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_STRING_PTR("fill_method", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, fill_method, 1, 16),
    TIER_FLOAT("average_time", average_time, CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_STRING_PTR("steady_rule", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, steady_rule, 1, 16),
    TIER_FLOAT("steady_se_angle_deg", steady_se_angle_deg, CYAML_FLAG_OPTIONAL),
    TIER_FLOAT("steady_se_csa_percent", steady_se_csa_percent, CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_SEQUENCE("average_time_per_rpm", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, average_time_per_rpm,
                         &float_entry, 1, 32),
    CYAML_FIELD_SEQUENCE("rpm", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, rpm, &float_entry, 0, 32),
    CYAML_FIELD_SEQUENCE("turned_start_rpm", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, turned_start_rpm,
                         &float_entry, 1, 32),
    TIER_FLOAT("turned_start_time", turned_start_time, CYAML_FLAG_OPTIONAL),
    TIER_FLOAT("cylinder_lambda", cylinder_lambda, CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_SEQUENCE("stiffness", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, stiffness, &float_entry, 2, 64),
    CYAML_FIELD_ENUM_PTR("stiffness_scene", CYAML_FLAG_OPTIONAL | CYAML_FLAG_STRICT, cal_tier, stiffness_scene,
                         stiffness_scenes, CYAML_ARRAY_LEN(stiffness_scenes)),
    CYAML_FIELD_INT("seeds", CYAML_FLAG_OPTIONAL, cal_tier, seeds),
    CYAML_FIELD_INT("grid", CYAML_FLAG_OPTIONAL, cal_tier, grid),
    CYAML_FIELD_INT("max_evaluations", CYAML_FLAG_OPTIONAL, cal_tier, max_evaluations),
    TIER_FLOAT("angle_sd_deg", angle_sd_deg, CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_STRING_PTR("angle_rule", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, angle_rule, 1, 16),
    CYAML_FIELD_SEQUENCE("csa_sd_percent", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, csa_sd_percent,
                         &float_entry, 1, 32),
    // _PTR: the plain ENUM macro drops CYAML_FLAG_POINTER and would write the value into the pointer itself.
    CYAML_FIELD_ENUM_PTR("bound_probes", CYAML_FLAG_OPTIONAL | CYAML_FLAG_STRICT, cal_tier, bound_probes, yes_no,
                         CYAML_ARRAY_LEN(yes_no)),
    CYAML_FIELD_ENUM_PTR("design_corners", CYAML_FLAG_OPTIONAL | CYAML_FLAG_STRICT, cal_tier, design_corners, yes_no,
                         CYAML_ARRAY_LEN(yes_no)),
    CYAML_FIELD_STRING_PTR("map_tier", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, cal_tier, map_tier, 1, 31),
    CYAML_FIELD_ENUM_PTR("map_correction", CYAML_FLAG_OPTIONAL | CYAML_FLAG_STRICT, cal_tier, map_correction, corrections,
                         CYAML_ARRAY_LEN(corrections)),
    CYAML_FIELD_INT("beds", CYAML_FLAG_OPTIONAL, cal_tier, beds),
    CYAML_FIELD_INT("posterior_runs", CYAML_FLAG_OPTIONAL, cal_tier, posterior_runs),
    CYAML_FIELD_INT("return_runs", CYAML_FLAG_OPTIONAL, cal_tier, return_runs),
    TIER_FLOAT("angle_aim_sd", angle_aim_sd, CYAML_FLAG_OPTIONAL),
    CYAML_FIELD_ENUM_PTR("purpose", CYAML_FLAG_OPTIONAL | CYAML_FLAG_STRICT, cal_tier, demonstration, purposes,
                         CYAML_ARRAY_LEN(purposes)),
    CYAML_FIELD_END};
static const cyaml_schema_value_t tier_entry = {CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, cal_tier, tier_fields)};

static const cyaml_schema_field_t fidelity_fields[] = {
    CYAML_FIELD_SEQUENCE("rpm", CYAML_FLAG_POINTER, cal_fidelity, rpm, &float_entry, 1, 16),
    CYAML_FIELD_INT("seeds", CYAML_FLAG_DEFAULT, cal_fidelity, seeds),
    CYAML_FIELD_FLOAT("budget_hours", CYAML_FLAG_DEFAULT, cal_fidelity, budget_hours),
    CYAML_FIELD_SEQUENCE("rungs", CYAML_FLAG_POINTER, cal_fidelity, rungs, &tier_entry, 1, 32), CYAML_FIELD_END};

static const cyaml_schema_field_t bounds_fields[] = {
    CYAML_FIELD_FLOAT("mu_s_min", CYAML_FLAG_DEFAULT, cal_bounds, mu_s_min),
    CYAML_FIELD_FLOAT("mu_s_max", CYAML_FLAG_DEFAULT, cal_bounds, mu_s_max),
    CYAML_FIELD_FLOAT("mu_r_min", CYAML_FLAG_DEFAULT, cal_bounds, mu_r_min),
    CYAML_FIELD_FLOAT("mu_r_max", CYAML_FLAG_DEFAULT, cal_bounds, mu_r_max), CYAML_FIELD_END};

#define CFG_FLOAT(key, member, flag) CYAML_FIELD_FLOAT(key, flag, cal_config, member)
#define CFG_STRING(key, member, flag, max) CYAML_FIELD_STRING_PTR(key, (flag) | CYAML_FLAG_POINTER, cal_config, member, 1, max)
static const cyaml_schema_field_t config_fields[] = {
    CFG_STRING("calibration", calibration, CYAML_FLAG_DEFAULT, 16),
    CFG_STRING("repose_angle", repose_angle, CYAML_FLAG_DEFAULT, 1000),
    CFG_STRING("occupied_area", occupied_area, CYAML_FLAG_DEFAULT, 1000),
    CFG_FLOAT("density", density, CYAML_FLAG_DEFAULT),
    // The size distribution: a log-normal (these three) or a measured table (check_gsd).
    CFG_FLOAT("median_diameter", median_diameter, CYAML_FLAG_OPTIONAL),
    CFG_FLOAT("geometric_sd", geometric_sd, CYAML_FLAG_OPTIONAL),
    CFG_FLOAT("truncation_sigmas", truncation_sigmas, CYAML_FLAG_OPTIONAL),
    CFG_STRING("gsd_table", gsd_table, CYAML_FLAG_OPTIONAL, 1000),
    CFG_STRING("gsd_basis", gsd_basis, CYAML_FLAG_OPTIONAL, 16),
    CFG_FLOAT("xi", xi, CYAML_FLAG_DEFAULT),
    CFG_STRING("damping", damping, CYAML_FLAG_OPTIONAL, 32),
    CFG_FLOAT("diameter", diameter, CYAML_FLAG_DEFAULT),
    CFG_FLOAT("depth", depth, CYAML_FLAG_DEFAULT),
    CFG_FLOAT("fill", fill, CYAML_FLAG_DEFAULT),
    CFG_STRING("granule_surface", granule_surface, CYAML_FLAG_DEFAULT, 47),
    CYAML_FIELD_SEQUENCE("materials", CYAML_FLAG_POINTER, cal_config, materials, &material_entry, 0, 16),
    CYAML_FIELD_SEQUENCE("stiffness", CYAML_FLAG_POINTER, cal_config, stiffness, &float_entry, 2, 64),
    CFG_FLOAT("stiffness_tolerance", stiffness_tolerance, CYAML_FLAG_OPTIONAL),
    CFG_FLOAT("k_n", k_n, CYAML_FLAG_DEFAULT),
    CFG_FLOAT("granule_mu_s", granule_mu_s, CYAML_FLAG_DEFAULT),
    CFG_FLOAT("granule_mu_r", granule_mu_r, CYAML_FLAG_DEFAULT),
    CFG_FLOAT("pour_mu_s", pour_mu_s, CYAML_FLAG_DEFAULT),
    CFG_FLOAT("pour_mu_r", pour_mu_r, CYAML_FLAG_DEFAULT),
    CYAML_FIELD_MAPPING("granule", CYAML_FLAG_DEFAULT, cal_config, granule, bounds_fields),
    CYAML_FIELD_MAPPING("wall", CYAML_FLAG_DEFAULT, cal_config, wall, bounds_fields),
    CFG_STRING("tier", tier, CYAML_FLAG_DEFAULT, 31),
    CYAML_FIELD_SEQUENCE("tiers", CYAML_FLAG_POINTER, cal_config, tiers, &tier_entry, 1, 16),
    CYAML_FIELD_INT("seed", CYAML_FLAG_DEFAULT, cal_config, seed),
    CYAML_FIELD_MAPPING_PTR("fidelity", CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL, cal_config, fidelity, fidelity_fields),
    CYAML_FIELD_END};
static const cyaml_schema_value_t config_schema = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, cal_config, config_fields)};

// "FILE:LINE: FIELD: message", the line found from `from_line` on.
static int located(const cal_config *c, int from_line, const char *field, char *err, size_t len, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
static int located(const cal_config *c, int from_line, const char *field, char *err, size_t len, const char *fmt, ...)
{
    char msg[300];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const char *leaf = strrchr(field, '.');
    int line = exp_yaml_line_of(c->path, leaf ? leaf + 1 : field, from_line);
    if (line > 0) return exp_fail(err, len, "%s:%d: %s: %s", c->path, line, field, msg);
    return exp_fail(err, len, "%s: %s: %s", c->path, field, msg);
}

static int bad_positive(double v) { return !(isfinite(v) && v > 0); }

static int check_bounds(const cal_config *c, const cal_bounds *b, const char *name, char *err, size_t len)
{
    int from = exp_yaml_line_of(c->path, name, 1);
    char field[64];
    snprintf(field, sizeof field, "%s.mu_s_min", name);
    if (!(b->mu_s_min >= 0 && b->mu_s_min < b->mu_s_max && b->mu_s_max <= 10))
        return located(c, from, field, err, len, "need 0 <= mu_s_min < mu_s_max <= 10 (got %g, %g)", b->mu_s_min,
                       b->mu_s_max);
    snprintf(field, sizeof field, "%s.mu_r_min", name);
    if (!(b->mu_r_min > 0 && b->mu_r_min < b->mu_r_max && b->mu_r_max <= 10))
        return located(c, from, field, err, len,
                       "need 0 < mu_r_min < mu_r_max <= 10 (got %g, %g): mu_r is searched on a log scale", b->mu_r_min,
                       b->mu_r_max);
    return 0;
}

// The line of the `name: NAME` entry, to locate a tier's or a rung's errors.
static int block_of(const cal_config *c, const char *name)
{
    for (int line = exp_yaml_line_of(c->path, "name", 1); line > 0; line = exp_yaml_line_of(c->path, "name", line + 1)) {
        FILE *f = fopen(c->path, "r");
        char text[512] = "";
        for (int k = 0; f && k < line && fgets(text, sizeof text, f); ++k) {}
        if (f) fclose(f);
        if (strstr(text, name)) return line;
    }
    return 1;
}

// The MSER rule stops a run itself: its two targets, and no averaging time.
static int check_steady_rule(const cal_config *c, int from, const cal_tier *t, char *err, size_t len)
{
    int rule = EXP_STEADY_WINDOWS;
    if (t->steady_rule && exp_drum_steady_rule_from_name(t->steady_rule, &rule))
        return located(c, from, "steady_rule", err, len, "'%s': use windows or mser", t->steady_rule);
    if (rule != EXP_STEADY_MSER) {
        if ((t->steady_se_angle_deg != 0 || t->steady_se_csa_percent != 0) && t->turned_start_rpm_count == 0)
            return located(c, from, "steady_se_angle_deg", err, len,
                           "the standard error targets need steady_rule: mser or turned_start_rpm");
        return 0;
    }
    if (bad_positive(t->steady_se_angle_deg) || bad_positive(t->steady_se_csa_percent))
        return located(c, from, "steady_se_angle_deg", err, len,
                       "steady_rule mser needs steady_se_angle_deg and steady_se_csa_percent > 0 (got %g, %g)",
                       t->steady_se_angle_deg, t->steady_se_csa_percent);
    if (t->average_time > 0 || t->average_time_per_rpm_count > 0)
        return located(c, from, "steady_rule", err, len, "mser stops each run itself: give no average_time");
    return 0;
}

// The drum's knobs, a tier's or a rung's; sample_interval and the steady
// test's tolerances are optional (0 or absent: the drum's default).
static int check_drum_knobs(const cal_config *c, int from, const cal_tier *t, char *err, size_t len)
{
    if (check_steady_rule(c, from, t, err, len)) return 1;
    if (!(isfinite(t->average_time) && t->average_time >= 0 && 2 * t->window + t->average_time <= t->max_time))
        return located(c, from, "average_time", err, len, "%g must be >= 0 and fit with two windows (%g s) in max_time (%g s)",
                       t->average_time, 2 * t->window, t->max_time);
    exp_drum_fill_method method;
    if (t->fill_method && exp_drum_fill_method_from_name(t->fill_method, &method))
        return located(c, from, "fill_method", err, len, "'%s': use pour or pack", t->fill_method);
    if (!(isfinite(t->lambda) && t->lambda >= 1)) return located(c, from, "lambda", err, len, "%g must be >= 1", t->lambda);
    if (bad_positive(t->max_time)) return located(c, from, "max_time", err, len, "%g must be > 0", t->max_time);
    if (bad_positive(t->window)) return located(c, from, "window", err, len, "%g must be > 0", t->window);
    if (!(isfinite(t->slice_depth) && t->slice_depth >= 0))
        return located(c, from, "slice_depth", err, len, "%g must be >= 0 and finite (0: full drum)", t->slice_depth);
    if (!(2 * t->window <= t->max_time))
        return located(c, from, "window", err, len, "two windows (%g s) must fit in max_time (%g s)", 2 * t->window,
                       t->max_time);
    const struct { const char *field; double v; } optional[] = {
        {"sample_interval", t->sample_interval}, {"steady_angle_tol_deg", t->steady_angle_tol_deg},
        {"steady_csa_tol_percent", t->steady_csa_tol_percent}};
    for (size_t k = 0; k < sizeof optional / sizeof *optional; ++k)
        if (!(isfinite(optional[k].v) && optional[k].v >= 0))
            return located(c, from, optional[k].field, err, len, "%g must be >= 0 and finite (0: the default)", optional[k].v);
    return 0;
}

// Where t's chain of map tiers ends, each tier once: 0; or the located
// error of a chain that comes back to a tier already in it (a -> b -> a, the
// whole chain named) or goes deeper than CAL_MAX_MAP_DEPTH. A map_tier that
// names no tier ends the chain here: that tier's own check says so.
static int check_map_chain(const cal_config *c, const cal_tier *t, int from, char *err, size_t len)
{
    const cal_tier *chain[CAL_MAX_MAP_DEPTH + 2] = {t};
    char path[(CAL_MAX_MAP_DEPTH + 2) * 36] = "";
    int n = 1;
    for (const cal_tier *m = t; m->map_tier; ++n) {
        m = cal_config_tier_named(c, m->map_tier);
        if (!m) return 0;
        snprintf(path + strlen(path), sizeof path - strlen(path), "%s -> ", chain[n - 1]->name);
        for (int k = 0; k < n; ++k)
            if (chain[k] == m)
                return located(c, from, "map_tier", err, len, "the map tiers make a cycle (%s%s): each must map with a "
                               "cheaper tier that ends in a one-tier search", path, m->name);
        if (n > CAL_MAX_MAP_DEPTH)
            return located(c, from, "map_tier", err, len, "more than %d levels of map tiers (%s%s): at most %d tiers may "
                           "map below one", CAL_MAX_MAP_DEPTH, path, m->name, CAL_MAX_MAP_DEPTH);
        chain[n] = m;
    }
    return 0;
}

// The map tier exists, is another tier, turns the same speeds (the
// correction is per measurement: one per speed), and its own chain of map
// tiers ends (check_map_chain): a map tier may itself map with another
// (levels, cal_stage_two_tier).
static int check_map_tier(const cal_config *c, const cal_tier *t, int from, char *err, size_t len)
{
    const cal_tier *m = cal_config_tier_named(c, t->map_tier);
    if (!m) return located(c, from, "map_tier", err, len, "'%s' is not one of the tiers", t->map_tier);
    if (m == t) return located(c, from, "map_tier", err, len, "'%s' is this tier itself", t->map_tier);
    int same = m->rpm_count == t->rpm_count;
    for (unsigned k = 0; same && k < t->rpm_count; ++k) same = m->rpm[k] == t->rpm[k];
    if (!same) return located(c, from, "map_tier", err, len, "'%s' must turn the same rpm list as this tier", t->map_tier);
    if (t->max_evaluations < 1)
        return located(c, from, "max_evaluations", err, len, "with a map_tier it bounds this tier's runs: give >= 1");
    return check_map_chain(c, t, from, err, len);
}

// One averaging time per speed, each fitting the run like average_time, and
// not both keys: which one would hold is not for the reader to guess.
static int check_average_per_rpm(const cal_config *c, const cal_tier *t, int from, char *err, size_t len)
{
    if (t->average_time_per_rpm_count == 0) return 0;
    if (t->average_time > 0)
        return located(c, from, "average_time_per_rpm", err, len, "give average_time or average_time_per_rpm, not both");
    if (t->average_time_per_rpm_count != t->rpm_count)
        return located(c, from, "average_time_per_rpm", err, len, "%u values for %u speeds: give one per entry of rpm",
                       t->average_time_per_rpm_count, t->rpm_count);
    for (unsigned k = 0; k < t->average_time_per_rpm_count; ++k) {
        double a = t->average_time_per_rpm[k];
        if (!(isfinite(a) && a >= 0 && 2 * t->window + a <= t->max_time))
            return located(c, from, "average_time_per_rpm", err, len,
                           "%g must be >= 0 and fit with two windows (%g s) in max_time (%g s)", a, 2 * t->window,
                           t->max_time);
    }
    return 0;
}

// Turned starts: speeds of the tier's own, a time to turn the bed first, and
// MSER's targets (it stops those runs: no averaging time at those speeds).
static int check_turned_start(const cal_config *c, const cal_tier *t, int from, char *err, size_t len)
{
    if (t->turned_start_rpm_count == 0) {
        if (t->turned_start_time != 0)
            return located(c, from, "turned_start_time", err, len, "give turned_start_rpm: the speeds it applies to");
        return 0;
    }
    if (!(isfinite(t->turned_start_time) && t->turned_start_time > 0 && t->turned_start_time <= 600))
        return located(c, from, "turned_start_time", err, len, "%g must be in (0, 600] s of turning",
                       t->turned_start_time);
    if (bad_positive(t->steady_se_angle_deg) || bad_positive(t->steady_se_csa_percent))
        return located(c, from, "turned_start_rpm", err, len,
                       "a turned start's runs stop by MSER: give steady_se_angle_deg and steady_se_csa_percent > 0");
    for (unsigned k = 0; k < t->turned_start_rpm_count; ++k) {
        double r = t->turned_start_rpm[k];
        int listed = 0;
        for (unsigned j = 0; j < t->rpm_count; ++j) listed |= t->rpm[j] == r;
        if (!listed) return located(c, from, "turned_start_rpm", err, len, "%g is not one of the tier's rpm", r);
        if (cal_tier_average_time(t, r) > 0)
            return located(c, from, "average_time_per_rpm", err, len,
                           "%g rpm starts turned and stops by MSER: give it an averaging time of 0", r);
    }
    return 0;
}

// Stage 1's candidates (the config's, or a tier's from its line on): each > 0, increasing.
static int check_stiffness(const cal_config *c, int from, const double *k, unsigned n, char *err, size_t len)
{
    for (unsigned i = 0; i < n; ++i) {
        if (bad_positive(k[i])) return located(c, from, "stiffness", err, len, "%g must be > 0", k[i]);
        if (i && !(k[i] > k[i - 1]))
            return located(c, from, "stiffness", err, len, "candidates must increase (%g after %g)", k[i], k[i - 1]);
    }
    return 0;
}

static int check_tier(const cal_config *c, const cal_tier *t, char *err, size_t len)
{
    int from = block_of(c, t->name); // the tier's own block starts at its `name:` line
    if (check_drum_knobs(c, from, t, err, len)) return 1;
    // Optional in the schema that a rung shares, required of a tier (absent reads as 0):
    static const char NEEDED[] = "a calibration tier needs it (the fidelity study's rungs do not)";
    if (t->cylinder_lambda == 0) return exp_fail(err, len, "%s:%d: cylinder_lambda: %s", c->path, from, NEEDED);
    if (t->seeds == 0) return exp_fail(err, len, "%s:%d: seeds: %s", c->path, from, NEEDED);
    if (!(isfinite(t->cylinder_lambda) && t->cylinder_lambda >= 1))
        return located(c, from, "cylinder_lambda", err, len, "%g must be >= 1", t->cylinder_lambda);
    if (check_stiffness(c, from, t->stiffness, t->stiffness_count, err, len)) return 1;
    if (t->seeds < 1 || t->seeds > 64) return located(c, from, "seeds", err, len, "%d must be in [1, 64]", t->seeds);
    if (t->grid < 0 || t->grid > 16) return located(c, from, "grid", err, len, "%d must be in [0, 16]", t->grid);
    if (t->beds < 0 || t->beds > 16) return located(c, from, "beds", err, len, "%d must be in [1, 16]", t->beds);
    if (t->max_evaluations < 0 || t->max_evaluations > 1000)
        return located(c, from, "max_evaluations", err, len, "%d must be in [0, 1000]", t->max_evaluations);
    if (t->grid < 2 && t->max_evaluations < 1)
        return located(c, from, "max_evaluations", err, len, "with grid < 2 the search needs evaluations");
    if (t->seeds < 2 && !(c->stiffness_tolerance > 0))
        return located(c, from, "seeds", err, len, "one seed gives no spread: use seeds >= 2 or set stiffness_tolerance");
    if (!(t->angle_sd_deg >= 0 && t->angle_sd_deg < 45))
        return located(c, from, "angle_sd_deg", err, len, "%g must be in [0, 45)", t->angle_sd_deg);
    for (unsigned k = 0; k < t->rpm_count; ++k)
        if (!(t->rpm[k] > 0 && t->rpm[k] <= 1000)) return located(c, from, "rpm", err, len, "%g must be in (0, 1000]", t->rpm[k]);
    if (t->angle_rule && strcmp(t->angle_rule, "constraint") != 0 && strcmp(t->angle_rule, "misfit") != 0)
        return located(c, from, "angle_rule", err, len, "'%s': use constraint (the paper's) or misfit", t->angle_rule);
    if (t->csa_sd_percent_count > 1 && t->csa_sd_percent_count != t->rpm_count)
        return located(c, from, "csa_sd_percent", err, len, "%u values for %u speeds: give one value, or one per rpm",
                       t->csa_sd_percent_count, t->rpm_count);
    for (unsigned k = 0; k < t->csa_sd_percent_count; ++k)
        if (!(t->csa_sd_percent[k] >= 0 && t->csa_sd_percent[k] < 50))
            return located(c, from, "csa_sd_percent", err, len, "%g must be in [0, 50) percentage points",
                           t->csa_sd_percent[k]);
    if (check_average_per_rpm(c, t, from, err, len)) return 1;
    if (check_turned_start(c, t, from, err, len)) return 1;
    if (t->map_correction && !t->map_tier)
        return located(c, from, "map_correction", err, len, "only a tier with a map_tier corrects a map");
    if (t->posterior_runs < 0 || t->posterior_runs > 16)
        return located(c, from, "posterior_runs", err, len, "%d must be in [0, 16]", t->posterior_runs);
    if (t->posterior_runs && !t->map_tier)
        return located(c, from, "posterior_runs", err, len, "only a tier with a map_tier has a corrected map to refine");
    if (t->return_runs < 0 || t->return_runs > 16)
        return located(c, from, "return_runs", err, len, "%d must be in [0, 16]", t->return_runs);
    if (t->return_runs && !t->posterior_runs)
        return located(c, from, "return_runs", err, len, "only a tier with posterior_runs has runs to return from");
    if (!(t->angle_aim_sd >= 0 && t->angle_aim_sd <= 3))
        return located(c, from, "angle_aim_sd", err, len, "%g must be in [0, 3] standard deviations", t->angle_aim_sd);
    if (t->angle_aim_sd > 0 && !t->map_tier)
        return located(c, from, "angle_aim_sd", err, len, "only a tier with a map_tier aims its runs on a corrected map");
    if (t->angle_aim_sd > 0 && cal_tier_angle_in_misfit(t))
        return located(c, from, "angle_aim_sd", err, len,
                       "angle_rule misfit weighs the angle in the misfit: there is no band to aim inside");
    return t->map_tier ? check_map_tier(c, t, from, err, len) : 0;
}

const char *cal_tier_calibration_key(const cal_tier *t)
{
    const struct { const char *key; int given; } keys[] = {
        {"average_time_per_rpm", t->average_time_per_rpm_count > 0}, {"rpm", t->rpm_count > 0},
        {"cylinder_lambda", t->cylinder_lambda != 0}, {"stiffness", t->stiffness_count > 0},
        {"stiffness_scene", t->stiffness_scene != NULL}, {"seeds", t->seeds != 0}, {"grid", t->grid != 0},
        {"max_evaluations", t->max_evaluations != 0}, {"angle_sd_deg", t->angle_sd_deg != 0},
        {"angle_rule", t->angle_rule != NULL}, {"csa_sd_percent", t->csa_sd_percent_count > 0},
        {"bound_probes", t->bound_probes != NULL}, {"design_corners", t->design_corners != NULL},
        {"map_tier", t->map_tier != NULL},
        {"map_correction", t->map_correction != NULL}, {"beds", t->beds != 0}, {"purpose", t->demonstration != NULL},
        {"posterior_runs", t->posterior_runs != 0}, {"return_runs", t->return_runs != 0},
        {"angle_aim_sd", t->angle_aim_sd != 0},
        {"turned_start_rpm", t->turned_start_rpm_count > 0}, {"turned_start_time", t->turned_start_time != 0}};
    for (size_t k = 0; k < sizeof keys / sizeof *keys; ++k)
        if (keys[k].given) return keys[k].key;
    return NULL;
}

int cal_tier_angle_in_misfit(const cal_tier *t) { return t->angle_rule && strcmp(t->angle_rule, "misfit") == 0; }
int cal_tier_beds(const cal_tier *t) { return t->beds > 0 ? t->beds : 1; }
int cal_tier_is_demonstration(const cal_tier *t) { return t->demonstration && *t->demonstration; }
int cal_tier_stiffness_on_drum(const cal_tier *t) { return t->stiffness_scene && *t->stiffness_scene; }
int cal_tier_bound_probes(const cal_tier *t) { return !t->bound_probes || *t->bound_probes; }
int cal_tier_design_corners(const cal_tier *t) { return t->design_corners && *t->design_corners; }
const double *cal_tier_stiffness(const cal_config *c, const cal_tier *t, unsigned *n)
{
    *n = t->stiffness_count ? t->stiffness_count : c->stiffness_count;
    return t->stiffness_count ? t->stiffness : c->stiffness;
}
const cal_tier *cal_tier_map_level(const cal_config *c, const cal_tier *t, int level)
{
    for (int k = 0; t && k < level; ++k) t = t->map_tier ? cal_config_tier_named(c, t->map_tier) : NULL;
    return t;
}
int cal_tier_map_depth(const cal_config *c, const cal_tier *t)
{
    int depth = 0;
    while (depth < CAL_MAX_MAP_DEPTH && cal_tier_map_level(c, t, depth + 1)) ++depth;
    return depth;
}
cal_mf_correction_kind cal_tier_map_correction(const cal_tier *t)
{
    return t->map_correction ? (cal_mf_correction_kind)*t->map_correction : CAL_MF_KRIGING;
}
double cal_tier_csa_sd(const cal_tier *t, unsigned i)
{
    if (t->csa_sd_percent_count == 0) return 0;
    return t->csa_sd_percent[t->csa_sd_percent_count == 1 ? 0 : i];
}

double cal_tier_average_time(const cal_tier *t, double rpm)
{
    for (unsigned k = 0; k < t->average_time_per_rpm_count && k < t->rpm_count; ++k)
        if (t->rpm[k] == rpm) return t->average_time_per_rpm[k];
    return t->average_time;
}

static int check_fidelity(const cal_config *c, char *err, size_t len)
{
    const cal_fidelity *f = c->fidelity;
    int from = exp_yaml_line_of(c->path, "fidelity", 1);
    if (f->seeds < 1 || f->seeds > 16) return located(c, from, "fidelity.seeds", err, len, "%d must be in [1, 16]", f->seeds);
    if (bad_positive(f->budget_hours))
        return located(c, from, "fidelity.budget_hours", err, len, "%g must be > 0", f->budget_hours);
    for (unsigned k = 0; k < f->rpm_count; ++k)
        if (!(f->rpm[k] > 0 && f->rpm[k] <= 1000))
            return located(c, from, "fidelity.rpm", err, len, "%g must be in (0, 1000]", f->rpm[k]);
    for (unsigned k = 0; k < f->rungs_count; ++k) {
        const cal_tier *r = &f->rungs[k];
        for (unsigned j = 0; j < k; ++j)
            if (strcmp(r->name, f->rungs[j].name) == 0)
                return located(c, from, "fidelity.rungs", err, len, "rung '%s' is defined twice", r->name);
        const char *tier_key = cal_tier_calibration_key(r);
        if (tier_key)
            return located(c, block_of(c, r->name), tier_key, err, len, "a key of a calibration tier: a rung takes the "
                           "drum's (lambda, slice_depth, max_time, window, sample_interval, steady_angle_tol_deg, "
                           "steady_csa_tol_percent, fill_method, average_time, steady_rule, steady_se_angle_deg, "
                           "steady_se_csa_percent); the study's speeds are fidelity.rpm");
        if (check_drum_knobs(c, block_of(c, r->name), r, err, len)) return 1;
    }
    return 0;
}

// "quick, ci, check, ...": the tiers the config defines, for an error that names a tier it lacks.
static void tier_names(const cal_config *c, char *out, size_t len)
{
    out[0] = 0;
    for (unsigned k = 0; k < c->tiers_count; ++k)
        snprintf(out + strlen(out), len - strlen(out), "%s%s", k ? ", " : "", c->tiers[k].name);
}

static int check_names(const cal_config *c, char *err, size_t len)
{
    if (strcmp(c->calibration, "drum") != 0) return located(c, 1, "calibration", err, len, "'%s': must be drum", c->calibration);
    if (c->damping && dem_damping_mode_from_name(c->damping) < 0)
        return located(c, 1, "damping", err, len, "'%s': use approaching, always, separating or no_tension", c->damping);
    for (unsigned k = 0; k < c->materials_count; ++k)
        for (unsigned j = 0; j < k; ++j)
            if (strcmp(c->materials[k].name, c->materials[j].name) == 0)
                return located(c, 1, "materials", err, len, "'%s' is listed twice", c->materials[k].name);
    for (unsigned k = 0; k < c->tiers_count; ++k)
        for (unsigned j = 0; j < k; ++j)
            if (strcmp(c->tiers[k].name, c->tiers[j].name) == 0)
                return located(c, 1, "tiers", err, len, "tier '%s' is defined twice", c->tiers[k].name);
    char names[512];
    tier_names(c, names, sizeof names);
    if (!cal_config_tier(c)) return located(c, 1, "tier", err, len, "'%s' is not one of its tiers: %s", c->tier, names);
    return 0;
}

// The log-normal's three keys, each in its range (absent reads as 0).
static int check_lognormal(const cal_config *c, char *err, size_t len)
{
    static const char OR_TABLE[] = "(absent reads as 0; or give gsd_table, a measured size table)";
    if (bad_positive(c->median_diameter))
        return located(c, 1, "median_diameter", err, len, "%g must be > 0 %s", c->median_diameter, OR_TABLE);
    if (!(c->geometric_sd >= 1 && c->geometric_sd < 5))
        return located(c, 1, "geometric_sd", err, len, "%g must be in [1, 5) %s", c->geometric_sd, OR_TABLE);
    if (!(c->truncation_sigmas > 0 && c->truncation_sigmas <= 4))
        return located(c, 1, "truncation_sigmas", err, len, "%g must be in (0, 4] %s", c->truncation_sigmas, OR_TABLE);
    return 0;
}

// The size distribution, into c->gsd: a log-normal by number, or a measured
// table (gsd_table, on gsd_basis; exp_gsd_table.h), not both. With a table,
// median_diameter and geometric_sd become the table's (number-based) values,
// for what reads a typical diameter.
static int check_gsd(cal_config *c, char *err, size_t len)
{
    if (!c->gsd_table) {
        if (c->gsd_basis) return located(c, 1, "gsd_basis", err, len, "given without gsd_table");
        if (check_lognormal(c, err, len)) return 1;
        c->gsd = dem_gsd_lognormal(c->median_diameter, c->geometric_sd, c->truncation_sigmas);
        return 0;
    }
    const struct { const char *field; double v; } lognormal[] = {
        {"median_diameter", c->median_diameter}, {"geometric_sd", c->geometric_sd},
        {"truncation_sigmas", c->truncation_sigmas}};
    for (size_t k = 0; k < sizeof lognormal / sizeof *lognormal; ++k)
        if (lognormal[k].v != 0)
            return located(c, 1, lognormal[k].field, err, len,
                           "gsd_table gives the size distribution: remove the log-normal's keys (give one or the other)");
    dem_gsd_basis basis;
    if (exp_gsd_basis_from_name(c->gsd_basis, &basis))
        return located(c, 1, "gsd_basis", err, len, "'%s': say what the table's percentages count: volume (laser "
                       "diffraction, sieving) or number", c->gsd_basis ? c->gsd_basis : "absent");
    char path[2048];
    cal_config_data_path(c, c->gsd_table, path, sizeof path);
    if (exp_gsd_table_load(path, c->gsd_basis, &c->gsd, err, len)) return 1;
    c->median_diameter = c->gsd.median_diameter, c->geometric_sd = c->gsd.geometric_sd;
    c->truncation_sigmas = c->gsd.truncation_sigmas;
    return 0;
}

static int validate(cal_config *c, char *err, size_t len)
{
    struct { const char *field; double v; } positive[] = {
        {"density", c->density}, {"diameter", c->diameter}, {"depth", c->depth}, {"k_n", c->k_n}};
    for (size_t k = 0; k < sizeof positive / sizeof *positive; ++k)
        if (bad_positive(positive[k].v)) return located(c, 1, positive[k].field, err, len, "%g must be > 0", positive[k].v);
    if (check_gsd(c, err, len)) return 1;
    if (!(c->xi >= 0 && c->xi <= 1)) return located(c, 1, "xi", err, len, "%g must be in [0, 1]", c->xi);
    if (!(c->fill > 0 && c->fill < 1)) return located(c, 1, "fill", err, len, "%g must be in (0, 1)", c->fill);
    if (!(c->granule_mu_s >= 0 && c->granule_mu_s <= 10))
        return located(c, 1, "granule_mu_s", err, len, "%g must be in [0, 10]", c->granule_mu_s);
    if (!(c->granule_mu_r >= 0 && c->granule_mu_r <= 10))
        return located(c, 1, "granule_mu_r", err, len, "%g must be in [0, 10]", c->granule_mu_r);
    if (!(c->pour_mu_s >= 0 && c->pour_mu_s <= 10)) return located(c, 1, "pour_mu_s", err, len, "%g must be in [0, 10]", c->pour_mu_s);
    if (!(c->pour_mu_r >= 0 && c->pour_mu_r <= 10)) return located(c, 1, "pour_mu_r", err, len, "%g must be in [0, 10]", c->pour_mu_r);
    if (!(isfinite(c->stiffness_tolerance) && c->stiffness_tolerance >= 0))
        return located(c, 1, "stiffness_tolerance", err, len, "%g must be >= 0 and finite", c->stiffness_tolerance);
    if (check_stiffness(c, 1, c->stiffness, c->stiffness_count, err, len)) return 1;
    if (check_names(c, err, len) || check_bounds(c, &c->granule, "granule", err, len) ||
        check_bounds(c, &c->wall, "wall", err, len))
        return 1;
    for (unsigned k = 0; k < c->tiers_count; ++k)
        if (check_tier(c, &c->tiers[k], err, len)) return 1;
    return c->fidelity ? check_fidelity(c, err, len) : 0;
}

cal_config *cal_config_load(const char *path, const char *tier_override, char *err, size_t len)
{
    cal_config *c = NULL;
    if (exp_yaml_load(path, &config_schema, (void **)&c, "see configs/calibration.yaml for every key", err, len))
        return NULL;
    snprintf(c->path, sizeof c->path, "%s", path);
    char copy[1024];
    snprintf(copy, sizeof copy, "%s", path);
    snprintf(c->dir, sizeof c->dir, "%s", dirname(copy));
    if (tier_override && !cal_config_tier_named(c, tier_override)) { // the user's option, not the file's line
        char names[512];
        tier_names(c, names, sizeof names);
        exp_fail(err, len, "--tier %s: not a tier of %s; its tiers: %s", tier_override, path, names);
        return cal_config_free(c), NULL;
    }
    if (tier_override) {
        char *t = strdup(tier_override);
        if (!t) return cal_config_free(c), exp_fail(err, len, "out of memory"), NULL;
        free(c->tier); // libcyaml allocates with plain malloc (cyaml_mem)
        c->tier = t;
    }
    if (validate(c, err, len)) return cal_config_free(c), NULL;
    return c;
}

void cal_config_free(cal_config *c) { exp_yaml_free(&config_schema, c); }

const cal_tier *cal_config_tier_named(const cal_config *c, const char *name)
{
    for (unsigned k = 0; k < c->tiers_count; ++k)
        if (strcmp(c->tiers[k].name, name) == 0) return &c->tiers[k];
    return NULL;
}

const cal_tier *cal_config_tier(const cal_config *c) { return cal_config_tier_named(c, c->tier); }

void cal_config_data_path(const cal_config *c, const char *rel, char *out, size_t len)
{
    if (rel[0] == '/') snprintf(out, len, "%s", rel);
    else snprintf(out, len, "%s/%s", c->dir, rel);
}
