// SPDX-License-Identifier: MIT
// The step loop: the time step chosen against the stability limit
// (dem_world_prepare), velocity-Verlet kicks and drift for each integration
// (explicit, implicit dashpot, implicit springs), the list refresh and the
// force evaluation in between, faults, and the team of threads that runs
// many steps in one parallel region.
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem_forces_internal.h"
#include "dem_implicit_internal.h"
#include "dem_lists_internal.h"
#include "dem_stability.h"
#include "dem_threads_internal.h"

static int check_periodic_length(dem_world *w)
{
    int a = w->def.periodic_axis;
    if (a < 0) return 0;
    double len = dem_world_period(w);
    // A pair must touch through one image only.
    double need = 2.0 * (2.0 * dem_granules_max_radius(w) + w->skin);
    if (len <= need)
        return dem_world_set_error(w,
                                   "periodic length %g m along axis %d is too short: it must exceed %g m "
                                   "(twice the largest diameter plus skin)",
                                   len, a, need);
    return 0;
}

// How the reports name the reference step dt_crit: eq. 14 for the linear
// law, the Rayleigh time for Hertz–Mindlin (dem_rayleigh_time).
typedef struct reference_step_text {
    const char *source, *formula, *note;
} reference_step_text;

static reference_step_text reference_step_of(const dem_world *w)
{
    if (w->def.granule.law == DEM_LAW_HERTZ_MINDLIN)
        return (reference_step_text){"Rayleigh time", "pi R sqrt(rho/G)/(0.1631 nu + 0.8766)",
                                     "Hertz-Mindlin's limit before a run is 0.2 of it"};
    return (reference_step_text){"eq. 14", "sqrt(m_min/k_n)", "the paper uses 0.6"};
}

// Check a configured step against a stability limit, or choose the step as
// dt_safety of it; record the limit and say how the step was found.
static dem_status apply_limit(dem_world *w, const dem_stability *st, const char *source)
{
    const reference_step_text ref = reference_step_of(w);
    if (w->def.dt > 0 && w->def.dt > st->dt_limit && !w->def.allow_unstable_dt) {
        dem_world_set_error(w,
                            "time step %g s (%.3f of dt_crit = %s = %g s, %s) is above the "
                            "%s stability limit %g s (%.3f of dt_crit): %s. Use a step <= %g s or leave dt unset.",
                            w->def.dt, w->def.dt / st->dt_crit, ref.formula, st->dt_crit, ref.source, source,
                            st->dt_limit, st->dt_limit / st->dt_crit, st->why, st->dt_limit);
        return DEM_ERR_UNSTABLE;
    }
    w->dt_limit = st->dt_limit;
    w->dt = w->def.dt > 0 ? w->def.dt : w->def.dt_safety * st->dt_limit;
    snprintf(w->dt_report, sizeof w->dt_report,
             "dt = %.4g s = %.3f dt_crit (%s: dt_crit = %s = %.4g s; %s); %s limit "
             "from the %s: %.4g s = %.3f dt_crit%s",
             w->dt, w->dt / st->dt_crit, ref.source, ref.formula, st->dt_crit, ref.note, source, st->why,
             st->dt_limit, st->dt_limit / st->dt_crit,
             w->def.dt > 0 ? " (step as configured)" : "; step chosen at dt_safety of it");
    return DEM_OK;
}

// Implicit springs on "auto": on where they are needed, i.e. for a configured
// step above the explicit integration's own limit (the paper's 0.6 dt_crit),
// unless the caller asked for the per-granule implicit dashpot. A step left
// to the engine stays explicit: per simulated second it costs less
// (docs/model.md, "What it costs and what it does to collisions";
// bench_restitution_default_step) and its collisions are more accurate.
static void decide_integration(dem_world *w)
{
    if (w->def.implicit_springs != DEM_IMPLICIT_AUTO) {
        w->implicit_springs = w->def.implicit_springs != 0;
        return;
    }
    w->implicit_springs = 0;
    if (w->def.implicit_damping || !(w->def.dt > 0) || w->n_fixed) return;
    w->implicit_springs = w->def.dt > dem_stability_apriori(w).dt_limit;
}

