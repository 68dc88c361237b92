// SPDX-License-Identifier: MIT
// The silo discharge benchmark (Appendix A.2, Table A.2).
#include "exp_silo.h"

#include <cyaml/cyaml.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "exp_contact_rules.h"
#include "exp_plot.h"
#include "exp_result.h"
#include "exp_yaml.h"

exp_silo_def exp_default_silo_def(void)
{
    exp_silo_def d;
    memset(&d, 0, sizeof d);
    d.gsd = dem_gsd_lognormal(1.0, 1.1, 2.0); // Table A.2: d50 = 1 m, σ_geo = 1.1
    d.density = 500;
    // Table A.2: k_n = k_s = 50 000 N/m, k_r = 0, ξ = 0, μ_s = 0.5, μ_r = 0.
    d.granule = (dem_contact_params){.k_n = 50000, .k_s = 50000, .mu_s = 0.5, .damping = EXP_DAMPING_DEFAULT};
    d.wall = d.granule;
    d.wall.k_n = d.wall.k_s = 100000;
    d.n_granules = 200;
    d.silo_radius = 6, d.orifice_radius = 2.95, d.plate_z = 2.5, d.plate_sphere_radius = 0.5;
    d.dt = 1e-3, d.duration = 120, d.sample_interval = 0.1;
    d.fill_xi = 0.5, d.fill_max_time = 20;
    d.seed = 1;
    return d;
}

int exp_silo_check(const exp_silo_def *d, char *msg, size_t len)
{
    char sub[256];
    if (dem_gsd_check(&d->gsd, sub, sizeof sub)) return exp_fail(msg, len, "%s", sub);
    if (!(d->density > 0)) return exp_fail(msg, len, "density = %g: must be > 0", d->density);
    if (dem_contact_params_check(&d->granule, sub, sizeof sub)) return exp_fail(msg, len, "granule_contact.%s", sub);
    if (dem_contact_params_check(&d->wall, sub, sizeof sub)) return exp_fail(msg, len, "wall_contact.%s", sub);
    if (d->n_granules < 1 || d->n_granules > 100000)
        return exp_fail(msg, len, "n_granules = %zu: must be in [1, 100000]", d->n_granules);
    double a = d->plate_sphere_radius, dmin = dem_gsd_min_diameter(&d->gsd);
    if (!(a > 0 && a < 0.5 * dmin / 0.22))
        return exp_fail(msg, len, "plate_sphere_radius = %g: must be > 0 and small enough that the plate's holes "
                                  "(0.22 of it) pass no granule", a);
    if (!(d->orifice_radius > dem_gsd_max_diameter(&d->gsd)))
        return exp_fail(msg, len, "orifice_radius = %g: must exceed the largest diameter", d->orifice_radius);
    if (!(d->silo_radius > d->orifice_radius + 2 * a))
        return exp_fail(msg, len, "silo_radius = %g: must exceed orifice_radius + 2 plate_sphere_radius", d->silo_radius);
    if (!(d->plate_z > 2 * a + dem_gsd_max_diameter(&d->gsd)))
        return exp_fail(msg, len, "plate_z = %g: the vessel below the plate is too shallow", d->plate_z);
    if (!(d->dt > 0)) return exp_fail(msg, len, "dt = %g: must be > 0", d->dt);
    if (!(d->duration > 0)) return exp_fail(msg, len, "duration = %g: must be > 0", d->duration);
    if (!(d->sample_interval >= d->dt)) return exp_fail(msg, len, "sample_interval = %g: must be >= dt", d->sample_interval);
    if (!(d->fill_xi >= 0 && d->fill_xi <= 1)) return exp_fail(msg, len, "fill_xi = %g: must be in [0, 1]", d->fill_xi);
    return 0;
}

void exp_silo_result_free(exp_silo_result *r)
{
    if (r) free(r->series), r->series = NULL, r->n_series = 0;
}

// ---------------------------------------------------------------- geometry

