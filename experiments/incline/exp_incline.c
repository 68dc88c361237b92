// SPDX-License-Identifier: MIT
// A sphere on an inclined plane against the textbook answer (see
// exp_incline.h). The physics only: its config is exp_incline_config.c, its
// runner exp_incline_runner.c.
#include "exp_incline.h"

#include <math.h>
#include <string.h>

#include "exp_common.h"
#include "exp_contact_rules.h"

// Measured regimes. The tangential spring has no dashpot: held, the sphere
// rocks on it at ~1e-4 m/s (a 2 mm granule, k 400 N/m), so rest is told by
// the fitted acceleration, below this fraction of g. Rolling, the contact
// point slips by the spring's rocking and the lever arm's h/R (~1e-3 of the
// speed); sliding, by a fraction of the speed itself (0.5-0.8 at 40-60 deg):
// rolling is a slip below this fraction of the speed.
#define REST_ACCELERATION 1e-3
#define ROLLING_SLIP 1e-2

exp_incline_def exp_default_incline_def(void)
{
    exp_incline_def d;
    memset(&d, 0, sizeof d);
    d.angle_deg = 20;
    d.diameter = 0.002, d.density = 1800;
    d.contact = exp_granule_pair(400, 0.7, 0.5, 0, EXP_DAMPING_DEFAULT);
    d.gravity = 9.81;
    d.duration = 0.1, d.sample_interval = 1e-3, d.skip_fraction = 0.1;
    return d;
}

int exp_incline_check(const exp_incline_def *d, char *msg, size_t len)
{
    char sub[256];
    if (!(d->angle_deg > 0 && d->angle_deg < 90)) return exp_fail(msg, len, "angle_deg = %g: must be in (0, 90)", d->angle_deg);
    if (!(isfinite(d->diameter) && d->diameter > 0)) return exp_fail(msg, len, "diameter = %g: must be > 0", d->diameter);
    if (!(isfinite(d->density) && d->density > 0)) return exp_fail(msg, len, "density = %g: must be > 0", d->density);
    if (!(isfinite(d->gravity) && d->gravity > 0)) return exp_fail(msg, len, "gravity = %g: must be > 0", d->gravity);
    if (dem_contact_params_check(&d->contact, sub, sizeof sub)) return exp_fail(msg, len, "contact.%s", sub);
    if (!(d->contact.k_n > 0)) return exp_fail(msg, len, "k_n = %g: must be > 0", d->contact.k_n);
    if (!(isfinite(d->duration) && d->duration > 0 && d->duration <= 10))
        return exp_fail(msg, len, "duration = %g: must be in (0, 10] s", d->duration);
    if (!(d->sample_interval > 0 && d->sample_interval * 10 <= d->duration))
        return exp_fail(msg, len, "sample_interval = %g: must be > 0 and leave 10 samples in the duration", d->sample_interval);
    if (!(d->skip_fraction >= 0 && d->skip_fraction <= 0.5))
        return exp_fail(msg, len, "skip_fraction = %g: must be in [0, 0.5]", d->skip_fraction);
    return 0;
}

const char *exp_incline_regime_name(exp_incline_regime r)
{
    return r == EXP_INCLINE_REST ? "rest" : r == EXP_INCLINE_ROLLING ? "rolling" : "sliding";
}

exp_incline_analytic exp_incline_predict(const exp_incline_def *d)
{
    double th = d->angle_deg * DEM_PI / 180, s = sin(th), c = cos(th), t = tan(th), g = d->gravity;
    double mu_s = d->contact.mu_s, mu_r = d->contact.mu_r;
    if (t <= mu_r) return (exp_incline_analytic){EXP_INCLINE_REST, 0};
    // Rolling needs the friction (2/7) m g sinθ + (5/7) μr m g cosθ within μs m g cosθ.
    if (t <= 3.5 * mu_s - 2.5 * mu_r) return (exp_incline_analytic){EXP_INCLINE_ROLLING, 5.0 / 7.0 * g * (s - mu_r * c)};
    return (exp_incline_analytic){EXP_INCLINE_SLIDING, g * (s - mu_s * c)};
}