dem_status dem_world_prepare(dem_world *w)
{
    if (w->prepared) return DEM_OK;
    // Skin: a fraction of the smallest radius keeps rebuilds rare while the
    // list stays short for the small granules of a wide GSD.
    w->skin = w->def.skin > 0 ? w->def.skin : 0.4 * dem_granules_min_radius(w);
    if (check_periodic_length(w)) return DEM_ERR_INVALID;
    if (w->n == 0) {
        w->dt = w->def.dt > 0 ? w->def.dt : 1e-6;
        snprintf(w->dt_report, sizeof w->dt_report, "no granules: dt = %g s", w->dt);
        w->prepared = 1;
        return DEM_OK;
    }
    decide_integration(w);
    if (w->implicit_springs && w->n_fixed) {
        dem_world_set_error(w, "fixed granules need the explicit integration or the implicit dashpot, not implicit "
                               "springs (the network solve would move them)");
        return DEM_ERR_INVALID;
    }
    dem_stability st = dem_stability_apriori(w);
    dem_status status = apply_limit(w, &st, "a priori");
    if (status != DEM_OK) return status;
    w->prepared = 1;
    w->forces_valid = 0;
    // Build the list now so diagnostics before the first step see contacts.
    if (dem_lists_rebuild(w)) return DEM_ERR_NOMEM;
    return DEM_OK;
}

dem_status dem_world_adopt_network_dt(dem_world *w)
{
    dem_status st = dem_world_prepare(w);
    if (st != DEM_OK) return st;
    dem_stability net = dem_stability_current(w);
    if (!(net.dt_limit > 0) || !isfinite(net.dt_limit)) return DEM_OK; // no contacts: keep the a-priori step
    st = apply_limit(w, &net, "current contact network");
    if (st != DEM_OK) return st;
    w->forces_valid = 0;
    return DEM_OK;
}

dem_status dem_world_check_network_dt(dem_world *w, dem_network_dt_check *out)
{
    *out = (dem_network_dt_check){NAN, 0};
    // Building the list here would rebuild it at another moment than the
    // steps do, and change the order forces are summed in.
    if (!w->list_valid || w->dt <= 0) return DEM_OK;
    dem_stability net = dem_stability_current(w);
    if (!(net.dt_limit > 0) || !isfinite(net.dt_limit)) return out->margin = INFINITY, DEM_OK;
    out->margin = net.dt_limit / w->dt;
    if (out->margin >= 1) return DEM_OK;
    dem_status st = apply_limit(w, &net, "current contact network (checked while running)");
    if (st != DEM_OK) return st;
    w->forces_valid = 0;
    out->lowered = 1;
    return DEM_OK;
}

// How the kicks find the rates: explicitly from F/m, with the implicit
// dashpot, or from the implicit spring solve (dem_implicit_solve).
typedef enum { KICK_EXPLICIT, KICK_IMPLICIT_DAMPING, KICK_IMPLICIT_SPRINGS } kick_mode;

// What the kicks and the drift read, copied out of the world once per pass:
// stores through the granule arrays could alias the world's own fields as
// far as the compiler knows, so read from the world every granule would
// reload them (and the drift's periodic wrap through a pointer to a
// component kept the position in memory; measured at N = 20 000, 1 thread:
// the two passes 15 % of the step before).
typedef struct kick_ctx {
    dem_vec3 *vel, *omg, *pos;
    const dem_vec3 *frc, *trq;
    const double *inv_mass, *inv_inertia, *mass, *acc, *damp;
    const unsigned char *fixed; // per granule: held still (read only where the world has fixed granules)
    dem_vec3 gravity, lo, hi;
    double half_dt, dt;
    double wrap_lo, wrap_len; // the periodic axis' lower end and length
    int axis;                 // periodic axis, or −1
    kick_mode mode;
} kick_ctx;

