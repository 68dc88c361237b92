// SPDX-License-Identifier: MIT
// The outputs of a calibration (see cal_report.h).
#include "cal_report.h"

#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cal_export.h"
#include "cal_figures.h"
#include "cal_files.h"
#include "cal_posterior.h"
#include "cal_status.h"
#include "exp_atomic_file.h"
#include "exp_common.h"
#include "exp_contact_rules.h"

// ---- the table ---------------------------------------------------------------

// ---- the posteriors -------------------------------------------------------------

// Each friction stage run now, its posterior (cal_posterior.h): [0] the
// granule stage, [1 + w] wall w. ok 0: not run now (read from a stage file),
// or no map to sample (why says so).
// The friction stages of an outcome: [0] granule–granule, [1 + w] wall w
// (cal_outcome.walls holds 16); a stage not run is NULL.
enum { MAX_STAGES = 17 };

static int n_stages(const cal_outcome *o) { return 1 + o->n_walls < MAX_STAGES ? 1 + o->n_walls : MAX_STAGES; }
static const cal_friction_result *stage_of(const cal_outcome *o, int i) { return i == 0 ? o->granule : o->walls[i - 1]; }
static const cal_bounds *stage_bounds(const cal_outcome *o, int i) { return i ? &o->config->wall : &o->config->granule; }

typedef struct posteriors {
    cal_posterior of[MAX_STAGES];
    int ok[MAX_STAGES];
    char why[MAX_STAGES][200];
} posteriors;

static void posteriors_sample(const cal_outcome *o, posteriors *p)
{
    memset(p, 0, sizeof *p);
    for (int i = 0; i < n_stages(o); ++i) {
        const cal_friction_result *r = stage_of(o, i);
        if (r) p->ok[i] = !cal_posterior_sample(r, stage_bounds(o, i), &p->of[i], p->why[i], sizeof p->why[i]);
    }
}

static void posteriors_free(posteriors *p)
{
    for (int i = 0; i < MAX_STAGES; ++i) cal_posterior_free(&p->of[i]);
}

// The posterior of a table row's friction, or NULL.
static const cal_posterior *row_posterior(const cal_outcome *o, const posteriors *p, const cal_table_row *row, int *param)
{
    *param = !strcmp(row->parameter, "mu_r");
    if (strcmp(row->parameter, "mu_s") && !*param) return NULL;
    for (int i = 0; i < n_stages(o); ++i) {
        const cal_friction_result *r = stage_of(o, i);
        if (r && p->ok[i] && !strcmp(r->material, row->material)) return &p->of[i];
    }
    return NULL;
}

static int write_table_csv(const char *dir, const cal_outcome *o, const posteriors *post, const cal_table_row *rows,
                           int n, char *err, size_t len)
{
    char path[1200], data[64];
    snprintf(path, sizeof path, "%s/calibrated_parameters.csv", dir);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    // identified_min/max: the range of the candidates the data cannot tell
    // apart (cal_friction_identify); not_excluded_min/max: its bracket, the
    // interval no evaluated candidate excludes (cal_range); empty where
    // nothing was calibrated. posterior_median, credible_min/max: the
    // posterior's median and 95 % credible interval (cal_posterior.h), empty
    // where the stage did not run now. status and flags: what the value is
    // (cal_status.h); tier, lambda, data and purpose: what the run is, on
    // every row, so that no comment line is needed and a row copied alone
    // still says it.
    cal_run_status rs = cal_run_status_of(o);
    cal_run_data_text(data, sizeof data, &rs);
    fputs("contact,material,parameter,value,unit,identified_min,identified_max,not_excluded_min,not_excluded_max,"
          "status,flags,tier,lambda,data,purpose,posterior_median,credible_min,credible_max\n", a.f);
    for (int i = 0; i < n; ++i) {
        const cal_range *g = &rows[i].range;
        fprintf(a.f, "%s,%s,%s,%.6g,%s,", rows[i].contact, rows[i].material, rows[i].parameter, rows[i].value, rows[i].unit);
        if (isfinite(g->lo)) fprintf(a.f, "%.6g,%.6g,", g->lo, g->hi);
        else fputs(",,", a.f);
        if (isfinite(g->bracket_lo)) fprintf(a.f, "%.6g,%.6g,", g->bracket_lo, g->bracket_hi);
        else fputs(",,", a.f);
        fprintf(a.f, "%s,%s,%s,%g,%s,%s,", cal_value_status_name(rows[i].verdict.status), rows[i].verdict.flags,
                rs.tier, rs.drum_lambda, data, cal_run_purpose(&rs));
        int p;
        const cal_posterior *q = row_posterior(o, post, &rows[i], &p);
        if (q) fprintf(a.f, "%.6g,%.6g,%.6g\n", q->median[p], q->lo[p], q->hi[p]);
        else fputs(",,\n", a.f);
    }
    return exp_atomic_commit(&a, err, len);
}

// The range, and a warning when the chosen value lies outside it: the choice
// is the search's best run of the deciding tier, while the range also holds the
// map tier's corrected candidates (report.md lists each with its origin).
static const char *range_cell(char out[160], cal_range g, double value)
{
    if (isfinite(g.lo) && isfinite(g.bracket_lo))
        snprintf(out, 160, "%.3g – %.3g (not excluded: %.3g – %.3g)", g.lo, g.hi, g.bracket_lo, g.bracket_hi);
    else if (isfinite(g.lo)) snprintf(out, 160, "%.3g – %.3g", g.lo, g.hi);
    else out[0] = '\0';
    if (isfinite(g.lo) && (value < g.lo || value > g.hi))
        strncat(out, "; the value lies outside it (report.md)", 160 - strlen(out) - 1);
    return out;
}

static const cal_table_row *find_row(const cal_table_row *rows, int n, const char *contact, const char *material,
                                     const char *parameter)
{
    for (int i = 0; i < n; ++i)
        if (!strcmp(rows[i].contact, contact) && !strcmp(rows[i].material, material) &&
            !strcmp(rows[i].parameter, parameter))
            return &rows[i];
    return NULL;
}

