// SPDX-License-Identifier: MIT
// Explicit-scene loading (libcyaml schema) and world building.
#include "exp_scene.h"

#include <cyaml/cyaml.h>

#include "exp_common.h"
#include "exp_contact_rules.h"
#include "exp_yaml.h"
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const cyaml_schema_value_t double_entry = {CYAML_VALUE_FLOAT(CYAML_FLAG_DEFAULT, double)};

#define VEC3_FIELD(key, flags, type, member) \
    CYAML_FIELD_SEQUENCE_FIXED(key, flags, type, member, &double_entry, 3)

static const cyaml_schema_field_t contact_fields[] = {
    CYAML_FIELD_FLOAT("k_n", CYAML_FLAG_DEFAULT, exp_contact_yaml, k_n),
    CYAML_FIELD_FLOAT("k_s", CYAML_FLAG_DEFAULT, exp_contact_yaml, k_s),
    CYAML_FIELD_FLOAT("k_r", CYAML_FLAG_DEFAULT, exp_contact_yaml, k_r),
    CYAML_FIELD_FLOAT("xi", CYAML_FLAG_DEFAULT, exp_contact_yaml, xi),
    CYAML_FIELD_FLOAT("mu_s", CYAML_FLAG_DEFAULT, exp_contact_yaml, mu_s),
    CYAML_FIELD_FLOAT("mu_r", CYAML_FLAG_DEFAULT, exp_contact_yaml, mu_r),
    CYAML_FIELD_STRING_PTR("damping", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_contact_yaml, damping, 1, 32),
    CYAML_FIELD_END};

static const cyaml_schema_field_t wall_fields[] = {
    CYAML_FIELD_STRING_PTR("name", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_wall_yaml, name, 1, 31),
    CYAML_FIELD_STRING_PTR("kind", CYAML_FLAG_POINTER, exp_wall_yaml, kind, 1, 16),
    VEC3_FIELD("point", CYAML_FLAG_DEFAULT, exp_wall_yaml, point),
    VEC3_FIELD("normal", CYAML_FLAG_OPTIONAL, exp_wall_yaml, normal),
    VEC3_FIELD("axis", CYAML_FLAG_OPTIONAL, exp_wall_yaml, axis),
    CYAML_FIELD_FLOAT("radius", CYAML_FLAG_OPTIONAL, exp_wall_yaml, radius),
    CYAML_FIELD_FLOAT("rpm", CYAML_FLAG_OPTIONAL, exp_wall_yaml, rpm),
    CYAML_FIELD_MAPPING("contact", CYAML_FLAG_DEFAULT, exp_wall_yaml, contact, contact_fields),
    CYAML_FIELD_END};

static const cyaml_schema_field_t granule_fields[] = {
    VEC3_FIELD("position", CYAML_FLAG_DEFAULT, exp_granule_yaml, position),
    VEC3_FIELD("velocity", CYAML_FLAG_OPTIONAL, exp_granule_yaml, velocity),
    VEC3_FIELD("omega", CYAML_FLAG_OPTIONAL, exp_granule_yaml, omega),
    CYAML_FIELD_FLOAT("radius", CYAML_FLAG_DEFAULT, exp_granule_yaml, radius),
    CYAML_FIELD_FLOAT("density", CYAML_FLAG_DEFAULT, exp_granule_yaml, density),
    CYAML_FIELD_END};

static const cyaml_schema_value_t wall_entry = {CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, exp_wall_yaml, wall_fields)};
static const cyaml_schema_value_t granule_entry = {
    CYAML_VALUE_MAPPING(CYAML_FLAG_DEFAULT, exp_granule_yaml, granule_fields)};