static kick_ctx kick_ctx_make(const dem_world *w)
{
    const int a = w->def.periodic_axis;
    const double wrap_lo = a >= 0 ? dem_v3_comp(w->def.domain_lo, a) : 0.0;
    const kick_mode mode = w->implicit_springs       ? KICK_IMPLICIT_SPRINGS
                           : w->def.implicit_damping ? KICK_IMPLICIT_DAMPING
                                                     : KICK_EXPLICIT;
    return (kick_ctx){w->vel, w->omg, w->pos, w->frc, w->trq, w->inv_mass, w->inv_inertia, w->mass, w->acc,
                      w->damp, w->fixed, w->def.gravity, w->def.domain_lo, w->def.domain_hi, 0.5 * w->dt, w->dt, wrap_lo,
                      a >= 0 ? dem_v3_comp(w->def.domain_hi, a) - wrap_lo : 0.0, a, mode};
}

// Velocity of granule i after a kick of `h`: v + h·(F/m + g) explicitly, or
// with the implicit dashpot v + h·(m·I + Δt·D)⁻¹(F + m g), D = Σγ n nᵀ of
// its contacts (symmetric positive semi-definite: the solve always exists).
static DEM_ALWAYS_INLINE dem_vec3 kicked_velocity(const kick_ctx *restrict c, size_t i, const kick_mode mode)
{
    const double h = c->half_dt;
    if (mode == KICK_IMPLICIT_SPRINGS) { // rates from the network solve (dem_implicit_solve)
        const double *a = c->acc + 6 * i;
        return dem_v3_axpy(h, dem_v3(a[0], a[1], a[2]), c->vel[i]);
    }
    if (mode == KICK_EXPLICIT) return dem_v3_axpy(h * c->inv_mass[i], c->frc[i], dem_v3_axpy(h, c->gravity, c->vel[i]));
    const double *d = c->damp + 6 * i, m = c->mass[i], dt = c->dt;
    double a = m + dt * d[0], b = m + dt * d[1], cz = m + dt * d[2], xy = dt * d[3], xz = dt * d[4], yz = dt * d[5];
    dem_vec3 f = dem_v3_axpy(m, c->gravity, c->frc[i]);
    // Cramer's rule on the symmetric matrix [[a xy xz] [xy b yz] [xz yz cz]].
    double c00 = b * cz - yz * yz, c01 = xz * yz - xy * cz, c02 = xy * yz - xz * b;
    double c11 = a * cz - xz * xz, c12 = xy * xz - a * yz, c22 = a * b - xy * xy;
    double det = a * c00 + xy * c01 + xz * c02;
    dem_vec3 x = dem_v3(c00 * f.x + c01 * f.y + c02 * f.z, c01 * f.x + c11 * f.y + c12 * f.z,
                        c02 * f.x + c12 * f.y + c22 * f.z);
    return dem_v3_axpy(h / det, x, c->vel[i]);
}

// Spin of granule i after a kick of `h`.
static DEM_ALWAYS_INLINE dem_vec3 kicked_spin(const kick_ctx *restrict c, size_t i, const kick_mode mode)
{
    if (mode == KICK_IMPLICIT_SPRINGS) {
        const double *a = c->acc + 6 * i;
        return dem_v3_axpy(c->half_dt, dem_v3(a[3], a[4], a[5]), c->omg[i]);
    }
    return dem_v3_axpy(c->half_dt * c->inv_inertia[i], c->trq[i], c->omg[i]);
}

// Forces and torques of the current state, and with implicit springs the
// rates they cause; 1 on out-of-memory.
static int evaluate(dem_world *w)
{
    dem_forces_compute(w);
    return dem_implicit_solve(w);
}

// Wrap one coordinate into [lo, lo + len) of the periodic axis. A centre
// still inside (0 <= x - lo < len, as rounded) keeps x, bit for bit what the
// formula gives: u = x - lo < len makes u/len < 1 - 2^-53, which rounds below
// 1, so the floor is 0 and x - len·0 is x. Skipping the division there took
// the drift's longest chain away (perf put a third of its samples on it).
static DEM_ALWAYS_INLINE double wrap_into(double x, double lo, double len)
{
    const double u = x - lo;
    return u >= 0.0 && u < len ? x : x - len * floor(u / len);
}

