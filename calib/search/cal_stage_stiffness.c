// SPDX-License-Identifier: MIT
// Stage 1 (section 4.1, Fig. 12): a poured bed's coordination number against
// the granule stiffness; keep the smallest k whose coordination number is
// within the seed-to-seed noise of the stiff limit. The bed is the poured
// cylinder, or the tier's drum's own bed (stiffness_scene: drum): the
// cylinder's knee did not move with its λ as eq. 15-18 would have it
// (results/stiffness_low_k/), so a tier may sweep where its drum runs.
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_files.h"
#include "cal_stages.h"
#include "exp_common.h"

static void summarise(cal_stiffness_result *s, const cal_record *rec, int seeds)
{
    for (int i = 0; i < s->n; ++i) {
        double sum = 0, sum2 = 0, wall = 0, phi = 0;
        int used = 0;
        for (int j = 0; j < seeds; ++j) {
            const cal_record *r = &rec[i * seeds + j];
            if (!cal_record_usable(r)) continue;
            sum += r->coordination, sum2 += r->coordination * r->coordination;
            wall += r->wall_contacts_per_granule, phi += r->solid_fraction;
            s->granules[i] = r->granules;
            used++;
        }
        s->failed[i] = seeds - used;
        s->cn_mean[i] = used ? sum / used : NAN;
        s->cn_sd[i] = used > 1 ? sqrt(fmax(0, (sum2 - sum * sum / used) / (used - 1))) : 0;
        s->wall_cn[i] = used ? wall / used : NAN;
        s->solid_fraction[i] = used ? phi / used : NAN;
    }
}

// Two standard errors of the difference of two means, from the pooled
// seed-to-seed spread: a k whose CN is closer than this to the stiff limit
// cannot be told apart from it with these seeds.
static double noise_tolerance(const cal_stiffness_result *s, int seeds)
{
    double pooled = 0;
    int m = 0;
    for (int i = 0; i < s->n; ++i)
        if (isfinite(s->cn_mean[i])) pooled += s->cn_sd[i] * s->cn_sd[i], m++;
    pooled = m ? sqrt(pooled / m) : 0;
    return 2 * pooled * sqrt(2.0 / seeds);
}

void cal_stiffness_choose(cal_stiffness_result *s)
{
    s->chosen_k = NAN;
    int first = s->n; // the softest candidate of the run within the noise of the stiff limit
    for (int i = s->n - 1; i >= 0; --i) {
        if (!isfinite(s->cn_mean[i]) || fabs(s->cn_mean[i] - s->stiff_limit) > s->tolerance) break;
        s->chosen_k = s->k[i], first = i;
    }
    // The CN departs from its stiff limit as k softens (more overlap, more
    // contacts: Fig. 12), so a real change persists down to the softest
    // candidate. If any softer candidate is back within the noise, the one
    // outside was noise too, and at this fidelity (few layers, little
    // pressure) the sweep cannot say where the change stops.
    s->resolved = isfinite(s->chosen_k) && first > 0;
    for (int i = 0; i < first && s->resolved; ++i)
        s->resolved = isfinite(s->cn_mean[i]) && fabs(s->cn_mean[i] - s->stiff_limit) > s->tolerance;
}

int cal_stage_stiffness(cal_env *env, const cal_config *c, const cal_tier *t, cal_stiffness_result *out, char *err,
                        size_t len)
{
    memset(out, 0, sizeof *out);
    double t0 = exp_wall_seconds();
    unsigned n_k;
    const double *stiffness = cal_tier_stiffness(c, t, &n_k);
    int seeds = t->seeds, n = (int)n_k;
    if (n > CAL_MAX_K) return exp_fail(err, len, "at most %d stiffness candidates", CAL_MAX_K);
    cal_bed_case *cases = calloc((size_t)(n * seeds), sizeof *cases);
    cal_record *rec = calloc((size_t)(n * seeds), sizeof *rec);
    if (!cases || !rec) return free(cases), free(rec), exp_fail(err, len, "out of memory");
    out->n = n;
    out->scene = cal_tier_stiffness_on_drum(t) ? "drum's own poured bed" : "poured cylinder";
    for (int i = 0; i < n; ++i) {
        out->k[i] = stiffness[i];
        for (int j = 0; j < seeds; ++j)
            cases[i * seeds + j] = cal_bed_case_make(c, t, stiffness[i], (uint64_t)(c->seed + j));
    }
    cal_env_set_stage(env, "stiffness");
    cal_progress_enter(env->progress, env->stage);
    int bad = cal_bed_evaluate(env, cases, n * seeds, rec, err, len);
    if (!bad) {
        summarise(out, rec, seeds);
        out->stiff_limit = out->cn_mean[n - 1];
        out->tolerance = c->stiffness_tolerance > 0 ? c->stiffness_tolerance : noise_tolerance(out, seeds);
        out->tolerance_rule = c->stiffness_tolerance > 0 ? "stiffness_tolerance of the config"
                                                          : "two standard errors of a difference of seed means";
        if (!isfinite(out->stiff_limit)) bad = exp_fail(err, len, "the stiffest %s (k_n = %g N/m) failed every seed", out->scene, out->k[n - 1]);
        else cal_stiffness_choose(out);
    }
    for (int i = 0; i < n * seeds; ++i) cal_record_free(&rec[i]);
    free(cases), free(rec);
    out->wall_time_s = exp_wall_seconds() - t0;
    return bad;
}
