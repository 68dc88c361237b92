// SPDX-License-Identifier: MIT
// The implicit-spring solve; see dem_implicit_internal.h.
#include <stdlib.h>
#include <string.h>

#include "dem_implicit_internal.h"
#include "dem_threads_internal.h"

// Granules per chunk of a dot product: partial sums in fixed chunks, added in
// order, keep the solve bitwise identical for any thread count.
#define DEM_IMP_CHUNK 256
#define DEM_IMP_TOL 1e-8     // relative residual (preconditioned norm) of the solve
#define DEM_IMP_MAX_IT 200

static void *grow_to(void *p, size_t bytes, int *fail)
{
    void *q = realloc(p, bytes ? bytes : 1);
    if (!q) *fail = 1;
    return q ? q : p;
}

// Scratch for the solve, sized to the granules and pairs of this step.
static int dem_imp_reserve(dem_world *w)
{
    if (!w->imp && !(w->imp = calloc(1, sizeof *w->imp))) return 1;
    dem_implicit *s = w->imp;
    int fail = 0;
    if (s->pair_cap < w->pair_cap || !s->pair) {
        size_t c = w->pair_cap;
        s->pair = grow_to(s->pair, c * sizeof *s->pair, &fail);
        s->pf = grow_to(s->pf, c * sizeof *s->pf, &fail);
        s->pti = grow_to(s->pti, c * sizeof *s->pti, &fail);
        s->ptj = grow_to(s->ptj, c * sizeof *s->ptj, &fail);
        if (!fail) s->pair_cap = c;
    }
    if (s->cap < w->cap || !s->wall) {
        size_t c = w->cap, chunks = c / DEM_IMP_CHUNK + 1;
        double **vec[] = {&s->b, &s->r, &s->z, &s->p, &s->q};
        s->wall = grow_to(s->wall, 36 * c * sizeof(double), &fail);
        s->chol = grow_to(s->chol, 36 * c * sizeof(double), &fail);
        for (int k = 0; k < 5; ++k) *vec[k] = grow_to(*vec[k], 6 * c * sizeof(double), &fail);
        s->partial = grow_to(s->partial, chunks * sizeof(double), &fail);
        if (!fail) s->cap = c, s->chunk_cap = chunks;
    }
    return fail;
}

void dem_implicit_free(dem_implicit *s)
{
    if (!s) return;
    void *a[] = {s->pair, s->pf, s->pti, s->ptj, s->wall, s->chol, s->b, s->r, s->z, s->p, s->q, s->partial};
    for (size_t k = 0; k < sizeof a / sizeof *a; ++k) free(a[k]);
    free(s);
}

int dem_implicit_begin(dem_world *w)
{
    const int on = w->implicit_springs && dem_imp_reserve(w) == 0;
    if (w->imp) w->imp->on = on;
    if (on) memset(w->imp->wall, 0, 36 * w->n * sizeof *w->imp->wall); // the wall loops add to it
    return on;
}

// A loop-level bit above the feature masks: the pair loop for a periodic

// ---------------------------------------------- implicit springs: the solve ---
//
// The step of dem_world_def.implicit_springs: velocity Verlet in which every
// granule's rates a (dv/dt, dω/dt) solve
//     (M + Δt·C + Δt²/4·K_t) a = F + M g,
// C the normal dashpots applied (eq. 3–4), K_t the sticking tangential and
// rolling springs (eq. 6–13 linearised; sliding ones have no stiffness), over
// the whole network. Newmark's β = 1/4 on K_t makes the spin mode leave the
// stability limit (dem_stability.h has the proof); because C and K_t act on
// relative motion only, a cluster falling or turning as a rigid body, and a
// bed at rest (F + M g = 0 ⇔ a = 0), see exactly their physical rates. A
// block-diagonal (per granule) solve alone would not: it would slow a falling
// cluster by (m + Δt²/4·Σk)/m, which is why each granule's own 6×6 block is
// the preconditioner of conjugate gradients and not the solve.