// Half kick and drift of granule i; 0 if it left the domain.
static DEM_ALWAYS_INLINE int kick_drift_one(const kick_ctx *restrict c, size_t i, const kick_mode mode)
{
    const dem_vec3 v = kicked_velocity(c, i, mode);
    c->omg[i] = kicked_spin(c, i, mode);
    c->vel[i] = v;
    dem_vec3 p = dem_v3_axpy(c->dt, v, c->pos[i]);
    switch (c->axis) { // wrap into [lo, hi) along the periodic axis
    case 0: p.x = wrap_into(p.x, c->wrap_lo, c->wrap_len); break;
    case 1: p.y = wrap_into(p.y, c->wrap_lo, c->wrap_len); break;
    case 2: p.z = wrap_into(p.z, c->wrap_lo, c->wrap_len); break;
    default: break;
    }
    c->pos[i] = p;
    return dem_v3_in_box(p, c->lo, c->hi);
}

// Second half kick of granule i; 0 if its state is not finite.
static DEM_ALWAYS_INLINE int kick_one(const kick_ctx *restrict c, size_t i, const kick_mode mode)
{
    const dem_vec3 v = kicked_velocity(c, i, mode), o = kicked_spin(c, i, mode), p = c->pos[i];
    c->vel[i] = v;
    c->omg[i] = o;
    // One test of a sum catches NaN or infinity in any component.
    return isfinite(v.x + v.y + v.z + o.x + o.y + o.z + p.x + p.y + p.z);
}

// The first granule of [lo, hi) for which f(c, i, mode) fails, or SIZE_MAX;
// one loop per mode, so that each is free of the others' branches, and the
// loops that pass over fixed granules (dem_world_set_granule_fixed) apart
// from those of a world without any.
#define KICK_PASS(name, f)                                                                            \
    static DEM_ALWAYS_INLINE size_t name##_mode(const kick_ctx *restrict c, size_t lo, size_t hi,      \
                                                const kick_mode mode, const int with_fixed)           \
    {                                                                                                 \
        size_t first_bad = SIZE_MAX;                                                                  \
        for (size_t i = lo; i < hi; ++i)                                                              \
            if (!(with_fixed && c->fixed[i]) && !f(c, i, mode) && i < first_bad) first_bad = i;       \
        return first_bad;                                                                             \
    }                                                                                                 \
    static size_t name##_fixed(const kick_ctx *c, size_t lo, size_t hi)                               \
    {                                                                                                 \
        if (c->mode == KICK_EXPLICIT) return name##_mode(c, lo, hi, KICK_EXPLICIT, 1);                \
        return name##_mode(c, lo, hi, KICK_IMPLICIT_DAMPING, 1);                                      \
    }                                                                                                 \
    static size_t name(const dem_world *w, size_t lo, size_t hi)                                      \
    {                                                                                                 \
        const kick_ctx c = kick_ctx_make(w);                                                          \
        if (w->n_fixed) return name##_fixed(&c, lo, hi);                                              \
        switch (c.mode) {                                                                             \
        case KICK_EXPLICIT: return name##_mode(&c, lo, hi, KICK_EXPLICIT, 0);                         \
        case KICK_IMPLICIT_DAMPING: return name##_mode(&c, lo, hi, KICK_IMPLICIT_DAMPING, 0);         \
        default: return name##_mode(&c, lo, hi, KICK_IMPLICIT_SPRINGS, 0);                            \
        }                                                                                             \
    }
KICK_PASS(kick_drift_range, kick_drift_one)
KICK_PASS(kick_range, kick_one)

