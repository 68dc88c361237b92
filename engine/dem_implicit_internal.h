// SPDX-License-Identifier: MIT
// The implicit-spring integrator (dem_world_def.implicit_springs): each
// step, the rates of every granule from one solve over the whole contact
// network, by conjugate gradients. It owns its scratch; the pair and wall
// loops hand it each contact's linearisation as they compute the forces.
#ifndef DEM_IMPLICIT_INTERNAL_H
#define DEM_IMPLICIT_INTERNAL_H

#include "dem_linear_contact_internal.h"
#include "dem_state_internal.h"

// One contact as the implicit spring solve sees it: normal, dashpot γ
// applied, stiffness of the sticking tangential and rolling springs (0 while
// sliding), lever arms and R*. All zero for an open contact.
typedef struct dem_imp_contact {
    dem_vec3 n;
    double g, kt, kr, ai, aj, rs;
} dem_imp_contact;

// The solve's scratch, allocated on first use.
struct dem_implicit {
    dem_imp_contact *pair; // per neighbour-list pair
    dem_vec3 *pf, *pti, *ptj; // per pair: operator output (force on i, torques on i and j)
    double *wall;  // per granule, 36: walls' part of the diagonal block
    double *chol;  // per granule, 36: Cholesky factor of the diagonal block (preconditioner)
    double *b, *r, *z, *p, *q; // per granule, 6 each
    double *partial;           // per chunk, for reproducible dot products
    size_t pair_cap, cap, chunk_cap;
    int on; // implicit springs on and scratch in place for this force evaluation
};

// One contact's part of the 6×6 diagonal block (v, ω) of Δt·C + Δt²/4·K_t for
// the granule whose unit normal (towards the partner) is n and lever arm a:
// the linearised contact (dem_linear_contact_internal.h) with the dashpot γ
// applied as its normal part (Δt·γ) and the sticking springs at c = Δt²/4.
static inline void dem_imp_add_block(double *b, dem_vec3 n, double g, double kt, double kr, double a, double rs,
                                     double dt)
{
    const dem_linear_contact l = {.n = n, .ai = a, .aj = 0.0, .rs = rs, .kn = dt * g, .kt = kt, .kr = kr,
                                  .c = 0.25 * dt * dt};
    dem_linear_contact_add_block(b, &l);
}

// Before a force evaluation: whether the loops are to hand the solve their
// contacts (implicit springs on and the scratch in place for this world's
// granules and pairs; its walls' blocks zeroed).
int dem_implicit_begin(dem_world *w);
// Whether the current force evaluation feeds the solve.
static inline int dem_implicit_on(const dem_world *w) { return w->imp && w->imp->on; }
// Solve (M + Δt C + Δt²/4 K_t) a = F + M g for every granule's rates a (into
// w->acc); 0 on success or without implicit springs, 1 out of memory.
int dem_implicit_solve(dem_world *w);
void dem_implicit_free(dem_implicit *s);

#endif
