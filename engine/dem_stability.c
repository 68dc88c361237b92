// SPDX-License-Identifier: MIT
// Power iteration on the linearised contact operators; see dem_stability.h.
#include "dem_stability.h"

#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_world_internal.h"

#define POWER_ITERATIONS 200
#define LATTICE_CELLS 4

// Generalised coordinates per granule: 3 translations, 3 rotations, both
// scaled by sqrt(mass) or sqrt(inertia) so the operators are symmetric.
typedef struct dof6 {
    dem_vec3 u, t;
} dof6;

typedef struct contact_geo {
    size_t i, j; // j == SIZE_MAX: a wall
    dem_vec3 n;
    double ai, aj, rstar, mstar;
    const dem_contact_params *p;
} contact_geo;

static size_t collect_contacts(dem_world *w, contact_geo **out)
{
    size_t cap = w->nl.count + w->n * (size_t)w->n_walls + 1, m = 0;
    contact_geo *c = malloc(cap * sizeof *c);
    if (!c) return 0;
    for (size_t i = 0; i < w->n; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) {
            size_t j = w->nl.j[k];
            dem_vec3 d = dem_world_min_image(w, dem_v3_sub(w->pos[j], w->pos[i]));
            double dist = dem_v3_norm(d), h = w->rad[i] + w->rad[j] - dist;
            if (!(h > 0) || dist <= 0) continue;
            c[m++] = (contact_geo){i, j, dem_v3_scale(d, 1 / dist), w->rad[i] - 0.5 * w->lever_factor * h,
                                   w->rad[j] - 0.5 * w->lever_factor * h, w->rad[i] * w->rad[j] / (w->rad[i] + w->rad[j]),
                                   1 / (w->inv_mass[i] + w->inv_mass[j]), &w->def.granule};
        }
    for (int k = 0; k < w->n_walls; ++k)
        for (size_t i = 0; i < w->n; ++i) {
            dem_wall_touch t = dem_wall_geometry(&w->walls[k].def, w->pos[i], w->rad[i]);
            double h = t.overlap;
            dem_vec3 n = t.normal;
            if (!(h > 0)) continue;
            c[m++] = (contact_geo){i, SIZE_MAX, n, w->rad[i] - w->lever_factor * h, 0, w->rad[i], w->mass[i],
                                   &w->walls[k].def.contact};
        }
    *out = c;
    return m;
}

// Which linearised operator `apply` forms.
enum op_kind {
    OP_STIFFNESS = 0, // K: normal, sticking tangential and rolling springs
    OP_DASHPOT = 1,   // C: normal dashpots
    OP_NORMAL = 2,    // K_n: normal springs alone
};

// y = K x, C x or K_n x, mass-normalised.
static void apply(const dem_world *w, const contact_geo *c, size_t m, const dof6 *x, dof6 *y, enum op_kind op)
{
    const int dashpot = op == OP_DASHPOT;
    memset(y, 0, w->n * sizeof *y);
    for (size_t k = 0; k < m; ++k) {
        const contact_geo *g = &c[k];
        size_t i = g->i, j = g->j;
        int wall = j == SIZE_MAX;
        double si = 1 / sqrt(w->mass[i]), ri = 1 / sqrt(w->inertia[i]);
        double sj = wall ? 0 : 1 / sqrt(w->mass[j]), rj = wall ? 0 : 1 / sqrt(w->inertia[j]);
        dem_vec3 ui = dem_v3_scale(x[i].u, si), ti = dem_v3_scale(x[i].t, ri);
        dem_vec3 uj = wall ? dem_v3(0, 0, 0) : dem_v3_scale(x[j].u, sj);
        dem_vec3 tj = wall ? dem_v3(0, 0, 0) : dem_v3_scale(x[j].t, rj);
        dem_vec3 du = dem_v3_sub(ui, uj), n = g->n;
        dem_vec3 f, torque_i = dem_v3(0, 0, 0), torque_j = dem_v3(0, 0, 0);
        if (dashpot) {
            f = dem_v3_scale(n, 2 * g->p->xi * sqrt(g->mstar * g->p->k_n) * dem_v3_dot(du, n));
        } else if (op == OP_NORMAL) {
            f = dem_v3_scale(n, g->p->k_n * dem_v3_dot(du, n));
        } else {
            f = dem_v3_scale(n, g->p->k_n * dem_v3_dot(du, n));
            dem_vec3 slip = dem_v3_add(dem_v3_axpy(-dem_v3_dot(du, n), n, du),
                                       dem_v3_cross(dem_v3_add(dem_v3_scale(ti, g->ai), dem_v3_scale(tj, g->aj)), n));
            dem_vec3 fs = dem_v3_scale(slip, g->p->k_s); // restoring force on i is −fs
            dem_vec3 roll = dem_v3_scale(dem_v3_cross(dem_v3_sub(ti, tj), n), -g->rstar);
            dem_vec3 fr = dem_v3_scale(roll, g->p->k_r);
            f = dem_v3_add(f, fs);
            dem_vec3 ts = dem_v3_cross(n, fs), tr = dem_v3_scale(dem_v3_cross(n, fr), g->rstar);
            torque_i = dem_v3_sub(dem_v3_scale(ts, g->ai), tr);
            torque_j = dem_v3_add(dem_v3_scale(ts, g->aj), tr);
        }
        y[i].u = dem_v3_axpy(si, f, y[i].u);
        y[i].t = dem_v3_axpy(ri, torque_i, y[i].t);
        if (!wall) {
            y[j].u = dem_v3_axpy(-sj, f, y[j].u);
            y[j].t = dem_v3_axpy(rj, torque_j, y[j].t);
        }
    }
}