// The pass `range` over all granules, on threads in blocks; the first
// granule it flags, or SIZE_MAX.
static size_t on_threads(dem_world *w, size_t (*range)(const dem_world *, size_t, size_t))
{
    size_t first_bad = SIZE_MAX;
#pragma omp parallel reduction(min : first_bad) if (w->n >= DEM_OMP_MIN_GRANULES) num_threads(dem_world_team(w))
    {
        size_t lo, hi;
        dem_thread_block(w->n, omp_get_thread_num(), omp_get_num_threads(), &lo, &hi);
        first_bad = range(w, lo, hi);
    }
    return first_bad;
}

// Half kick and drift in one pass; the first granule that left the domain,
// or SIZE_MAX.
static size_t kick_drift(dem_world *w) { return on_threads(w, kick_drift_range); }

// Second half kick; the first granule whose state is not finite, or SIZE_MAX.
static size_t kick(dem_world *w) { return on_threads(w, kick_range); }

static dem_status fault(dem_world *w, dem_status code, size_t i, const char *what)
{
    dem_vec3 p = w->pos[i], v = w->vel[i];
    dem_world_set_error(w,
                        "%s: granule id %llu at step %llu (t = %.6g s), position (%g, %g, %g) m, velocity "
                        "(%g, %g, %g) m/s, radius %g m",
                        what, (unsigned long long)w->id[i], (unsigned long long)w->step, w->time, p.x, p.y, p.z,
                        v.x, v.y, v.z, w->rad[i]);
    return code;
}

// First granule whose position, velocity or spin is not finite, or SIZE_MAX.
static size_t first_nonfinite(const dem_world *w)
{
    for (size_t i = 0; i < w->n; ++i)
        if (!dem_v3_isfinite(w->pos[i]) || !dem_v3_isfinite(w->vel[i]) || !dem_v3_isfinite(w->omg[i])) return i;
    return SIZE_MAX;
}

// ------------------------------------------------------- the step team ---
//
// With several threads and the explicit integration, the steps run in one
// parallel region: each thread keeps its block of granules (dem_thread_block)
// through the whole step, so a step needs three barriers — after the drift
// (every block drifted before any pair reads a partner; the list and escape
// checks agree), after the pairs crossing a block's edge (their slots read by
// the block above), after the kick (the non-finite check agrees before the
// next drift) — where a fork and a join per loop needed about a dozen
// synchronisations. With OpenMP's passive waiting each is a sleep and a
// wake-up of the other threads. Every granule goes through the same
// arithmetic in the same order, so the results are bitwise those of the
// loop-by-loop step. (Doing the kick in the same pass as the next drift
// would save a barrier and a pass over the granules; measured, it bought
// nothing above the noise at N = 20 000 on 1 thread or 100 000 on 2, and
// it would have left a faulted world half a step further on: not kept.)

// Why the team stopped: its steps done, or after a drift that needs the
// ordinary path to finish the step (a list rebuild, an escape, or centres
// too far apart for one wrap: see dem_forces_one_wrap), or after a kick that
// left a state not finite.
typedef enum { TEAM_DONE, TEAM_AFTER_DRIFT, TEAM_NONFINITE } team_stop;

typedef struct team_result {
    uint64_t steps; // complete steps (the non-finite one included)
    team_stop stop;
    size_t bad; // the escaped or non-finite granule, or SIZE_MAX
} team_result;

// What each thread hands the others at a barrier, one cache line per thread.
// The drift's fields and the kick's are apart: a thread may write the next
// drift's while a slower one still reads the kick's.
typedef struct team_slot {
    size_t escaped, nonfinite;
    double displacement2;
    double lowest, highest; // the block's centres along the periodic axis
    size_t crossing_rows;   // rows of the block with a pair past its end (set once)
    char pad[64 - 3 * sizeof(size_t) - 3 * sizeof(double)];
} team_slot;

// Whether a wall of the world has a prescribed motion (dem_wall_def.motion).
static int walls_move(const dem_world *w)
{
    for (int k = 0; k < w->n_walls; ++k)
        if (w->walls[k].def.motion != DEM_WALL_STANDS) return 1;
    return 0;
}

// One step of every wall's prescribed motion, before the step's kick and
// drift: where a caller moved the wall between single steps, so that the
// step's force evaluation sees it there.
static void move_walls(dem_world *w)
{
    for (int k = 0; k < w->n_walls; ++k) dem_wall_advance(&w->walls[k], w->dt);
}

