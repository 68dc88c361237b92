// SPDX-License-Identifier: MIT
// Table 3 in CI as a twin experiment (usage: test_twin_table3 [TWIN_CALIBRATION_DIR]: with a folder,
// the rule below is applied to that committed calibration, which CI has verified from its stores;
// without, the twin is made and calibrated here, as follows). The ci tier is far too coarse to be
// compared with the lab (its granules pile ~8 deg steeper: docs/fidelity.md),
// and no tier may be handed a correction measured at the answer. So the data
// are made by the ci tier itself at Table 3's parameters (results/
// paper_table3.csv) on beds the calibration does not use (`granucal
// synthesize --seeds 101,102,103,104`), and `granucal calibrate --tier ci
// --data` must find them again:
//  - every calibrated friction: Table 3's value inside the interval the
//    calibration's data do not exclude (not_excluded_min/max: from the
//    nearest candidate beyond the identified ones, Delta chi^2 > 3.84 over
//    the evaluated candidates, or the search bound where none), and that
//    interval an answer: the data exclude some evaluated value of the
//    parameter (an end inside the search range, or an excluded candidate at
//    a bound); where they exclude none, the tier cannot identify the
//    parameter, and the test fails saying so (one entry excepted, by name,
//    with its evidence: known_unidentified below);
//  - every input (density, xi, the stiffnesses, given here as the config's
//    k_n: the twin's drum data say nothing about stage 1): carried exactly.
// The rule was written before the first twin run with the identified range
// (the extent of the identified candidates) in place of the not-excluded
// interval. That run put the granule mu_s range at 1 - 1: the three
// identified candidates all had mu_s = 1, the nearest excluded one 0.775, and
// no candidate between was run, so Table 3's 0.8 fell in a gap the data say
// nothing about. The extent of a sparse set is not what the data identify;
// the calibrated table now carries the not-excluded interval beside it, and
// the test checks that. No number in the rule was fitted.
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

typedef struct entry {
    char contact[24], material[32], parameter[16];
    double value;
    double identified_min, identified_max;     ///< NAN where the table gives no range
    double not_excluded_min, not_excluded_max; ///< NAN where the table gives no range
} entry;

/// The friction search's bounds (configs/calibration.yaml: granule, wall).
typedef struct search_range {
    const char *contact, *parameter;
    double min, max;
} search_range;
static const search_range search_ranges[] = {
    {"granule-granule", "mu_s", 0.1, 1.0},
    {"granule-granule", "mu_r", 0.001, 0.5},
    {"granule-boundary", "mu_s", 0.1, 1.0},
    {"granule-boundary", "mu_r", 0.00001, 0.5},
};

// A number, or NAN for an absent or empty field.
static double field_value(const char *field)
{
    return field && *field && *field != '\n' ? strtod(field, NULL) : NAN;
}

// calibrated_parameters.csv (or Table 3's, which has no range columns).
static int read_table(const char *path, entry *out, int cap)
{
    FILE *f = fopen(path, "r");
    if (!f) fail_msg("cannot open %s", path);
    char line[256];
    int n = 0;
    if (!fgets(line, sizeof line, f)) fail_msg("%s: empty", path);
    while (n < cap && fgets(line, sizeof line, f)) {
        entry *e = &out[n];
        char *fields[9] = {0}, *p = line;
        for (int k = 0; k < 9 && p; ++k) { // comma-separated, empty fields kept
            fields[k] = p;
            p = strchr(p, ',');
            if (p) *p++ = '\0';
        }
        if (!fields[4]) fail_msg("%s: malformed line '%s'", path, line);
        snprintf(e->contact, sizeof e->contact, "%.23s", fields[0]);
        snprintf(e->material, sizeof e->material, "%.31s", fields[1]);
        snprintf(e->parameter, sizeof e->parameter, "%.15s", fields[2]);
        e->value = strtod(fields[3], NULL);
        e->identified_min = field_value(fields[5]), e->identified_max = field_value(fields[6]);
        e->not_excluded_min = field_value(fields[7]), e->not_excluded_max = field_value(fields[8]);
        n++;
    }
    fclose(f);
    return n;
}

static const entry *find(const entry *t, int n, const entry *like)
{
    for (int i = 0; i < n; ++i)
        if (!strcmp(t[i].contact, like->contact) && !strcmp(t[i].material, like->material) &&
            !strcmp(t[i].parameter, like->parameter))
            return &t[i];
    return NULL;
}

