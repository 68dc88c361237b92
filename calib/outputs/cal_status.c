// SPDX-License-Identifier: MIT
// What a calibration's outputs are, and what each value in them is (see cal_status.h).
#include "cal_status.h"

#include <math.h>
#include <string.h>

#include "cal_files.h"
#include "exp_common.h"
#include "exp_contact_rules.h"

// ---- one value -------------------------------------------------------------------

static void add_flag(cal_verdict *v, const char *flag)
{
    size_t used = strlen(v->flags);
    snprintf(v->flags + used, sizeof v->flags - used, "%s%s", used ? ";" : "", flag);
}

static void remove_flag(cal_verdict *v, const char *flag)
{
    char kept[sizeof v->flags] = "", *save = NULL;
    for (char *f = strtok_r(v->flags, ";", &save); f; f = strtok_r(NULL, ";", &save))
        if (strcmp(f, flag) != 0) snprintf(kept + strlen(kept), sizeof kept - strlen(kept), "%s%s", kept[0] ? ";" : "", f);
    snprintf(v->flags, sizeof v->flags, "%s", kept);
}

int cal_verdict_has_flag(const cal_verdict *v, const char *flag)
{
    size_t n = strlen(flag);
    for (const char *f = v->flags; (f = strstr(f, flag)) != NULL; f += n)
        if ((f == v->flags || f[-1] == ';') && (f[n] == '\0' || f[n] == ';')) return 1;
    return 0;
}

static const char *open_flag(int side) { return side > 0 ? "not_excluded_to_upper_bound" : "not_excluded_to_lower_bound"; }

// A value on a bound, relative to the bound's size (μr's bounds span decades).
static int on_bound(double value, double bound) { return fabs(value - bound) <= 1e-9 * fabs(bound); }

const char *cal_verdict_posterior_clause(const cal_verdict *v)
{
    if (cal_verdict_has_flag(v, "credible_correction_exact"))
        return "; its posterior takes a correction with no variance model as exact, and decides nothing";
    return cal_verdict_has_flag(v, "credible_wide") ? "; its posterior spans more than half the search range" : "";
}

// The width of friction `which`'s [lo, hi] as a fraction of its search range, on the search's scale.
static double range_fraction(const cal_bounds *b, int which, double lo, double hi)
{
    double u[2], v[2];
    cal_friction_to_unit(b, lo, lo, &u[0], &v[0]);
    cal_friction_to_unit(b, hi, hi, &u[1], &v[1]);
    return which ? v[1] - v[0] : u[1] - u[0];
}

static int outside(double value, double lo, double hi)
{
    // The ranges are written to 6 significant digits and read back the
    // same way from a stage file: a value at an end must not fall out of it.
    const double slack = 1e-6;
    return value < lo * (1 - slack) || value > hi * (1 + slack);
}

cal_verdict cal_verdict_friction(double value, cal_range g, const cal_bounds *b, int which, int angle_matched)
{
    const double bound_lo = which ? b->mu_r_min : b->mu_s_min, bound_hi = which ? b->mu_r_max : b->mu_s_max;
    cal_verdict v = {.status = CAL_VALUE_CALIBRATED};
    if (!isfinite(g.lo)) {
        v.status = CAL_VALUE_NOT_RUN;
        add_flag(&v, "stage_not_run");
        return v;
    }
    if (on_bound(value, bound_lo)) add_flag(&v, "at_lower_bound"), v.side = -1;
    if (on_bound(value, bound_hi)) add_flag(&v, "at_upper_bound"), v.side = +1;
    v.on_bound = v.side != 0;
    int out_identified = outside(value, g.lo, g.hi);
    int out_bracket = isfinite(g.bracket_lo) && outside(value, g.bracket_lo, g.bracket_hi);
    if (out_identified) add_flag(&v, "outside_identified");
    if (out_bracket) add_flag(&v, "outside_not_excluded");
    // The interval no run excludes, open to each bound it reaches; open to both, every value of the
    // search range fits; open to one, with the value off the bounds, the data close one side only.
    int open_lo = isfinite(g.bracket_lo) && on_bound(g.bracket_lo, bound_lo);
    int open_hi = isfinite(g.bracket_hi) && on_bound(g.bracket_hi, bound_hi);
    int none_excluded = open_lo && open_hi;
    if (none_excluded) add_flag(&v, "not_identified");
    if (angle_matched == 0) add_flag(&v, "angle_not_matched");
    // The strongest verdict wins: a value outside its own interval is no
    // result at all; one the data do not constrain is not identified; a
    // bound the data do not close gives one side only.
    if (out_identified || out_bracket) v.status = CAL_VALUE_NOT_A_RESULT, v.side = 0;
    else if (none_excluded) v.status = CAL_VALUE_NOT_IDENTIFIED, v.side = 0;
    else if (!v.side && (open_lo || open_hi)) {
        v.side = open_hi ? +1 : -1; // flagged only where it decides the status
        add_flag(&v, open_flag(v.side));
    }
    if (v.status == CAL_VALUE_CALIBRATED && v.side) {
        // Open upwards the data say only that μ is above the nearest
        // excluded value below (and the mirror on the lower bound).
        v.status = CAL_VALUE_ONE_SIDED;
        double other = v.side > 0 ? g.bracket_lo : g.bracket_hi;
        v.known = isfinite(other) ? other : value;
    } else if (v.status == CAL_VALUE_CALIBRATED && isfinite(g.bracket_lo) &&
               range_fraction(b, which, g.bracket_lo, g.bracket_hi) > CAL_CALIBRATED_MAX_WIDTH) {
        // Closed on both sides by the runs, but most of the range left: between, not chosen.
        v.status = CAL_VALUE_BOUNDED;
        v.between[0] = g.bracket_lo, v.between[1] = g.bracket_hi;
        add_flag(&v, "not_excluded_wide");
    }
    return v;
}