// Operator output of each pair for x (6 per granule): P's off-diagonal and
// diagonal contact parts, in per-pair slots like the forces (reproducible).
static void imp_pair_apply(dem_world *restrict w, const double *restrict x)
{
    const size_t n = w->n;
    const double cc = 0.25 * w->dt * w->dt, dt = w->dt;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t i = 0; i < n; ++i)
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) {
            const dem_imp_contact *c = &w->imp->pair[k];
            if (c->g == 0.0 && c->kt == 0.0 && c->kr == 0.0) {
                w->imp->pf[k] = w->imp->pti[k] = w->imp->ptj[k] = dem_v3(0, 0, 0);
                continue;
            }
            const double *xi = x + 6 * i, *xj = x + 6 * (size_t)w->nl.j[k];
            const dem_vec3 du = dem_v3(xi[0] - xj[0], xi[1] - xj[1], xi[2] - xj[2]);
            const dem_vec3 ti = dem_v3(xi[3], xi[4], xi[5]), tj = dem_v3(xj[3], xj[4], xj[5]);
            // The dashpot along n, the sticking springs on the slip and roll
            // of x (the block of imp_blocks_and_rhs is this operator's).
            const dem_linear_contact l = {.n = c->n, .ai = c->ai, .aj = c->aj, .rs = c->rs, .kn = dt * c->g,
                                          .kt = c->kt, .kr = c->kr, .c = cc};
            const dem_linear_response r = dem_linear_contact_apply(&l, du, ti, tj);
            w->imp->pf[k] = r.f;
            w->imp->pti[k] = r.torque_i;
            w->imp->ptj[k] = r.torque_j;
        }
}

static inline void mat6_mul_add(const double *a, const double *x, double *y)
{
    for (int r = 0; r < 6; ++r)
        for (int q = 0; q < 6; ++q) y[r] += a[6 * r + q] * x[q];
}

// y = P x.
static void imp_apply(dem_world *restrict w, const double *restrict x, double *restrict y)
{
    imp_pair_apply(w, x);
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t i = 0; i < n; ++i) {
        const double *xi = x + 6 * i;
        double *yi = y + 6 * i, m = w->mass[i], in = w->inertia[i];
        yi[0] = m * xi[0], yi[1] = m * xi[1], yi[2] = m * xi[2];
        yi[3] = in * xi[3], yi[4] = in * xi[4], yi[5] = in * xi[5];
        mat6_mul_add(w->imp->wall + 36 * i, xi, yi);
        dem_vec3 f = dem_v3(0, 0, 0), t = dem_v3(0, 0, 0);
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k)
            f = dem_v3_add(f, w->imp->pf[k]), t = dem_v3_add(t, w->imp->pti[k]);
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1]; ++r) {
            size_t k = w->rev_pair[r];
            f = dem_v3_sub(f, w->imp->pf[k]), t = dem_v3_add(t, w->imp->ptj[k]);
        }
        yi[0] += f.x, yi[1] += f.y, yi[2] += f.z, yi[3] += t.x, yi[4] += t.y, yi[5] += t.z;
    }
}

// In-place Cholesky factor (lower, row-major) of a symmetric positive
// definite 6×6 block: the mass alone makes every block positive definite.
static void chol6(double *a)
{
    for (int j = 0; j < 6; ++j) {
        double d = a[6 * j + j];
        for (int k = 0; k < j; ++k) d -= a[6 * j + k] * a[6 * j + k];
        a[6 * j + j] = sqrt(d);
        for (int i = j + 1; i < 6; ++i) {
            double s = a[6 * i + j];
            for (int k = 0; k < j; ++k) s -= a[6 * i + k] * a[6 * j + k];
            a[6 * i + j] = s / a[6 * j + j];
        }
    }
}

static inline void chol6_solve(const double *l, const double *b, double *x)
{
    double y[6];
    for (int i = 0; i < 6; ++i) {
        double s = b[i];
        for (int k = 0; k < i; ++k) s -= l[6 * i + k] * y[k];
        y[i] = s / l[6 * i + i];
    }
    for (int i = 5; i >= 0; --i) {
        double s = y[i];
        for (int k = i + 1; k < 6; ++k) s -= l[6 * k + i] * x[k];
        x[i] = s / l[6 * i + i];
    }
}

