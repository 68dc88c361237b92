// SPDX-License-Identifier: MIT
// A world's stability limits (dem_stability.h): its contact network, or the
// densest cluster of its lightest granules, handed to the pure analysis of
// dem_stability.c.
#include <stdint.h>
#include <stdlib.h>

#include "dem_lists_internal.h"
#include "dem_stability.h"

static int switches(const dem_contact_params *p) { return p->xi > 0 && p->damping != DEM_DAMPING_ALWAYS; }

// Whether any dashpot of the world is switched on and off within a contact.
static int dashpot_switches(const dem_world *w)
{
    int s = switches(&w->def.granule);
    for (int k = 0; k < w->n_walls; ++k) s |= switches(&w->walls[k].def.contact);
    return s;
}

// The world's touching pairs, in the neighbour list's order, then its wall
// contacts, wall by wall; their count (0 also when out of memory).
static size_t collect_contacts(const dem_world *w, dem_network_contact **out)
{
    size_t cap = w->nl.count + w->n * (size_t)w->n_walls + 1, m = 0;
    dem_network_contact *c = malloc(cap * sizeof *c);
    *out = c;
    if (!c) return 0;
    for (size_t i = 0; i < w->n; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) {
            size_t j = w->nl.j[k];
            dem_vec3 d = dem_world_min_image(w, dem_v3_sub(w->pos[j], w->pos[i]));
            double dist = dem_v3_norm(d), h = w->rad[i] + w->rad[j] - dist;
            if (!(h > 0) || dist <= 0) continue;
            c[m++] = (dem_network_contact){i, j, dem_v3_scale(d, 1 / dist), w->rad[i] - 0.5 * w->lever_factor * h,
                                           w->rad[j] - 0.5 * w->lever_factor * h,
                                           w->rad[i] * w->rad[j] / (w->rad[i] + w->rad[j]),
                                           1 / (w->inv_mass[i] + w->inv_mass[j]), &w->def.granule, h};
        }
    for (int k = 0; k < w->n_walls; ++k)
        for (size_t i = 0; i < w->n; ++i) {
            dem_wall_touch t = dem_wall_geometry(&w->walls[k].def, w->pos[i], w->rad[i]);
            double h = t.overlap;
            dem_vec3 n = t.normal;
            if (!(h > 0)) continue;
            c[m++] = (dem_network_contact){i, SIZE_MAX, n, w->rad[i] - w->lever_factor * h, 0, w->rad[i], w->mass[i],
                                           &w->walls[k].def.contact, h};
        }
    return m;
}

static dem_integration integration_of(const dem_world *w)
{
    return (dem_integration){w->def.implicit_damping, w->implicit_springs, dashpot_switches(w)};
}

static int hertzian(const dem_world *w) { return w->def.granule.law == DEM_LAW_HERTZ_MINDLIN; }

// The reference step of the granules' law: eq. 14's sqrt(m_min/k_n), or
// the Rayleigh time of a Hertz–Mindlin law.
static double reference_step(const dem_world *w)
{
    if (hertzian(w)) return dem_rayleigh_time(&w->def.granule, dem_granules_min_mass(w), dem_granules_min_radius(w));
    return sqrt(dem_granules_min_mass(w) / w->def.granule.k_n);
}

dem_stability dem_stability_current(dem_world *w)
{
    dem_stability st = {0};
    st.dt_crit = w->n ? reference_step(w) : 0;
    if (!w->list_valid && w->n) {
        if (w->skin <= 0) w->skin = 0.4 * dem_granules_min_radius(w);
        if (dem_lists_rebuild(w)) return st;
    }
    dem_network_contact *c = NULL;
    const dem_contact_network net = {w->n, w->mass, w->inertia, collect_contacts(w, &c), c};
    const dem_integration how = integration_of(w);
    st = dem_stability_of_network(&net, &how, st.dt_crit);
    free(c);
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

dem_stability dem_stability_apriori(const dem_world *w)
{
    const dem_stability none = {0};
    if (!w->n) return none;
    double m_min = dem_granules_min_mass(w), r_min = dem_granules_min_radius(w);
    // The granules' law decides; the walls' moduli do not enter a Rayleigh time.
    if (hertzian(w)) return dem_stability_rayleigh(&w->def.granule, m_min, r_min);
    double dt_crit = sqrt(m_min / w->def.granule.k_n);
    dem_contact_params p = stiffest(w);
    // Sticking springs are the worst case: friction never truncates them here.
    p.mu_s = p.mu_r = 1e300;
    char msg[256];
    if (dem_contact_params_check(&p, msg, sizeof msg)) return none;
    // The cluster's own dashpots switch as the stiffest parameters' do.
    const dem_integration how = {w->def.implicit_damping, w->implicit_springs, switches(&p)};
    return dem_stability_fcc(&p, w->lever_factor, &how, m_min, r_min, dt_crit);
}