void cal_verdict_credible(cal_verdict *v, double value, const cal_credible *c)
{
    if (!c || !c->known || v->status == CAL_VALUE_NOT_RUN) return;
    if (c->correction_exact) {
        // A correction measured at one run (or fitted as a plane) has no variance model: the posterior's
        // width then counts nothing of how well this tier's runs measured it, so it neither closes nor
        // narrows what the runs leave, nor throws out what they keep. The runs' intervals decide alone.
        add_flag(v, "credible_correction_exact");
        return;
    }
    // Beyond an end that runs to its search bound, the value lies between that end and the bound: the
    // posterior does not hold it off (its 2.5 % and 97.5 % points sit inside the bounds by construction).
    int beyond_open_end = (value > c->hi && c->reaches_upper) || (value < c->lo && c->reaches_lower);
    if (outside(value, c->lo, c->hi) && !beyond_open_end) {
        // The flag that made it one-sided or bounded decides nothing now.
        if (v->status == CAL_VALUE_ONE_SIDED && !v->on_bound) remove_flag(v, open_flag(v->side));
        if (v->status == CAL_VALUE_BOUNDED) remove_flag(v, "not_excluded_wide");
        add_flag(v, "outside_credible");
        v->status = CAL_VALUE_NOT_A_RESULT, v->side = 0;
        return;
    }
    if (v->status == CAL_VALUE_BOUNDED) { // the runs close both sides: a narrow posterior pins the value
        if (c->width > CAL_CALIBRATED_MAX_WIDTH) add_flag(v, "credible_wide");
        else remove_flag(v, "not_excluded_wide"), v->status = CAL_VALUE_CALIBRATED;
        return;
    }
    if (v->status != CAL_VALUE_ONE_SIDED || v->on_bound || (v->side > 0 ? c->reaches_upper : c->reaches_lower)) return;
    if (c->width > CAL_CALIBRATED_MAX_WIDTH) {
        add_flag(v, "credible_wide"); // held off the bound, but not narrowed
        return;
    }
    remove_flag(v, open_flag(v->side)); // the posterior closes the side the runs' cut leaves open
    v->status = CAL_VALUE_CALIBRATED, v->side = 0, v->known = 0;
}

const char *cal_value_status_name(cal_value_status s)
{
    static const char *const names[] = {"input",          "derived",      "calibrated",   "one-sided", "bounded",
                                        "not identified", "not a result", "stage not run"};
    return names[s];
}

const char *cal_verdict_value_text(char *out, size_t len, double value, const cal_verdict *v)
{
    switch (v->status) {
    case CAL_VALUE_ONE_SIDED: snprintf(out, len, "%s %.3g", v->side > 0 ? "≥" : "≤", v->known); break;
    case CAL_VALUE_BOUNDED: snprintf(out, len, "%.3g – %.3g", v->between[0], v->between[1]); break;
    case CAL_VALUE_NOT_IDENTIFIED: snprintf(out, len, "not identified"); break;
    case CAL_VALUE_NOT_A_RESULT: snprintf(out, len, "not a result"); break;
    default: snprintf(out, len, "%.4g", value);
    }
    return out;
}

