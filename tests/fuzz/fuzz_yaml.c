// SPDX-License-Identifier: MIT
// libFuzzer target: the YAML loaders (libcyaml) on any bytes. Every input is
// read by each of them: the calibration config (calib/inputs/cal_config.c,
// with and without a --tier override), the drum experiment
// (experiments/drum/exp_drum_config.c, with and without --set overrides) and
// the explicit scene (experiments/scene/exp_scene.c).
// Invariant: a loader either accepts the file, and then what it returns
// holds what it validated (every number finite and in its range: the values
// the simulations will use), or refuses it with a non-empty message naming
// the file; never a crash, a leak or undefined behaviour (ASan, UBSan).
#include <math.h>
#include <string.h>

#include "cal_config.h"
#include "exp_drum.h"
#include "exp_drum_config.h"
#include "exp_scene.h"
#include "fuzz_common.h"

static char detail[256];

static void finite(const char *loader, const char *field, double v)
{
    if (isfinite(v)) return;
    char what[160];
    snprintf(what, sizeof what, "%s accepted a non-finite %s", loader, field);
    snprintf(detail, sizeof detail, "%s = %g", field, v);
    fuzz_violation(what, detail);
}

static void check_contact(const char *loader, const dem_contact_params *p)
{
    finite(loader, "k_n", p->k_n), finite(loader, "k_s", p->k_s), finite(loader, "k_r", p->k_r);
    finite(loader, "xi", p->xi), finite(loader, "mu_s", p->mu_s), finite(loader, "mu_r", p->mu_r);
}

// A tier's or rung's bed-building and averaging as the drum can run them.
static void known_fill(const char *fill_method, double average_time, double window, double max_time)
{
    exp_drum_fill_method m;
    if (fill_method && exp_drum_fill_method_from_name(fill_method, &m))
        fuzz_violation("cal_config_load accepted an unknown fill_method", fill_method);
    if (!(average_time >= 0 && 2 * window + average_time <= max_time))
        fuzz_violation("cal_config_load accepted an average_time that does not fit in max_time", NULL);
}

static void check_config(const cal_config *c, const char *path)
{
    const char *L = "cal_config_load";
    if (strcmp(c->path, path) != 0) fuzz_violation("cal_config_load: path not recorded", c->path);
    if (!cal_config_tier(c)) fuzz_violation("cal_config_load accepted a config whose tier is not defined", c->tier);
    if (!c->calibration || !c->repose_angle || !c->occupied_area || !c->granule_surface || !c->tier)
        fuzz_violation("cal_config_load accepted a config without a required string", NULL);
    const struct { const char *name; double v; } scalars[] = {
        {"density", c->density}, {"median_diameter", c->median_diameter}, {"geometric_sd", c->geometric_sd},
        {"truncation_sigmas", c->truncation_sigmas}, {"xi", c->xi}, {"diameter", c->diameter}, {"depth", c->depth},
        {"fill", c->fill}, {"stiffness_tolerance", c->stiffness_tolerance}, {"k_n", c->k_n},
        {"granule_mu_s", c->granule_mu_s}, {"granule_mu_r", c->granule_mu_r}, {"pour_mu_s", c->pour_mu_s},
        {"pour_mu_r", c->pour_mu_r}, {"granule.mu_s_min", c->granule.mu_s_min}, {"granule.mu_s_max", c->granule.mu_s_max},
        {"granule.mu_r_min", c->granule.mu_r_min}, {"granule.mu_r_max", c->granule.mu_r_max},
        {"wall.mu_s_min", c->wall.mu_s_min}, {"wall.mu_s_max", c->wall.mu_s_max}, {"wall.mu_r_min", c->wall.mu_r_min},
        {"wall.mu_r_max", c->wall.mu_r_max}};
    for (size_t k = 0; k < sizeof scalars / sizeof *scalars; ++k) finite(L, scalars[k].name, scalars[k].v);
    if (c->stiffness_count < 2) fuzz_violation("cal_config_load accepted fewer than 2 stiffness candidates", NULL);
    for (unsigned k = 0; k < c->stiffness_count; ++k) finite(L, "stiffness", c->stiffness[k]);
    for (unsigned k = 0; k < c->materials_count; ++k)
        if (!c->materials[k].name || !c->materials[k].surface) fuzz_violation("material without name or surface", NULL);
    for (unsigned k = 0; k < c->tiers_count; ++k) {
        const cal_tier *t = &c->tiers[k];
        finite(L, "tier lambda", t->lambda), finite(L, "tier slice_depth", t->slice_depth);
        finite(L, "tier max_time", t->max_time), finite(L, "tier window", t->window);
        finite(L, "tier sample_interval", t->sample_interval), finite(L, "tier cylinder_lambda", t->cylinder_lambda);
        finite(L, "tier steady_angle_tol_deg", t->steady_angle_tol_deg), finite(L, "tier angle_sd_deg", t->angle_sd_deg);
        finite(L, "tier steady_csa_tol_percent", t->steady_csa_tol_percent);
        known_fill(t->fill_method, t->average_time, t->window, t->max_time);
        for (unsigned j = 0; j < t->rpm_count; ++j) finite(L, "tier rpm", t->rpm[j]);
        if (t->angle_rule && strcmp(t->angle_rule, "constraint") != 0 && strcmp(t->angle_rule, "misfit") != 0)
            fuzz_violation("cal_config_load accepted an unknown angle_rule", t->angle_rule);
        if (t->csa_sd_percent_count > 1 && t->csa_sd_percent_count != t->rpm_count)
            fuzz_violation("cal_config_load accepted csa_sd_percent not one per speed", NULL);
        for (unsigned j = 0; j < t->csa_sd_percent_count; ++j)
            if (!(t->csa_sd_percent[j] >= 0 && t->csa_sd_percent[j] < 50))
                fuzz_violation("cal_config_load accepted a csa_sd_percent outside [0, 50)", NULL);
    }
    if (c->fidelity) {
        const cal_fidelity *f = c->fidelity;
        finite(L, "fidelity.budget_hours", f->budget_hours);
        for (unsigned j = 0; j < f->rpm_count; ++j) finite(L, "fidelity.rpm", f->rpm[j]);
        for (unsigned k = 0; k < f->rungs_count; ++k) {
            const cal_tier *r = &f->rungs[k];
            finite(L, "rung lambda", r->lambda), finite(L, "rung slice_depth", r->slice_depth);
            finite(L, "rung max_time", r->max_time), finite(L, "rung window", r->window);
            finite(L, "rung sample_interval", r->sample_interval);
            finite(L, "rung steady_angle_tol_deg", r->steady_angle_tol_deg);
            finite(L, "rung steady_csa_tol_percent", r->steady_csa_tol_percent);
            known_fill(r->fill_method, r->average_time, r->window, r->max_time);
        }
    }
}

