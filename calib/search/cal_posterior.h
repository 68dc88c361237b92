// SPDX-License-Identifier: MIT
/// @file cal_posterior.h
/// What the data say about a friction stage's (μs, μr), beyond the Δχ² cut
/// over the runs made: the posterior of (μs, log10 μr) given the data and
/// their spreads, sampled by MCMC on the stage's map of the measurements, and
/// how far each measurement moves across each parameter's search range.
///
/// The model of a measurement at (u, v) of the unit square: the two-tier
/// stage's corrected map (the map tier's quadratic map plus the discrepancy
/// measured at this tier's runs), or, for a one-tier stage, a least-squares
/// map through its own candidates (cal_mf_fit: quadratic with 8 or more,
/// linear with 3 or more). Its spread: the data's (the angle's tolerance,
/// the CSA's lab and tier spreads), the map's rms residual and the kriging's
/// own standard deviation there (cal_mf_correction_sd), in quadrature. Prior:
/// flat over the search's bounds in μs and log10 μr.
#ifndef CAL_POSTERIOR_H
#define CAL_POSTERIOR_H

#include "cal_stages.h"

enum { CAL_POSTERIOR_CHAINS = 4 };

typedef struct cal_posterior {
    const char *model;                  ///< which map the posterior samples (see above)
    int n_y;                            ///< measurements: the angle, then the CSA at each speed
    char observable[CAL_MF_MAX_Y][32];  ///< "angle at 4 rpm", "CSA at 116 rpm"
    double data_sd[CAL_MF_MAX_Y];       ///< the data's spread of each
    int n;                              ///< samples kept, over every chain
    double *mu_s, *mu_r;                ///< the samples
    double acceptance;                  ///< of the Metropolis steps after burn-in
    /// Median and 95 % credible interval (2.5 and 97.5 percentiles) of μs [0]
    /// and μr [1]; reaches_lower / reaches_upper: the interval runs to within
    /// 3 % of the search range of that bound, so the data do not hold the
    /// parameter off it (a flat posterior, whose 2.5 % point sits at 2.5 % of
    /// the range, reaches both).
    double median[2], lo[2], hi[2];
    int reaches_lower[2], reaches_upper[2];
    /// The 95 % interval's width as a fraction of the search range, on the
    /// search's own scale (μs, log10 μr): 0.95 for a flat posterior.
    double width[2];
    /// The chains' medians, furthest apart, in units of the search range: a
    /// posterior the chains did not explore alike says so.
    double chain_spread[2];
    /// How far measurement i moves when μs [0] or log10 μr [1] crosses its
    /// whole search range (the other at its median), in the data's spreads:
    /// |value| < 1 means that measurement cannot tell that parameter at all.
    double sensitivity[CAL_MF_MAX_Y][2];
    /// What each measurement's spread in the likelihood is made of besides
    /// data_sd: the map's rms residual (the same everywhere; runs at this
    /// tier do not shrink it) and the kriging's sd at the posterior median (0
    /// for a one-tier map); spread: the three in quadrature there, as the
    /// likelihood counts them.
    double map_rms[CAL_MF_MAX_Y], kriging_sd[CAL_MF_MAX_Y], spread[CAL_MF_MAX_Y];
    /// NULL, or why the corrected map's correction has no variance model
    /// (cal_mf_correction_unmodelled: one run at this tier, an affine
    /// correction): then the posterior takes the correction as exact, its
    /// width counts nothing of how well this tier's runs measured it, and it
    /// decides no value's status (cal_verdict_credible). NULL for a one-tier
    /// map (no correction).
    const char *correction_unmodelled;
} cal_posterior;

/// Whether the map's residual, not the data's spread, is the larger part of
/// a measurement's spread for some measurement that moves by a data spread
/// across a parameter the data can tell: then the posterior is as wide as
/// the map tier's own fit, and runs at this tier cannot narrow it.
int cal_posterior_map_bound(const cal_posterior *p);

/// Sample the posterior of stage r (bounds b). 0 on success; 1 with a
/// message (and out->n = 0) when there is no map to sample (fewer than three
/// usable candidates). Deterministic: a fixed seed.
int cal_posterior_sample(const cal_friction_result *r, const cal_bounds *b, cal_posterior *out, char *err, size_t len);

/// Whether parameter k's interval reaches a search bound, as the report
/// says it after the interval: " (both bounds)", " (to the lower bound)",
/// " (to the upper bound)" or "".
const char *cal_posterior_reach_text(const cal_posterior *p, int k);

/// 1 if no measurement moves by one data spread across parameter p's search range (0: μs, 1: μr).
int cal_posterior_blind(const cal_posterior *p, int parameter);

/// A run at this tier narrows the posterior only where the map's own
/// uncertainty (the kriging's variance of the correction) holds it wide; where
/// the data's spread and the map's residual make the width, more runs cannot
/// narrow it. So: among the measurements that move by one data spread across
/// a parameter the data can tell (cal_posterior_blind), the one whose kriging
/// variance is the largest share of its whole variance, on average over the
/// posterior's samples; if that share reaches CAL_POSTERIOR_MAP_SHARE, the
/// next run goes to the sample where that measurement's share is largest.
#define CAL_POSTERIOR_MAP_SHARE 0.25

/// Which measurement asks for a run, and its share (see above).
typedef struct cal_posterior_need {
    int measurement; ///< index as in cal_posterior.observable; -1: none moves with a parameter the data tell
    double share;    ///< its kriging variance share, mean over the samples
} cal_posterior_need;

/// Where the next run of a two-tier stage goes (unit square), by the rule
/// above, from its posterior p (sampled on r's corrected map, r->has_map).
/// 0 with (u, v) when one is wanted; 1 when none (need says why).
int cal_posterior_next_run(const cal_friction_result *r, const cal_bounds *b, const cal_posterior *p, double *u,
                           double *v, cal_posterior_need *need);

void cal_posterior_free(cal_posterior *p);

#endif
