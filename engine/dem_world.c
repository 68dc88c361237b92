// SPDX-License-Identifier: MIT
// The world: its lifetime (create, clone, destroy), its granules and walls,
// and its accessors. Stepping is dem_step.c's.
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_implicit_internal.h"
#include "dem_memory_internal.h"
#include "dem_state_internal.h"

dem_world_def dem_default_world_def(void)
{
    dem_world_def d;
    memset(&d, 0, sizeof d);
    d.gravity = dem_v3(0.0, -9.81, 0.0);
    // Table 3, granule–granule.
    d.granule = (dem_contact_params){.k_n = 200, .k_s = 200, .k_r = 200, .xi = 0.7, .mu_s = 0.8, .mu_r = 0.2,
                                     .damping = DEM_DAMPING_APPROACHING};
    d.dt = 0.0;
    d.dt_safety = 0.9;
    d.domain_lo = dem_v3(-0.5, -0.5, -0.5);
    d.domain_hi = dem_v3(0.5, 0.5, 0.5);
    d.periodic_axis = -1;
    d.skin = 0.0;
    d.lever_arm = DEM_LEVER_CONTACT_POINT;
    d.threads = 0;
    d.implicit_springs = DEM_IMPLICIT_AUTO;
    return d;
}

static int check_def(const dem_world_def *d, char *msg, size_t len)
{
    char sub[256];
    if (dem_contact_params_check(&d->granule, sub, sizeof sub)) {
        snprintf(msg, len, "granule–granule contact: %s", sub);
        return 1;
    }
    if (!(d->dt >= 0) || !isfinite(d->dt)) return snprintf(msg, len, "dt = %g: must be >= 0", d->dt), 1;
    if (!(d->dt_safety > 0 && d->dt_safety <= 1))
        return snprintf(msg, len, "dt_safety = %g: must be in (0, 1]", d->dt_safety), 1;
    if (!(d->skin >= 0)) return snprintf(msg, len, "skin = %g: must be >= 0", d->skin), 1;
    if (!(d->network_check_interval >= 0) || !isfinite(d->network_check_interval) ||
        !(d->network_check_chunk >= 0) || !isfinite(d->network_check_chunk))
        return snprintf(msg, len, "network_check_interval = %g, network_check_chunk = %g: must be >= 0",
                        d->network_check_interval, d->network_check_chunk), 1;
    if (d->periodic_axis < -1 || d->periodic_axis > 2)
        return snprintf(msg, len, "periodic_axis = %d: must be -1, 0, 1 or 2", d->periodic_axis), 1;
    for (int a = 0; a < 3; ++a)
        if (!(dem_v3_comp(d->domain_hi, a) > dem_v3_comp(d->domain_lo, a)))
            return snprintf(msg, len, "domain: hi must exceed lo on axis %d", a), 1;
    return 0;
}

static void refresh_features(dem_world *w)
{
    w->gg = dem_contact_coeffs_make(&w->def.granule);
    w->features = dem_contact_features(&w->def.granule) | (w->def.periodic_axis >= 0 ? DEM_FEAT_PERIODIC : 0u);
}

dem_world *dem_world_create(const dem_world_def *def, char *err, size_t err_len)
{
    char msg[512];
    if (check_def(def, msg, sizeof msg)) {
        if (err) snprintf(err, err_len, "%s", msg);
        return NULL;
    }
    dem_world *w = calloc(1, sizeof *w);
    if (!w) {
        if (err) snprintf(err, err_len, "out of memory");
        return NULL;
    }
    w->def = *def;
    // Provisional until dem_world_prepare decides "auto" (dem_stability_current
    // may be asked before).
    w->implicit_springs = def->implicit_springs == DEM_IMPLICIT_AUTO ? 0 : def->implicit_springs != 0;
    w->threads = def->threads > 0 ? def->threads : 0; // OpenMP's process-wide count is the caller's
    w->lever_factor = def->lever_arm == DEM_LEVER_RADIUS ? 0.0 : 1.0;
    w->checks.margin_min = NAN; // no check yet
    refresh_features(w);
    return w;
}

