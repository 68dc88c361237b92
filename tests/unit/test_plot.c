// SPDX-License-Identifier: MIT
// Every kind of figure granucal draws (experiments/plot/exp_plot through
// calib/outputs/cal_figures and directly), from small synthetic data: each file must
// be a PNG, more than a few KB, and more than a few colours (a blank or
// single-colour page means nothing was drawn); an unwritable path must fail
// with a message naming the file. GRANUCAL_PLOT_DIR keeps the figures in that
// folder (to look at them); else they go to a temporary folder, removed after.
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmocka.h>
#include <math.h>
#include <png.h>

#include "capture_fd.h"
#include "cal_data.h"
#include "cal_figures.h"
#include "exp_plot.h"

static char dir[1024];
static int keep;

static int setup(void **state)
{
    const char *wanted = getenv("GRANUCAL_PLOT_DIR");
    if (wanted && *wanted) {
        snprintf(dir, sizeof dir, "%s", wanted);
        mkdir(dir, 0777);
        keep = 1;
    } else {
        snprintf(dir, sizeof dir, "/tmp/granucal_plot_XXXXXX");
        if (!mkdtemp(dir)) return -1;
    }
    return 0;
}

static int teardown(void **state)
{
    if (keep) return 0;
    char command[1200];
    snprintf(command, sizeof command, "rm -rf '%s'", dir);
    return system(command) == 0 ? 0 : -1;
}

// Distinct colours of an RGB image, counted up to `enough`.
static int distinct_colours(const unsigned char *px, size_t pixels, int enough)
{
    uint32_t seen[64];
    int n = 0;
    for (size_t k = 0; k < pixels && n < enough && n < 64; ++k) {
        uint32_t c = (uint32_t)px[3 * k] << 16 | (uint32_t)px[3 * k + 1] << 8 | px[3 * k + 2];
        int known = 0;
        for (int j = 0; j < n && !known; ++j) known = seen[j] == c;
        if (!known) seen[n++] = c;
    }
    return n;
}

// The RGB pixels of PNG `path` (free them), its size in *width, *height.
static unsigned char *read_rgb(const char *path, unsigned *width, unsigned *height)
{
    png_image img;
    memset(&img, 0, sizeof img);
    img.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&img, path)) fail_msg("%s is not a PNG: %s", path, img.message);
    img.format = PNG_FORMAT_RGB;
    unsigned char *px = malloc(3 * (size_t)img.width * img.height);
    assert_non_null(px);
    assert_true(png_image_finish_read(&img, NULL, px, 0, NULL));
    *width = img.width, *height = img.height;
    return px;
}

// The file is a PNG of more than min_bytes with at least min_colours colours.
static void assert_figure(const char *name, long min_bytes, int min_colours)
{
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    struct stat st;
    if (stat(path, &st) != 0) fail_msg("%s was not written", path);
    if (st.st_size < min_bytes) fail_msg("%s: %ld bytes, expected more than %ld", path, (long)st.st_size, min_bytes);
    unsigned width, height;
    unsigned char *px = read_rgb(path, &width, &height);
    size_t pixels = (size_t)width * height;
    int colours = distinct_colours(px, pixels, min_colours);
    free(px);
    if (colours < min_colours) fail_msg("%s: %d colours, expected at least %d", path, colours, min_colours);
}

static void path_in_dir(char *path, size_t len, const char *name)
{
    snprintf(path, len, "%s/%s", dir, name);
}

// ---- the charts ---------------------------------------------------------------------