// A wall placed by a caller, or moved by the step before the team, that has
// moved half a skin leaves the step to the ordinary path, whose list refresh
// sees it (the team checks its own walls' moves after each drift).
static int team_eligible(const dem_world *w)
{
    return w->list_valid && dem_forces_threaded(w) && dem_forces_blockwise(w) && !dem_lists_walls_moved(w);
}

static size_t team_first(const team_slot *slot, int nt, int nonfinite)
{
    size_t first = SIZE_MAX;
    for (int t = 0; t < nt; ++t) {
        const size_t b = nonfinite ? slot[t].nonfinite : slot[t].escaped;
        first = b < first ? b : first;
    }
    return first;
}

static double team_max_displacement2(const team_slot *slot, int nt)
{
    double m = 0;
    for (int t = 0; t < nt; ++t) m = slot[t].displacement2 > m ? slot[t].displacement2 : m;
    return m;
}

// Whether the drifted centres are near enough for one wrap along the
// periodic axis, as the team's force evaluations take them to be. A drift
// wraps every centre into the domain, so this is a check: should it fail,
// the team stops and the ordinary step goes on.
static int team_one_wrap(const dem_world *w, const team_slot *slot, int nt)
{
    double lowest = slot[0].lowest, highest = slot[0].highest;
    for (int t = 1; t < nt; ++t) {
        lowest = slot[t].lowest < lowest ? slot[t].lowest : lowest;
        highest = slot[t].highest > highest ? slot[t].highest : highest;
    }
    return dem_forces_one_wrap(w, lowest, highest);
}

// The pairs crossing a block's end, shared out: thread t takes the first
// half of its own block's crossing rows and the second half of the block
// below's, so that no thread waits at the barrier that follows for the
// others' (all of them on the block's own thread made 2 threads wait 8 % of
// the step at N = 100 000).
static void team_crossing_pairs(dem_world *w, const team_slot *slot, const uint32_t *rows, int t, int nt)
{
    size_t lo, hi;
    dem_thread_block(w->n, t, nt, &lo, &hi);
    const size_t own = slot[t].crossing_rows;
    dem_forces_crossing(w, rows + lo, t + 1 < nt ? own / 2 : own, hi);
    if (t == 0) return;
    size_t lo_below, hi_below;
    dem_thread_block(w->n, t - 1, nt, &lo_below, &hi_below);
    const size_t below = slot[t - 1].crossing_rows;
    dem_forces_crossing(w, rows + lo_below + below / 2, below - below / 2, hi_below);
}

// One thread's part of up to `steps` steps; every thread reaches the same
// stop. `rows`: n entries, each block's crossing rows at its own start.
// `moving`: walls with a prescribed motion, which thread 0 moves before each
// step but the first (moved by the caller, dem_world_step): the barrier at
// the end of the step before keeps every thread's last force evaluation
// ahead of the move, the one after the drift the move ahead of the next.
static team_result team_thread(dem_world *w, team_slot *slot, uint32_t *rows, uint64_t steps, int moving)
{
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const double half_skin = 0.5 * w->skin;
    size_t lo, hi;
    dem_thread_block(w->n, t, nt, &lo, &hi);
    slot[t].crossing_rows = dem_forces_crossing_rows(w, lo, hi, rows + lo); // the list stays through the region
    team_result r = {0, TEAM_DONE, SIZE_MAX};
    while (r.steps < steps) {
        if (moving && t == 0 && r.steps > 0) move_walls(w);
        slot[t].escaped = kick_drift_range(w, lo, hi);
        slot[t].displacement2 = dem_lists_displacement2_range(w, lo, hi);
        dem_forces_axis_extent(w, lo, hi, &slot[t].lowest, &slot[t].highest);
#pragma omp barrier
        r.bad = team_first(slot, nt, 0);
        if (r.bad != SIZE_MAX || team_max_displacement2(slot, nt) > half_skin * half_skin ||
            !team_one_wrap(w, slot, nt) || (moving && dem_lists_walls_moved(w))) {
            r.stop = TEAM_AFTER_DRIFT;
            return r;
        }
        team_crossing_pairs(w, slot, rows, t, nt);
#pragma omp barrier
        dem_forces_block(w, lo, hi);
        slot[t].nonfinite = kick_range(w, lo, hi);
#pragma omp barrier
        r.steps++;
        r.bad = team_first(slot, nt, 1);
        if (r.bad != SIZE_MAX) {
            r.stop = TEAM_NONFINITE;
            return r;
        }
    }
    return r;
}