static double dot6(const dof6 *a, const dof6 *b, size_t n)
{
    double s = 0;
    for (size_t i = 0; i < n; ++i) s += dem_v3_dot(a[i].u, b[i].u) + dem_v3_dot(a[i].t, b[i].t);
    return s;
}

// Largest eigenvalue of a symmetric positive semi-definite operator.
static double largest_eigenvalue(const dem_world *w, const contact_geo *c, size_t m, enum op_kind op)
{
    size_t n = w->n;
    dof6 *x = malloc(n * sizeof *x), *y = malloc(n * sizeof *y);
    if (!x || !y) {
        free(x), free(y);
        return NAN;
    }
    uint64_t s = 0x9E3779B97F4A7C15ull; // fixed start: the estimate is reproducible
    double *xs = (double *)x;
    for (size_t k = 0; k < 6 * n; ++k) {
        s = s * 6364136223846793005ull + 1442695040888963407ull;
        xs[k] = (double)(s >> 11) / 9007199254740992.0 - 0.5;
    }
    double lambda = 0;
    for (int it = 0; it < POWER_ITERATIONS; ++it) {
        double norm = sqrt(dot6(x, x, n));
        if (norm == 0) break;
        for (size_t k = 0; k < 6 * n; ++k) xs[k] /= norm;
        apply(w, c, m, x, y, op);
        double next = dot6(x, y, n); // Rayleigh quotient
        dof6 *t = x;
        x = y, y = t, xs = (double *)x;
        if (it > 20 && fabs(next - lambda) <= 1e-6 * next) {
            lambda = next;
            break;
        }
        lambda = next;
    }
    free(x), free(y);
    return lambda;
}

static int switches(const dem_contact_params *p) { return p->xi > 0 && p->damping != DEM_DAMPING_ALWAYS; }

// Whether any dashpot of the world is switched on and off within a contact.
static int dashpot_switches(const dem_world *w)
{
    int s = switches(&w->def.granule);
    for (int k = 0; k < w->n_walls; ++k) s |= switches(&w->walls[k].def.contact);
    return s;
}

// Implicit springs (dem_world_def.implicit_springs): the limit is the normal
// springs' own, ω_n·Δt < 2 (proof in dem_stability.h); the sticking
// tangential and rolling springs and the dashpots do not enter it.
static dem_stability limit_implicit_springs(const dem_world *w, const contact_geo *c, size_t m, double dt_crit)
{
    dem_stability st = {0};
    st.dt_crit = dt_crit;
    double k = m ? largest_eigenvalue(w, c, m, OP_NORMAL) : 0;
    // A dashpot switched by the sign of v_rel,n (eq. 4 read as approaching or
    // separating; no_tension switches it off at zero force) pumps the mode
    // once it turns by more than 120° a step: ω_n·Δt < √3, for any ξ
    // (measured on one contact; 2 for a dashpot that never switches).
    const double bound = dashpot_switches(w) ? sqrt(3.0) : 2.0;
    st.omega_max = sqrt(k > 0 ? k : 0);
    st.dt_limit = st.omega_max > 0 ? bound / st.omega_max : DBL_MAX;
    snprintf(st.why, sizeof st.why, "%zu contacts; implicit springs: %s/omega_n, omega_n = %.4g rad/s", m,
             bound < 2.0 ? "sqrt(3)" : "2", st.omega_max);
    return st;
}