void dem_world_destroy(dem_world *w)
{
    if (!w) return;
    void *arrays[] = {w->pos, w->vel, w->omg, w->frc, w->trq, w->rad, w->mass, w->inertia, w->inv_mass,
                      w->inv_inertia, w->id, w->pair_f, w->pair_ti, w->pair_tj, w->rev_start, w->rev_pair,
                      w->pair_n, w->pair_g, w->damp, w->acc, w->fixed,
                      w->pos_at_build};
    for (size_t k = 0; k < sizeof arrays / sizeof *arrays; ++k) free(arrays[k]);
    for (int k = 0; k < w->n_walls; ++k) free(w->walls[k].hist), free(w->walls[k].near), free(w->walls[k].force);
    dem_nl_free(&w->nl);
    dem_nl_free(&w->nl_old);
    dem_implicit_free(w->imp);
    free(w);
}

dem_world *dem_world_clone(const dem_world *w)
{
    dem_world *c = malloc(sizeof *c);
    if (!c) return NULL;
    *c = *w;
    int fail = 0;
    size_t cap = w->cap, pc = w->pair_cap;
#define DUP(field, count) c->field = dem_dup_bytes(w->field, (count) * sizeof *w->field, &fail)
    DUP(pos, cap), DUP(vel, cap), DUP(omg, cap), DUP(frc, cap), DUP(trq, cap), DUP(rad, cap), DUP(mass, cap);
    DUP(inertia, cap), DUP(inv_mass, cap), DUP(inv_inertia, cap), DUP(id, cap), DUP(pos_at_build, cap);
    DUP(fixed, cap);
    DUP(pair_f, pc), DUP(pair_ti, pc), DUP(pair_tj, pc), DUP(rev_pair, pc), DUP(pair_n, pc), DUP(pair_g, pc);
    DUP(damp, 6 * cap), DUP(acc, 6 * cap);
    c->imp = NULL; // scratch: allocated on the clone's first step
    DUP(rev_start, w->rev_start ? w->n + 1 : 0);
#undef DUP
    for (int k = 0; k < w->n_walls; ++k) {
        c->walls[k].def.name = c->walls[k].name;
        size_t hl = (size_t)(w->walls[k].hist_len ? w->walls[k].hist_len : 1);
        c->walls[k].hist = dem_dup_bytes(w->walls[k].hist, (cap ? cap : 1) * hl * sizeof(double), &fail);
        c->walls[k].near = dem_dup_bytes(w->walls[k].near, w->walls[k].near_cap * sizeof *w->walls[k].near, &fail);
        c->walls[k].force = dem_dup_bytes(w->walls[k].force, w->walls[k].near_cap * sizeof *w->walls[k].force, &fail);
    }
    dem_nl_clone(&c->nl, &w->nl, &fail);
    dem_nl_clone(&c->nl_old, &w->nl_old, &fail);
    if (fail) {
        dem_world_destroy(c);
        return NULL;
    }
    return c;
}

#define GROW(ptr, cap) ((ptr) = realloc_or_keep((ptr), (cap) * sizeof *(ptr), &fail))
static void *realloc_or_keep(void *p, size_t bytes, int *fail)
{
    void *q = realloc(p, bytes);
    if (!q) *fail = 1;
    return q ? q : p;
}

static int grow_granules(dem_world *w, size_t need)
{
    if (need <= w->cap) return 0;
    size_t cap = need < 64 ? 64 : need + need / 2;
    int fail = 0;
    GROW(w->pos, cap), GROW(w->vel, cap), GROW(w->omg, cap), GROW(w->frc, cap), GROW(w->trq, cap);
    GROW(w->rad, cap), GROW(w->mass, cap), GROW(w->inertia, cap), GROW(w->inv_mass, cap);
    GROW(w->inv_inertia, cap), GROW(w->id, cap), GROW(w->pos_at_build, cap), GROW(w->fixed, cap);
    w->damp = realloc_or_keep(w->damp, cap * 6 * sizeof *w->damp, &fail);
    double *acc = realloc(w->acc, cap * 6 * sizeof *acc);
    if (acc) memset(acc + 6 * w->cap, 0, (cap - w->cap) * 6 * sizeof *acc), w->acc = acc;
    else fail = 1;
    for (int k = 0; k < w->n_walls; ++k) {
        size_t hl = (size_t)(w->walls[k].hist_len ? w->walls[k].hist_len : 1);
        GROW(w->walls[k].hist, cap * hl);
    }
    if (fail) return dem_world_set_error(w, "out of memory growing to %zu granules", cap);
    w->cap = cap;
    return 0;
}

