// SPDX-License-Identifier: MIT
// Independent reference integration of eq. 1–14 (Tiscar et al. 2019) for the
// Table A.1 verification scene. See ref_two_particles.h. Deliberately shares
// nothing with engine/: its own vectors, its own loops, no engine headers.
#include "ref_two_particles.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#define REF_PI 3.14159265358979323846

// --- vectors -----------------------------------------------------------------

static ref_vec3 rv(double x, double y, double z) { ref_vec3 r = {x, y, z}; return r; }
static ref_vec3 radd(ref_vec3 a, ref_vec3 b) { return rv(a.x + b.x, a.y + b.y, a.z + b.z); }
static ref_vec3 rsub(ref_vec3 a, ref_vec3 b) { return rv(a.x - b.x, a.y - b.y, a.z - b.z); }
static ref_vec3 rscale(ref_vec3 a, double s) { return rv(a.x * s, a.y * s, a.z * s); }
static double rdot(ref_vec3 a, ref_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static double rnorm(ref_vec3 a) { return sqrt(rdot(a, a)); }
static ref_vec3 rcross(ref_vec3 a, ref_vec3 b)
{
    return rv(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static ref_vec3 rzero(void) { return rv(0.0, 0.0, 0.0); }

// --- options -------------------------------------------------------------------

ref_options ref_default_options(void)
{
    ref_options o;
    o.damping = REF_DAMP_APPROACHING;
    o.lever = REF_LEVER_CONTACT_POINT;
    o.dt = 1e-4;
    o.duration = 5.0;
    return o;
}

static const char *const ref_damping_names[4] = {"approaching", "always", "separating",
                                                 "no_tension"};

const char *ref_damping_name(int damping)
{
    return damping >= 0 && damping < 4 ? ref_damping_names[damping] : "?";
}

int ref_damping_from_name(const char *name)
{
    if (name == NULL)
        return -1;
    for (int i = 0; i < 4; ++i)
        if (strcmp(name, ref_damping_names[i]) == 0)
            return i;
    if (strcmp(name, "no-tension") == 0)
        return REF_DAMP_NO_TENSION;
    return -1;
}

int ref_frame_count(double duration)
{
    if (!(duration >= 0.0))
        return 0;
    return (int)floor(duration / REF_FRAME_INTERVAL + 1e-9) + 1;
}

// --- scene ---------------------------------------------------------------------

static double sphere_mass(double R, double rho) { return rho * 4.0 / 3.0 * REF_PI * R * R * R; }

void ref_sim_init_table_a1(ref_sim *s, const ref_options *opt)
{
    ref_options o = opt ? *opt : ref_default_options();
    memset(s, 0, sizeof *s);
    s->n = 2;
    s->R[0] = 0.025;
    s->R[1] = 0.03;
    for (int i = 0; i < 2; ++i) {
        s->m[i] = sphere_mass(s->R[i], 500.0);
        s->I[i] = 0.4 * s->m[i] * s->R[i] * s->R[i];
    }
    s->x[0] = rv(0.0, 0.5, 0.0);
    s->x[1] = rv(0.0, 0.2, 0.0);
    s->w[0] = rv(0.0, 0.0, -300.0);
    s->g = rv(0.0, -9.81, 0.0);
    s->pair = (ref_contact){.kn = 200, .ks = 200, .kr = 200, .xi = 0.7, .mu_s = 0.5, .mu_r = 0.2};
    for (int i = 0; i < 2; ++i)
        s->wall[i] =
            (ref_contact){.kn = 400, .ks = 400, .kr = 400, .xi = 0.7, .mu_s = 0.8, .mu_r = 0.2};
    s->damping = o.damping;
    s->lever = o.lever;
    s->dt = o.dt;
    s->step = 0;
}

// --- contact law (eq. 3–13) ------------------------------------------------------

// Carries a history spring onto the plane normal to n (Luding 2008): turn it
// about n with the mean spin of the two bodies, project it onto the tangent
// plane, and give it back its length from before the carry.
static ref_vec3 carry_spring(ref_vec3 d, ref_vec3 n, double theta)
{
    double len = rnorm(d);
    if (len == 0.0)
        return rzero();
    d = radd(d, rscale(rcross(n, d), theta));
    d = rsub(d, rscale(n, rdot(d, n)));
    double l2 = rnorm(d);
    if (l2 == 0.0)
        return rzero();
    return rscale(d, len / l2);
}

// Truncates a spring force at the Coulomb limit `lim` (eq. 8, 13) and resets
// the spring so that k|δ| equals that limit.
static void coulomb(ref_vec3 *F, ref_vec3 *d, double k, double lim)
{
    double mag = rnorm(*F);
    if (mag > lim) {
        *F = mag > 0.0 ? rscale(*F, lim / mag) : rzero();
        *d = rscale(*F, -1.0 / k);
    }
}

// Body j of a contact. For the floor: infinite mass and radius, at rest.
typedef struct body {
    ref_vec3 v, w;
    double a;      // lever arm
    int is_wall;
} body;

// Evaluates one closed contact with overlap h > 0, unit normal n (from i to
// j), reduced mass ms and reduced radius Rs; adds forces and torques on i (and
// on j unless a wall). `dt_inc` is the step used to carry and increment the
// springs (0 at the initial evaluation).
static void contact_force(ref_sim *s, const ref_contact *c, ref_contact_state *cs, int i, int j,
                          ref_vec3 n, double h, double ms, double Rs, double a_i, double a_j,
                          double dt_inc)
{
    ref_vec3 vi = s->v[i], wi = s->w[i];
    ref_vec3 vj = j >= 0 ? s->v[j] : rzero();
    ref_vec3 wj = j >= 0 ? s->w[j] : rzero();

    // Velocity of i's contact point minus velocity of j's contact point.
    ref_vec3 pi = radd(vi, rscale(rcross(wi, n), a_i));
    ref_vec3 pj = j >= 0 ? rsub(vj, rscale(rcross(wj, n), a_j)) : rzero();
    ref_vec3 vc = rsub(pi, pj);
    double vn = rdot(vc, n); // > 0 approaching

    // Normal force, eq. 3–4, under the chosen reading of eq. 4.
    double gamma = 2.0 * c->xi * sqrt(ms * c->kn);
    double on;
    switch (s->damping) {
    case REF_DAMP_APPROACHING: on = vn > 0.0 ? 1.0 : 0.0; break;
    case REF_DAMP_SEPARATING: on = vn < 0.0 ? 1.0 : 0.0; break;
    default: on = 1.0; break;
    }
    double f = c->kn * h + on * gamma * vn;
    if (s->damping == REF_DAMP_NO_TENSION && f < 0.0)
        f = 0.0;
    double fabs_n = fabs(f);

    // Carry both springs onto the current tangent plane.
    double theta = 0.5 * rdot(radd(wi, wj), n) * dt_inc;
    cs->ds = carry_spring(cs->ds, n, theta);
    cs->dr = carry_spring(cs->dr, n, theta);

    // Tangential spring, eq. 6–8 (no tangential damping).
    ref_vec3 vt = rsub(vc, rscale(n, vn));
    cs->ds = radd(cs->ds, rscale(vt, dt_inc));
    ref_vec3 Fs = rscale(cs->ds, -c->ks);
    coulomb(&Fs, &cs->ds, c->ks, c->mu_s * fabs_n);

    // Rolling quasi-force, eq. 11–13.
    ref_vec3 vr = rscale(rcross(rsub(wi, wj), n), -Rs);
    cs->dr = radd(cs->dr, rscale(vr, dt_inc));
    ref_vec3 Fr = rscale(cs->dr, -c->kr);
    coulomb(&Fr, &cs->dr, c->kr, c->mu_r * fabs_n);

    // Forces and torques, eq. 1, 9, 10.
    ref_vec3 Fi = radd(rscale(n, -f), Fs);
    ref_vec3 nFs = rcross(n, Fs), nFr = rcross(n, Fr);
    s->F[i] = radd(s->F[i], Fi);
    s->T[i] = radd(s->T[i], rsub(rscale(nFs, a_i), rscale(nFr, Rs)));
    if (j >= 0) {
        s->F[j] = rsub(s->F[j], Fi);
        s->T[j] = radd(s->T[j], radd(rscale(nFs, a_j), rscale(nFr, Rs)));
    }
    cs->h = h;
    cs->f = f;
}

static void open_contact(ref_contact_state *cs, double h)
{
    cs->ds = rzero();
    cs->dr = rzero();
    cs->h = h;
    cs->f = 0.0;
}

// Forces and torques at the current positions, with the current (half-step)
// velocities and spins.
static void compute_forces(ref_sim *s, double dt_inc)
{
    for (int i = 0; i < s->n; ++i) {
        s->F[i] = rscale(s->g, s->m[i]);
        s->T[i] = rzero();
    }
    // Particle – particle.
    if (s->n == 2) {
        ref_vec3 d = rsub(s->x[1], s->x[0]);
        double dist = rnorm(d);
        double h = s->R[0] + s->R[1] - dist;
        if (h > 0.0 && dist > 0.0) {
            ref_vec3 n = rscale(d, 1.0 / dist);
            double ms = s->m[0] * s->m[1] / (s->m[0] + s->m[1]);
            double Rs = s->R[0] * s->R[1] / (s->R[0] + s->R[1]);
            double a0 = s->lever == REF_LEVER_RADIUS ? s->R[0] : s->R[0] - 0.5 * h;
            double a1 = s->lever == REF_LEVER_RADIUS ? s->R[1] : s->R[1] - 0.5 * h;
            contact_force(s, &s->pair, &s->cs_pair, 0, 1, n, h, ms, Rs, a0, a1, dt_inc);
        } else {
            open_contact(&s->cs_pair, h);
        }
    }
    // Particle – floor y = 0 (a granule of infinite mass and radius below).
    for (int i = 0; i < s->n; ++i) {
        double h = s->R[i] - s->x[i].y;
        if (h > 0.0) {
            double a = s->lever == REF_LEVER_RADIUS ? s->R[i] : s->R[i] - h;
            contact_force(s, &s->wall[i], &s->cs_wall[i], i, -1, rv(0.0, -1.0, 0.0), h, s->m[i],
                          s->R[i], a, 0.0, dt_inc);
        } else {
            open_contact(&s->cs_wall[i], h);
        }
    }
}

void ref_sim_start(ref_sim *s) { compute_forces(s, 0.0); }

static void kick(ref_sim *s, double tau)
{
    for (int i = 0; i < s->n; ++i) {
        s->v[i] = radd(s->v[i], rscale(s->F[i], tau / s->m[i]));
        s->w[i] = radd(s->w[i], rscale(s->T[i], tau / s->I[i]));
    }
}

void ref_sim_step(ref_sim *s)
{
    kick(s, 0.5 * s->dt);
    for (int i = 0; i < s->n; ++i)
        s->x[i] = radd(s->x[i], rscale(s->v[i], s->dt));
    compute_forces(s, s->dt);
    kick(s, 0.5 * s->dt);
    s->step++;
}

static double spring_energy(const ref_contact *c, const ref_contact_state *cs)
{
    if (!(cs->h > 0.0))
        return 0.0;
    return 0.5 * (c->kn * cs->h * cs->h + c->ks * rdot(cs->ds, cs->ds) +
                  c->kr * rdot(cs->dr, cs->dr));
}

double ref_sim_energy(const ref_sim *s)
{
    double e = 0.0;
    for (int i = 0; i < s->n; ++i) {
        e += 0.5 * s->m[i] * rdot(s->v[i], s->v[i]);
        e += 0.5 * s->I[i] * rdot(s->w[i], s->w[i]);
        e -= s->m[i] * rdot(s->g, s->x[i]);
        e += spring_energy(&s->wall[i], &s->cs_wall[i]);
    }
    if (s->n == 2)
        e += spring_energy(&s->pair, &s->cs_pair);
    return e;
}

void ref_sim_frame(const ref_sim *s, ref_frame *fr)
{
    memset(fr, 0, sizeof *fr);
    fr->t = (double)s->step * s->dt;
    for (int i = 0; i < s->n; ++i) {
        const ref_vec3 *src[3] = {&s->x[i], &s->v[i], &s->w[i]};
        double *dst[3] = {fr->x[i], fr->v[i], fr->w[i]};
        for (int k = 0; k < 3; ++k) {
            dst[k][0] = src[k]->x;
            dst[k][1] = src[k]->y;
            dst[k][2] = src[k]->z;
        }
    }
}

// --- the run ---------------------------------------------------------------------

int ref_two_particles_run(const ref_options *opt, ref_frame *frames, int max_frames)
{
    ref_options o = opt ? *opt : ref_default_options();
    if (!(o.dt > 0.0) || !(o.duration >= 0.0) || o.damping < 0 || o.damping > 3 || o.lever < 0 ||
        o.lever > 1 || (frames == NULL && max_frames > 0))
        return -1;
    ref_sim s;
    ref_sim_init_table_a1(&s, &o);
    ref_sim_start(&s);

    const long nsteps = lround(o.duration / o.dt);
    const int nframes = ref_frame_count(o.duration);
    int written = 0;
    for (int k = 0; k < nframes && written < max_frames; ++k) {
        // Frame k at the step nearest to k·interval (exact for Δt dividing it).
        long target = lround(k * REF_FRAME_INTERVAL / o.dt);
        if (target > nsteps)
            target = nsteps;
        while (s.step < target)
            ref_sim_step(&s);
        ref_sim_frame(&s, &frames[written++]);
    }
    return written;
}