// The value as a person reads it, with what the search ended at where the
// data did not choose it.
static const char *value_cell(char out[224], const cal_table_row *r)
{
    char text[48];
    cal_verdict_value_text(text, sizeof text, r->value, &r->verdict);
    if (r->verdict.status == CAL_VALUE_NOT_IDENTIFIED)
        snprintf(out, 224, "%s (any in %.3g – %.3g; the search ended at %.3g)", text, r->range.bracket_lo,
                 r->range.bracket_hi, r->value);
    else if (r->verdict.status == CAL_VALUE_ONE_SIDED && r->verdict.on_bound)
        snprintf(out, 224, "%s (the search stopped on its bound %.3g)", text, r->value);
    else if (r->verdict.status == CAL_VALUE_ONE_SIDED)
        snprintf(out, 224, "%s (the search ended at %.3g; no run excludes a value between %.3g and the bound%s)", text,
                 r->value, r->verdict.known, cal_verdict_posterior_clause(&r->verdict));
    else if (r->verdict.status == CAL_VALUE_BOUNDED)
        snprintf(out, 224, "%s (the search ended at %.3g; no run excludes a value between these, more than half the "
                           "range%s)", text, r->value,
                 cal_verdict_posterior_clause(&r->verdict));
    else if (r->verdict.status == CAL_VALUE_NOT_A_RESULT)
        snprintf(out, 224, "%s (the search ended at %.3g, outside its own interval)", text, r->value);
    else snprintf(out, 224, "%s", text);
    return out;
}

typedef struct md_table {
    FILE *f;
    const cal_outcome *o;
    const posteriors *post;
} md_table;

// The posterior's median and 95 % credible interval of a friction row, or "".
static const char *posterior_cell(char out[96], const md_table *t, const cal_table_row *r)
{
    int p;
    const cal_posterior *q = row_posterior(t->o, t->post, r, &p);
    if (!q) return out[0] = '\0', out;
    snprintf(out, 96, "%.3g [%.3g – %.3g]%s", q->median[p], q->lo[p], q->hi[p], cal_posterior_reach_text(q, p));
    return out;
}

// One row of the Markdown table: label, material, value, status and flags, range, posterior, source.
static void md_row(const md_table *t, const char *contact, const char *label, const cal_table_row *r, const char *source)
{
    char value[224], range[160], posterior[96];
    fprintf(t->f, "| %s | %s | %s | %s | %s%s%s%s | %s | %s | %s |\n", contact, label, r->material, value_cell(value, r),
            cal_value_status_name(r->verdict.status), r->verdict.flags[0] ? " (" : "", r->verdict.flags,
            r->verdict.flags[0] ? ")" : "", range_cell(range, r->range, r->value), posterior_cell(posterior, t, r),
            source);
}

static int write_table_md(const char *dir, const cal_outcome *o, const posteriors *post, const cal_table_row *rows,
                          int n, char *err, size_t len)
{
    const cal_table *t = &o->table;
    char path[1200];
    snprintf(path, sizeof path, "%s/calibrated_parameters.md", dir);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    cal_run_status rs = cal_run_status_of(o);
    cal_run_status_banner(f, &rs, "> ");
    fputs("\n| Contact | Parameter | Material | Value | Status | Identified range (95 %) | Posterior median [95 % "
          "credible] | Source |\n|---|---|---|---|---|---|---|---|\n", f);
    const md_table m = {f, o, post};
    const char *gg = "granule-granule", *gw = "granule-boundary";
    md_row(&m, "Granule–granule", "Granule density ρ_g (kg/m³)", find_row(rows, n, gg, "", "density"), "config");
    md_row(&m, "", "Normal, tangential, rolling stiffness k_n = k_s = k_r (N/m)", find_row(rows, n, gg, "", "k_n"),
           t->k_source);
    md_row(&m, "", "Damping ratio ξ", find_row(rows, n, gg, "", "xi"), "config");
    md_row(&m, "", "Sliding friction μs,g-g", find_row(rows, n, gg, "", "mu_s"), t->gg_source);
    md_row(&m, "", "Rolling friction μr,g-g", find_row(rows, n, gg, "", "mu_r"), t->gg_source);
    md_row(&m, "Granule–boundary", "k_n = k_s = k_r (N/m)", find_row(rows, n, gw, "", "k_n"),
           "2 k_n, springs in series (Table 3)");
    md_row(&m, "", "Damping ratio ξ", find_row(rows, n, gw, "", "xi"), "config");
    for (int w = 0; w < t->n_walls; ++w)
        md_row(&m, "", "Sliding friction μs,g-s", find_row(rows, n, gw, t->wall_name[w], "mu_s"), t->wall_source[w]);
    for (int w = 0; w < t->n_walls; ++w)
        md_row(&m, "", "Rolling friction μr,g-s", find_row(rows, n, gw, t->wall_name[w], "mu_r"), t->wall_source[w]);
    return exp_atomic_commit(&a, err, len);
}

typedef struct h5_row {
    char contact[24], material[32], parameter[16], unit[8], status[16], flags[192];
    double value, identified_min, identified_max; ///< NaN: not calibrated
} h5_row;