static void invalidate(dem_world *w)
{
    w->list_valid = 0;
    w->forces_valid = 0;
}

int64_t dem_world_add_granule(dem_world *w, dem_vec3 position, dem_vec3 velocity, dem_vec3 omega, double radius,
                              double density)
{
    if (!(radius > 0) || !isfinite(radius) || !(density > 0) || !isfinite(density)) {
        dem_world_set_error(w, "granule radius %g m and density %g kg/m3 must be positive and finite", radius,
                            density);
        return -1;
    }
    if (!dem_v3_isfinite(position) || !dem_v3_isfinite(velocity) || !dem_v3_isfinite(omega)) {
        dem_world_set_error(w, "granule position, velocity and spin must be finite");
        return -1;
    }
    if (w->n >= UINT32_MAX || grow_granules(w, w->n + 1)) return -1;
    size_t i = w->n++;
    double m = density * 4.0 / 3.0 * DEM_PI * radius * radius * radius;
    double inertia = 0.4 * m * radius * radius; // solid sphere
    w->pos[i] = position;
    w->vel[i] = velocity;
    w->omg[i] = omega;
    w->frc[i] = w->trq[i] = dem_v3(0, 0, 0);
    w->rad[i] = radius;
    w->mass[i] = m;
    w->inertia[i] = inertia;
    w->inv_mass[i] = 1.0 / m;
    w->inv_inertia[i] = 1.0 / inertia;
    w->id[i] = w->next_id++;
    w->fixed[i] = 0;
    for (int k = 0; k < w->n_walls; ++k)
        memset(w->walls[k].hist + i * w->walls[k].hist_len, 0, w->walls[k].hist_len * sizeof(double));
    invalidate(w);
    w->prepared = 0;
    return (int64_t)w->id[i];
}

static dem_status wall_set_contact(dem_world *w, dem_wall *wall, const dem_contact_params *p)
{
    char sub[256];
    if (dem_contact_params_check(p, sub, sizeof sub))
        return dem_world_set_error(w, "wall '%s' contact: %s", wall->name, sub), DEM_ERR_INVALID;
    wall->def.contact = *p;
    wall->coeffs = dem_contact_coeffs_make(p);
    const unsigned old = wall->features;
    wall->features = dem_contact_features(p);
    int hl = dem_history_len(wall->features);
    if (!wall->hist || !dem_same_history_layout(old, wall->features)) { // springs restart
        size_t cap = w->cap ? w->cap : 1;
        double *h = realloc(wall->hist, cap * (size_t)(hl ? hl : 1) * sizeof *h);
        if (!h) return dem_world_set_error(w, "out of memory for wall history"), DEM_ERR_NOMEM;
        wall->hist = h;
        wall->hist_len = hl;
        memset(h, 0, cap * (size_t)(hl ? hl : 1) * sizeof *h);
    }
    w->forces_valid = 0;
    return DEM_OK;
}

static int check_wall_geometry(dem_world *w, const dem_wall_def *d)
{
    double axis_len = dem_v3_norm(d->axis), normal_len = dem_v3_norm(d->normal);
    if ((unsigned)d->kind > DEM_WALL_CYLINDER) return dem_world_set_error(w, "wall kind %d unknown", (int)d->kind);
    if (d->kind != DEM_WALL_CYLINDER && fabs(normal_len - 1.0) > 1e-9)
        return dem_world_set_error(w, "wall '%s': normal must be a unit vector", d->name ? d->name : "");
    if ((d->kind == DEM_WALL_CYLINDER || d->spin != 0.0) && fabs(axis_len - 1.0) > 1e-9)
        return dem_world_set_error(w, "wall '%s': axis must be a unit vector", d->name ? d->name : "");
    if (d->kind != DEM_WALL_PLANE && !(d->radius > 0))
        return dem_world_set_error(w, "wall '%s': radius must be positive", d->name ? d->name : "");
    if (!isfinite(d->spin)) return dem_world_set_error(w, "wall '%s': spin must be finite", d->name ? d->name : "");
    if (!dem_v3_isfinite(d->velocity))
        return dem_world_set_error(w, "wall '%s': velocity must be finite", d->name ? d->name : "");
    if ((unsigned)d->motion > DEM_WALL_TRANSLATES)
        return dem_world_set_error(w, "wall '%s': motion %d unknown", d->name ? d->name : "", (int)d->motion);
    if (!dem_v3_isfinite(d->step_displacement))
        return dem_world_set_error(w, "wall '%s': step displacement must be finite", d->name ? d->name : "");
    return 0;
}