static void chart_with_every_style(void **state)
{
    double x[6] = {1, 2, 3, 4, 5, 6}, y[6] = {3, 4.5, 4, 6, 5.5, 7}, e[6] = {0.3, 0.4, 0.2, 0.5, 0.3, 0.4};
    double y2[6] = {2, NAN, 3, 3.5, 3, 4}, ref[1] = {5};
    const char *names[6] = {"a", NULL, "c", "d", NULL, "f"};
    exp_plot_series s[4] = {
        {.n = 6, .x = x, .y = y, .err = e, .label = "with error bars", .rgb = {0.8, 0.1, 0.1},
         .style = EXP_PLOT_LINE_POINTS, .marker = EXP_MARK_SQUARE, .names = names},
        {.n = 6, .x = x, .y = y2, .label = "a line broken at a NaN", .rgb = {0.1, 0.3, 0.8}, .dashed = 1},
        {.n = 1, .x = ref, .y = ref, .label = "a reference level", .rgb = {0.5, 0.5, 0.5}, .style = EXP_PLOT_HLINE},
        {.n = 1, .x = x + 3, .y = y + 3, .label = NULL, .rgb = {0.9, 0.5, 0}, .style = EXP_PLOT_POINTS,
         .marker = EXP_MARK_STAR}, // drawn, no legend entry
    };
    exp_plot_axes a = {.title = "Every style", .xlabel = "x (unit)", .ylabel = "y (unit)"};
    char path[1200], err[512];
    path_in_dir(path, sizeof path, "chart_styles.png");
    if (exp_plot_png(path, &a, 4, s, 900, 600, err, sizeof err)) fail_msg("%s", err);
    assert_figure("chart_styles.png", 8000, 6);
}

// One speed only: the axis must still be a range (issue 24's 116-117 rpm).
static void chart_of_one_x_value(void **state)
{
    double x[1] = {116}, y[1] = {45.2}, e[1] = {0.6};
    exp_plot_series s = {.n = 1, .x = x, .y = y, .err = e, .label = "data", .style = EXP_PLOT_POINTS};
    exp_plot_axes a = {.title = "One speed", .xlabel = "drum speed (rpm)", .ylabel = "CSA (%)"};
    char path[1200], err[512];
    path_in_dir(path, sizeof path, "chart_one_x.png");
    if (exp_plot_png(path, &a, 1, &s, 900, 600, err, sizeof err)) fail_msg("%s", err);
    assert_figure("chart_one_x.png", 5000, 3);
}

static void chart_on_log_axes(void **state)
{
    double x[5] = {10, 100, 1000, 1e4, 1e5}, y[5] = {1e-3, 2e-2, 0.5, 3, 40};
    exp_plot_series s = {.n = 5, .x = x, .y = y, .label = "power law", .rgb = {0.2, 0.6, 0.2},
                         .style = EXP_PLOT_LINE_POINTS};
    exp_plot_axes a = {.title = "Log axes", .xlabel = "x", .ylabel = "y", .log_x = 1, .log_y = 1};
    char path[1200], err[512];
    path_in_dir(path, sizeof path, "chart_log.png");
    if (exp_plot_png(path, &a, 1, &s, 900, 600, err, sizeof err)) fail_msg("%s", err);
    assert_figure("chart_log.png", 5000, 3);
}

// Dark pixels in the band across the top 6 % of the page, left of its middle.
static long ink_top_left(const char *path)
{
    unsigned width, height;
    unsigned char *px = read_rgb(path, &width, &height);
    long dark = 0;
    for (unsigned y = 0; y < height * 6 / 100; ++y)
        for (unsigned x = 0; x < width * 4 / 10; ++x) {
            const unsigned char *c = px + 3 * ((size_t)y * width + x);
            dark += c[0] < 128 && c[1] < 128 && c[2] < 128;
        }
    free(px);
    return dark;
}

