// SPDX-License-Identifier: MIT
/// @file exp_incline.h
/// A sphere on an inclined plane, started at rest: the one-granule check of
/// the wall contact's friction against a textbook answer. Down a plane tilted
/// by θ, with sliding friction μs and rolling friction μr (the rolling
/// torque's limit μr·R·N, docs/model.md), a solid sphere (I = 2/5 m R²)
///  - stays at rest while tan θ ≤ μr (the rolling spring holds it);
///  - rolls without slip, a = (5/7) g (sin θ − μr cos θ), while the friction
///    this needs, (2/7) m g sin θ + (5/7) μr m g cos θ, is within μs·N, that is
///    tan θ ≤ (7/2) μs − (5/2) μr (with μr = 0: tan θ ≤ (7/2) μs);
///  - slides otherwise, a = g (sin θ − μs cos θ).
/// The experiment measures the acceleration of the centre along the slope (a
/// straight-line fit of its velocity over time) and the slip of the contact
/// point, and states the analytic answer beside them.
///
/// Geometry: the plane is the wall y = 0 (normal +y) and gravity is tilted
/// instead, g (sin θ, −cos θ, 0): the same physics, with the slope along +x.
/// The sphere starts at x = 0 at its equilibrium overlap m g cos θ / k_n, so
/// no bounce precedes the motion. No coarse graining: one real granule.
///
/// The physics only: exp_incline_config.h loads a definition from YAML,
/// exp_incline_runner.h runs it and writes its files.
#ifndef EXP_INCLINE_H
#define EXP_INCLINE_H

#include <stddef.h>

#include "dem_world.h"

typedef struct exp_incline_def {
    double angle_deg;           ///< θ, the plane's tilt, in (0, 90)
    double diameter;            ///< m
    double density;             ///< kg/m³
    dem_contact_params contact; ///< sphere–plane contact (k_n, k_s, k_r, xi, μs, μr, damping)
    double gravity;             ///< m/s² (9.81)
    double duration;            ///< s of motion simulated
    double sample_interval;     ///< s between the velocity samples fitted
    double skip_fraction;       ///< the first this fraction of the duration is left out of the fit (the springs' transient)
} exp_incline_def;

exp_incline_def exp_default_incline_def(void);

/// Every field of a definition exp_incline_run would run, or 1 with a
/// message that starts with the field ("angle_deg = ...", "contact.mu_s = ...").
int exp_incline_check(const exp_incline_def *d, char *msg, size_t len);

typedef enum exp_incline_regime { EXP_INCLINE_REST, EXP_INCLINE_ROLLING, EXP_INCLINE_SLIDING } exp_incline_regime;

/// "rest", "rolling" or "sliding".
const char *exp_incline_regime_name(exp_incline_regime r);

/// The textbook answer for d (above): regime and acceleration along the slope.
typedef struct exp_incline_analytic {
    exp_incline_regime regime;
    double acceleration; ///< m/s²
} exp_incline_analytic;
exp_incline_analytic exp_incline_predict(const exp_incline_def *d);

typedef struct exp_incline_result {
    double acceleration;      ///< m/s²: slope of the centre's velocity along the slope over the fitted samples
    double spin_acceleration; ///< m/s²: slope of −ω_z R, the contact point's rolling speed (equals acceleration when rolling)
    double speed;             ///< m/s along the slope at the end
    double slip_speed;        ///< m/s: the contact point's speed over the plane at the end (v + ω_z R)
    double travel;            ///< m along the slope
    exp_incline_regime regime;///< measured: rest (|acceleration| < 1e-3 g), rolling (slip < 1e-2 of the speed), sliding
    exp_incline_analytic analytic;
    double relative_error;    ///< (acceleration − analytic) / analytic; absolute (m/s² over g) when the analytic is 0
    size_t samples;           ///< samples fitted
    double simulated_time_s;
} exp_incline_result;

/// Build the world, let the sphere go, sample and fit. Returns the world at
/// the end (the caller destroys it) or NULL with a message.
dem_world *exp_incline_run(const exp_incline_def *d, exp_incline_result *out, char *err, size_t len);

#endif
