// SPDX-License-Identifier: MIT
// `granucal measure PHOTO.png...`: the angle of repose and occupied CSA of
// real drum photographs (or the frames of a video), and their mean and
// spread as the rows of experiments/data/'s CSV files.
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "cal_commands.h"
#include "cal_data.h"
#include "cal_files.h"
#include "cal_options.h"
#include "exp_photo.h"

static const char measure_synopsis[] =
    "usage: granucal measure PHOTO.png... [--center X,Y --radius R] [--dark | --light] [--closing N]\n"
    "                        [--max-sd F] [--mask OUT] [--surface NAME --rpm RPM [--csv-angle FILE]\n"
    "                        [--csv-area FILE] [--skip-refused]]\n"
    "\n"
    "Measure photographs of the drum face as the paper does by hand (sections 3.2.2-3.2.3):\n"
    "  csa_percent  powder pixels over pixels inside the drum circle (eq. 20)\n"
    "  angle_deg    angle to the horizontal of a line fitted to the free surface\n"
    "               over the central 60 % of its width (angle_signed_deg: counter-\n"
    "               clockwise positive, as granucal's simulations report it)\n"
    "\n"
    "The drum: without --center/--radius it is found (the strongest circle in the\n"
    "picture, then the innermost edge concentric with it: the inside of the rim).\n"
    "With them (pixels, image y downwards) it is moved onto the drum's inner edge\n"
    "within 3 % of R of the centre and 4 % of the radius given. Either way the\n"
    "circle used is printed (center, radius) and drawn in red in --mask.\n"
    "The powder: two tones are told apart under uneven light (a threshold halfway\n"
    "between planes fitted to each tone's grey levels); the powder is the tone that\n"
    "lies lower in the drum (--dark or --light to say; --invert = --light); pores are\n"
    "closed with a disc of N pixels (default 3); the largest piece is kept and the\n"
    "holes in it filled. The surface: per column the top of the powder below the\n"
    "drum's empty part, away from the wall, fitted with Tukey's biweight (GSL);\n"
    "surface_fit_sd_px is its robust spread. A photo whose surface lies more than\n"
    "F·R about the line (--max-sd, default 0.04) or that shows no surface is\n"
    "refused: a message, and exit status 1.\n"
    "\n"
    "Prints one JSON object per photo; with several photos, one more with their mean\n"
    "and standard deviation; a number it does not have is null (the spread of one\n"
    "photo). --mask OUT writes the photo with the powder tinted, the circle, the\n"
    "surface points used and the line (several photos: OUT is a directory, one mask\n"
    "per photo under the photo's file name).\n";

static const char measure_epilogue[] =
    "From a video of the drum to the calibration's input files:\n"
    "  ffmpeg -i run.mp4 -vf fps=2 frames/%04d.png     # (crop first if the drum is small)\n"
    "  granucal measure frames/*.png --surface PTFE --rpm 4 \\\n"
    "      --csv-angle experiments/data/repose_angle.csv --csv-area experiments/data/occupied_area.csv\n"
    "appends 'PTFE,4,<mean angle>,<sd>' to repose_angle.csv (surface,rpm,angle_deg,angle_sd_deg)\n"
    "and 'PTFE,4,<mean CSA>,<sd>' to occupied_area.csv (surface,rpm,csa_percent,csa_sd_percent),\n"
    "creating either with its header; a file that already has this surface and speed is left\n"
    "alone (an error). The rows need at least 2 measured frames, and every frame measured\n"
    "unless --skip-refused leaves the refused ones out (they are listed either way).\n"
    "Check a few masks before trusting the numbers.\n";

typedef struct measure_args {
    exp_photo_opts opts;
    exp_circle circle;
    int circle_given;
    const char *mask, *surface, *csv_angle, *csv_area;
    double rpm;
    int skip_refused;
    int tone;                  ///< --dark, --light: exp_powder_tone
    double cx, cy, radius;     ///< --center, --radius (NAN: not given)
    char **photos;
    int n_photos;
} measure_args;

// --center X,Y: two numbers.
static int take_center(const char *s, void *context)
{
    measure_args *a = context;
    char *end;
    a->cx = strtod(s, &end);
    if (end == s || *end != ',') return 1;
    const char *p = end + 1;
    a->cy = strtod(p, &end);
    return end == p || *end != '\0' || !isfinite(a->cx) || !isfinite(a->cy);
}