// Only a wall with a nonzero velocity adds it to its contacts' relative
// velocity: adding a zero vector can turn a −0 into +0, and every result of a
// wall at rest must stay the same bits.
static int wall_translates(const dem_wall_def *d)
{
    return d->velocity.x != 0.0 || d->velocity.y != 0.0 || d->velocity.z != 0.0;
}

int dem_world_add_wall(dem_world *w, const dem_wall_def *def)
{
    if (w->n_walls >= DEM_MAX_WALLS) return dem_world_set_error(w, "at most %d walls", DEM_MAX_WALLS), -1;
    if (check_wall_geometry(w, def)) return -1;
    dem_wall *wall = &w->walls[w->n_walls];
    memset(wall, 0, sizeof *wall);
    wall->def = *def;
    snprintf(wall->name, sizeof wall->name, "%s", def->name ? def->name : "wall");
    wall->def.name = wall->name;
    wall->translating = wall_translates(&wall->def);
    if (wall_set_contact(w, wall, &def->contact)) return -1;
    w->prepared = 0;
    return w->n_walls++;
}

static int no_wall(dem_world *w, int wall)
{
    return wall < 0 || wall >= w->n_walls ? dem_world_set_error(w, "no wall %d (the world has %d)", wall, w->n_walls) : 0;
}

dem_status dem_world_set_wall_spin(dem_world *w, int wall, double spin)
{
    if (no_wall(w, wall)) return DEM_ERR_INVALID;
    if (!isfinite(spin)) return dem_world_set_error(w, "wall %d: spin %g must be finite", wall, spin), DEM_ERR_INVALID;
    w->walls[wall].def.spin = spin;
    w->forces_valid = 0;
    return DEM_OK;
}

// Not an invalidation: the step in progress ends with the forces it has, and
// the next evaluation sees the wall where it now is (the wall's lists are
// rebuilt once it has moved half a skin: dem_lists_refresh).
dem_status dem_world_set_wall_point(dem_world *w, int wall, dem_vec3 point)
{
    if (no_wall(w, wall)) return DEM_ERR_INVALID;
    if (!dem_v3_isfinite(point)) return dem_world_set_error(w, "wall %d: point must be finite", wall), DEM_ERR_INVALID;
    w->walls[wall].def.point = point;
    return DEM_OK;
}

// Not an invalidation either: like the point, the velocity is what the next
// force evaluation sees.
dem_status dem_world_set_wall_velocity(dem_world *w, int wall, dem_vec3 velocity)
{
    if (no_wall(w, wall)) return DEM_ERR_INVALID;
    if (!dem_v3_isfinite(velocity))
        return dem_world_set_error(w, "wall %d: velocity must be finite", wall), DEM_ERR_INVALID;
    w->walls[wall].def.velocity = velocity;
    w->walls[wall].translating = wall_translates(&w->walls[wall].def);
    return DEM_OK;
}

// The wall's law is read by the step (dem_wall_advance), before each kick:
// like the point, nothing computed is invalidated.
dem_status dem_world_set_wall_translation(dem_world *w, int wall, dem_vec3 velocity, dem_vec3 step_displacement)
{
    if (no_wall(w, wall)) return DEM_ERR_INVALID;
    if (!dem_v3_isfinite(step_displacement))
        return dem_world_set_error(w, "wall %d: step displacement must be finite", wall), DEM_ERR_INVALID;
    dem_status st = dem_world_set_wall_velocity(w, wall, velocity);
    if (st != DEM_OK) return st;
    w->walls[wall].def.motion = DEM_WALL_TRANSLATES;
    w->walls[wall].def.step_displacement = step_displacement;
    return DEM_OK;
}

