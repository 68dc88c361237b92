// SPDX-License-Identifier: MIT
// Compare granucal's and LIGGGHTS' silo discharge curves (Appendix A.2,
// Fig. A.4, A.5): built and run by tests/peers/compare_silo.sh.
//   compare_silo GRANUCAL_SERIES.csv LIGGGHTS_THERMO.csv N_GRANULES OUTDIR
// GRANUCAL_SERIES.csv: t_s,contacts,wall_contacts,ke_translational_J,ke_rotational_J,ke_total_J,discharged,...
// LIGGGHTS_THERMO.csv: t_s,contacts,ke_translational_J,ke_rotational_J,discharged
// Writes OUTDIR/comparison.csv, contacts.png, kinetic_energy.png,
// discharged.png, and prints the metrics as a Markdown table; exit status 1
// if a metric is outside its tolerance (stated below, fixed before the runs).
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "exp_plot.h"

// Tolerances. Insertion is identical (one data file), but the codes differ
// in floating-point order, the tangential spring's carry-over and the torque
// lever arm, and a discharge of 200 frictional spheres amplifies any
// difference (chaos): the curves are compared as statistics, not per step.
#define TOL_DISCHARGED_FRACTION 0.10 // max |f_g(t) − f_l(t)| of the discharged fraction
#define TOL_FINAL_DISCHARGED 0.05    // |final counts| difference over N
#define TOL_CONTACTS_LATE 0.15       // mean contacts over the last 20 s, relative
#define TOL_KE_PEAK 0.25             // peak kinetic energy, relative

typedef struct series {
    size_t n;
    double *t, *contacts, *ke, *discharged;
} series;

static int read_csv(const char *path, int liggghts, series *s)
{
    FILE *f = fopen(path, "r");
    if (!f) return fprintf(stderr, "cannot read %s\n", path), 1;
    char line[1024];
    size_t cap = 4096;
    s->n = 0;
    s->t = malloc(cap * sizeof(double)), s->contacts = malloc(cap * sizeof(double));
    s->ke = malloc(cap * sizeof(double)), s->discharged = malloc(cap * sizeof(double));
    if (!fgets(line, sizeof line, f)) return fclose(f), 1; // header
    while (fgets(line, sizeof line, f)) {
        double v[8] = {0};
        int k = sscanf(line, "%lf,%lf,%lf,%lf,%lf,%lf,%lf,%lf", &v[0], &v[1], &v[2], &v[3], &v[4], &v[5], &v[6], &v[7]);
        if (k < 5) continue;
        if (s->n == cap) {
            cap *= 2;
            s->t = realloc(s->t, cap * sizeof(double)), s->contacts = realloc(s->contacts, cap * sizeof(double));
            s->ke = realloc(s->ke, cap * sizeof(double)), s->discharged = realloc(s->discharged, cap * sizeof(double));
        }
        s->t[s->n] = v[0], s->contacts[s->n] = v[1];
        if (liggghts) s->ke[s->n] = v[2] + v[3], s->discharged[s->n] = v[4];
        else s->ke[s->n] = v[5], s->discharged[s->n] = v[6];
        s->n++;
    }
    fclose(f);
    return s->n == 0;
}

// Value of a series at time t (linear interpolation; clamped at the ends).
static double at(const series *s, const double *y, double t)
{
    if (t <= s->t[0]) return y[0];
    for (size_t k = 1; k < s->n; ++k)
        if (s->t[k] >= t) {
            double u = (t - s->t[k - 1]) / (s->t[k] - s->t[k - 1]);
            return y[k - 1] + u * (y[k] - y[k - 1]);
        }
    return y[s->n - 1];
}

static double time_to(const series *s, double count)
{
    for (size_t k = 0; k < s->n; ++k)
        if (s->discharged[k] >= count) return s->t[k];
    return NAN;
}

static double late_mean(const series *s, const double *y, double from)
{
    double sum = 0;
    int n = 0;
    for (size_t k = 0; k < s->n; ++k)
        if (s->t[k] >= from) sum += y[k], n++;
    return n ? sum / n : NAN;
}

static double peak(const series *s, const double *y)
{
    double m = 0;
    for (size_t k = 0; k < s->n; ++k) m = fmax(m, y[k]);
    return m;
}

// x_end > 0: the time axis ends there (xlabel says why), else at the data's end.
static int plot2(const char *dir, const char *name, const char *title, const char *ylabel, const series *g,
                 const series *l, const double *yg, const double *yl, int log_y, double x_end, const char *xlabel)
{
    char path[1200], err[1300];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    exp_plot_series s[2] = {{.n = g->n, .x = g->t, .y = yg, .label = "granucal", .rgb = {0.12, 0.47, 0.71}},
                            {.n = l->n, .x = l->t, .y = yl, .label = "LIGGGHTS 3.8", .rgb = {0.84, 0.15, 0.16}, .dashed = 1}};
    exp_plot_axes ax = {.title = title, .xlabel = xlabel ? xlabel : "t (s)", .ylabel = ylabel, .xlo = 0, .xhi = x_end,
                        .log_y = log_y};
    if (exp_plot_png(path, &ax, 2, s, 900, 500, err, sizeof err)) return fprintf(stderr, "%s\n", err), 1;
    return 0;
}