static int usage(const char *why)
{
    fprintf(stderr, "granucal measure: %s; see `granucal measure --help`\n", why);
    return 2;
}

// The options that go together, once all are read.
static int check_together(measure_args *a)
{
    if (isnan(a->cx) != isnan(a->radius)) return usage("--center and --radius go together (or neither: the drum is found)");
    a->circle_given = !isnan(a->cx);
    a->circle = (exp_circle){a->cx, a->cy, a->radius, 0};
    a->opts.tone = (exp_powder_tone)a->tone;
    if ((a->csv_angle || a->csv_area) && (!a->surface || !(a->rpm > 0)))
        return usage("--csv-angle and --csv-area need --surface NAME and --rpm RPM");
    return 0;
}

// 0: parsed; -1: --help printed; else the exit status of a usage error.
static int parse_args(int argc, char **argv, measure_args *a)
{
    a->cx = a->cy = a->radius = NAN, a->tone = (int)a->opts.tone;
    const cal_option table[] = {
        {.name = "center", .short_name = 'c', .kind = CAL_OPT_CUSTOM, .parse = take_center, .context = a,
         .value = "X,Y", .expected = "X,Y: two numbers (pixels)",
         .help = "the drum's centre, pixels, image y downwards (with --radius; default: found)"},
        {.name = "radius", .short_name = 'r', .kind = CAL_OPT_REAL, .real = &a->radius, .lo = 0, .lo_open = 1,
         .hi = INFINITY, .value = "R", .expected = "a radius in pixels", .help = "the drum's inner radius, pixels"},
        {.name = "dark", .short_name = 'd', .kind = CAL_OPT_FLAG, .flag = &a->tone, .set_to = EXP_POWDER_DARK,
         .help = "the powder is the darker tone"},
        {.name = "light", .kind = CAL_OPT_FLAG, .flag = &a->tone, .set_to = EXP_POWDER_LIGHT,
         .help = "the powder is the lighter tone"},
        {.name = "invert", .short_name = 'i', .kind = CAL_OPT_FLAG, .flag = &a->tone, .set_to = EXP_POWDER_LIGHT,
         .help = "the same as --light"},
        {.name = "closing", .short_name = 'k', .kind = CAL_OPT_INT, .integer = &a->opts.closing_px, .lo = 0,
         .hi = 10000, .value = "N", .expected = "a whole number of pixels",
         .help = "close the powder's pores with a disc of N pixels (default 3)"},
        {.name = "max-sd", .kind = CAL_OPT_REAL, .real = &a->opts.max_sd_fraction, .lo = 0, .lo_open = 1,
         .hi = INFINITY, .value = "F", .expected = "a fraction of the drum radius",
         .help = "refuse a photo whose surface lies more than F times R about its line (default 0.04)"},
        {.name = "mask", .short_name = 'm', .kind = CAL_OPT_TEXT, .text = &a->mask, .value = "OUT",
         .help = "write the photo with what was measured drawn on it (several photos: OUT is a directory)"},
        {.name = "surface", .kind = CAL_OPT_TEXT, .text = &a->surface, .value = "NAME",
         .help = "the drum lining, the rows' surface column"},
        {.name = "rpm", .kind = CAL_OPT_REAL, .real = &a->rpm, .lo = 0, .lo_open = 1, .hi = INFINITY,
         .value = "RPM", .expected = "a drum speed (rpm)", .help = "the drum's speed, the rows' rpm column"},
        {.name = "csv-angle", .kind = CAL_OPT_TEXT, .text = &a->csv_angle, .value = "FILE",
         .help = "append the mean angle and its spread to FILE (repose_angle.csv's columns)"},
        {.name = "csv-area", .kind = CAL_OPT_TEXT, .text = &a->csv_area, .value = "FILE",
         .help = "append the mean CSA and its spread to FILE (occupied_area.csv's columns)"},
        {.name = "skip-refused", .kind = CAL_OPT_FLAG, .flag = &a->skip_refused, .set_to = 1,
         .help = "write the rows from the photos measured, leaving the refused ones out"},
    };
    const cal_command_line line = {.command = "measure", .synopsis = measure_synopsis, .epilogue = measure_epilogue,
                                   .options = table, .n_options = sizeof table / sizeof *table,
                                   .operand = "photo", .min_operands = 1, .max_operands = -1};
    int status = cal_options_parse(&line, argc, argv, &a->photos, &a->n_photos);
    return status ? status : check_together(a);
}