// A stamp (what the figure is from) is drawn above the title, at the left; none without one.
static void stamp_above_the_title(void **state)
{
    double x[3] = {1, 2, 3}, y[3] = {2, 3, 2.5};
    exp_plot_series s = {.n = 3, .x = x, .y = y, .label = "data", .style = EXP_PLOT_LINE_POINTS};
    exp_plot_axes a = {.title = "T", .xlabel = "x", .ylabel = "y"};
    char plain[1200], stamped[1200], err[512];
    path_in_dir(plain, sizeof plain, "chart_unstamped.png"), path_in_dir(stamped, sizeof stamped, "chart_stamped.png");
    if (exp_plot_png(plain, &a, 1, &s, 1000, 640, err, sizeof err)) fail_msg("%s", err);
    a.stamp = "DEMONSTRATION, tier 'quick', drum λ = 65536; angle: lab, CSA: SYNTHETIC";
    if (exp_plot_png(stamped, &a, 1, &s, 1000, 640, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(ink_top_left(plain), 0);
    assert_true(ink_top_left(stamped) > 100);
}

// ---- the calibration's figures ----------------------------------------------------------

static void stiffness_sweep(void **state)
{
    cal_stiffness_result s = {.n = 5, .k = {50, 200, 800, 3200, 12800}, .cn_mean = {5.4, 4.9, 4.6, 4.5, 4.45},
                              .cn_sd = {0.08, 0.07, 0.05, 0.06, 0.05}, .stiff_limit = 4.45, .tolerance = 0.12,
                              .chosen_k = 800, .resolved = 1};
    char err[512];
    if (cal_figure_stiffness(dir, &s, "CALIBRATION, tier 'check', drum λ = 32768; angle: lab, CSA: SYNTHETIC",
                             err, sizeof err))
        fail_msg("%s", err);
    assert_figure("cn_vs_k.png", 8000, 6);
}

// A friction stage: a 3 x 3 grid, a few COBYLA steps and a failed run;
// the angle rises with both frictions. One CSA speed, as the quick tier has.
static void friction_stage(cal_friction_result *r, int n_rpm)
{
    memset(r, 0, sizeof *r);
    snprintf(r->material, sizeof r->material, "PTFE");
    r->angle_target = 36, r->angle_tolerance = 1.5, r->angle_rpm = 4;
    r->n_rpm = n_rpm;
    for (int j = 0; j < n_rpm; ++j) r->rpm[j] = 4 + 40 * j, r->csa_data[j] = 44 + j, r->csa_data_sd[j] = 0.5;
    double pts[][2] = {{0.25, 0.003}, {0.25, 0.03}, {0.25, 0.3}, {0.5, 0.003}, {0.5, 0.03}, {0.5, 0.3}, {0.75, 0.003},
                       {0.75, 0.03}, {0.75, 0.3}, {0.6, 0.05}, {0.55, 0.04}, {0.58, 0.045}, {0.9, 0.9}};
    r->n = (int)(sizeof pts / sizeof *pts);
    for (int i = 0; i < r->n; ++i) {
        cal_candidate *k = &r->cand[i];
        k->mu_s = pts[i][0], k->mu_r = pts[i][1], k->origin = i < 9 ? "grid" : "COBYLA";
        k->angle_deg = 25 + 14 * k->mu_s + 3 * (log10(k->mu_r) + 3);
        k->angle_violation = fabs(k->angle_deg - r->angle_target) - r->angle_tolerance;
        for (int j = 0; j < n_rpm; ++j) k->csa[j] = 43 + 2 * k->mu_s + j, k->csa_sd[j] = 0.3;
        k->objective = k->misfit = 0.05 + 4 * pow(k->mu_s - 0.58, 2) + (k->angle_violation > 0 ? 3 : 0);
        k->identified = k->angle_violation <= 0;
    }
    r->cand[r->n - 1].angle_deg = NAN; // a failed run
    r->best = -1;
    for (int i = 0; i < r->n; ++i) // the rule's choice: the least objective matching the angle
        if (r->cand[i].angle_violation <= 0 && (r->best < 0 || r->cand[i].objective < r->cand[r->best].objective))
            r->best = i;
    r->best_feasible = 1;
}

static void friction_figures(void **state)
{
    cal_friction_result *r = malloc(sizeof *r);
    assert_non_null(r);
    cal_bounds b = {0.1, 1.0, 0.001, 1.0};
    char err[512];
    friction_stage(r, 1);
    if (cal_figures_friction(dir, &b, r, NULL, err, sizeof err)) fail_msg("%s", err);
    assert_figure("angle_map_PTFE.png", 20000, 20);
    assert_figure("convergence_PTFE.png", 8000, 6);
    assert_figure("csa_vs_rpm_PTFE.png", 8000, 6);
    friction_stage(r, 4);
    snprintf(r->material, sizeof r->material, "aluminium");
    if (cal_figures_friction(dir, &b, r, NULL, err, sizeof err)) fail_msg("%s", err);
    assert_figure("csa_vs_rpm_aluminium.png", 8000, 6);
    free(r);
}

// A two-tier stage: this tier's runs, then the map tier's candidates with the
// correction (predicted), the target angle below every value of the map; the
// data synthetic. Drawn: the files are written (the look was checked by eye).
static void two_tier_figures_with_the_target_not_reached(void **state)
{
    cal_friction_result *r = malloc(sizeof *r);
    assert_non_null(r);
    cal_bounds b = {0.1, 1.0, 1e-5, 0.5};
    char err[512];
    friction_stage(r, 3);
    snprintf(r->material, sizeof r->material, "PP");
    snprintf(r->level[0].tier, sizeof r->level[0].tier, "ci"), r->n_levels = 1;
    r->angle_target = 20; // below every candidate's angle
    r->csa_source = (cal_provenance){1, 512};
    for (int i = 5; i < r->n; ++i) r->cand[i].predicted = 1;
    r->cand[0].mu_s = 1.0, r->cand[0].mu_r = 0.5, r->best = 0; // the chosen on the bounds' corner
    if (cal_figures_friction(dir, &b, r, NULL, err, sizeof err)) fail_msg("%s", err);
    assert_figure("angle_map_PP.png", 20000, 20);
    assert_figure("convergence_PP.png", 8000, 6);
    assert_figure("csa_vs_rpm_PP.png", 8000, 6);
    free(r);
}

// ---- pure helpers --------------------------------------------------------------------

static void band_reached_or_not(void **state)
{
    double z[5] = {45.1, NAN, 47.8, 46.0, 45.5}, lo, hi;
    assert_int_equal(exp_plot_band_reached(38.2, 41.6, 5, z, &lo, &hi), 0); // wholly below
    assert_float_equal(lo, 45.1, 1e-12);
    assert_float_equal(hi, 47.8, 1e-12);
    assert_int_equal(exp_plot_band_reached(48, 50, 5, z, &lo, &hi), 0);       // wholly above
    assert_int_equal(exp_plot_band_reached(44, 45.2, 5, z, &lo, &hi), 1);     // meets the lowest
    assert_int_equal(exp_plot_band_reached(NAN, 45.0, 5, z, &lo, &hi), 0);    // open below, still under
    assert_int_equal(exp_plot_band_reached(NAN, 46.0, 5, z, &lo, &hi), 1);
    assert_int_equal(exp_plot_band_reached(NAN, NAN, 5, z, &lo, &hi), 1);     // no band
    double none[2] = {NAN, NAN};
    assert_int_equal(exp_plot_band_reached(1, 2, 2, none, &lo, &hi), 1);      // nothing to judge by
    assert_true(isnan(lo) && isnan(hi));
}

static void settled_from_the_last_change(void **state)
{
    double t[8] = {0, 1, 2, 3, 4, 5, 6, 7}, y[8] = {0, 10, 50, 90, 95, 96, 96, 96};
    assert_float_equal(exp_plot_settled_from(8, t, y, 0.5), 5, 1e-12);
    assert_float_equal(exp_plot_settled_from(8, t, y, 1.5), 4, 1e-12); // within the tolerance of the last value
    double rising[3] = {1, 2, 3};
    assert_float_equal(exp_plot_settled_from(3, t, rising, 0.1), 2, 1e-12); // never settles: its end
    assert_true(isnan(exp_plot_settled_from(0, t, y, 0.5)));
}

static int overlap(const exp_plot_box *a, const exp_plot_box *b)
{
    return a->x0 < b->x1 && b->x0 < a->x1 && a->y0 < b->y1 && b->y0 < a->y1;
}

// Six long names on points one over another (two rungs of one λ, as the
// fidelity ladder has): no name over another, over a marker, or out of the area.
static void labels_placed_without_collisions(void **state)
{
    enum { N = 6 };
    double px[N] = {100, 100.5, 101, 100, 150, 290}, py[N] = {50, 51, 50.5, 49, 50, 50}, w[N], h = 4.5, mark = 2.3;
    exp_plot_box markers[N], box[N];
    for (int k = 0; k < N; ++k) {
        w[k] = 45;
        markers[k] = (exp_plot_box){px[k] - mark, py[k] - mark, px[k] + mark, py[k] + mark};
    }
    assert_int_equal(exp_plot_place_labels(N, px, py, w, h, mark, 2, N, markers, 300, 170, box), 0);
    for (int k = 0; k < N; ++k) {
        assert_true(box[k].x0 >= 0 && box[k].y0 >= 0 && box[k].x1 <= 300 && box[k].y1 <= 170);
        assert_true(fabs(box[k].x1 - box[k].x0 - w[k]) < 1e-9);
        for (int j = 0; j < N; ++j) {
            if (overlap(&box[k], &markers[j])) fail_msg("name %d over marker %d", k, j);
            if (j != k && overlap(&box[k], &box[j])) fail_msg("names %d and %d collide", k, j);
        }
    }
    // The point at x 290 has no room on its right: its name goes to the left.
    assert_true(box[5].x1 <= px[5]);
    // An area too small for all of them: the ones left over are counted.
    assert_true(exp_plot_place_labels(N, px, py, w, h, mark, 2, N, markers, 300, 12, box) > 0);
}

static void speed_axis_of_one_and_of_several_speeds(void **state)
{
    double one[1] = {116};
    cal_speed_axis a = cal_figures_speed_axis(1, one, 5);
    assert_true(a.lo < 116 && a.hi > 116 && a.hi - a.lo <= 5); // around it, not 105-127
    assert_float_equal((a.lo + a.hi) / 2, 116, 1e-9);
    assert_true(a.widest_shift < (a.hi - a.lo) / 2);            // every series inside the axis
    double several[5] = {4, 40, 80, 105, 116};
    a = cal_figures_speed_axis(5, several, 6);
    assert_true(a.lo < 4 && a.hi > 116);
    assert_true(a.widest_shift <= 0.015 * (a.hi - a.lo)); // small beside the axis (±1.5 rpm on 4-116)
    assert_float_equal(cal_figures_speed_axis(5, several, 1).widest_shift, 0, 0);
    assert_float_equal(cal_figures_dodge(0, 0.01), 0, 0);
    assert_float_equal(cal_figures_dodge(1, 0.01), -0.01, 1e-15);
    assert_float_equal(cal_figures_dodge(2, 0.01), 0.01, 1e-15);
    assert_float_equal(cal_figures_dodge(3, 0.01), -0.02, 1e-15);
}

// The CSA file's SYNTHETIC header is kept with the series, and its λ.
static void synthetic_data_known_from_the_header(void **state)
{
    char path[1200], err[512];
    path_in_dir(path, sizeof path, "occupied_area.csv");
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs("# SYNTHETIC stand-in, made by a script.\n# SYNTHETIC - not lab data. made by tier 'fine' (lambda 512, "
          "periodic slice)\nsurface,rpm,csa_percent,csa_sd_percent\nPP,4,45.2,0.1\n",
          f);
    fclose(f);
    cal_series s;
    if (cal_series_load(&s, path, CAL_DATA_CSA, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(s.synthetic, 1);
    assert_float_equal(s.synthetic_lambda, 512, 0);
    cal_series_free(&s);
    f = fopen(path, "w");
    assert_non_null(f);
    fputs("# lab measurements (lambda 1 would be the real powder)\nsurface,rpm,csa_percent,csa_sd_percent\nPP,4,45.2,0.1\n", f);
    fclose(f);
    if (cal_series_load(&s, path, CAL_DATA_CSA, err, sizeof err)) fail_msg("%s", err);
    assert_int_equal(s.synthetic, 0);
    assert_true(isnan(s.synthetic_lambda));
    cal_series_free(&s);
    remove(path);
}

// Two points span no area: the map has nothing to fill, but its markers
// and axes are still drawn and the call succeeds.
static void map_of_too_few_points(void **state)
{
    double x[2] = {0.3, 0.6}, y[2] = {0.01, 0.1}, z[2] = {30, 40};
    exp_plot_map m = {.title = "Two points", .xlabel = "μs", .ylabel = "μr", .n = 2, .x = x, .y = y, .z = z,
                      .xlo = 0, .xhi = 1, .ylo = 0.001, .yhi = 1, .log_y = 1, .band_lo = 34, .band_hi = 36,
                      .band_label = "band", .chosen = 1};
    char path[1200], err[512];
    path_in_dir(path, sizeof path, "map_two_points.png");
    if (exp_plot_map_png(path, &m, 900, 700, err, sizeof err)) fail_msg("%s", err);
    assert_figure("map_two_points.png", 5000, 3);
}

// A search's 2 × 2 start grid alone: four sites on one circle, which the
// triangulation under plgriddata (qhull) refused by ending the process, and,
// once moved apart by too little, met with a precision warning on stderr (in
// every log of such a run). Drawn with stderr kept in a file, which must hold
// no word from qhull.
static void map_of_a_square_grid(void **state)
{
    double x[4] = {0.325, 0.325, 0.775, 0.775}, y[4] = {1.5e-4, 0.0334, 1.5e-4, 0.0334}, z[4] = {38.4, 37.2, 38.7, 39.1};
    exp_plot_map m = {.title = "2 × 2 grid", .xlabel = "μs", .ylabel = "μr", .n = 4, .x = x, .y = y, .z = z,
                      .xlo = 0.1, .xhi = 1, .ylo = 1e-5, .yhi = 0.5, .log_y = 1, .band_lo = 37, .band_hi = 38.5,
                      .band_label = "band", .chosen = 2};
    char path[1200], err[512], said[4096] = "";
    path_in_dir(path, sizeof path, "map_square_grid.png");
    capture_fd captured;
    assert_int_equal(capture_begin(&captured, STDERR_FILENO), 0);
    int bad = exp_plot_map_png(path, &m, 900, 700, err, sizeof err);
    capture_end(&captured, said, sizeof said);
    if (bad) fail_msg("%s", err);
    assert_figure("map_square_grid.png", 10000, 10);
    if (strstr(said, "qhull") || strstr(said, "QH")) fail_msg("drawing the map printed: %s", said);
}

// ---- failures ------------------------------------------------------------------------

static void unwritable_path_is_an_error_naming_it(void **state)
{
    double x[2] = {0, 1}, y[2] = {0, 1};
    exp_plot_series s = {.n = 2, .x = x, .y = y, .label = "line"};
    exp_plot_axes a = {.title = "t"};
    char err[512] = "";
    const char *path = "/nonexistent_granucal_dir/chart.png";
    assert_int_not_equal(exp_plot_png(path, &a, 1, &s, 600, 400, err, sizeof err), 0);
    assert_non_null(strstr(err, path));
    exp_plot_map m = {.n = 2, .x = x, .y = y, .z = y, .xlo = 0, .xhi = 1, .ylo = 0, .yhi = 1, .chosen = -1};
    err[0] = 0;
    assert_int_not_equal(exp_plot_map_png(path, &m, 600, 400, err, sizeof err), 0);
    assert_non_null(strstr(err, path));
    // A figure after a failed one is drawn normally (no state left behind).
    char ok[1200];
    path_in_dir(ok, sizeof ok, "after_failure.png");
    if (exp_plot_png(ok, &a, 1, &s, 600, 400, err, sizeof err)) fail_msg("%s", err);
    assert_figure("after_failure.png", 3000, 3);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(chart_with_every_style),
        cmocka_unit_test(chart_of_one_x_value),
        cmocka_unit_test(chart_on_log_axes),
        cmocka_unit_test(stamp_above_the_title),
        cmocka_unit_test(stiffness_sweep),
        cmocka_unit_test(friction_figures),
        cmocka_unit_test(two_tier_figures_with_the_target_not_reached),
        cmocka_unit_test(band_reached_or_not),
        cmocka_unit_test(settled_from_the_last_change),
        cmocka_unit_test(labels_placed_without_collisions),
        cmocka_unit_test(speed_axis_of_one_and_of_several_speeds),
        cmocka_unit_test(synthetic_data_known_from_the_header),
        cmocka_unit_test(map_of_too_few_points),
        cmocka_unit_test(map_of_a_square_grid),
        cmocka_unit_test(unwritable_path_is_an_error_naming_it),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}