// Up to `steps` whole steps on the team; 0 steps and TEAM_DONE if its
// scratch could not be had (the ordinary step then goes on). The scratch and
// the crossing rows are made once per region, i.e. per call and per list
// rebuild: not per step, except for a caller that steps one step per call.
static team_result step_team(dem_world *w, uint64_t steps, int moving)
{
    team_result r = {0, TEAM_DONE, SIZE_MAX};
    const int team = dem_world_team(w);
    team_slot *slot = aligned_alloc(64, (size_t)team * sizeof *slot);
    uint32_t *rows = malloc(w->n * sizeof *rows);
    if (slot && rows) {
        w->hist_dt = w->dt;
        dem_forces_blocks_begin(w);
#pragma omp parallel num_threads(team)
        {
            const team_result mine = team_thread(w, slot, rows, steps, moving);
            if (omp_get_thread_num() == 0) r = mine; // every thread's is the same
        }
    }
    free(slot);
    free(rows);
    return r;
}

// The clock of `steps` steps, one addition per step as the step loop does.
static void advance_clock(dem_world *w, uint64_t steps)
{
    for (uint64_t s = 0; s < steps; ++s) {
        w->step++;
        w->time += w->dt;
    }
}

// The rest of a step after its kick and drift (`escaped`: the first granule
// that left the domain, or SIZE_MAX): clock, list, forces, second kick.
static dem_status finish_step(dem_world *w, size_t escaped)
{
    advance_clock(w, 1);
    if (escaped != SIZE_MAX) {
        w->forces_valid = 0;
        w->moved = 1;
        // A position that overflowed to infinity or NaN did not leave the domain.
        if (!dem_v3_isfinite(w->pos[escaped]))
            return fault(w, DEM_ERR_NONFINITE, escaped, "non-finite state (NaN or infinity)");
        return fault(w, DEM_ERR_ESCAPED, escaped, "granule left the domain");
    }
    if (dem_lists_refresh(w)) return DEM_ERR_NOMEM;
    w->hist_dt = w->dt;
    if (evaluate(w)) return DEM_ERR_NOMEM;
    w->moved = 0;
    const size_t bad = kick(w);
    if (bad != SIZE_MAX) return fault(w, DEM_ERR_NONFINITE, bad, "non-finite state (NaN or infinity)");
    return DEM_OK;
}

// Forces of the state the next step starts from, where no evaluation holds
// (a new world, or a changed contact law, spin or step: a network check that
// lowered dt within a call re-evaluates here as the next call would have).
static dem_status ensure_forces(dem_world *w)
{
    if (w->forces_valid) return DEM_OK;
    if (dem_lists_refresh(w)) return DEM_ERR_NOMEM;
    w->hist_dt = w->moved ? w->dt : 0.0; // re-evaluation at an unchanged configuration: springs stay
    if (evaluate(w)) return DEM_ERR_NOMEM;
    w->moved = 0;
    w->forces_valid = 1;
    return DEM_OK;
}