// A JSON string, quotes and backslashes escaped, control characters dropped.
static void print_json_string(const char *s)
{
    putchar('"');
    for (; *s; ++s) {
        if (*s == '"' || *s == '\\') putchar('\\');
        if ((unsigned char)*s >= 0x20) putchar(*s);
    }
    putchar('"');
}

// A JSON number with `decimals` decimals, or null where there is none (JSON
// has no NaN or infinity: a spread of one photo, a mean of none).
static void print_json_number(const char *before, double v, int decimals)
{
    fputs(before, stdout);
    if (isfinite(v)) printf("%.*f", decimals, v);
    else fputs("null", stdout);
}

static void print_result(const char *photo, const exp_photo_result *r, int given, int closing, int found)
{
    printf("{\"photo\": ");
    print_json_string(photo);
    if (found) {
        print_json_number(", \"angle_deg\": ", fabs(r->angle_deg), 3);
        print_json_number(", \"angle_signed_deg\": ", r->angle_deg, 3);
        print_json_number(", \"surface_fit_sd_px\": ", r->surface_sd_px, 3);
        printf(", \"surface_points\": %d", r->surface_points);
    } else printf(", \"angle_deg\": null");
    print_json_number(", \"csa_percent\": ", r->csa_percent, 3);
    print_json_number(", \"center\": [", r->circle.cx, 2);
    print_json_number(", ", r->circle.cy, 2);
    print_json_number("], \"radius\": ", r->circle.r, 2);
    printf(", \"circle\": \"%s\"", given ? "given, refined" : "found");
    print_json_number(", \"circle_support\": ", r->circle.support, 2);
    printf(", \"powder\": \"%s\", \"closing_px\": %d, \"surface_found\": %s}\n", r->powder_dark ? "dark" : "light",
           closing, found ? "true" : "false");
}

static int write_mask(const measure_args *a, const char *photo, int several, const exp_photo_result *r)
{
    char path[4096], err[1024];
    const char *name = strrchr(photo, '/');
    if (several) snprintf(path, sizeof path, "%s/%s", a->mask, name ? name + 1 : photo);
    else snprintf(path, sizeof path, "%s", a->mask);
    if (exp_photo_write_mask(path, r, err, sizeof err)) return fprintf(stderr, "granucal measure: %s\n", err), 1;
    return 0;
}

typedef struct frame_stats {
    int frames, measured, failed;
    double angle_sum, angle_sq, csa_sum, csa_sq;
} frame_stats;

static void add_frame(frame_stats *s, double angle, double csa)
{
    s->measured++;
    s->angle_sum += angle, s->angle_sq += angle * angle;
    s->csa_sum += csa, s->csa_sq += csa * csa;
}

static double mean_of(double sum, int n) { return n ? sum / n : NAN; }

// Sample standard deviation over the frames (n - 1).
static double sd_of(double sum, double sq, int n)
{
    return n > 1 ? sqrt(fmax(0, (sq - sum * sum / n) / (n - 1))) : NAN;
}

static int measure_one(const measure_args *a, const char *photo, int several, frame_stats *s)
{
    char err[1024];
    exp_photo_result r;
    s->frames++;
    int rc = exp_photo_measure(photo, a->circle_given ? &a->circle : NULL, &a->opts, &r, err, sizeof err);
    if (rc == EXP_PHOTO_ERROR) return fprintf(stderr, "granucal measure: %s\n", err), s->failed++, 1;
    if (rc) fprintf(stderr, "granucal measure: refused %s\n", err), s->failed++;
    else add_frame(s, fabs(r.angle_deg), r.csa_percent);
    print_result(photo, &r, a->circle_given, a->opts.closing_px, rc == EXP_PHOTO_OK);
    int bad = a->mask && write_mask(a, photo, several, &r);
    exp_photo_result_free(&r);
    return rc || bad;
}