dem_status dem_world_stop_wall(dem_world *w, int wall)
{
    if (no_wall(w, wall)) return DEM_ERR_INVALID;
    w->walls[wall].def.motion = DEM_WALL_STANDS;
    w->walls[wall].def.step_displacement = dem_v3(0, 0, 0);
    return dem_world_set_wall_velocity(w, wall, dem_v3(0, 0, 0));
}

dem_status dem_world_set_network_check(dem_world *w, double interval, double chunk)
{
    if (!(interval >= 0) || !isfinite(interval) || !(chunk >= 0) || !isfinite(chunk))
        return dem_world_set_error(w, "network check every %g s in chunks of %g s: both must be >= 0", interval, chunk),
               DEM_ERR_INVALID;
    w->def.network_check_interval = interval;
    w->def.network_check_chunk = chunk;
    w->steps_since_check = 0;
    w->checks = (dem_network_checks){0, 0, NAN, 0.0};
    return DEM_OK;
}

dem_network_checks dem_world_network_checks(const dem_world *w) { return w->checks; }

const dem_wall_def *dem_world_wall(const dem_world *w, int wall)
{
    return wall >= 0 && wall < w->n_walls ? &w->walls[wall].def : NULL;
}

dem_vec3 dem_world_wall_force(const dem_world *w, int wall)
{
    if (wall < 0 || wall >= w->n_walls) return dem_v3(NAN, NAN, NAN);
    return dem_wall_force_total(&w->walls[wall]);
}

dem_status dem_world_set_granule_contact(dem_world *w, const dem_contact_params *p)
{
    char sub[256];
    if (dem_contact_params_check(p, sub, sizeof sub))
        return dem_world_set_error(w, "granule–granule contact: %s", sub), DEM_ERR_INVALID;
    unsigned old = w->features;
    w->def.granule = *p;
    refresh_features(w);
    if (!dem_same_history_layout(old, w->features)) w->list_valid = 0; // springs restart
    w->forces_valid = 0;
    w->prepared = 0;
    return DEM_OK;
}

dem_status dem_world_set_wall_contact(dem_world *w, int wall, const dem_contact_params *p)
{
    if (no_wall(w, wall)) return DEM_ERR_INVALID;
    w->prepared = 0;
    return wall_set_contact(w, &w->walls[wall], p);
}

double dem_world_min_mass(const dem_world *w) { return dem_granules_min_mass(w); }
double dem_world_min_radius(const dem_world *w) { return dem_granules_min_radius(w); }
double dem_world_max_radius(const dem_world *w) { return dem_granules_max_radius(w); }

dem_status dem_world_remove_granules(dem_world *w, int (*keep)(const dem_granules_view *g, size_t i, void *ctx),
                                     void *ctx)
{
    dem_granules_view view = dem_world_granules(w);
    size_t out = 0;
    for (size_t i = 0; i < w->n; ++i) {
        if (!keep(&view, i, ctx)) continue;
        w->pos[out] = w->pos[i], w->vel[out] = w->vel[i], w->omg[out] = w->omg[i];
        w->frc[out] = w->frc[i], w->trq[out] = w->trq[i];
        w->rad[out] = w->rad[i], w->mass[out] = w->mass[i], w->inertia[out] = w->inertia[i];
        w->inv_mass[out] = w->inv_mass[i], w->inv_inertia[out] = w->inv_inertia[i], w->id[out] = w->id[i];
        memmove(w->acc + 6 * out, w->acc + 6 * i, 6 * sizeof *w->acc);
        w->fixed[out] = w->fixed[i];
        for (int k = 0; k < w->n_walls; ++k) {
            size_t hl = (size_t)w->walls[k].hist_len;
            memmove(w->walls[k].hist + out * hl, w->walls[k].hist + i * hl, hl * sizeof(double));
        }
        out++;
    }
    w->n = out;
    w->n_fixed = 0;
    for (size_t i = 0; i < out; ++i) w->n_fixed += w->fixed[i];
    invalidate(w);
    w->prepared = 0;
    return DEM_OK;
}

// Not checked for finiteness: a fault can be injected this way (the first
// step reports it against its granule).
dem_status dem_world_set_granule_velocity(dem_world *w, size_t i, dem_vec3 velocity, dem_vec3 omega)
{
    if (i >= w->n) return dem_world_set_error(w, "no granule %zu (the world has %zu)", i, w->n), DEM_ERR_INVALID;
    w->vel[i] = velocity;
    w->omg[i] = omega;
    w->forces_valid = 0;
    return DEM_OK;
}