static const search_range *range_of(const entry *e)
{
    for (size_t k = 0; k < sizeof search_ranges / sizeof *search_ranges; ++k)
        if (!strcmp(search_ranges[k].contact, e->contact) && !strcmp(search_ranges[k].parameter, e->parameter))
            return &search_ranges[k];
    return NULL;
}

static int run(const char *cmd)
{
    printf("running: %s\n", cmd);
    fflush(stdout);
    return system(cmd);
}

// "--wall NAME=MU_S,MU_R" for each wall material of Table 3.
static void wall_options(const entry *paper, int n, char *out, size_t len)
{
    out[0] = '\0';
    for (int i = 0; i < n; ++i) {
        if (strcmp(paper[i].contact, "granule-boundary") || strcmp(paper[i].parameter, "mu_s") || !paper[i].material[0])
            continue;
        entry want = paper[i];
        snprintf(want.parameter, sizeof want.parameter, "mu_r");
        const entry *mu_r = find(paper, n, &want);
        if (!mu_r) fail_msg("Table 3 has no mu_r for %s", paper[i].material);
        snprintf(out + strlen(out), len - strlen(out), " --wall '%s=%.17g,%.17g'", paper[i].material, paper[i].value,
                 mu_r->value);
    }
}

/// The one entry the ci drum is known not to identify, and why (a finding of
/// the twin runs, results/twin_ci/README.md): at the wall μs the search
/// lands on (1.0) the bed does not slide on the wall, and the drum's angle and
/// CSA are the same for every wall μr from 1e-5 to 0.5 (45.37° at both
/// bounds). The test fails if any other entry is not identified, and also if
/// this one becomes identified, so that this list stays true.
static const struct {
    const char *contact, *material, *parameter;
} known_unidentified[] = {{"granule-boundary", "aluminium", "mu_r"}};

static int known_to_be_unidentified(const entry *e)
{
    for (size_t k = 0; k < sizeof known_unidentified / sizeof *known_unidentified; ++k)
        if (!strcmp(known_unidentified[k].contact, e->contact) && !strcmp(known_unidentified[k].material, e->material) &&
            !strcmp(known_unidentified[k].parameter, e->parameter))
            return 1;
    return 0;
}

static const char *verdict(const entry *ours, const entry *truth, const search_range *r)
{
    if (!r) return fabs(ours->value - truth->value) <= 1e-9 * fabs(truth->value) ? "ok: carried" : "DIFFERS";
    double lo = ours->not_excluded_min, hi = ours->not_excluded_max;
    if (!(isfinite(lo) && isfinite(hi))) return "NO RANGE";
    if (!(truth->value >= lo * (1 - 1e-9) && truth->value <= hi * (1 + 1e-9))) return "OUTSIDE the interval not excluded";
    // An answer: an end inside the search range, or an end that is an
    // excluded candidate's value (beyond the identified ones) rather than the
    // search bound itself.
    int informative = lo > r->min * (1 + 1e-9) || hi < r->max * (1 - 1e-9) || lo < ours->identified_min * (1 - 1e-9) ||
                      hi > ours->identified_max * (1 + 1e-9);
    int known = known_to_be_unidentified(truth);
    if (informative) return known ? "IDENTIFIED, though listed as not: update known_unidentified" : "ok: recovered";
    return known ? "ok: inside, NOT IDENTIFIED (known: the whole search range)"
                 : "NOT IDENTIFIED: the interval is the whole search range";
}

/// The twin's calibration folder to judge: set by the command line (a committed twin, verified from
/// its store by verify_committed.sh and verify_twin_data.sh), or made fresh by run_twin.
static char twin_dir[1200];