// Each granule's own block M_i + (Δt C + Δt²/4 K_t)_ii, factored; and the
// right-hand side F + M g (gravity through the same matrix: C and K_t do not
// see a rigid translation, so free fall is exact). Returns whether any block
// has an off-mass part (if none, P = M and the block solve is the answer).
static int imp_blocks_and_rhs(dem_world *restrict w)
{
    const size_t n = w->n;
    const dem_vec3 g = w->def.gravity;
    int any = 0;
#pragma omp parallel for schedule(static) reduction(|| : any) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t i = 0; i < n; ++i) {
        double *b = w->imp->chol + 36 * i, *rhs = w->imp->b + 6 * i;
        memcpy(b, w->imp->wall + 36 * i, 36 * sizeof *b);
        for (int k = 0; k < 36; ++k) any = any || b[k] != 0.0;
        for (int d = 0; d < 3; ++d) b[7 * d] += w->mass[i], b[7 * (d + 3)] += w->inertia[i];
        for (size_t k = w->nl.start[i]; k < w->nl.start[i + 1]; ++k) {
            const dem_imp_contact *c = &w->imp->pair[k];
            if (c->g == 0.0 && c->kt == 0.0 && c->kr == 0.0) continue;
            dem_imp_add_block(b, c->n, c->g, c->kt, c->kr, c->ai, c->rs, w->dt);
            any = 1;
        }
        for (size_t r = w->rev_start[i]; r < w->rev_start[i + 1]; ++r) {
            const dem_imp_contact *c = &w->imp->pair[w->rev_pair[r]];
            if (c->g == 0.0 && c->kt == 0.0 && c->kr == 0.0) continue;
            dem_imp_add_block(b, dem_v3_neg(c->n), c->g, c->kt, c->kr, c->aj, c->rs, w->dt);
        }
        chol6(b);
        const dem_vec3 f = dem_v3_axpy(w->mass[i], g, w->frc[i]), t = w->trq[i];
        rhs[0] = f.x, rhs[1] = f.y, rhs[2] = f.z, rhs[3] = t.x, rhs[4] = t.y, rhs[5] = t.z;
    }
    return any;
}

// Σ a·b over all granules, summed in fixed chunks and then in order.
static double imp_dot(dem_world *restrict w, const double *a, const double *b)
{
    const size_t n = w->n, chunks = (n + DEM_IMP_CHUNK - 1) / DEM_IMP_CHUNK;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t c = 0; c < chunks; ++c) {
        size_t end = (c + 1) * DEM_IMP_CHUNK < n ? (c + 1) * DEM_IMP_CHUNK : n;
        double s = 0;
        for (size_t k = 6 * c * DEM_IMP_CHUNK; k < 6 * end; ++k) s += a[k] * b[k];
        w->imp->partial[c] = s;
    }
    double s = 0;
    for (size_t c = 0; c < chunks; ++c) s += w->imp->partial[c];
    return s;
}

static void imp_precondition(dem_world *restrict w, const double *r, double *z)
{
    const size_t n = w->n;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t i = 0; i < n; ++i) chol6_solve(w->imp->chol + 36 * i, r + 6 * i, z + 6 * i);
}

// y += α p; r −= α q; then z = B⁻¹ r.
static void imp_update(dem_world *restrict w, double alpha, double *y)
{
    const size_t len = 6 * w->n;
    dem_implicit *s = w->imp;
#pragma omp parallel for schedule(static) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    for (size_t k = 0; k < len; ++k) y[k] += alpha * s->p[k], s->r[k] -= alpha * s->q[k];
    imp_precondition(w, s->r, s->z);
}