static void load_config(const char *path, const char *tier)
{
    char err[2048] = "";
    cal_config *c = cal_config_load(path, tier, err, sizeof err);
    if (!c) {
        fuzz_check_failure_message("cal_config_load", path, err);
        return;
    }
    fuzz_report("cal_config_load", NULL);
    check_config(c, path);
    if (tier && strcmp(cal_config_tier(c)->name, tier) != 0) fuzz_violation("cal_config_load ignored the tier override", tier);
    cal_config_free(c);
}

static void load_drum(const char *path, int n_sets, char **sets)
{
    const char *L = "exp_drum_config_load";
    char err[2048] = "", msg[512] = "";
    exp_drum_yaml *y = exp_drum_config_load(path, n_sets, sets, err, sizeof err);
    if (!y) {
        fuzz_check_failure_message(L, path, err);
        return;
    }
    fuzz_report(L, NULL);
    exp_drum_def def;
    exp_drum_run_opts run;
    if (exp_drum_config_defs(y, &def, &run, msg, sizeof msg) || exp_drum_check(&def, msg, sizeof msg))
        fuzz_violation("exp_drum_config_load accepted a config its definitions refuse", msg);
    finite(L, "diameter", def.diameter), finite(L, "depth", def.depth), finite(L, "fill", def.fill);
    finite(L, "lambda", def.lambda), finite(L, "density", def.density), finite(L, "pixel", def.pixel);
    finite(L, "median_diameter", def.gsd.median_diameter), finite(L, "geometric_sd", def.gsd.geometric_sd);
    finite(L, "truncation_sigmas", def.gsd.truncation_sigmas);
    check_contact(L, &def.granule), check_contact(L, &def.wall), check_contact(L, &def.end_plate);
    for (unsigned k = 0; k < y->materials_count; ++k)
        finite(L, "material mu_s", y->materials[k].mu_s), finite(L, "material mu_r", y->materials[k].mu_r);
    finite(L, "rpm", run.rpm), finite(L, "max_time", run.max_time), finite(L, "window", run.window);
    finite(L, "sample_interval", run.sample_interval);
    if (!(run.start_tilt_deg >= 0 && run.start_tilt_deg <= 90))
        fuzz_violation("exp_drum_config_load accepted a start tilt outside [0, 90] degrees", NULL);
    if (!(run.max_time > 0 && run.window > 0 && run.sample_interval > 0))
        fuzz_violation("exp_drum_config_load accepted a non-positive time", NULL);
    exp_drum_config_free(y);
}

static void load_scene(const char *path)
{
    const char *L = "exp_scene_load";
    char err[2048] = "";
    exp_scene *s = exp_scene_load(path, err, sizeof err);
    if (!s) {
        fuzz_check_failure_message(L, path, err);
        return;
    }
    fuzz_report(L, NULL);
    finite(L, "duration", s->duration), finite(L, "output_interval", s->output_interval), finite(L, "dt", s->dt);
    if (!(s->duration > 0 && s->output_interval > 0 && s->dt >= 0)) fuzz_violation("exp_scene_load: bad times", NULL);
    if (!s->name || s->granules_count < 1) fuzz_violation("exp_scene_load: no name or no granules", NULL);
    for (unsigned k = 0; k < s->granules_count; ++k)
        if (!(s->granules[k].radius > 0 && s->granules[k].density > 0))
            fuzz_violation("exp_scene_load accepted a non-positive radius or density", NULL);
    for (unsigned k = 0; k < s->granules_count; ++k)
        finite(L, "granule radius", s->granules[k].radius), finite(L, "granule density", s->granules[k].density);
    exp_scene_free(s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char set_rpm[] = "rpm=40", set_wall[] = "wall=PTFE";
    static char *sets[] = {set_rpm, set_wall};
    const char *path = fuzz_write_temp(data, size);
    load_config(path, NULL);
    load_config(path, "ci");
    load_drum(path, 0, NULL);
    load_drum(path, 2, sets);
    load_scene(path);
    return 0;
}