// granucal synthesize at Table 3's pairs, then both friction stages on those data, in fresh folders
// under the build directory: the whole twin, about 15 minutes on 2 cores.
static void run_twin(const entry *paper, int n_paper)
{
    const char *src = getenv("GRANUCAL_SOURCE_DIR"), *bin = getenv("GRANUCAL_BINARY_DIR");
    assert_non_null(src), assert_non_null(bin);
    char cmd[8192], walls[2048];
    entry want = {.contact = "granule-granule", .parameter = "mu_s"};
    const entry *gg_mu_s = find(paper, n_paper, &want);
    snprintf(want.parameter, sizeof want.parameter, "mu_r");
    const entry *gg_mu_r = find(paper, n_paper, &want);
    snprintf(want.parameter, sizeof want.parameter, "k_n");
    const entry *k_n = find(paper, n_paper, &want);
    assert_non_null(gg_mu_s), assert_non_null(gg_mu_r), assert_non_null(k_n);
    wall_options(paper, n_paper, walls, sizeof walls);
    // Fresh folders: a twin reads only what this run made.
    snprintf(cmd, sizeof cmd, "rm -rf '%s/twin' && cd '%s' && '%s/granucal' synthesize configs/calibration.yaml --tier ci "
             "--seeds 101,102,103,104 --granule %.17g,%.17g --k-n %.17g%s --out '%s/twin/data'",
             bin, src, bin, gg_mu_s->value, gg_mu_r->value, k_n->value, walls, bin);
    assert_int_equal(run(cmd), 0);
    // Stage 1 is not run: the twin's drum data say nothing about it, and the
    // config's k_n (checked equal to Table 3's below) is the twin's.
    for (int stage = 0; stage < 2; ++stage) {
        snprintf(cmd, sizeof cmd, "cd '%s' && '%s/granucal' calibrate configs/calibration.yaml --tier ci --stage %s "
                 "--data '%s/twin/data' --out '%s/twin/calibration'", src, bin, stage ? "wall" : "granule", bin, bin);
        assert_int_equal(run(cmd), 0);
    }
    snprintf(twin_dir, sizeof twin_dir, "%s/twin/calibration", bin);
}

static void test_twin_recovers_table3(void **state)
{
    (void)state;
    const char *src = getenv("GRANUCAL_SOURCE_DIR");
    assert_non_null(src);
    char cmd[8192], path[1300];
    entry paper[64], ours[64];
    snprintf(path, sizeof path, "%s/results/paper_table3.csv", src);
    int n_paper = read_table(path, paper, 64);
    if (!twin_dir[0]) run_twin(paper, n_paper);
    printf("judging the twin calibration in %s\n", twin_dir);
    snprintf(path, sizeof path, "%s/calibrated_parameters.csv", twin_dir);
    int n_ours = read_table(path, ours, 64);
    assert_int_equal(n_ours, n_paper);
    printf("\n%-17s %-10s %-9s %12s %12s %21s %21s %21s  %s\n", "contact", "material", "parameter", "truth", "calibrated",
           "identified range", "not excluded", "search range", "verdict");
    int failed = 0;
    for (int i = 0; i < n_paper; ++i) {
        const entry *o = find(ours, n_ours, &paper[i]);
        if (!o) fail_msg("no %s %s %s in the calibrated table", paper[i].contact, paper[i].material, paper[i].parameter);
        const search_range *r = range_of(&paper[i]);
        const char *v = verdict(o, &paper[i], r);
        failed += strncmp(v, "ok", 2) != 0;
        char identified[32] = "", not_excluded[32] = "", searched[32] = "";
        if (isfinite(o->identified_min)) snprintf(identified, sizeof identified, "%.3g - %.3g", o->identified_min, o->identified_max);
        if (isfinite(o->not_excluded_min))
            snprintf(not_excluded, sizeof not_excluded, "%.3g - %.3g", o->not_excluded_min, o->not_excluded_max);
        if (r) snprintf(searched, sizeof searched, "%.3g - %.3g", r->min, r->max);
        printf("%-17s %-10s %-9s %12.5g %12.5g %21s %21s %21s  %s\n", paper[i].contact, paper[i].material,
               paper[i].parameter, paper[i].value, o->value, identified, not_excluded, searched, v);
    }
    printf("(truth: Table 3, results/paper_table3.csv; identified range: the candidates the twin data cannot tell "
           "from the best, Delta chi^2 <= 3.84; not excluded: from the nearest excluded candidate beyond them, or the "
           "search bound)\n\n");
    fflush(stdout);
    snprintf(cmd, sizeof cmd, "grep -h 'Target angle\\|Chosen\\|Unresolved\\|^- μ' '%s/report.md'", twin_dir);
    if (system(cmd) != 0) printf("(could not show report.md)\n");
    assert_int_equal(failed, 0);
}

// usage: test_twin_table3 [TWIN_CALIBRATION_DIR]: without it, the twin is made and calibrated here.
int main(int argc, char **argv)
{
    if (argc > 1) snprintf(twin_dir, sizeof twin_dir, "%s", argv[1]);
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_twin_recovers_table3)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