static const cyaml_schema_field_t scene_fields[] = {
    CYAML_FIELD_STRING_PTR("scene", CYAML_FLAG_POINTER, exp_scene, name, 1, 64),
    CYAML_FIELD_FLOAT("duration", CYAML_FLAG_DEFAULT, exp_scene, duration),
    CYAML_FIELD_FLOAT("dt", CYAML_FLAG_OPTIONAL, exp_scene, dt),
    CYAML_FIELD_FLOAT("output_interval", CYAML_FLAG_DEFAULT, exp_scene, output_interval),
    VEC3_FIELD("gravity", CYAML_FLAG_DEFAULT, exp_scene, gravity),
    VEC3_FIELD("domain_lo", CYAML_FLAG_DEFAULT, exp_scene, domain_lo),
    VEC3_FIELD("domain_hi", CYAML_FLAG_DEFAULT, exp_scene, domain_hi),
    CYAML_FIELD_STRING_PTR("lever_arm", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_scene, lever_arm, 1, 32),
    CYAML_FIELD_MAPPING("granule_contact", CYAML_FLAG_DEFAULT, exp_scene, granule_contact, contact_fields),
    CYAML_FIELD_SEQUENCE("walls", CYAML_FLAG_OPTIONAL | CYAML_FLAG_POINTER, exp_scene, walls, &wall_entry, 0, 8),
    CYAML_FIELD_SEQUENCE("granules", CYAML_FLAG_POINTER, exp_scene, granules, &granule_entry, 1, CYAML_UNLIMITED),
    CYAML_FIELD_END};

static const cyaml_schema_value_t scene_schema = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, exp_scene, scene_fields)};

// libcyaml reports errors as a message plus a backtrace of fields; collect
// them into one line for the user.
typedef struct log_buffer {
    char text[768];
    size_t used;
} log_buffer;

static void collect_log(cyaml_log_t level, void *ctx, const char *fmt, va_list args)
{
    log_buffer *b = ctx;
    if (level < CYAML_LOG_ERROR || b->used >= sizeof b->text - 1) return;
    char line[256];
    vsnprintf(line, sizeof line, fmt, args);
    line[strcspn(line, "\n")] = '\0';
    int n = snprintf(b->text + b->used, sizeof b->text - b->used, "%s%s", b->used ? "; " : "", line);
    if (n > 0) b->used += (size_t)n;
}

static const cyaml_config_t *config_for(log_buffer *b)
{
    static _Thread_local cyaml_config_t cfg;
    cfg = (cyaml_config_t){.log_fn = collect_log, .log_ctx = b, .mem_fn = cyaml_mem, .log_level = CYAML_LOG_ERROR,
                           .flags = CYAML_CFG_DEFAULT};
    return &cfg;
}

int exp_contact_from_yaml(const exp_contact_yaml *y, dem_contact_params *out, const char *where, char *err,
                          size_t err_len)
{
    *out = (dem_contact_params){.k_n = y->k_n, .k_s = y->k_s, .k_r = y->k_r, .xi = y->xi, .mu_s = y->mu_s,
                                .mu_r = y->mu_r, .damping = EXP_DAMPING_DEFAULT};
    char field[96];
    snprintf(field, sizeof field, "%s.damping", where);
    if (exp_damping_from_name(y->damping, field, &out->damping, err, err_len)) return 1;
    char sub[256];
    if (dem_contact_params_check(out, sub, sizeof sub)) return exp_fail(err, err_len, "%s.%s", where, sub);
    return 0;
}

// Point a message at the line of its field: "path:line: field...: why".
static int located(const char *path, const char *msg, char *err, size_t len)
{
    char field[EXP_FIELD_LEN];
    int line = exp_yaml_line_of(path, exp_message_field(msg, field), 1);
    if (line > 0) return exp_fail(err, len, "%s:%d: %s", path, line, msg);
    return exp_fail(err, len, "%s: %s", path, msg);
}

static int check_positive(const char *path, const char *field, double v, char *err, size_t len)
{
    if (isfinite(v) && v > 0) return 0;
    char msg[128];
    snprintf(msg, sizeof msg, "%s = %g: must be a positive finite number", field, v);
    return located(path, msg, err, len);
}

static int validate(const char *path, const exp_scene *s, char *err, size_t len)
{
    if (check_positive(path, "duration", s->duration, err, len) ||
        check_positive(path, "output_interval", s->output_interval, err, len))
        return 1;
    if (!(s->dt >= 0 && isfinite(s->dt))) return located(path, "dt: must be >= 0 (0: automatic)", err, len);
    if (s->lever_arm && strcmp(s->lever_arm, "contact_point") && strcmp(s->lever_arm, "radius"))
        return located(path, "lever_arm: must be contact_point or radius", err, len);
    char msg[300];
    dem_contact_params p;
    if (exp_contact_from_yaml(&s->granule_contact, &p, "granule_contact", msg, sizeof msg))
        return located(path, msg, err, len);
    for (unsigned k = 0; k < s->granules_count; ++k) {
        char field[64];
        snprintf(field, sizeof field, "granules[%u].radius", k);
        if (check_positive(path, field, s->granules[k].radius, err, len)) return 1;
        snprintf(field, sizeof field, "granules[%u].density", k);
        if (check_positive(path, field, s->granules[k].density, err, len)) return 1;
    }
    for (unsigned k = 0; k < s->walls_count; ++k) {
        char where[32];
        snprintf(where, sizeof where, "walls[%u].contact", k);
        if (exp_contact_from_yaml(&s->walls[k].contact, &p, where, msg, sizeof msg)) return located(path, msg, err, len);
    }
    return 0;
}