// The plane y = 0 and the sphere resting on it at its equilibrium overlap,
// gravity tilted by θ (the slope runs along +x).
static dem_world *build(const exp_incline_def *d, char *err, size_t len)
{
    double th = d->angle_deg * DEM_PI / 180, r = 0.5 * d->diameter;
    double travel = 0.5 * d->gravity * d->duration * d->duration; // free fall along the slope bounds it
    dem_world_def def = dem_default_world_def();
    def.gravity = dem_v3(d->gravity * sin(th), -d->gravity * cos(th), 0);
    def.granule = d->contact; // one granule: its own pair never touches, but it sets the a-priori step
    def.domain_lo = dem_v3(-4 * r, -2 * r, -4 * r);
    def.domain_hi = dem_v3(travel + 4 * r, 6 * r, 4 * r);
    dem_world *w = dem_world_create(&def, err, len);
    if (!w) return NULL;
    dem_wall_def plane = {.kind = DEM_WALL_PLANE, .point = {0, 0, 0}, .normal = {0, 1, 0}, .axis = {0, 1, 0},
                          .contact = d->contact, .name = "incline"};
    double mass = d->density * DEM_PI / 6 * d->diameter * d->diameter * d->diameter;
    double overlap = mass * d->gravity * cos(th) / d->contact.k_n;
    if (dem_world_add_wall(w, &plane) < 0 ||
        dem_world_add_granule(w, dem_v3(0, r - overlap, 0), dem_v3(0, 0, 0), dem_v3(0, 0, 0), r, d->density) < 0 ||
        dem_world_prepare(w) != DEM_OK) {
        exp_fail(err, len, "incline: %s", dem_world_error(w));
        dem_world_destroy(w);
        return NULL;
    }
    return w;
}

// Least-squares slopes of the samples' speeds over time.
typedef struct fit_sums {
    double n, t, tt, v, tv, u, tu;
} fit_sums;

static void fit_add(fit_sums *f, double t, double v, double u)
{
    f->n += 1, f->t += t, f->tt += t * t, f->v += v, f->tv += t * v, f->u += u, f->tu += t * u;
}

static double fit_slope(const fit_sums *f, double sy, double sty)
{
    double den = f->n * f->tt - f->t * f->t;
    return den > 0 ? (f->n * sty - f->t * sy) / den : NAN;
}

static void classify(const exp_incline_def *d, exp_incline_result *out)
{
    out->analytic = exp_incline_predict(d);
    out->regime = fabs(out->acceleration) < REST_ACCELERATION * d->gravity ? EXP_INCLINE_REST
                  : fabs(out->slip_speed) < ROLLING_SLIP * out->speed ? EXP_INCLINE_ROLLING
                                                                      : EXP_INCLINE_SLIDING;
    double a = out->analytic.acceleration;
    out->relative_error = a != 0 ? (out->acceleration - a) / a : out->acceleration / d->gravity;
}

dem_world *exp_incline_run(const exp_incline_def *d, exp_incline_result *out, char *err, size_t len)
{
    memset(out, 0, sizeof *out);
    if (exp_incline_check(d, err, len)) return NULL;
    dem_world *w = build(d, err, len);
    if (!w) return NULL;
    double r = 0.5 * d->diameter, dt = dem_world_dt(w);
    uint64_t per = (uint64_t)(d->sample_interval / dt + 0.5), total = (uint64_t)(d->duration / dt + 0.5);
    if (per == 0) per = 1;
    fit_sums f = {0};
    dem_granules_view g = dem_world_granules(w);
    for (uint64_t done = 0; done < total;) {
        uint64_t n = total - done < per ? total - done : per;
        if (dem_world_step(w, n) != DEM_OK) {
            exp_fail(err, len, "incline: %s", dem_world_error(w));
            dem_world_destroy(w);
            return NULL;
        }
        done += n;
        g = dem_world_granules(w);
        double t = dem_world_time(w);
        if (t >= d->skip_fraction * d->duration) fit_add(&f, t, g.velocity[0].x, -g.omega[0].z * r), out->samples++;
    }
    out->acceleration = fit_slope(&f, f.v, f.tv);
    out->spin_acceleration = fit_slope(&f, f.u, f.tu);
    out->speed = g.velocity[0].x;
    out->slip_speed = g.velocity[0].x + g.omega[0].z * r;
    out->travel = g.position[0].x;
    out->simulated_time_s = dem_world_time(w);
    classify(d, out);
    return w;
}
