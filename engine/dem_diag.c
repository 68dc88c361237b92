// SPDX-License-Identifier: MIT
// Diagnostics of the current state: contacts, coordination number, kinetic
// and elastic energy, largest overlap. Read-only; called once per output
// interval, never inside the step loop.
#include "dem_state_internal.h"

// Elastic energy of a contact at overlap h with effective radius R*: its
// normal spring (the law's, dem_contact_model.normal_energy) and its
// tangential and rolling springs at their stiffness at this overlap.
static double contact_energy(const double *hist, unsigned features, const dem_contact_params *p, double h,
                             double rstar)
{
    const dem_contact_model *law = dem_contact_model_of(p->law);
    const double k_t = law->stiffness_at(p, h, rstar, 0.0).k_t;
    double e = 0;
    int slot = 0;
    if (features & DEM_FEAT_TANGENTIAL) {
        e += 0.5 * k_t * (hist[0] * hist[0] + hist[1] * hist[1] + hist[2] * hist[2]);
        slot = 3;
    }
    if (features & DEM_FEAT_ROLLING)
        e += 0.5 * p->k_r * (hist[slot] * hist[slot] + hist[slot + 1] * hist[slot + 1] + hist[slot + 2] * hist[slot + 2]);
    return law->normal_energy(p, h, rstar) + e;
}

// Overlap of neighbour-list pair k of granule i (> 0: in contact).
static double pair_overlap(const dem_world *w, size_t i, size_t k)
{
    size_t j = w->nl.j[k];
    dem_vec3 dv = dem_world_min_image(w, dem_v3_sub(w->pos[j], w->pos[i]));
    return w->rad[i] + w->rad[j] - dem_v3_norm(dv);
}

void dem_world_contact_counts(const dem_world *w, unsigned *counts)
{
    for (size_t i = 0; i < w->n; ++i) counts[i] = 0;
    for (size_t i = 0; i < w->n && w->list_valid; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k)
            if (pair_overlap(w, i, k) > 0) counts[i]++, counts[w->nl.j[k]]++;
}

static void pair_diagnostics(const dem_world *w, dem_diagnostics *d)
{
    const dem_contact_params *p = &w->def.granule;
    int hl = w->nl.hist_len;
    for (size_t i = 0; i < w->n && w->list_valid; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) {
            size_t j = w->nl.j[k];
            double h = pair_overlap(w, i, k);
            if (!(h > 0)) continue;
            d->contacts++;
            double rmin = w->rad[i] < w->rad[j] ? w->rad[i] : w->rad[j];
            if (h / rmin > d->max_overlap_ratio) d->max_overlap_ratio = h / rmin;
            const double rstar = w->rad[i] * w->rad[j] / (w->rad[i] + w->rad[j]);
            d->potential_elastic += contact_energy(w->nl.hist + k * hl, w->features, p, h, rstar);
        }
}

static void wall_diagnostics(const dem_world *w, dem_diagnostics *d)
{
    for (int k = 0; k < w->n_walls; ++k) {
        const dem_wall *wl = &w->walls[k];
        for (size_t i = 0; i < w->n; ++i) {
            double h = dem_wall_geometry(&wl->def, w->pos[i], w->rad[i]).overlap;
            if (!(h > 0)) continue;
            d->wall_contacts++;
            if (h / w->rad[i] > d->max_overlap_ratio) d->max_overlap_ratio = h / w->rad[i];
            d->potential_elastic +=
                contact_energy(wl->hist + i * (size_t)wl->hist_len, wl->features, &wl->def.contact, h, w->rad[i]);
        }
    }
}

dem_diagnostics dem_world_diagnose(const dem_world *w)
{
    dem_diagnostics d = {0};
    d.time = w->time;
    d.step = w->step;
    d.granules = w->n;
    d.list_pairs = w->list_valid ? w->nl.count : 0;
    d.list_rebuilds = w->rebuilds;
    for (size_t i = 0; i < w->n; ++i) {
        d.ke_translational += 0.5 * w->mass[i] * dem_v3_norm2(w->vel[i]);
        d.ke_rotational += 0.5 * w->inertia[i] * dem_v3_norm2(w->omg[i]);
        d.mass += w->mass[i];
    }
    pair_diagnostics(w, &d);
    wall_diagnostics(w, &d);
    if (w->n) {
        d.coordination = 2.0 * (double)d.contacts / (double)w->n;
        d.coordination_walls = (2.0 * (double)d.contacts + (double)d.wall_contacts) / (double)w->n;
    }
    return d;
}