// A string attribute of the file's root: what the run is.
static int h5_root_string(hid_t file, const char *name, const char *value)
{
    hid_t type = H5Tcopy(H5T_C_S1), space = H5Screate(H5S_SCALAR);
    H5Tset_size(type, strlen(value) + 1);
    hid_t attr = H5Acreate2(file, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
    int bad = attr < 0 || H5Awrite(attr, type, value) < 0;
    if (attr >= 0) H5Aclose(attr);
    H5Sclose(space);
    H5Tclose(type);
    return bad;
}

static int h5_run_status(hid_t file, const cal_outcome *o)
{
    cal_run_status rs = cal_run_status_of(o);
    char data[64], lambda[32], cylinder[32];
    snprintf(lambda, sizeof lambda, "%g", rs.drum_lambda);
    snprintf(cylinder, sizeof cylinder, "%g", rs.cylinder_lambda);
    return h5_root_string(file, "purpose", cal_run_purpose(&rs)) || h5_root_string(file, "tier", rs.tier) ||
           h5_root_string(file, "lambda", lambda) || h5_root_string(file, "cylinder_lambda", cylinder) ||
           h5_root_string(file, "data", cal_run_data_text(data, sizeof data, &rs)) ||
           h5_root_string(file, "granucal", exp_version());
}

static void h5_rows(const cal_table_row *rows, int n, h5_row *data)
{
    for (int i = 0; i < n; ++i) {
        snprintf(data[i].contact, sizeof data[i].contact, "%s", rows[i].contact);
        snprintf(data[i].material, sizeof data[i].material, "%s", rows[i].material);
        snprintf(data[i].parameter, sizeof data[i].parameter, "%s", rows[i].parameter);
        snprintf(data[i].unit, sizeof data[i].unit, "%s", rows[i].unit);
        snprintf(data[i].status, sizeof data[i].status, "%s", cal_value_status_name(rows[i].verdict.status));
        snprintf(data[i].flags, sizeof data[i].flags, "%s", rows[i].verdict.flags);
        data[i].value = rows[i].value;
        data[i].identified_min = rows[i].range.lo, data[i].identified_max = rows[i].range.hi;
    }
}

static int write_table_h5(const char *dir, const cal_outcome *o, const cal_table_row *rows, int n, char *err,
                          size_t len)
{
    char path[1200], tmp[1300];
    snprintf(path, sizeof path, "%s/calibrated_parameters.h5", dir);
    exp_temporary_name(path, tmp, sizeof tmp);
    h5_row *data = calloc((size_t)n, sizeof *data);
    if (!data) return exp_fail(err, len, "out of memory");
    h5_rows(rows, n, data);
    hid_t file = H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    hid_t type = H5Tcreate(H5T_COMPOUND, sizeof(h5_row));
    enum { N_STRINGS = 6 };
    size_t sizes[N_STRINGS] = {24, 32, 16, 8, 16, 192};
    size_t offsets[N_STRINGS] = {offsetof(h5_row, contact), offsetof(h5_row, material), offsetof(h5_row, parameter),
                                 offsetof(h5_row, unit),    offsetof(h5_row, status),   offsetof(h5_row, flags)};
    const char *names[N_STRINGS] = {"contact", "material", "parameter", "unit", "status", "flags"};
    hid_t strings[N_STRINGS];
    for (int k = 0; k < N_STRINGS; ++k) {
        strings[k] = H5Tcopy(H5T_C_S1);
        H5Tset_size(strings[k], sizes[k]);
        H5Tinsert(type, names[k], offsets[k], strings[k]);
    }
    H5Tinsert(type, "value", offsetof(h5_row, value), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "identified_min", offsetof(h5_row, identified_min), H5T_NATIVE_DOUBLE);
    H5Tinsert(type, "identified_max", offsetof(h5_row, identified_max), H5T_NATIVE_DOUBLE);
    hsize_t dims[1] = {(hsize_t)n};
    hid_t space = H5Screate_simple(1, dims, NULL);
    hid_t set = file >= 0 ? H5Dcreate2(file, "calibrated_parameters", type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int bad = set < 0 || H5Dwrite(set, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0 || h5_run_status(file, o);
    if (set >= 0) H5Dclose(set);
    H5Sclose(space);
    for (int k = 0; k < N_STRINGS; ++k) H5Tclose(strings[k]);
    H5Tclose(type);
    if (file >= 0) bad |= H5Fclose(file) < 0;
    free(data);
    if (bad || rename(tmp, path) != 0) return exp_fail(err, len, "%s: cannot write", path);
    return 0;
}

// ---- every simulation ------------------------------------------------------------

// The distinct simulations a calibration used: a run two stages share (two wall
// materials with the same data, the same candidate) is counted once. Drum
// runs are counted by level: TALLY_LEVEL the tier's own, TALLY_LEVEL + 1 its
// map tier's, + 2 that tier's map tier's...
enum { TALLY_CYLINDER, TALLY_LEVEL, TALLY_KINDS = TALLY_LEVEL + 1 + CAL_MAX_MAP_DEPTH };
typedef struct sim_tally {
    char (*hash)[17];
    int n, cap;
    int count[TALLY_KINDS];
    double core_s[TALLY_KINDS];
} sim_tally;

static void tally_add(sim_tally *t, const char *hash, int kind, const cal_record *rec)
{
    for (int i = 0; i < t->n; ++i)
        if (strcmp(t->hash[i], hash) == 0) return;
    if (t->n == t->cap) {
        int cap = t->cap ? 2 * t->cap : 256;
        char(*grown)[17] = realloc(t->hash, (size_t)cap * sizeof *grown);
        if (!grown) return; // the count is then short; the table and records are unaffected
        t->hash = grown, t->cap = cap;
    }
    memcpy(t->hash[t->n++], hash, 17);
    t->count[kind]++, t->core_s[kind] += cal_record_cost_s(rec);
}

// Candidate i's records on bed b of tier t, the tier at `level` of the
// stage's levels, one row a speed.
static void bed_simulations(FILE *f, const cal_outcome *o, const cal_tier *t, int level, const cal_friction_result *r,
                            int i, int b, const char *store, sim_tally *tally)
{
    char stage[64];
    cal_progress_level_name(r->material[0] ? r->material : "granule", level, stage, sizeof stage);
    const cal_candidate *k = &r->cand[i];
    cal_drum_case dc = cal_friction_case(o->config, t, r, k->mu_s, k->mu_r, b);
    double rpm[CAL_MAX_RPM + 1];
    int n = r->n_rpm;
    memcpy(rpm, r->rpm, sizeof(double) * (size_t)n);
    int has_angle = 0;
    for (int j = 0; j < n; ++j) has_angle |= rpm[j] == r->angle_rpm;
    if (!has_angle) rpm[n++] = r->angle_rpm;
    for (int j = 0; j < n; ++j) {
        char key[2048], hash[17], err[256];
        cal_drum_key(&dc, rpm[j], key, sizeof key);
        cal_store_hash(key, hash);
        cal_record rec;
        if (cal_store_get(store, key, &rec, err, sizeof err) != 0) continue;
        fprintf(f, "%s,%d,%s,drum,%.6g,%.6g,%g,%s,\"%s\",%.4f,%.4f,%.4f,%.4f,%d,%.4f,%.1f,%.1f,%.4g,%d,%.6g,%.1f\n", stage,
                i + 1, hash, k->mu_s, k->mu_r, rpm[j], rec.status, rec.reason ? rec.reason : "", rec.angle_deg,
                rec.angle_sd_deg, rec.csa_percent, rec.csa_sd_percent, rec.steady, rec.simulated_time_s, rec.wall_time_s,
                rec.fill_wall_time_s, rec.particle_steps, rec.granules, rec.dt_s, rec.peak_rss_mb);
        tally_add(tally, hash, TALLY_LEVEL + level, &rec);
        cal_record_free(&rec);
    }
}

// A stage's simulations: its own candidates', and in a two-tier stage each
// level's below, found through the predicted candidates that stand for them
// (a map candidate with a failed speed has none, and is not listed).
static void simulations_of(FILE *f, const cal_outcome *o, const cal_friction_result *r, const char *store,
                           sim_tally *tally)
{
    for (int i = 0; i < r->n; ++i) {
        int level = r->cand[i].predicted ? r->cand[i].level : 0;
        const cal_tier *t = cal_tier_map_level(o->config, o->tier, level);
        for (int b = 0; t && b < cal_tier_beds(t); ++b) bed_simulations(f, o, t, level, r, i, b, store, tally);
    }
}

static int write_simulations(const char *dir, const char *store, const cal_outcome *o, sim_tally *tally, char *err,
                             size_t len)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/simulations.csv", dir);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    fputs("stage,candidate,record,experiment,mu_s,mu_r,rpm_or_k_n,status,reason,angle_deg,angle_sd_deg,csa_percent,"
          "csa_sd_percent,steady,simulated_time_s,wall_time_s,fill_wall_time_s,particle_steps,granules,"
          "dt_s_or_coordination,peak_rss_mb\n",
          a.f);
    const cal_stiffness_result *s = o->stiffness;
    for (int i = 0; s && i < s->n; ++i)
        for (int j = 0; j < o->tier->seeds; ++j) {
            cal_bed_case bed = cal_bed_case_make(o->config, o->tier, s->k[i], (uint64_t)(o->config->seed + j));
            char key[2048], hash[17], e2[256];
            cal_bed_key(&bed, key, sizeof key);
            cal_store_hash(key, hash);
            cal_record rec;
            if (cal_store_get(store, key, &rec, e2, sizeof e2) != 0) continue;
            fprintf(a.f, "stiffness,%d,%s,%s,%.6g,%.6g,%g,%s,\"%s\",,,,,1,%.4f,%.1f,0,,%d,%.5f,%.1f\n", i + 1, hash,
                    bed.on_drum ? "drum_bed" : "cylinder", o->config->pour_mu_s, o->config->pour_mu_r, s->k[i], rec.status,
                    rec.reason ? rec.reason : "", rec.simulated_time_s, rec.wall_time_s, rec.granules, rec.coordination,
                    rec.peak_rss_mb);
            tally_add(tally, hash, TALLY_CYLINDER, &rec);
            cal_record_free(&rec);
        }
    if (o->granule) simulations_of(a.f, o, o->granule, store, tally);
    for (int w = 0; w < o->n_walls; ++w) simulations_of(a.f, o, o->walls[w], store, tally);
    return exp_atomic_commit(&a, err, len);
}

// ---- report -------------------------------------------------------------------------

// One end of an identified range: at the search bound, bracketed by an
// excluded candidate, or open (nothing evaluated beyond it).
static void range_end(FILE *f, const char *side, double end, double beyond, double bound)
{
    if (fabs(end - bound) <= 1e-9 * fabs(bound))
        fprintf(f, "reaches the search's %s bound (the data do not bound it there)", side);
    else if (isfinite(beyond))
        fprintf(f, "%s end between %.3g and the excluded %.3g", side, end, beyond);
    else fprintf(f, "%s end not bracketed (nothing evaluated beyond %.3g)", side, end);
}

static void report_range(FILE *f, const char *name, cal_range g, double lo_bound, double hi_bound)
{
    fprintf(f, "- %s from %.4g to %.4g: ", name, g.lo, g.hi);
    range_end(f, "lower", g.lo, g.below, lo_bound);
    fputs("; ", f);
    range_end(f, "upper", g.hi, g.above, hi_bound);
    fputs(".\n", f);
}

// The not-excluded intervals read along the other parameter (cal_friction_range_along), beside the stage's.
static void report_along(FILE *f, const cal_friction_result *r, const cal_bounds *b)
{
    const char *name[2] = {"μs", "μr"};
    const cal_range *own[2] = {&r->mu_s_range, &r->mu_r_range};
    fputs("- Read along the other friction (an excluded candidate brackets only where its other friction lies inside "
          "that one's identified range, as a profile over it would; no status reads this):",
          f);
    for (int p = 0; p < 2; ++p) {
        cal_range g = cal_friction_range_along(r, p, b);
        fprintf(f, "%s %s not excluded %.3g – %.3g", p ? ";" : "", name[p], g.bracket_lo, g.bracket_hi);
        if (g.bracket_lo == own[p]->bracket_lo && g.bracket_hi == own[p]->bracket_hi) fputs(" (the same)", f);
        else fprintf(f, " (the stage's interval: %.3g – %.3g)", own[p]->bracket_lo, own[p]->bracket_hi);
    }
    fputs(".\n", f);
}

static void report_identified(FILE *f, const cal_friction_result *r, const cal_bounds *b)
{
    int tier_sd = 0;
    for (int j = 0; j < r->n_rpm; ++j) tier_sd |= r->csa_tier_sd[j] > 0;
    fprintf(f, "\nWhat the data identify: every candidate's χ² over the angle (by its tolerance) and the CSA speeds "
               "(by the lab's spread%s), each spread with the candidate's own uncertainty in quadrature (a "
               "prediction's sd; the spread of a run's series where it did not reach steady); the candidates within "
               "Δχ² = %.2f of the least run's (one parameter's 95 %% interval) are ones these measurements cannot "
               "tell from the best (%d of %d). A prediction below the least run's (Δχ² < 0) fits only as well as "
               "the map knows: it widens what is not excluded, and never sets the least:\n\n",
            tier_sd ? " and this tier's measured seed spread" : " only: this tier's seed spread is not "
                      "measured (csa_sd_percent), so the ranges are too narrow",
            r->chi2_threshold, r->identified_count, r->n);
    fputs("| candidate | from | μs | μr | angle (°) | χ² | Δχ² | told apart |\n|---|---|---|---|---|---|---|---|\n", f);
    for (int i = 0; i < r->n; ++i) {
        const cal_candidate *k = &r->cand[i];
        char own[32] = ""; // the angle's own uncertainty, where the χ² counted one
        double sd = cal_candidate_own_sd(k, 0);
        if (sd > 0) snprintf(own, sizeof own, " ± %.2g", sd);
        fprintf(f, "| %d | %s | %.4g | %.4g | %.2f%s | %.3g | %.3g | %s |\n", i + 1, k->origin ? k->origin : "", k->mu_s,
                k->mu_r, k->angle_deg, own, k->chi2, k->chi2 - r->chi2_least, k->identified ? "no" : "yes");
    }
    fputc('\n', f);
    if (!isfinite(r->mu_s_range.lo)) return;
    report_range(f, "μs", r->mu_s_range, b->mu_s_min, b->mu_s_max);
    report_range(f, "μr", r->mu_r_range, b->mu_r_min, b->mu_r_max);
    report_along(f, r, b);
}

// One level's row: its tier, what it ran and cost, what its own search chose, how it ended.
static void level_row(FILE *f, int level, const cal_level *l)
{
    fprintf(f, "| %d | %s | %g | %d | %d | %.3f | %.0f | %.4g, %.4g, %.2f° | %s |\n", level, l->tier, l->lambda, l->runs,
            l->simulations, l->core_s / 3600, l->wall_time_s, l->best_mu_s, l->best_mu_r, l->best_angle_deg,
            l->outcome ? l->outcome : "its whole one-tier search");
}

// A multilevel stage (the map tier maps with another): each level, the
// cheapest first, with what it ran, cost and chose, so that a reader sees
// what each level bought.
static void report_levels(FILE *f, const cal_friction_result *r, const cal_tier *t)
{
    fputs("Levels, the cheapest first: each level's result (its runs and, above the first, its predicted candidates) "
          "is the map of the level above, fitted by least squares with each point weighed by its own spread (a "
          "prediction by the run it stands for and the kriging's spread where it stands), and corrected only by the "
          "discrepancy measured at that level's own runs.\n\n| level | tier | λ | runs | simulations | core-hours | "
          "wall (s) | its choice: μs, μr, angle | outcome |\n|---|---|---|---|---|---|---|---|---|\n", f);
    for (int k = r->n_levels - 1; k >= 0; --k) level_row(f, r->n_levels - k, &r->level[k]);
    cal_level own = {.lambda = t->lambda, .runs = r->expensive_candidates, .simulations = r->simulations,
                     .core_s = r->core_s, .wall_time_s = r->wall_time_s, .outcome = r->two_tier_outcome,
                     .best_mu_s = NAN, .best_mu_r = NAN, .best_angle_deg = NAN};
    snprintf(own.tier, sizeof own.tier, "%s", t->name);
    if (r->best >= 0)
        own.best_mu_s = r->cand[r->best].mu_s, own.best_mu_r = r->cand[r->best].mu_r,
        own.best_angle_deg = r->cand[r->best].angle_deg;
    level_row(f, r->n_levels + 1, &own);
    fputc('\n', f);
}

// How much of the search box the map tier's candidates span (the predicted
// candidates stand where they ran): outside it the map extrapolates, and the
// correction measured there is the map's error as much as the tiers'.
static void report_map_span(FILE *f, const cal_friction_result *r, const cal_bounds *b)
{
    double s_lo = INFINITY, s_hi = -INFINITY, r_lo = INFINITY, r_hi = -INFINITY;
    for (int i = 0; i < r->n; ++i)
        if (r->cand[i].predicted) {
            const cal_candidate *k = &r->cand[i];
            s_lo = fmin(s_lo, k->mu_s), s_hi = fmax(s_hi, k->mu_s), r_lo = fmin(r_lo, k->mu_r), r_hi = fmax(r_hi, k->mu_r);
        }
    if (!(s_lo <= s_hi)) return;
    int whole = s_lo <= b->mu_s_min && s_hi >= b->mu_s_max && r_lo <= b->mu_r_min && r_hi >= b->mu_r_max;
    fprintf(f, "The map's candidates span μs %.4g–%.4g and μr %.4g–%.4g of the search box (μs %.4g–%.4g, μr "
               "%.4g–%.4g)%s.\n\n", s_lo, s_hi, r_lo, r_hi, b->mu_s_min, b->mu_s_max, b->mu_r_min, b->mu_r_max,
            whole ? ": all of it" : "; beyond that span the map extrapolates, and a run there measures its error as "
                                    "much as the tiers' (`design_corners` adds the box's corners)");
}

// A two-tier stage: what the map tier cost, what this tier's runs measured
// against it, and how the loop ended; with levels, each level first.
static void report_two_tier(FILE *f, const cal_friction_result *r, const cal_tier *t, const cal_bounds *b)
{
    if (r->n_levels > 1) report_levels(f, r, t);
    int predicted = 0;
    for (int i = 0; i < r->n; ++i) predicted += r->cand[i].predicted;
    int levels = r->n_levels > 1; // the map tier's result is its runs and its own predictions
    fprintf(f, "Two tiers: tier '%s' mapped the plane (%d %s, %.0f s); this tier ran %d candidate(s) where the "
               "corrected map put the optimum (%.0f s). Outcome: %s. The correction measured between the "
               "tiers (this tier minus the map, carried over the plane by %s, at the last run): angle %+.2f°",
            r->level[0].tier, r->level[0].runs, levels ? "runs of its own, on its own map" : "candidates",
            r->level[0].wall_time_s, r->expensive_candidates - r->posterior_runs - r->return_runs, r->wall_time_s,
            r->two_tier_outcome ? r->two_tier_outcome : "not run", r->map_correction ? r->map_correction : "-",
            r->correction[0]);
    for (int j = 0; j < r->n_rpm; ++j) fprintf(f, ", CSA at %g rpm %+.2f points", r->rpm[j], r->correction[1 + j]);
    fprintf(f, ". The %d candidates marked \"map + correction\" below are the map tier's runs%s plus the correction "
               "where they stand, "
               "not runs of this tier: they enter the identified ranges, never the choice.\n\n",
            predicted, levels ? " and its predicted candidates" : "");
    report_map_span(f, r, b);
    if (t->angle_aim_sd > 0)
        fprintf(f, "Each run of the loop was aimed where the corrected map's angle stands %g standard deviation(s) of "
                   "what a run there would read (this tier's run noise and the kriging's sd of the correction) inside "
                   "the angle's tolerance, at most at its centre (angle_aim_sd); the choice among the runs is the "
                   "stage's own rule.\n\n",
                t->angle_aim_sd);
    if (t->posterior_runs > 0)
        fprintf(f, "After the loop, at most %d more run(s) of this tier where the posterior on the corrected map is "
                   "still held wide by the map's own uncertainty: each at the posterior sample where the kriging's "
                   "variance is the largest share of a measurement's whole variance, and none once that share, "
                   "averaged over the posterior, is below %.0f %% for every measurement that moves with a parameter "
                   "the data can tell (there the width is the data's and the map's residual, which runs cannot narrow). Made: %d; %s; "
                   "the last share seen: %.0f %% (%s).\n\n",
                t->posterior_runs, 100 * CAL_POSTERIOR_MAP_SHARE, r->posterior_runs,
                r->posterior_runs_outcome ? r->posterior_runs_outcome : "not run", 100 * r->posterior_share,
                r->posterior_share_of[0] ? r->posterior_share_of : "-");
    if (t->return_runs > 0)
        fprintf(f, "Then, where the posterior's runs were made, at most %d more back at the corrected map's optimum "
                   "(those runs moved the correction, and so the optimum): the loop resumed. Made: %d; %s.\n\n",
                t->return_runs, r->return_runs,
                r->return_outcome ? r->return_outcome : "not resumed (no run after the loop)");
}

static void report_friction(FILE *f, const cal_friction_result *r, const cal_bounds *bounds, const cal_tier *t)
{
    const char *stage = r->material[0] ? r->material : "granule-granule";
    fprintf(f, "\n## %s (surface '%s' in the data)\n\n", stage, r->surface);
    if (r->material[0]) fprintf(f, "Granule–granule frozen at μs = %.4g, μr = %.4g. ", r->frozen_mu_s, r->frozen_mu_r);
    fprintf(f, "Target angle %.2f° at %g rpm", r->angle_target, r->angle_rpm);
    fprintf(f, ", tolerance ±%.2f° (lab spread and this tier's spread combined). CSA at %d speeds. ", r->angle_tolerance,
            r->n_rpm);
    if (r->n_levels) report_two_tier(f, r, t, bounds);
    else fprintf(f, "NLopt COBYLA: %s. %d candidates, %.0f s.\n\n", r->nlopt_result, r->n, r->wall_time_s);
    if (r->angle_in_misfit)
        fputs("Rule (`angle_rule: misfit`): the angle is one more measurement in the misfit, its z-score taken against "
              "the tolerance, averaged with the CSA speeds' squared z-scores; the tier's angle noise is as wide as the "
              "band, so a hard constraint would let that noise choose.\n\n", f);
    if (r->best >= 0) {
        const cal_candidate *b = &r->cand[r->best];
        char with_angle[64] = "";
        if (r->angle_in_misfit) snprintf(with_angle, sizeof with_angle, ", misfit with the angle %.3g", b->objective);
        fprintf(f, "**Chosen:** μs = %.4g, μr = %.4g: angle %.2f° ± %.2f, CSA misfit %.3g%s%s.\n\n", b->mu_s, b->mu_r,
                b->angle_deg, b->angle_sd_deg, b->misfit, with_angle,
                r->best_feasible ? ""
                : r->angle_in_misfit ? " (its angle is outside the tolerance)"
                                     : " — **no candidate matched the angle within its tolerance; this is the closest**");
    }
    fputs("Pairs matching the angle within the tolerance (the paper's ambiguity):\n\n| μs | μr | angle (°) | CSA misfit |"
          "\n|---|---|---|---|\n", f);
    int any = 0;
    for (int i = 0; i < r->n; ++i)
        if (cal_candidate_angle_matched(&r->cand[i]))
            any = 1, fprintf(f, "| %.4g | %.4g | %.2f | %.3g |\n", r->cand[i].mu_s, r->cand[i].mu_r, r->cand[i].angle_deg,
                             r->cand[i].misfit);
    if (!any) fputs("| none | | | |\n", f);
    fputs("\nCSA of the chosen pair against the data:\n\n| rpm | data (%) | simulated (%) | steady |\n|---|---|---|---|\n", f);
    for (int j = 0; r->best >= 0 && j < r->n_rpm; ++j)
        fprintf(f, "| %g | %.2f ± %.2f | %.2f ± %.2f | %s |\n", r->rpm[j], r->csa_data[j], r->csa_data_sd[j],
                r->cand[r->best].csa[j], r->cand[r->best].csa_sd[j], r->cand[r->best].usable[j] ? "yes" : "no");
    report_identified(f, r, bounds);
}

// A stage's posterior beside its Δχ² ranges, and which measurement moves with which parameter.
static void report_posterior(FILE *f, const cal_friction_result *r, const cal_bounds *b, const cal_posterior *p,
                             const char *why)
{
    if (!p) {
        fprintf(f, "\nNo posterior: %s.\n", why);
        return;
    }
    fprintf(f, "\nPosterior of (μs, log10 μr) given the data (MCMC, %d samples over %d chains, acceptance %.2f; flat "
               "prior over the search's bounds), on %s; each measurement's spread is the data's, the map's rms "
               "residual and the kriging's own, in quadrature. The chains' medians lie within %.3f (μs) and %.3f "
               "(log μr) of the search range of each other.\n\n| | median | 95 %% credible interval | Δχ² identified "
               "(not excluded) |\n|---|---|---|---|\n",
            p->n, CAL_POSTERIOR_CHAINS, p->acceptance, p->model, p->chain_spread[0], p->chain_spread[1]);
    const cal_range *g[2] = {&r->mu_s_range, &r->mu_r_range};
    const char *names[2] = {"μs", "μr"};
    for (int k = 0; k < 2; ++k)
        fprintf(f, "| %s | %.3g | %.3g – %.3g%s | %.3g – %.3g (%.3g – %.3g) |\n", names[k], p->median[k], p->lo[k],
                p->hi[k], cal_posterior_reach_text(p, k), g[k]->lo, g[k]->hi, g[k]->bracket_lo, g[k]->bracket_hi);
    fputs("\nWhat each measurement can tell (its change across each parameter's whole search range, the other at "
          "its posterior median, in the data's spreads; below 1 it cannot tell that parameter at all):\n\n"
          "| measurement | data spread | across μs | across μr |\n|---|---|---|---|\n", f);
    for (int k = 0; k < p->n_y; ++k)
        fprintf(f, "| %s | %.3g | %+.2f | %+.2f |\n", p->observable[k], p->data_sd[k], p->sensitivity[k][0],
                p->sensitivity[k][1]);
    fputs("\nWhat each measurement's spread in the posterior is made of (in quadrature): the data's, the map's rms "
          "residual (the same over the whole plane; runs at this tier do not shrink it) and the kriging's sd of the "
          "correction at the posterior median:\n\n"
          "| measurement | data | map's residual | kriging | in all |\n|---|---|---|---|---|\n", f);
    for (int k = 0; k < p->n_y; ++k)
        fprintf(f, "| %s | %.3g | %.3g | %.3g | %.3g |\n", p->observable[k], p->data_sd[k], p->map_rms[k],
                p->kriging_sd[k], p->spread[k]);
    if (p->correction_unmodelled)
        fprintf(f, "\n**This posterior takes the correction as exact** (%s): the kriging's sd, the one part of the "
                   "spread that says how well this tier's runs measured the correction, is absent, so its width "
                   "counts nothing of that. It decides no status here: each friction's is the runs' intervals' "
                   "alone (flag credible_correction_exact).\n",
                p->correction_unmodelled);
    if (cal_posterior_map_bound(p))
        fputs("\n**The map's residual, not the data, sets this posterior's width**: for a measurement that tells a "
              "parameter, the map tier's fit misses its own candidates by more than the data's spread. More runs at "
              "this tier do not narrow that; a map that fits better would.\n", f);
    double lo[2] = {b->mu_s_min, b->mu_r_min}, hi[2] = {b->mu_s_max, b->mu_r_max};
    for (int k = 0; k < 2; ++k)
        if (cal_posterior_blind(p, k))
            fprintf(f, "\n**The data cannot tell this stage's %s**: no measurement moves by one spread across its "
                       "whole search range; any value in %.3g – %.3g fits.\n", names[k], lo[k], hi[k]);
}

static void cost_row(FILE *f, const char *stage, const char *tier, int candidates, int simulations, double core_s)
{
    fprintf(f, "| %s | %s | %d | %d | %.2f |\n", stage, tier, candidates, simulations, core_s / 3600);
}

// What each stage and tier ran and cost (stored simulations at the cost they
// had), the distinct simulations in all, beside the paper's procedure and two
// reference systems.
static void report_cost(FILE *f, const cal_outcome *o, const sim_tally *t)
{
    fputs("\n## What it cost\n\n| stage | tier | candidates | simulations | core-hours |\n|---|---|---|---|---|\n", f);
    for (int i = 0; i < n_stages(o); ++i) {
        const cal_friction_result *r = stage_of(o, i);
        if (!r) continue;
        const char *name = r->material[0] ? r->material : "granule-granule";
        for (int k = r->n_levels - 1; k >= 0; --k) // the cheapest level first, as they ran
            cost_row(f, name, r->level[k].tier, r->level[k].runs, r->level[k].simulations, r->level[k].core_s);
        int own = 0;
        for (int k = 0; k < r->n; ++k) own += !r->cand[k].predicted;
        cost_row(f, name, o->tier->name, own, r->simulations, r->core_s);
    }
    double drum_s = 0;
    for (int k = 0; k <= CAL_MAX_MAP_DEPTH; ++k) drum_s += t->core_s[TALLY_LEVEL + k];
    fprintf(f, "\nDistinct simulations in all: %d, %.2f core-hours: %d drum runs at tier '%s' (%.2f)", t->n,
            (drum_s + t->core_s[TALLY_CYLINDER]) / 3600, t->count[TALLY_LEVEL], o->tier->name,
            t->core_s[TALLY_LEVEL] / 3600);
    for (int k = 1; k <= cal_tier_map_depth(o->config, o->tier); ++k) {
        const cal_tier *below = cal_tier_map_level(o->config, o->tier, k), *above = cal_tier_map_level(o->config, o->tier, k - 1);
        if (k == 1) fprintf(f, ", %d at its map tier '%s'", t->count[TALLY_LEVEL + k], below->name);
        else fprintf(f, ", %d at tier '%s', map tier of '%s'", t->count[TALLY_LEVEL + k], below->name, above->name);
        fprintf(f, " (%.2f)", t->core_s[TALLY_LEVEL + k] / 3600);
    }
    fprintf(f, ", %d %s (%.2f). A run two stages share (the same candidate for two wall materials) is "
               "counted once here and under each stage above", t->count[TALLY_CYLINDER],
            cal_tier_stiffness_on_drum(o->tier) ? "poured drum beds of stage 1" : "poured cylinders",
            t->core_s[TALLY_CYLINDER] / 3600);
    fputs(". For scale: the paper ran 14 poured cylinders for the stiffness (section 4.1) and, per drum lining, "
          "a grid of (μs, μr) pairs (Fig. 13, 17) at λ = 64, 200 000 granules, 6 s each; the reference calibration "
          "systems spend about 80 (GrainLearning) to 480 (ACCES) simulations per calibration.\n", f);
}

// How the tier's runs start and stop, where a speed starts turned (the
// reader of the angle must know it was not a level bed's first seconds).
static void report_run_starts(FILE *f, const cal_outcome *o)
{
    const cal_tier *t = o->tier;
    if (t->turned_start_rpm_count == 0) return;
    fputs("Runs: ", f);
    for (unsigned k = 0; k < t->turned_start_rpm_count; ++k) fprintf(f, "%s%g", k ? ", " : "", t->turned_start_rpm[k]);
    fprintf(f, " rpm from the stage's bed turned %g s at that speed first (stage 2: poured and turned at the pour's "
               "prior pair μs = %g, μr = %g; stage 3: at the frozen granule pair, lined with granules), going on with "
               "the candidate's pair, MSER cutting the change and stopping at a standard error of %g° and %g points "
               "(or at %g s, not steady); the other speeds from the level bed tilted by the start tilt, the windows' "
               "test, then their averaging time.\n\n",
            t->turned_start_time, o->config->pour_mu_s, o->config->pour_mu_r, t->steady_se_angle_deg,
            t->steady_se_csa_percent, t->max_time);
}

static int write_report(const char *dir, const cal_outcome *o, const posteriors *post, const sim_tally *tally,
                        char *err, size_t len)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/report.md", dir);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    FILE *f = a.f;
    const cal_tier *t = o->tier;
    cal_run_status rs = cal_run_status_of(o);
    fprintf(f, "# granucal %s\n\nCommand: `%s`  \nConfig: `%s`, tier `%s` (drum λ = %g, %s, up to %g s per "
               "speed, window %g s; cylinder λ = %g), granucal %s (commit %s), %d rank(s) × %d worker(s), %.0f s wall.\n\n",
            rs.demonstration ? "demonstration (not a calibration of this powder)" : "calibration", o->command,
            o->config->path, t->name, t->lambda, t->slice_depth > 0 ? "periodic slice" : "full drum", t->max_time,
            t->window, t->cylinder_lambda, exp_version(), cal_build_commit(), o->ranks, o->workers, o->wall_time_s);
    report_run_starts(f, o);
    cal_run_status_banner(f, &rs, "> ");
    fputs("\nValues the data did not choose (each row's status in `calibrated_parameters.csv`):\n\n", f);
    long before = ftell(f);
    cal_table_caveats(f, o, "- ");
    if (ftell(f) == before) fputs("- none: every friction was chosen by the data.\n", f);
    fputc('\n', f);
    fputs("Files: `calibrated_parameters.{csv,md,h5}`, `simulations.csv` (every simulation, its cost and status), "
          "plots `cn_vs_k.png`, `angle_map_*.png`, `csa_vs_rpm_*.png`, `convergence_*.png`, `posterior_*.png`, "
          "the table for LIGGGHTS and LAMMPS (`liggghts_parameters.in`, `lammps_parameters.in`) and complete decks "
          "of the drum (`liggghts_drum.in`, `lammps_drum.in`, where a wall stage ran).\n", f);
    const cal_stiffness_result *s = o->stiffness;
    if (s) {
        fprintf(f, "\n## Stiffness (the %s, pour friction μs = %g, μr = %g)\n\n| k_n (N/m) | CN mean | CN sd | "
                   "wall contacts/granule | solid fraction | granules | failed seeds |\n|---|---|---|---|---|---|---|\n",
                s->scene ? s->scene : "poured cylinder", o->config->pour_mu_s, o->config->pour_mu_r);
        for (int i = 0; i < s->n; ++i)
            fprintf(f, "| %g | %.3f | %.3f | %.3f | %.3f | %d | %d |\n", s->k[i], s->cn_mean[i], s->cn_sd[i], s->wall_cn[i],
                    s->solid_fraction[i], s->granules[i], s->failed[i]);
        fprintf(f, "\nStiff limit %.3f (the stiffest candidate); tolerance %.3f (%s). ", s->stiff_limit, s->tolerance,
                s->tolerance_rule);
        if (s->resolved)
            fprintf(f, "Chosen: **k_n = %g N/m**, the smallest k from which every stiffer candidate stays within the "
                       "tolerance.\n", s->chosen_k);
        else
            fprintf(f, "**Unresolved:** the coordination number does not depart from its stiff limit all the way down "
                       "to the softest candidate (%g N/m): some softer candidate is within the tolerance, so what this "
                       "tier's sweep shows is noise, with no change to stop at; the config's k_n = %g N/m was used. "
                       "Softer candidates may find the change: the coarser the cylinder, the softer its knee (at "
                       "cylinder λ 32768 the CN rose below 50 N/m, results/stiffness_low_k/).\n",
                    s->k[0], o->config->k_n);
    }
    for (int i = 0; i < n_stages(o); ++i)
        if (stage_of(o, i)) {
            report_friction(f, stage_of(o, i), stage_bounds(o, i), o->tier);
            report_posterior(f, stage_of(o, i), stage_bounds(o, i), post->ok[i] ? &post->of[i] : NULL, post->why[i]);
        }
    report_cost(f, o, tally);
    cal_export_report(f, dir);
    return exp_atomic_commit(&a, err, len);
}