// ---- the table ---------------------------------------------------------------------

static const cal_range no_range = CAL_NO_RANGE_INIT;

static cal_table_row plain_row(const char *contact, const char *parameter, double value, const char *unit,
                               cal_value_status status)
{
    return (cal_table_row){contact, "", parameter, value, unit, no_range, {.status = status}};
}

// Friction `which` (0 μs, 1 μr) of a stage searched within b.
static cal_table_row friction_row(const char *contact, const char *material, int which, double value, cal_range g,
                                  const cal_bounds *b, int angle_matched, const cal_credible *credible)
{
    cal_table_row r = {contact, "", which ? "mu_r" : "mu_s", value, "-", g,
                       cal_verdict_friction(value, g, b, which, angle_matched)};
    cal_verdict_credible(&r.verdict, value, credible);
    snprintf(r.material, sizeof r.material, "%s", material);
    return r;
}

// The stiffness rows: stage 1's choice, or the config's where it did not choose.
static cal_table_row stiffness_row(const cal_outcome *o, const char *contact, const char *parameter, double k)
{
    const cal_table *t = &o->table;
    int own = strcmp(contact, "granule-granule") == 0 && strcmp(parameter, "k_n") == 0;
    cal_table_row r = plain_row(contact, parameter, k, "N/m", own ? CAL_VALUE_CALIBRATED : CAL_VALUE_DERIVED);
    if (!t->k_calibrated) {
        if (own) r.verdict.status = CAL_VALUE_NOT_RUN;
        add_flag(&r.verdict, "stage_not_run");
    } else if (!cal_tier_stiffness_on_drum(o->tier) && o->tier->cylinder_lambda != o->tier->lambda)
        add_flag(&r.verdict, "stiffness_at_cylinder_lambda"); // a drum-bed sweep ran at the drum's own λ
    return r;
}

int cal_table_rows(const cal_outcome *o, cal_table_row *rows)
{
    const cal_table *t = &o->table;
    const cal_bounds *gb = &o->config->granule, *wb = &o->config->wall;
    const char *gg = "granule-granule", *gw = "granule-boundary", *k_names[] = {"k_n", "k_s", "k_r"};
    int n = 0;
    rows[n++] = plain_row(gg, "density", t->density, "kg/m3", CAL_VALUE_INPUT);
    for (int k = 0; k < 3; ++k) rows[n++] = stiffness_row(o, gg, k_names[k], t->k_n);
    rows[n++] = plain_row(gg, "xi", t->xi, "-", CAL_VALUE_INPUT);
    const cal_credible(*cr)[2] = o->credible;
    rows[n++] = friction_row(gg, "", 0, t->gg_mu_s, t->gg_mu_s_range, gb, t->gg_angle_matched, &cr[0][0]);
    rows[n++] = friction_row(gg, "", 1, t->gg_mu_r, t->gg_mu_r_range, gb, t->gg_angle_matched, &cr[0][1]);
    for (int k = 0; k < 3; ++k) rows[n++] = stiffness_row(o, gw, k_names[k], exp_boundary_stiffness(t->k_n));
    rows[n++] = plain_row(gw, "xi", t->xi, "-", CAL_VALUE_INPUT);
    for (int w = 0; w < t->n_walls && n + 2 <= CAL_TABLE_MAX_ROWS; ++w) {
        int matched = t->wall_angle_matched[w];
        rows[n++] = friction_row(gw, t->wall_name[w], 0, t->wall_mu_s[w], t->wall_mu_s_range[w], wb, matched,
                                 &cr[1 + w][0]);
        rows[n++] = friction_row(gw, t->wall_name[w], 1, t->wall_mu_r[w], t->wall_mu_r_range[w], wb, matched,
                                 &cr[1 + w][1]);
    }
    return n;
}

// ---- the run -------------------------------------------------------------------------

