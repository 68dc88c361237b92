// SPDX-License-Identifier: MIT
// Power iteration on the linearised contact operators of a contact network;
// see dem_stability.h. A pure function of the network: no world here.
#include "dem_stability.h"

#include <float.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_linear_contact_internal.h" // the contact operator K of apply()

#define POWER_ITERATIONS 200
#define LATTICE_CELLS 4

// Generalised coordinates per granule: 3 translations, 3 rotations, both
// scaled by sqrt(mass) or sqrt(inertia) so the operators are symmetric.
typedef struct dof6 {
    dem_vec3 u, t;
} dof6;

// Which linearised operator `apply` forms.
enum op_kind {
    OP_STIFFNESS = 0, // K: normal, sticking tangential and rolling springs
    OP_DASHPOT = 1,   // C: normal dashpots
    OP_NORMAL = 2,    // K_n: normal springs alone
};

// y = K x, C x or K_n x, mass-normalised.
static void apply(const dem_contact_network *net, const dof6 *x, dof6 *y, enum op_kind op)
{
    const int dashpot = op == OP_DASHPOT;
    const double *mass = net->mass, *inertia = net->inertia;
    memset(y, 0, net->granules * sizeof *y);
    for (size_t k = 0; k < net->count; ++k) {
        const dem_network_contact *g = &net->contact[k];
        size_t i = g->i, j = g->j;
        int wall = j == SIZE_MAX;
        double si = 1 / sqrt(mass[i]), ri = 1 / sqrt(inertia[i]);
        double sj = wall ? 0 : 1 / sqrt(mass[j]), rj = wall ? 0 : 1 / sqrt(inertia[j]);
        dem_vec3 ui = dem_v3_scale(x[i].u, si), ti = dem_v3_scale(x[i].t, ri);
        dem_vec3 uj = wall ? dem_v3(0, 0, 0) : dem_v3_scale(x[j].u, sj);
        dem_vec3 tj = wall ? dem_v3(0, 0, 0) : dem_v3_scale(x[j].t, rj);
        dem_vec3 du = dem_v3_sub(ui, uj), n = g->n;
        dem_vec3 f, torque_i = dem_v3(0, 0, 0), torque_j = dem_v3(0, 0, 0);
        // The law's tangent stiffnesses at this contact's overlap (the
        // linear law's are its constants k_n, k_s, k_r and eq. 4's dashpot).
        const dem_contact_stiffness ks =
            dem_contact_model_of(g->p->law)->stiffness_at(g->p, g->overlap, g->rstar, g->mstar);
        if (dashpot) {
            f = dem_v3_scale(n, ks.gamma * dem_v3_dot(du, n));
        } else if (op == OP_NORMAL) {
            f = dem_v3_scale(n, ks.k_n * dem_v3_dot(du, n));
        } else { // every spring sticking, at its own stiffness
            const dem_linear_contact l = {.n = n, .ai = g->ai, .aj = g->aj, .rs = g->rstar, .kn = ks.k_n,
                                          .kt = ks.k_t, .kr = ks.k_r, .c = 1.0};
            const dem_linear_response r = dem_linear_contact_apply(&l, du, ti, tj);
            f = r.f, torque_i = r.torque_i, torque_j = r.torque_j;
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
static double largest_eigenvalue(const dem_contact_network *net, enum op_kind op)
{
    size_t n = net->granules;
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
        apply(net, x, y, op);
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

// Implicit springs (dem_world_def.implicit_springs): the limit is the normal
// springs' own, ω_n·Δt < 2 (proof in dem_stability.h); the sticking
// tangential and rolling springs and the dashpots do not enter it.
static dem_stability limit_implicit_springs(const dem_contact_network *net, const dem_integration *how, double dt_crit)
{
    dem_stability st = {0};
    st.dt_crit = dt_crit;
    const size_t m = net->count;
    double k = m ? largest_eigenvalue(net, OP_NORMAL) : 0;
    // A dashpot switched by the sign of v_rel,n (eq. 4 read as approaching or
    // separating; no_tension switches it off at zero force) pumps the mode
    // once it turns by more than 120° a step: ω_n·Δt < √3, for any ξ
    // (measured on one contact; 2 for a dashpot that never switches).
    const double bound = how->dashpot_switches ? sqrt(3.0) : 2.0;
    st.omega_max = sqrt(k > 0 ? k : 0);
    st.dt_limit = st.omega_max > 0 ? bound / st.omega_max : DBL_MAX;
    snprintf(st.why, sizeof st.why, "%zu contacts; implicit springs: %s/omega_n, omega_n = %.4g rad/s", m,
             bound < 2.0 ? "sqrt(3)" : "2", st.omega_max);
    return st;
}

dem_stability dem_stability_of_network(const dem_contact_network *net, const dem_integration *how, double dt_crit)
{
    if (how->implicit_springs) return limit_implicit_springs(net, how, dt_crit);
    dem_stability st = {0};
    st.dt_crit = dt_crit;
    const size_t m = net->count;
    // With the implicit dashpot the dashpot leaves the limit: ω·dt < 2.
    double k = m ? largest_eigenvalue(net, OP_STIFFNESS) : 0;
    double d = m && !how->implicit_damping ? largest_eigenvalue(net, OP_DASHPOT) : 0;
    st.omega_max = sqrt(k > 0 ? k : 0);
    st.damping_max = d > 0 ? d : 0;
    double denom = sqrt(4 * k + d * d) + d;
    st.dt_limit = denom > 0 ? 4.0 / denom : DBL_MAX;
    snprintf(st.why, sizeof st.why, "%zu contacts: highest frequency %.4g rad/s, dashpot rate %.4g 1/s", m,
             st.omega_max, st.damping_max);
    return st;
}

// The cluster's granules: LATTICE_CELLS³ cells of 4, nearest neighbours at
// 2R(1 − 1e-6), so every one of them is in contact. Masses and inertias in
// the arithmetic of dem_world_add_granule, the granules in the order the
// cluster was once added to a world in: the limit is bitwise that of such a
// world's network.
#define FCC_GRANULES (4 * LATTICE_CELLS * LATTICE_CELLS * LATTICE_CELLS)
typedef struct fcc_cluster {
    dem_vec3 pos[FCC_GRANULES];
    double mass[FCC_GRANULES], inertia[FCC_GRANULES], inv_mass[FCC_GRANULES];
} fcc_cluster;

static void fcc_place(fcc_cluster *c, double radius, double density)
{
    double a = 2 * radius * (1 - 1e-6) * sqrt(2.0);
    const double basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
    size_t i = 0;
    for (int x = 0; x < LATTICE_CELLS; ++x)
        for (int y = 0; y < LATTICE_CELLS; ++y)
            for (int z = 0; z < LATTICE_CELLS; ++z)
                for (int b = 0; b < 4; ++b, ++i) {
                    c->pos[i] = dem_v3(a * (x + basis[b][0]), a * (y + basis[b][1]), a * (z + basis[b][2]));
                    double m = density * 4.0 / 3.0 * DEM_PI * radius * radius * radius;
                    c->mass[i] = m;
                    c->inertia[i] = 0.4 * m * radius * radius; // solid sphere
                    c->inv_mass[i] = 1.0 / m;
                }
}

// The cluster's touching pairs, i < j in ascending order (as a neighbour
// list's rows, sorted by partner, give them), into out; their count.
static size_t fcc_contacts(const fcc_cluster *c, double radius, double lever_factor, const dem_contact_params *p,
                           dem_network_contact *out)
{
    size_t m = 0;
    for (size_t i = 0; i < FCC_GRANULES; ++i)
        for (size_t j = i + 1; j < FCC_GRANULES; ++j) {
            dem_vec3 d = dem_v3_sub(c->pos[j], c->pos[i]);
            double dist = dem_v3_norm(d), h = radius + radius - dist;
            if (!(h > 0) || dist <= 0) continue;
            out[m++] = (dem_network_contact){i, j, dem_v3_scale(d, 1 / dist), radius - 0.5 * lever_factor * h,
                                             radius - 0.5 * lever_factor * h, radius * radius / (radius + radius),
                                             1 / (c->inv_mass[i] + c->inv_mass[j]), p, h};
        }
    return m;
}

dem_stability dem_stability_fcc(const dem_contact_params *p, double lever_factor, const dem_integration *how,
                                double m_min, double r_min, double dt_crit)
{
    dem_stability st = {0};
    fcc_cluster *c = malloc(sizeof *c);
    dem_network_contact *contact = malloc(6 * FCC_GRANULES * sizeof *contact); // 12 each, each pair once
    if (!c || !contact) {
        free(c), free(contact);
        return st;
    }
    double density = m_min / (4.0 / 3.0 * DEM_PI * r_min * r_min * r_min);
    fcc_place(c, r_min, density);
    const dem_contact_network net = {FCC_GRANULES, c->mass, c->inertia,
                                     fcc_contacts(c, r_min, lever_factor, p, contact), contact};
    st = dem_stability_of_network(&net, how, dt_crit);
    free(c), free(contact);
    char inner[100];
    snprintf(inner, sizeof inner, "%.99s", st.why);
    snprintf(st.why, sizeof st.why, "densest cluster of the lightest granules (FCC, 12 sticking contacts; %.99s)",
             inner);
    return st;
}

// Poisson's ratio and shear modulus of the granules' material from the
// effective moduli of two equal granules: E* = E/(2(1−ν²)) and G* =
// G/(2(2−ν)) with G = E/(2(1+ν)) give G*/E* = (1−ν)/(2(2−ν)), so ν = (1 −
// 4r)/(1 − 2r) for r = G*/E*, kept within [0, 0.5]. Without G* (no
// tangential spring), ν = 0: the stiffest shear modulus, G = E*, the
// shortest Rayleigh time.
static void material_of(const dem_contact_params *p, double *nu, double *shear)
{
    const double r = p->shear_modulus / p->youngs_modulus;
    double v = p->shear_modulus > 0 ? (1 - 4 * r) / (1 - 2 * r) : 0.0;
    v = v < 0 ? 0 : v > 0.5 ? 0.5 : v;
    *nu = v;
    *shear = p->shear_modulus > 0 ? 2 * (2 - v) * p->shear_modulus : (1 - v) * p->youngs_modulus;
}

double dem_rayleigh_time(const dem_contact_params *p, double m_min, double r_min)
{
    double nu, shear;
    material_of(p, &nu, &shear);
    const double density = m_min / (4.0 / 3.0 * DEM_PI * r_min * r_min * r_min);
    return DEM_PI * r_min * sqrt(density / shear) / (0.1631 * nu + 0.8766);
}

dem_stability dem_stability_rayleigh(const dem_contact_params *p, double m_min, double r_min)
{
    dem_stability st = {0};
    st.dt_crit = dem_rayleigh_time(p, m_min, r_min);
    st.dt_limit = DEM_RAYLEIGH_FRACTION * st.dt_crit;
    snprintf(st.why, sizeof st.why, "Hertz-Mindlin: %.2g of the Rayleigh time %.4g s of the smallest granules",
             DEM_RAYLEIGH_FRACTION, st.dt_crit);
    return st;
}