// `steps` steps, each after its walls' prescribed motion, on the team where
// it can run them.
static dem_status step_run(dem_world *w, uint64_t steps)
{
    dem_status st = ensure_forces(w);
    if (st != DEM_OK) return st;
    const int moving = walls_move(w);
    for (uint64_t s = 0; s < steps; ++s) {
        if (moving) move_walls(w);
        if (team_eligible(w)) {
            const team_result r = step_team(w, steps - s, moving);
            advance_clock(w, r.steps);
            s += r.steps;
            if (r.stop == TEAM_NONFINITE) return fault(w, DEM_ERR_NONFINITE, r.bad, "non-finite state (NaN or infinity)");
            if (r.stop == TEAM_AFTER_DRIFT) {
                st = finish_step(w, r.bad);
                if (st != DEM_OK) return st;
                continue;
            }
            if (s == steps) break;
        }
        st = finish_step(w, kick_drift(w));
        if (st != DEM_OK) return st;
    }
    return DEM_OK;
}

// ------------------------------------------------ the scheduled checks ---
//
// The world's network checks (dem_world_def.network_check_interval) are
// counted in steps, never by comparing simulated times (sums of dt that two
// ways of stepping could round apart): round(interval/chunk) chunks of
// round(chunk/dt) steps, the rounding a caller stepping in chunks does
// itself, so that each check falls at the end of one of its chunks, and,
// after a lowered step, on chunks of the new length. A call is cut into runs
// that end where a check is due; the runs step as one call would.

static int checks_on(const dem_world *w) { return w->def.network_check_interval > 0; }

// Steps from one check to the next at the step now in use (at least 1).
static uint64_t check_every(const dem_world *w)
{
    const double interval = w->def.network_check_interval, chunk = w->def.network_check_chunk;
    uint64_t steps = chunk > 0 ? (uint64_t)(interval / chunk + 0.5) : 1;
    steps = steps ? steps : 1; // an interval under half a chunk: every chunk
    steps *= (uint64_t)((chunk > 0 ? chunk : interval) / w->dt + 0.5);
    return steps ? steps : 1;
}

// Of `left` steps, those before the next check is due (0: due now).
static uint64_t steps_before_check(const dem_world *w, uint64_t left)
{
    if (!checks_on(w)) return left;
    const uint64_t every = check_every(w), due = every > w->steps_since_check ? every - w->steps_since_check : 0;
    return due < left ? due : left;
}

// The check itself, and what it found in the world's totals.
static dem_status network_check(dem_world *w)
{
    const double t0 = omp_get_wtime();
    dem_network_dt_check c;
    const dem_status st = dem_world_check_network_dt(w, &c);
    dem_network_checks *k = &w->checks;
    k->wall_s += omp_get_wtime() - t0;
    k->checks++;
    if (!isnan(c.margin)) k->margin_min = isnan(k->margin_min) ? c.margin : fmin(k->margin_min, c.margin);
    k->lowered += (uint64_t)c.lowered;
    return st;
}

// `run` steps done: the check, if it is due.
static dem_status count_steps(dem_world *w, uint64_t run)
{
    if (!checks_on(w)) return DEM_OK;
    w->steps_since_check += run;
    if (w->steps_since_check < check_every(w)) return DEM_OK;
    w->steps_since_check = 0;
    return network_check(w);
}

dem_status dem_world_step(dem_world *w, uint64_t steps)
{
    dem_status st = dem_world_prepare(w);
    if (st != DEM_OK) return st;
    // A state that is already not finite (put there through
    // dem_world_set_granule_velocity, or left by an earlier fault) is reported
    // against its own granule before anything is computed from it: the force
    // evaluation would pass the NaN to its contact partners, and the first of
    // those by index would be named; the drift would make its position NaN,
    // which the domain test would report as an escape. One pass per call.
    size_t bad0 = first_nonfinite(w);
    if (bad0 != SIZE_MAX) return fault(w, DEM_ERR_NONFINITE, bad0, "non-finite state (NaN or infinity)");
    st = ensure_forces(w);
    const uint64_t step0 = w->step; // the clock counts the steps taken, also those of a run that faults
    for (uint64_t done = 0; st == DEM_OK && done < steps;) {
        const uint64_t run = steps_before_check(w, steps - done);
        st = step_run(w, run);
        done += run;
        if (st == DEM_OK) st = count_steps(w, run);
    }
    w->particle_steps += (w->step - step0) * (uint64_t)w->n;
    return st;
}