cal_run_status cal_run_status_of(const cal_outcome *o)
{
    return (cal_run_status){.demonstration = cal_tier_is_demonstration(o->tier),
                            .tier = o->tier->name,
                            .drum_lambda = o->tier->lambda,
                            .cylinder_lambda = o->tier->cylinder_lambda,
                            .stiffness_on_drum = cal_tier_stiffness_on_drum(o->tier),
                            .angle_synthetic = o->angle_data_synthetic,
                            .csa_synthetic = o->csa_data_synthetic};
}

const char *cal_run_purpose(const cal_run_status *s) { return s->demonstration ? "demonstration" : "calibration"; }

const char *cal_run_data_text(char *out, size_t len, const cal_run_status *s)
{
    snprintf(out, len, "angle %s / CSA %s", s->angle_synthetic ? "synthetic" : "lab", s->csa_synthetic ? "synthetic" : "lab");
    return out;
}

const char *cal_run_stamp(char *out, size_t len, const cal_run_status *s)
{
    snprintf(out, len, "%s, tier '%s', drum λ = %g; angle: %s, CSA: %s", s->demonstration ? "DEMONSTRATION" : "CALIBRATION",
             s->tier, s->drum_lambda, s->angle_synthetic ? "SYNTHETIC" : "lab", s->csa_synthetic ? "SYNTHETIC" : "lab");
    return out;
}

void cal_run_status_banner(FILE *f, const cal_run_status *s, const char *prefix)
{
    if (s->demonstration)
        fprintf(f, "%sDEMONSTRATION - not a calibration of this powder: tier '%s' is marked `purpose: demonstration` "
                   "(too coarse for its values to stand for the powder).\n", prefix, s->tier);
    else fprintf(f, "%sCALIBRATION at tier '%s'.\n", prefix, s->tier);
    if (s->stiffness_on_drum)
        fprintf(f, "%sCoarse-grained (eq. 15-18): the drum and its stiffness sweep ran at lambda = %g; the values are "
                   "for simulations at lambda = %g.\n", prefix, s->drum_lambda, s->drum_lambda);
    else
        fprintf(f, "%sCoarse-grained (eq. 15-18): the drum ran at lambda = %g, the stiffness cylinder at lambda = %g; "
                   "the values are for simulations at lambda = %g.\n", prefix, s->drum_lambda, s->cylinder_lambda,
                s->drum_lambda);
    fprintf(f, "%sData: repose angle %s, occupied area (CSA) %s.\n", prefix,
            s->angle_synthetic ? "SYNTHETIC (simulated, not measured: see the data file's header)" : "from the lab",
            s->csa_synthetic ? "SYNTHETIC (simulated, not measured: see the data file's header)" : "from the lab");
    fprintf(f, "%sEach value's status: calibrated (chosen by the data), one-sided (a search bound the data do not "
               "close: >= or <=), bounded (the data exclude both ends but leave more than half the search range), "
               "not identified (the data exclude nothing in the search range), not a result (the "
               "search's choice lies outside the interval its own data leave, or outside its posterior's 95 %% "
               "credible interval), stage not run (the config's value), input, derived.\n", prefix);
}

void cal_table_caveats(FILE *f, const cal_outcome *o, const char *prefix)
{
    cal_table_row rows[CAL_TABLE_MAX_ROWS];
    int n = cal_table_rows(o, rows);
    for (int i = 0; i < n; ++i) {
        const cal_table_row *r = &rows[i];
        cal_value_status st = r->verdict.status;
        if (st == CAL_VALUE_INPUT || st == CAL_VALUE_DERIVED || st == CAL_VALUE_CALIBRATED) continue;
        fprintf(f, "%s%s %s%s%s = %.6g: %s", prefix, r->contact, r->material, r->material[0] ? " " : "", r->parameter,
                r->value, cal_value_status_name(st));
        const char *clause = cal_verdict_posterior_clause(&r->verdict);
        if (st == CAL_VALUE_ONE_SIDED)
            fprintf(f, ", only %s %.6g is known (%s%s)", r->verdict.side > 0 ? ">=" : "<=", r->verdict.known,
                    r->verdict.on_bound ? "the search stopped on its bound"
                                        : "no run excludes a value from there to the search's bound",
                    clause);
        if (st == CAL_VALUE_BOUNDED)
            fprintf(f, ", only %.6g - %.6g is known (the runs exclude both sides, leaving more than half the search "
                       "range%s)", r->verdict.between[0], r->verdict.between[1], clause);
        fprintf(f, " (%s)\n", r->verdict.flags);
    }
}