dem_status dem_world_set_granule_fixed(dem_world *w, size_t i, int fixed)
{
    if (i >= w->n) return dem_world_set_error(w, "no granule %zu (the world has %zu)", i, w->n), DEM_ERR_INVALID;
    const unsigned char f = fixed != 0;
    w->n_fixed += (size_t)f - (size_t)w->fixed[i];
    w->fixed[i] = f;
    if (f) w->vel[i] = w->omg[i] = dem_v3(0, 0, 0);
    w->forces_valid = 0;
    w->prepared = 0; // the integration is decided again (implicit springs cannot hold a granule)
    return DEM_OK;
}

int dem_world_granule_fixed(const dem_world *w, size_t i) { return i < w->n && w->fixed[i]; }

dem_status dem_world_freeze(dem_world *w)
{
    for (size_t i = 0; i < w->n; ++i) w->vel[i] = w->omg[i] = dem_v3(0, 0, 0);
    w->forces_valid = 0;
    return DEM_OK;
}

dem_granules_view dem_world_granules(const dem_world *w)
{
    return (dem_granules_view){w->n,   w->pos,  w->vel,     w->omg, w->frc, w->trq,
                               w->rad, w->mass, w->inertia, w->id};
}

double dem_world_time(const dem_world *w) { return w->time; }
uint64_t dem_world_particle_steps(const dem_world *w) { return w->particle_steps; }
double dem_world_dt(const dem_world *w) { return w->dt; }
double dem_world_dt_limit(const dem_world *w) { return w->dt_limit; }
int dem_world_implicit_springs(const dem_world *w) { return w->implicit_springs; }
int dem_world_threads(const dem_world *w) { return dem_world_team(w); }

dem_status dem_world_set_threads(dem_world *w, int threads)
{
    if (threads < 0) return dem_world_set_error(w, "threads = %d: must be >= 0", threads), DEM_ERR_INVALID;
    w->threads = threads;
    return DEM_OK;
}
double dem_world_implicit_iterations(const dem_world *w)
{
    return w->imp_stats.solves ? (double)w->imp_stats.iterations / (double)w->imp_stats.solves : 0.0;
}
unsigned dem_world_features(const dem_world *w)
{
    unsigned f = w->features;
    for (int k = 0; k < w->n_walls; ++k) f |= w->walls[k].features;
    return f;
}
const char *dem_world_error(const dem_world *w) { return w->err; }
const char *dem_world_dt_report(const dem_world *w) { return w->dt_report; }

// The law, named only where it is not the default, so that a linear scene's
// description (and the result.json that carries it) stays as it was.
static const char *law_note(const dem_contact_params *p)
{
    return p->law == DEM_LAW_HERTZ_MINDLIN ? ", law hertz_mindlin" : "";
}

void dem_world_describe_features(const dem_world *w, char *buf, size_t len)
{
    unsigned f = w->features;
    int used = snprintf(buf, len, "granule-granule: damping %s (%s), tangential %s, rolling %s%s; periodic axis %s",
                        f & DEM_FEAT_DAMPING ? "on" : "off", dem_damping_mode_name(w->def.granule.damping),
                        f & DEM_FEAT_TANGENTIAL ? "on" : "off", f & DEM_FEAT_ROLLING ? "on" : "off",
                        law_note(&w->def.granule),
                        f & DEM_FEAT_PERIODIC ? (const char *[]){"x", "y", "z"}[w->def.periodic_axis] : "off");
    for (int k = 0; k < w->n_walls && used > 0 && (size_t)used < len; ++k) {
        const dem_wall *wl = &w->walls[k];
        used += snprintf(buf + used, len - used, "; wall %s (%s%s): damping %s, tangential %s, rolling %s%s",
                         wl->name, (const char *[]){"plane", "disc", "cylinder"}[wl->def.kind],
                         wl->def.spin != 0 || wl->translating ? ", moving" : "", wl->features & DEM_FEAT_DAMPING ? "on" : "off",
                         wl->features & DEM_FEAT_TANGENTIAL ? "on" : "off",
                         wl->features & DEM_FEAT_ROLLING ? "on" : "off", law_note(&wl->def.contact));
    }
}