int main(int argc, char **argv)
{
    if (argc != 5) return fprintf(stderr, "usage: %s GRANUCAL.csv LIGGGHTS.csv N OUTDIR\n", argv[0]), 2;
    series g, l;
    if (read_csv(argv[1], 0, &g) || read_csv(argv[2], 1, &l)) return fprintf(stderr, "empty series\n"), 2;
    double n = atof(argv[3]);
    const char *dir = argv[4];
    char path[1200];
    snprintf(path, sizeof path, "%s/comparison.csv", dir);
    FILE *f = fopen(path, "w");
    if (!f) return fprintf(stderr, "cannot write %s\n", path), 2;
    fprintf(f, "t_s,contacts_granucal,contacts_liggghts,ke_granucal_J,ke_liggghts_J,discharged_granucal,"
               "discharged_liggghts\n");
    double max_df = 0, t_end = fmin(g.t[g.n - 1], l.t[l.n - 1]);
    for (size_t k = 0; k < g.n && g.t[k] <= t_end + 1e-9; ++k) {
        double t = g.t[k], dl = at(&l, l.discharged, t);
        max_df = fmax(max_df, fabs(g.discharged[k] - dl) / n);
        fprintf(f, "%.3f,%.0f,%.1f,%.6g,%.6g,%.0f,%.1f\n", t, g.contacts[k], at(&l, l.contacts, t), g.ke[k],
                at(&l, l.ke, t), g.discharged[k], dl);
    }
    fclose(f);
    double fin_g = at(&g, g.discharged, t_end), fin_l = at(&l, l.discharged, t_end);
    double cg = late_mean(&g, g.contacts, t_end - 20), cl = late_mean(&l, l.contacts, t_end - 20);
    double kg = peak(&g, g.ke), kl = peak(&l, l.ke);
    int ok_df = max_df <= TOL_DISCHARGED_FRACTION, ok_fin = fabs(fin_g - fin_l) / n <= TOL_FINAL_DISCHARGED;
    int ok_c = fabs(cg - cl) / cl <= TOL_CONTACTS_LATE, ok_k = fabs(kg - kl) / kl <= TOL_KE_PEAK;
    printf("| metric | granucal | LIGGGHTS | difference | tolerance | |\n|---|---|---|---|---|---|\n");
    printf("| discharged fraction, largest gap over t | | | %.3f | %.2f | %s |\n", max_df, TOL_DISCHARGED_FRACTION,
           ok_df ? "pass" : "FAIL");
    printf("| discharged at %.0f s (of %.0f) | %.0f | %.0f | %.1f %% of N | %.0f %% | %s |\n", t_end, n, fin_g, fin_l,
           100 * fabs(fin_g - fin_l) / n, 100 * TOL_FINAL_DISCHARGED, ok_fin ? "pass" : "FAIL");
    printf("| time to half discharged (s) | %.1f | %.1f | %.1f %% | | |\n", time_to(&g, 0.5 * n), time_to(&l, 0.5 * n),
           100 * fabs(time_to(&g, 0.5 * n) - time_to(&l, 0.5 * n)) / time_to(&l, 0.5 * n));
    printf("| time to 90 %% discharged (s) | %.1f | %.1f | | | |\n", time_to(&g, 0.9 * n), time_to(&l, 0.9 * n));
    printf("| contacts, mean of the last 20 s | %.1f | %.1f | %.1f %% | %.0f %% | %s |\n", cg, cl, 100 * fabs(cg - cl) / cl,
           100 * TOL_CONTACTS_LATE, ok_c ? "pass" : "FAIL");
    printf("| contacts at t = 0 | %.0f | %.0f | | | |\n", g.contacts[0], l.contacts[0]);
    printf("| peak kinetic energy (J) | %.4g | %.4g | %.1f %% | %.0f %% | %s |\n", kg, kl, 100 * fabs(kg - kl) / kl,
           100 * TOL_KE_PEAK, ok_k ? "pass" : "FAIL");
    printf("| kinetic energy, mean of the last 20 s (J) | %.4g | %.4g | %.1f %% | | |\n", late_mean(&g, g.ke, t_end - 20),
           late_mean(&l, l.ke, t_end - 20),
           100 * fabs(late_mean(&g, g.ke, t_end - 20) - late_mean(&l, l.ke, t_end - 20)) / late_mean(&l, l.ke, t_end - 20));
    int bad = plot2(dir, "contacts.png", "Silo discharge: contacts (Fig. A.4)", "contacts", &g, &l, g.contacts, l.contacts,
                    0, 0, NULL);
    bad |= plot2(dir, "kinetic_energy.png", "Silo discharge: kinetic energy (Fig. A.5)", "kinetic energy (J)", &g, &l, g.ke,
                 l.ke, 1, 0, NULL);
    // The discharge is over in seconds of a long run: its axis ends a quarter past the last granule out.
    double over = fmax(exp_plot_settled_from(g.n, g.t, g.discharged, 0.5), exp_plot_settled_from(l.n, l.t, l.discharged, 0.5));
    char xlabel[160];
    double x_end = over >= 1 ? ceil(1.25 * over) : 1.25 * over;
    snprintf(xlabel, sizeof xlabel, "t (s); the count is final from %.2g s (the run goes on to %.0f s)", over, t_end);
    bad |= plot2(dir, "discharged.png", "Silo discharge: granules below the plate", "granules", &g, &l, g.discharged,
                 l.discharged, 0, x_end > 0 && x_end < t_end ? x_end : 0, xlabel);
    return bad ? 2 : !(ok_df && ok_fin && ok_c && ok_k);
}