// The solve stops at a tolerance, so Σ M a misses Σ F by the residual. In an
// isolated world (no wall, no periodic axis) a rigid acceleration of the whole
// world is in the null space of C and K_t (the contact-point lever arm makes
// an infinitesimal rigid rotation slip-free), so adding one that carries the
// missing force and torque restores momentum and angular momentum to rounding.
static void imp_restore_momenta(dem_world *restrict w)
{
    const size_t n = w->n;
    const double *b = w->imp->b, *a = w->acc;
    double mt = 0;
    dem_vec3 c = dem_v3(0, 0, 0), f = dem_v3(0, 0, 0), t = dem_v3(0, 0, 0);
    for (size_t i = 0; i < n; ++i) mt += w->mass[i], c = dem_v3_axpy(w->mass[i], w->pos[i], c);
    c = dem_v3_scale(c, 1.0 / mt);
    double j[3][3] = {{0}};
    for (size_t i = 0; i < n; ++i) {
        const double *bi = b + 6 * i, *ai = a + 6 * i, m = w->mass[i], in = w->inertia[i];
        const dem_vec3 rho = dem_v3_sub(w->pos[i], c);
        const dem_vec3 df = dem_v3(bi[0] - m * ai[0], bi[1] - m * ai[1], bi[2] - m * ai[2]);
        const dem_vec3 dt = dem_v3(bi[3] - in * ai[3], bi[4] - in * ai[4], bi[5] - in * ai[5]);
        f = dem_v3_add(f, df), t = dem_v3_add(t, dem_v3_add(dem_v3_cross(rho, df), dt));
        const double r[3] = {rho.x, rho.y, rho.z}, r2 = dem_v3_norm2(rho);
        for (int p = 0; p < 3; ++p)
            for (int q = 0; q < 3; ++q) j[p][q] += m * ((p == q) * r2 - r[p] * r[q]) + (p == q) * in;
    }
    // α = J⁻¹ t (Cramer; J is the world's inertia tensor about its centre of mass).
    const double c00 = j[1][1] * j[2][2] - j[1][2] * j[2][1], c01 = j[0][2] * j[2][1] - j[0][1] * j[2][2];
    const double c02 = j[0][1] * j[1][2] - j[0][2] * j[1][1], c11 = j[0][0] * j[2][2] - j[0][2] * j[2][0];
    const double c12 = j[0][2] * j[1][0] - j[0][0] * j[1][2], c22 = j[0][0] * j[1][1] - j[0][1] * j[1][0];
    const double det = j[0][0] * c00 + j[0][1] * (j[1][2] * j[2][0] - j[1][0] * j[2][2]) + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    const dem_vec3 alpha = dem_v3_scale(dem_v3(c00 * t.x + c01 * t.y + c02 * t.z, c01 * t.x + c11 * t.y + c12 * t.z,
                                               c02 * t.x + c12 * t.y + c22 * t.z), 1.0 / det);
    const dem_vec3 lin = dem_v3_scale(f, 1.0 / mt);
    for (size_t i = 0; i < n; ++i) {
        double *ai = w->acc + 6 * i;
        const dem_vec3 d = dem_v3_add(lin, dem_v3_cross(alpha, dem_v3_sub(w->pos[i], c)));
        ai[0] += d.x, ai[1] += d.y, ai[2] += d.z, ai[3] += alpha.x, ai[4] += alpha.y, ai[5] += alpha.z;
    }
}

int dem_implicit_solve(dem_world *w)
{
    if (!dem_implicit_on(w)) return w->implicit_springs ? 1 : 0;
    dem_implicit *s = w->imp;
    const size_t len = 6 * w->n;
    double *y = w->acc;
    const int coupled = imp_blocks_and_rhs(w);
    imp_precondition(w, s->b, y); // block-Jacobi start: exact for an isolated granule
    w->imp_stats.solves++;
    if (!coupled) return 0; // no dashpot or sticking spring in contact: P = M
    const double bz = imp_dot(w, s->b, y);
    imp_apply(w, y, s->q);
    for (size_t k = 0; k < len; ++k) s->r[k] = s->b[k] - s->q[k];
    imp_precondition(w, s->r, s->z);
    memcpy(s->p, s->z, len * sizeof *s->p);
    double rz = imp_dot(w, s->r, s->z);
    int it = 0;
    while (rz > DEM_IMP_TOL * DEM_IMP_TOL * bz && it < DEM_IMP_MAX_IT) {
        imp_apply(w, s->p, s->q);
        const double alpha = rz / imp_dot(w, s->p, s->q);
        imp_update(w, alpha, y);
        const double rz_next = imp_dot(w, s->r, s->z), beta = rz_next / rz;
        rz = rz_next;
        for (size_t k = 0; k < len; ++k) s->p[k] = s->z[k] + beta * s->p[k];
        ++it;
    }
    w->imp_stats.iterations += (uint64_t)it;
    w->imp_stats.last_iterations = it;
    if (it > w->imp_stats.max_iterations) w->imp_stats.max_iterations = it;
    if (rz > DEM_IMP_TOL * DEM_IMP_TOL * bz) w->imp_stats.unconverged++;
    if (w->n_walls == 0 && w->def.periodic_axis < 0 && w->lever_factor == 1.0 && w->n > 1) imp_restore_momenta(w);
    return 0;
}