static int write_figures(const char *dir, const cal_outcome *o, const posteriors *post, char *err, size_t len)
{
    char stamp[256];
    cal_run_status rs = cal_run_status_of(o);
    cal_run_stamp(stamp, sizeof stamp, &rs);
    if (o->stiffness && isfinite(o->stiffness->chosen_k) && cal_figure_stiffness(dir, o->stiffness, stamp, err, len))
        return 1;
    for (int i = 0; i < n_stages(o); ++i) {
        const cal_friction_result *r = stage_of(o, i);
        const cal_bounds *b = stage_bounds(o, i);
        if (!r) continue;
        if (cal_figures_friction(dir, b, r, stamp, err, len)) return 1;
        if (post->ok[i] && cal_figure_posterior(dir, b, r, &post->of[i], stamp, err, len)) return 1;
    }
    return 0;
}

// The outcome with each friction's credible interval from its stage's
// posterior, so that every output judges a value against it alike.
static cal_outcome with_credible(const cal_outcome *o, const posteriors *post)
{
    cal_outcome judged = *o;
    memset(judged.credible, 0, sizeof judged.credible);
    for (int i = 0; i < n_stages(o); ++i) {
        if (!post->ok[i]) continue;
        const cal_posterior *q = &post->of[i];
        for (int k = 0; k < 2; ++k)
            judged.credible[i][k] = (cal_credible){1, q->lo[k], q->hi[k], q->reaches_lower[k], q->reaches_upper[k],
                                                     q->width[k], q->correction_unmodelled != NULL};
    }
    return judged;
}

int cal_report_write(const char *dir, const cal_outcome *outcome, char *err, size_t len)
{
    posteriors *post = malloc(sizeof *post);
    if (!post) return exp_fail(err, len, "out of memory");
    posteriors_sample(outcome, post);
    cal_outcome judged = with_credible(outcome, post);
    const cal_outcome *o = &judged;
    cal_table_row rows[CAL_TABLE_MAX_ROWS];
    int n = cal_table_rows(o, rows);
    char store[1100];
    snprintf(store, sizeof store, "%s/store", dir);
    sim_tally tally = {0};
    int bad = write_table_csv(dir, o, post, rows, n, err, len) || write_table_md(dir, o, post, rows, n, err, len) ||
              write_table_h5(dir, o, rows, n, err, len) || cal_export_write(dir, o, err, len) ||
              write_simulations(dir, store, o, &tally, err, len) || write_report(dir, o, post, &tally, err, len);
    free(tally.hash);
    bad = bad || write_figures(dir, o, post, err, len);
    posteriors_free(post);
    free(post);
    return bad;
}