exp_scene *exp_scene_load(const char *path, char *err, size_t err_len)
{
    log_buffer log = {{0}, 0};
    exp_scene *s = NULL;
    cyaml_err_t e = cyaml_load_file(path, config_for(&log), &scene_schema, (cyaml_data_t **)&s, NULL);
    if (e != CYAML_OK) {
        exp_fail(err, err_len, "%s: %s%s%s", path, cyaml_strerror(e), log.used ? ": " : "", log.text);
        return NULL;
    }
    if (!s) { // an empty document (no bytes, only comments) loads as CYAML_OK and NULL
        exp_fail(err, err_len, "%s: no YAML document in the file", path);
        return NULL;
    }
    if (validate(path, s, err, err_len)) {
        exp_scene_free(s);
        return NULL;
    }
    return s;
}

void exp_scene_free(exp_scene *s)
{
    log_buffer log = {{0}, 0};
    if (s) cyaml_free(config_for(&log), &scene_schema, s, 0);
}

static dem_vec3 v3(const double a[3]) { return dem_v3(a[0], a[1], a[2]); }

static int wall_kind_from_name(const char *name)
{
    const char *names[] = {"plane", "disc", "cylinder"};
    for (int k = 0; k < 3; ++k)
        if (strcmp(name, names[k]) == 0) return k;
    return -1;
}

static int add_walls(const exp_scene *s, dem_world *w, char *err, size_t len)
{
    for (unsigned k = 0; k < s->walls_count; ++k) {
        const exp_wall_yaml *y = &s->walls[k];
        dem_wall_def d = {0};
        int kind = wall_kind_from_name(y->kind);
        if (kind < 0) return exp_fail(err, len, "walls[%u].kind = '%s': use plane, disc or cylinder", k, y->kind);
        d.kind = (dem_wall_kind)kind;
        d.point = v3(y->point), d.normal = v3(y->normal), d.axis = v3(y->axis);
        d.radius = y->radius;
        d.spin = y->rpm * 2.0 * DEM_PI / 60.0;
        d.name = y->name;
        char where[32];
        snprintf(where, sizeof where, "walls[%u].contact", k);
        if (exp_contact_from_yaml(&y->contact, &d.contact, where, err, len)) return 1;
        if (dem_world_add_wall(w, &d) < 0) return exp_fail(err, len, "walls[%u]: %s", k, dem_world_error(w));
    }
    return 0;
}

dem_world *exp_scene_build(const exp_scene *s, char *err, size_t err_len)
{
    dem_world_def def = dem_default_world_def();
    def.gravity = v3(s->gravity);
    def.dt = s->dt;
    def.domain_lo = v3(s->domain_lo), def.domain_hi = v3(s->domain_hi);
    def.lever_arm = s->lever_arm && strcmp(s->lever_arm, "radius") == 0 ? DEM_LEVER_RADIUS : DEM_LEVER_CONTACT_POINT;
    if (exp_contact_from_yaml(&s->granule_contact, &def.granule, "granule_contact", err, err_len)) return NULL;
    dem_world *w = dem_world_create(&def, err, err_len);
    if (!w) return NULL;
    if (add_walls(s, w, err, err_len)) {
        dem_world_destroy(w);
        return NULL;
    }
    for (unsigned k = 0; k < s->granules_count; ++k) {
        const exp_granule_yaml *g = &s->granules[k];
        if (dem_world_add_granule(w, v3(g->position), v3(g->velocity), v3(g->omega), g->radius, g->density) < 0) {
            exp_fail(err, err_len, "granules[%u]: %s", k, dem_world_error(w));
            dem_world_destroy(w);
            return NULL;
        }
    }
    return w;
}
