// SPDX-License-Identifier: MIT
// The silo discharge benchmark (Appendix A.2, Table A.2): the physics only.
// Its config is exp_silo_config.c, its runner (the files it writes)
// exp_silo_runner.c.
#include "exp_silo.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "exp_contact_rules.h"

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
    if (!(d->fill_max_time > 0)) return exp_fail(msg, len, "fill_max_time = %g: must be > 0", d->fill_max_time);
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

double exp_silo_orifice_clear_radius(const exp_silo_def *d) { return plate_inner_ring(d) - d->plate_sphere_radius; }

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
    double a = d->plate_sphere_radius;
    long plate = add_rings(w, d, d->silo_radius - a, 0, 1); // closed: the gate fills the orifice
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