static dem_world *create_vessel(const exp_silo_def *d, const dem_contact_params *gg, const dem_contact_params *gw,
                                char *err, size_t len)
{
    double r = d->silo_radius;
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(0, 0, -9.81);
    def.granule = *gg;
    def.dt = d->dt;
    def.domain_lo = dem_v3(-1.2 * r, -1.2 * r, -2);
    def.domain_hi = dem_v3(1.2 * r, 1.2 * r, d->plate_z + 4 * (double)d->n_granules / (r * r) + 20);
    dem_world *w = dem_world_create(&def, err, len);
    if (!w) return NULL;
    dem_wall_def side = {.kind = DEM_WALL_CYLINDER, .point = {0, 0, 0}, .axis = {0, 0, 1}, .radius = r,
                         .contact = *gw, .name = "silo and vessel"};
    dem_wall_def floor = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 0, 1}, .axis = {0, 0, 1},
                          .contact = *gw, .name = "vessel floor"};
    if (dem_world_add_wall(w, &side) < 0 || dem_world_add_wall(w, &floor) < 0) {
        exp_fail(err, len, "%s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    return w;
}

// One sphere of the plate, fixed (dem_world_set_granule_fixed) at `p`: the
// engine holds it still against gravity and its contacts, as LIGGGHTS holds
// the same spheres in tests/peers/silo/in.silo by integrating only the
// flowing group. Its density is the granules' (written so in silo_initial.data);
// it enters the reduced mass of the fill's dashpot as any granule's does.
// The world is not re-sorted while the plate is built, so the granule just
// added is the last of the view.
static int add_plate_sphere(dem_world *w, const exp_silo_def *d, dem_vec3 p)
{
    if (dem_world_add_granule(w, p, dem_v3(0, 0, 0), dem_v3(0, 0, 0), d->plate_sphere_radius, d->density) < 0)
        return -1;
    return dem_world_set_granule_fixed(w, dem_world_granules(w).count - 1, 1) == DEM_OK ? 0 : -1;
}

// Rings of fixed spheres from the silo wall inwards down to radius `inner`
// (centres), 2.02 a apart radially and at least 2a along each ring, each ring
// turned by half a spacing against the previous one; a centre sphere if
// `centre`. Returns the number added, or -1.
static long add_rings(dem_world *w, const exp_silo_def *d, double outer, double inner, int centre)
{
    double a = d->plate_sphere_radius;
    long n = 0;
    int k = 0;
    for (double rho = outer; rho >= inner - 1e-9; rho -= 2.02 * a, ++k) {
        int m = (int)floor(2 * DEM_PI * rho / (2.06 * a));
        if (m < 3) break;
        for (int j = 0; j < m; ++j) {
            double phi = 2 * DEM_PI * (j + 0.5 * (k % 2)) / m;
            if (add_plate_sphere(w, d, dem_v3(rho * cos(phi), rho * sin(phi), d->plate_z))) return -1;
            n++;
        }
    }
    if (centre) {
        if (add_plate_sphere(w, d, dem_v3(0, 0, d->plate_z))) return -1;
        n++;
    }
    return n;
}

// Radius of the innermost ring of the plate: the orifice's clear radius is
// this less a.
static double plate_inner_ring(const exp_silo_def *d)
{
    double a = d->plate_sphere_radius, outer = d->silo_radius - a, rho = outer;
    while (rho - 2.02 * a - a >= d->orifice_radius - 1e-9) rho -= 2.02 * a;
    return rho;
}

// Kinetic energy of the flowing granules (ids from n_fixed on).
static void flowing_ke(const dem_world *w, size_t n_fixed, double *ket, double *ker)
{
    dem_granules_view g = dem_world_granules(w);
    *ket = *ker = 0;
    for (size_t i = 0; i < g.count; ++i) {
        if (g.id[i] < n_fixed) continue;
        *ket += 0.5 * g.mass[i] * dem_v3_norm2(g.velocity[i]);
        *ker += 0.5 * g.inertia[i] * dem_v3_norm2(g.omega[i]);
    }
}

// Fill: granules on a lattice above the closed plate, settled with a dashpot.
static dem_world *fill(const exp_silo_def *d, exp_progress_fn progress, void *ctx, char *err, size_t len)
{
    dem_contact_params gg = d->granule, gw = d->wall;
    gg.xi = gw.xi = d->fill_xi;
    dem_world *w = create_vessel(d, &gg, &gw, err, len);
    if (!w) return NULL;
    double a = d->plate_sphere_radius, inner = plate_inner_ring(d);
    long plate = add_rings(w, d, d->silo_radius - a, 0, 1); // closed: the gate fills the orifice
    (void)inner;
    double *diam = malloc(d->n_granules * sizeof *diam);
    if (plate < 0 || !diam || dem_gsd_sample(&d->gsd, d->seed, d->n_granules, diam)) {
        exp_fail(err, len, "silo fill: %s", plate < 0 ? dem_world_error(w) : "cannot sample sizes");
        free(diam), dem_world_destroy(w);
        return NULL;
    }
    double pitch = 1.03 * dem_gsd_max_diameter(&d->gsd), reach = d->silo_radius - 0.55 * pitch;
    size_t placed = 0;
    for (int layer = 0; placed < d->n_granules; ++layer) {
        double z = d->plate_z + a + 0.55 * pitch + layer * pitch;
        for (double x = -reach; x <= reach && placed < d->n_granules; x += pitch)
            for (double y = -reach; y <= reach && placed < d->n_granules; y += pitch) {
                if (x * x + y * y > reach * reach) continue;
                // A small sideways jitter (deterministic) so layers do not stack in columns.
                double jx = 0.05 * pitch * sin(1.7 * (double)placed), jy = 0.05 * pitch * cos(2.3 * (double)placed);
                if (dem_world_add_granule(w, dem_v3(x + jx, y + jy, z), dem_v3(0, 0, 0), dem_v3(0, 0, 0),
                                          0.5 * diam[placed], d->density) < 0) {
                    exp_fail(err, len, "silo fill: %s", dem_world_error(w));
                    free(diam), dem_world_destroy(w);
                    return NULL;
                }
                placed++;
            }
    }
    free(diam);
    // Settle until the flowing granules' kinetic energy is below 1e-4 of
    // their weight times d50 (or fill_max_time).
    double weight = (double)d->n_granules * d->density * DEM_PI / 6 * pow(d->gsd.median_diameter, 3) * 9.81;
    for (double t = 0; t < d->fill_max_time; t += 0.5) {
        if (dem_world_step(w, (uint64_t)(0.5 / d->dt + 0.5)) != DEM_OK) {
            exp_fail(err, len, "silo fill: %s", dem_world_error(w));
            dem_world_destroy(w);
            return NULL;
        }
        double ket, ker;
        flowing_ke(w, (size_t)plate, &ket, &ker);
        if (progress) progress("fill", dem_world_time(w), d->n_granules, ctx);
        if (ket + ker < 1e-4 * weight * d->gsd.median_diameter) break;
    }
    return w;
}

dem_world *exp_silo_prepare(const exp_silo_def *d, exp_progress_fn progress, void *ctx, size_t *plate_spheres,
                            char *err, size_t len)
{
    if (len) err[0] = '\0';
    if (exp_silo_check(d, err, len)) return NULL;
    dem_world *f = fill(d, progress, ctx, err, len);
    if (!f) return NULL;
    dem_world *w = create_vessel(d, &d->granule, &d->wall, err, len);
    if (!w) return dem_world_destroy(f), NULL;
    long plate = add_rings(w, d, d->silo_radius - d->plate_sphere_radius, plate_inner_ring(d), 0);
    // The settled granules, in id order, at rest, without contact history.
    dem_granules_view g = dem_world_granules(f);
    size_t n_fixed_fill = g.count - d->n_granules, added = 0;
    size_t *order = malloc(g.count * sizeof *order);
    if (plate < 0 || !order) {
        exp_fail(err, len, "silo: %s", plate < 0 ? dem_world_error(w) : "out of memory");
        free(order), dem_world_destroy(f), dem_world_destroy(w);
        return NULL;
    }
    for (size_t i = 0; i < g.count; ++i) order[g.id[i]] = i;
    for (size_t k = n_fixed_fill; k < g.count; ++k) {
        size_t i = order[k];
        if (g.position[i].z < d->plate_z) continue; // fell through a hole while filling: not part of the fill
        if (dem_world_add_granule(w, g.position[i], dem_v3(0, 0, 0), dem_v3(0, 0, 0), g.radius[i], d->density) < 0) break;
        added++;
    }
    free(order);
    dem_world_destroy(f);
    if (added == 0) {
        exp_fail(err, len, "silo: no granule left in the silo after filling: %s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    *plate_spheres = (size_t)plate;
    return w;
}

dem_status exp_silo_discharge(dem_world *w, const exp_silo_def *d, size_t plate_spheres, exp_progress_fn progress,
                              void *ctx, exp_silo_result *out)
{
    memset(out, 0, sizeof *out);
    dem_status st = dem_world_prepare(w);
    if (st != DEM_OK) return st;
    size_t cap = (size_t)(d->duration / d->sample_interval + 2.5);
    out->series = malloc(cap * sizeof *out->series);
    if (!out->series) return DEM_ERR_NOMEM;
    out->plate_spheres = plate_spheres;
    out->granules = dem_world_granules(w).count - plate_spheres;
    uint64_t per = (uint64_t)(d->sample_interval / d->dt + 0.5), total = (uint64_t)(d->duration / d->dt + 0.5), done = 0;
    double t0 = dem_world_time(w);
    while (1) {
        exp_silo_sample *s = &out->series[out->n_series++];
        dem_diagnostics dg = dem_world_diagnose(w);
        dem_granules_view g = dem_world_granules(w);
        s->t = dem_world_time(w) - t0;
        s->contacts = dg.contacts;
        s->wall_contacts = dg.wall_contacts;
        flowing_ke(w, plate_spheres, &s->ke_translational, &s->ke_rotational);
        s->discharged = 0, s->discharged_mass = 0;
        for (size_t i = 0; i < g.count; ++i)
            if (g.id[i] >= plate_spheres && g.position[i].z < d->plate_z - d->plate_sphere_radius)
                s->discharged++, s->discharged_mass += g.mass[i];
        if (done >= total || out->n_series >= cap) break;
        uint64_t n = total - done < per ? total - done : per;
        st = dem_world_step(w, n);
        done += n;
        if (st != DEM_OK) break;
        if (progress) progress("discharge", s->t, out->granules, ctx);
    }
    out->particle_steps = (unsigned long long)done * dem_world_granules(w).count;
    return st;
}

// ------------------------------------------------------------------ output

int exp_silo_write_liggghts_data(const char *path, const dem_world *w, const exp_silo_def *d, size_t plate_spheres,
                                 char *err, size_t len)
{
    char tmp[1200];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) return exp_fail(err, len, "cannot write '%s': %s", tmp, strerror(errno));
    dem_granules_view g = dem_world_granules(w);
    double r = d->silo_radius;
    fprintf(f, "LIGGGHTS data file: silo discharge at t = 0 (granucal exp_silo; type 1 flowing, 2 plate)\n\n");
    fprintf(f, "%zu atoms\n3 atom types\n\n", g.count);
    fprintf(f, "%.6f %.6f xlo xhi\n%.6f %.6f ylo yhi\n%.6f %.6f zlo zhi\n\nAtoms\n\n", -1.2 * r, 1.2 * r, -1.2 * r, 1.2 * r,
            -2.0, d->plate_z + 4 * (double)d->n_granules / (r * r) + 20);
    // atom_style granular: atom-ID atom-type diameter density x y z
    for (size_t i = 0; i < g.count; ++i) {
        int plate = g.id[i] < plate_spheres;
        fprintf(f, "%llu %d %.17g %.17g %.17g %.17g %.17g\n", (unsigned long long)g.id[i] + 1, plate ? 2 : 1,
                2 * g.radius[i], d->density, g.position[i].x, g.position[i].y, g.position[i].z);
    }
    if (fclose(f) != 0 || rename(tmp, path) != 0) return exp_fail(err, len, "cannot write '%s'", path);
    return 0;
}

int exp_silo_write_series(const exp_silo_result *r, const char *csv_path, const char *png_prefix, char *err, size_t len)
{
    char tmp[1200];
    snprintf(tmp, sizeof tmp, "%s.tmp", csv_path);
    FILE *f = fopen(tmp, "w");
    if (!f) return exp_fail(err, len, "cannot write '%s': %s", tmp, strerror(errno));
    fprintf(f, "t_s,contacts,wall_contacts,ke_translational_J,ke_rotational_J,ke_total_J,discharged,discharged_mass_kg\n");
    for (size_t k = 0; k < r->n_series; ++k) {
        const exp_silo_sample *s = &r->series[k];
        fprintf(f, "%.4f,%zu,%zu,%.6g,%.6g,%.6g,%zu,%.6g\n", s->t, s->contacts, s->wall_contacts, s->ke_translational,
                s->ke_rotational, s->ke_translational + s->ke_rotational, s->discharged, s->discharged_mass);
    }
    if (fclose(f) != 0 || rename(tmp, csv_path) != 0) return exp_fail(err, len, "cannot write '%s'", csv_path);
    if (!png_prefix) return 0;
    size_t n = r->n_series;
    double *t = malloc((n + 1) * sizeof *t), *c = malloc((n + 1) * sizeof *c), *ke = malloc((n + 1) * sizeof *ke);
    if (!t || !c || !ke) return free(t), free(c), free(ke), exp_fail(err, len, "out of memory");
    for (size_t k = 0; k < n; ++k)
        t[k] = r->series[k].t, c[k] = (double)r->series[k].contacts,
        ke[k] = r->series[k].ke_translational + r->series[k].ke_rotational;
    char path[1200];
    exp_plot_series s = {.n = n, .x = t, .y = c, .label = "granucal", .rgb = {0.12, 0.47, 0.71}};
    exp_plot_axes ax = {.title = "Silo discharge: contacts (Fig. A.4)", .xlabel = "t (s)", .ylabel = "contacts"};
    snprintf(path, sizeof path, "%scontacts.png", png_prefix);
    int rc = exp_plot_png(path, &ax, 1, &s, 900, 500, err, len);
    s.y = ke;
    exp_plot_axes ax2 = {.title = "Silo discharge: kinetic energy (Fig. A.5)", .xlabel = "t (s)", .ylabel = "kinetic energy (J)",
                         .log_y = 1};
    snprintf(path, sizeof path, "%skinetic_energy.png", png_prefix);
    if (!rc) rc = exp_plot_png(path, &ax2, 1, &s, 900, 500, err, len);
    free(t), free(c), free(ke);
    return rc;
}

// ------------------------------------------------------------ config + CLI

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

static silo_yaml *load_config(const char *path, int n_sets, char **sets, exp_silo_def *d, char *err, size_t len)
{
    silo_yaml *y = NULL;
    if (exp_yaml_load(path, &silo_schema, (void **)&y, "check the keys and value types against configs/silo.yaml", err, len)) return NULL;
    int bad = 0;
    char msg[300];
    for (int k = 0; k < n_sets && !bad; ++k) bad = apply_set(y, sets[k], err, len);
    if (!bad && strcmp(y->experiment, "silo") != 0) {
        int line = exp_yaml_line_of(path, "experiment", 1);
        bad = exp_fail(err, len, "%s:%d: experiment: must be silo", path, line);
    }
    if (!bad && y->n_granules < 1) {
        int line = exp_yaml_line_of(path, "n_granules", 1);
        bad = exp_fail(err, len, "%s:%d: n_granules: %d must be >= 1", path, line, y->n_granules);
    }
    if (!bad) {
        to_def(y, d);
        if (exp_silo_check(d, msg, sizeof msg)) {
            char field[EXP_FIELD_LEN];
            const char *leaf = exp_message_field(msg, field);
            // granule_contact.k_n: the YAML key is k_n, wall_contact.k_n is wall_k_n.
            char key[64];
            snprintf(key, sizeof key, "%s%s", strncmp(field, "wall_contact", 12) == 0 ? "wall_" : "", leaf);
            int line = exp_yaml_line_of(path, key, 1);
            bad = line > 0 ? exp_fail(err, len, "%s:%d: %s: %s", path, line, key, msg)
                           : exp_fail(err, len, "%s: %s: %s", path, key, msg);
        }
    }
    if (bad) {
        exp_yaml_free(&silo_schema, y);
        return NULL;
    }
    return y;
}

static void write_json(FILE *f, const exp_silo_def *d, const exp_silo_result *r, const dem_world *w, const char *status)
{
    char effects[1024];
    dem_world_describe_features(w, effects, sizeof effects);
    const exp_silo_sample *last = r->n_series ? &r->series[r->n_series - 1] : NULL;
    // Time at which half and 90 % of the granules were below the plate.
    double t50 = NAN, t90 = NAN;
    for (size_t k = 0; k < r->n_series; ++k) {
        if (isnan(t50) && r->series[k].discharged * 2 >= r->granules) t50 = r->series[k].t;
        if (isnan(t90) && r->series[k].discharged * 10 >= r->granules * 9) t90 = r->series[k].t;
    }
    char s50[32], s90[32]; // JSON has no NaN: null when not reached
    snprintf(s50, sizeof s50, isnan(t50) ? "null" : "%.3f", t50);
    snprintf(s90, sizeof s90, isnan(t90) ? "null" : "%.3f", t90);
    fprintf(f,
            "{\"experiment\": \"silo\", \"status\": \"%s\", \"granules\": %zu, \"plate_spheres\": %zu, \"seed\": %llu, "
            "\"dt_s\": %.6g, \"simulated_time_s\": %.4f, \"fill_time_s\": %.3f, \"wall_time_s\": %.2f, "
            "\"particle_steps\": %llu, \"orifice_clear_radius_m\": %.3f, \"final_contacts\": %zu, \"final_ke_J\": %.6g, \"discharged_final\": %zu, "
            "\"t_half_discharged_s\": %s, \"t_90_discharged_s\": %s, \"effects\": \"%s\"}\n",
            status, r->granules, r->plate_spheres, (unsigned long long)d->seed, dem_world_dt(w), last ? last->t : 0.0,
            r->fill_time_s, r->wall_time_s, r->particle_steps, plate_inner_ring(d) - d->plate_sphere_radius, last ? last->contacts : 0,
            last ? last->ke_translational + last->ke_rotational : 0.0, last ? last->discharged : 0, s50, s90, effects);
}

int exp_silo_simulate(const char *path, int n_sets, char **sets, const char *out)
{
    char err[1400], dir[1024], p[1200];
    exp_silo_def d;
    silo_yaml *y = load_config(path, n_sets, sets, &d, err, sizeof err);
    if (!y) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_yaml_free(&silo_schema, y);
    snprintf(dir, sizeof dir, "%s", out ? out : "results/runs/silo");
    if (exp_mkdirs(dir, err, sizeof err)) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    exp_progress_printer ps = {.scene = "silo", .start = exp_wall_seconds()};
    size_t plate = 0;
    dem_world *w = exp_silo_prepare(&d, exp_print_progress, &ps, &plate, err, sizeof err);
    if (!w) return fprintf(stderr, "granucal simulate: %s\n", err), 1;
    double fill_wall = exp_wall_seconds() - ps.start;
    if (dem_world_prepare(w) != DEM_OK) {
        fprintf(stderr, "granucal simulate: silo: %s\n", dem_world_error(w));
        dem_world_destroy(w);
        return 1;
    }
    snprintf(p, sizeof p, "%s/silo_initial.data", dir);
    int bad = exp_silo_write_liggghts_data(p, w, &d, plate, err, sizeof err);
    fprintf(stderr, "granucal simulate: silo filled (%zu granules, %zu plate spheres) in %.0f s; %s\n",
            dem_world_granules(w).count - plate, plate, fill_wall, dem_world_dt_report(w));
    exp_silo_result r;
    double t0 = exp_wall_seconds();
    dem_status st = exp_silo_discharge(w, &d, plate, exp_print_progress, &ps, &r);
    r.wall_time_s = exp_wall_seconds() - t0;
    r.fill_time_s = fill_wall;
    if (st != DEM_OK) fprintf(stderr, "granucal simulate: silo: %s\n", dem_world_error(w));
    char prefix[1100];
    snprintf(p, sizeof p, "%s/series.csv", dir);
    snprintf(prefix, sizeof prefix, "%s/", dir);
    bad = bad || exp_silo_write_series(&r, p, prefix, err, sizeof err);
    if (!bad) bad = exp_result_write_h5(dir, w, err, sizeof err);
    const char *status = st == DEM_OK ? "ok" : "failed";
    if (!bad) {
        char tmp[1300];
        snprintf(p, sizeof p, "%s/result.json", dir);
        snprintf(tmp, sizeof tmp, "%s.tmp", p);
        FILE *f = fopen(tmp, "w");
        if (f) write_json(f, &d, &r, w, status);
        bad = !f || fclose(f) != 0 || rename(tmp, p) != 0;
        if (bad) snprintf(err, sizeof err, "cannot write '%s'", p);
    }
    if (bad) fprintf(stderr, "granucal simulate: %s\n", err);
    write_json(stdout, &d, &r, w, status);
    exp_silo_result_free(&r);
    dem_world_destroy(w);
    return bad || st != DEM_OK;
}