dem_stability dem_stability_of_network(dem_world *w, double dt_crit)
{
    dem_stability st = {0};
    st.dt_crit = dt_crit;
    if (!w->list_valid && w->n) {
        if (w->skin <= 0) w->skin = 0.4 * dem_world_min_radius(w);
        if (dem_nl_rebuild(w)) return st;
    }
    contact_geo *c = NULL;
    size_t m = collect_contacts(w, &c);
    if (w->def.implicit_springs) {
        st = limit_implicit_springs(w, c, m, dt_crit);
        free(c);
        return st;
    }
    // With the implicit dashpot the dashpot leaves the limit: ω·dt < 2.
    double k = m ? largest_eigenvalue(w, c, m, OP_STIFFNESS) : 0;
    double d = m && !w->def.implicit_damping ? largest_eigenvalue(w, c, m, OP_DASHPOT) : 0;
    free(c);
    st.omega_max = sqrt(k > 0 ? k : 0);
    st.damping_max = d > 0 ? d : 0;
    double denom = sqrt(4 * k + d * d) + d;
    st.dt_limit = denom > 0 ? 4.0 / denom : DBL_MAX;
    snprintf(st.why, sizeof st.why, "%zu contacts: highest frequency %.4g rad/s, dashpot rate %.4g 1/s", m,
             st.omega_max, st.damping_max);
    return st;
}

static dem_contact_params stiffest(const dem_world *w)
{
    dem_contact_params p = w->def.granule;
    // A granule on a wall of stiffness k_w moves like one in a pair of
    // stiffness k_w/2 between equals, so walls enter at half their stiffness.
    for (int k = 0; k < w->n_walls; ++k) {
        const dem_contact_params *q = &w->walls[k].def.contact;
        p.k_n = fmax(p.k_n, 0.5 * q->k_n);
        p.k_s = fmax(p.k_s, 0.5 * q->k_s);
        p.k_r = fmax(p.k_r, 0.5 * q->k_r);
        p.xi = fmax(p.xi, q->xi);
    }
    // A switching wall dashpot bounds the implicit-spring step like one of the granules'.
    if (dashpot_switches(w) && p.damping == DEM_DAMPING_ALWAYS) p.damping = DEM_DAMPING_APPROACHING;
    return p;
}

static void add_fcc_cluster(dem_world *lat, double radius, double density)
{
    // Nearest neighbours at 2R(1 − 1e-6): every one of them is in contact.
    double a = 2 * radius * (1 - 1e-6) * sqrt(2.0);
    const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
    for (int x = 0; x < LATTICE_CELLS; ++x)
        for (int y = 0; y < LATTICE_CELLS; ++y)
            for (int z = 0; z < LATTICE_CELLS; ++z)
                for (int b = 0; b < 4; ++b)
                    dem_world_add_granule(lat, dem_v3(a * (x + basis[b][0]), a * (y + basis[b][1]), a * (z + basis[b][2])),
                                          dem_v3(0, 0, 0), dem_v3(0, 0, 0), radius, density);
}

dem_stability dem_stability_apriori(const dem_world *w)
{
    double m_min = dem_world_min_mass(w), r_min = dem_world_min_radius(w);
    double dt_crit = sqrt(m_min / w->def.granule.k_n);
    dem_world_def def = dem_default_world_def();
    def.granule = stiffest(w);
    // Sticking springs are the worst case: friction never truncates them here.
    def.granule.mu_s = def.granule.mu_r = 1e300;
    def.lever_arm = w->def.lever_arm;
    def.implicit_damping = w->def.implicit_damping;
    def.implicit_springs = w->def.implicit_springs;
    def.domain_lo = dem_v3(-r_min, -r_min, -r_min);
    def.domain_hi = dem_v3_scale(dem_v3(1, 1, 1), 2 * r_min * (LATTICE_CELLS * 1.5 + 1));
    dem_world *lat = dem_world_create(&def, NULL, 0);
    dem_stability st = {0};
    if (!lat) return st;
    double density = m_min / (4.0 / 3.0 * DEM_PI * r_min * r_min * r_min);
    add_fcc_cluster(lat, r_min, density);
    st = dem_stability_of_network(lat, dt_crit);
    dem_world_destroy(lat);
    char inner[100];
    snprintf(inner, sizeof inner, "%.99s", st.why);
    snprintf(st.why, sizeof st.why, "densest cluster of the lightest granules (FCC, 12 sticking contacts; %.99s)",
             inner);
    return st;
}

dem_stability dem_stability_current(dem_world *w)
{
    double dt_crit = w->n ? sqrt(dem_world_min_mass(w) / w->def.granule.k_n) : 0;
    return dem_stability_of_network(w, dt_crit);
}