// Append one row to a data file, with its header if the file is new. The
// file as it stands must load, and hold no row for this surface and speed.
static int append_row(const char *path, cal_data_kind kind, const char *surface, double rpm, double value, double sd)
{
    static const char *const headers[2] = {"surface,rpm,angle_deg,angle_sd_deg", "surface,rpm,csa_percent,csa_sd_percent"};
    struct stat st;
    int exists = stat(path, &st) == 0 && st.st_size > 0;
    if (exists) {
        cal_series s = {0};
        char err[1024];
        if (cal_series_load(&s, path, kind, err, sizeof err))
            return fprintf(stderr, "granucal measure: not appending to %s: %s\n", path, err), 1;
        int duplicate = 0;
        for (size_t k = 0; k < s.count; ++k)
            duplicate |= strcasecmp(s.points[k].surface, surface) == 0 && s.points[k].rpm == rpm;
        cal_series_free(&s);
        if (duplicate)
            return fprintf(stderr, "granucal measure: %s already has a row for %s at %g rpm; not appending\n", path,
                           surface, rpm), 1;
    }
    FILE *f = fopen(path, "a");
    if (!f) return fprintf(stderr, "granucal measure: cannot open %s: %s\n", path, strerror(errno)), 1;
    if (!exists) fprintf(f, "%s\n", headers[kind]);
    int quote = strpbrk(surface, ",\"") != NULL;
    fprintf(f, "%s%s%s,%g,%.2f,%.2f\n", quote ? "\"" : "", surface, quote ? "\"" : "", rpm, value, sd);
    if (fclose(f)) return fprintf(stderr, "granucal measure: cannot write %s: %s\n", path, strerror(errno)), 1;
    fprintf(stderr, "granucal measure: appended %s,%g,%.2f,%.2f to %s\n", surface, rpm, value, sd, path);
    return 0;
}

static int write_rows(const measure_args *a, const frame_stats *s)
{
    if (!a->csv_angle && !a->csv_area) return 0;
    if (s->failed && !a->skip_refused)
        return fprintf(stderr, "granucal measure: %d of %d photos not measured: no rows written "
                               "(--skip-refused leaves them out)\n", s->failed, s->frames), 1;
    if (s->measured < 2)
        return fprintf(stderr, "granucal measure: %d photo measured gives no spread: the rows need 2 or more\n",
                       s->measured), 1;
    if (strpbrk(a->surface, "\"\n\r"))
        return fprintf(stderr, "granucal measure: --surface: no quotes or line breaks\n"), 1;
    int rc = 0;
    if (a->csv_angle)
        rc |= append_row(a->csv_angle, CAL_DATA_ANGLE, a->surface, a->rpm, mean_of(s->angle_sum, s->measured),
                         sd_of(s->angle_sum, s->angle_sq, s->measured));
    if (a->csv_area)
        rc |= append_row(a->csv_area, CAL_DATA_CSA, a->surface, a->rpm, mean_of(s->csa_sum, s->measured),
                         sd_of(s->csa_sum, s->csa_sq, s->measured));
    return rc;
}

static void print_summary(const frame_stats *s)
{
    printf("{\"frames\": %d, \"measured\": %d", s->frames, s->measured);
    print_json_number(", \"angle_deg\": ", mean_of(s->angle_sum, s->measured), 3);
    print_json_number(", \"angle_sd_deg\": ", sd_of(s->angle_sum, s->angle_sq, s->measured), 3);
    print_json_number(", \"csa_percent\": ", mean_of(s->csa_sum, s->measured), 3);
    print_json_number(", \"csa_sd_percent\": ", sd_of(s->csa_sum, s->csa_sq, s->measured), 3);
    puts("}");
}

int cal_cmd_measure(int argc, char **argv)
{
    measure_args a = {.opts = exp_default_photo_opts()};
    int rc = parse_args(argc, argv, &a);
    if (rc) return rc < 0 ? 0 : rc;
    int several = a.n_photos > 1;
    struct stat st;
    if (a.mask && several && (stat(a.mask, &st) != 0 || !S_ISDIR(st.st_mode)))
        return usage("--mask with several photos names an existing directory (one mask per photo)");
    frame_stats s = {0};
    int bad = 0;
    for (int k = 0; k < a.n_photos; ++k) bad |= measure_one(&a, a.photos[k], several, &s);
    if (several) print_summary(&s);
    if (s.failed && s.frames > 1)
        fprintf(stderr, "granucal measure: %d of %d photos not measured\n", s.failed, s.frames);
    int rows = write_rows(&a, &s);
    if (a.skip_refused && s.measured > 0) bad = 0;
    return bad || rows;
}
