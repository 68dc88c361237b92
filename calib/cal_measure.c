// SPDX-License-Identifier: MIT
// `granucal measure PHOTO.png`: the angle of repose and occupied CSA of a
// real drum photograph, by the same raster code that measures simulations.
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "cal_commands.h"
#include "exp_image.h"

static const char measure_help[] =
    "usage: granucal measure PHOTO.png --center X,Y --radius R [--invert] [--closing N] [--mask OUT.png]\n"
    "\n"
    "Measure a photograph of the drum face as the paper does (sections 3.2.2-3.2.3):\n"
    "the pixels inside the drum circle (centre X,Y and radius R in pixels, image y\n"
    "downwards) are binarised with Otsu's automatic threshold, the powder dark on a\n"
    "lighter drum (--invert for a light powder), closed with a disc of N pixels\n"
    "(default 3) to remove pores and noise, and measured:\n"
    "  csa_percent  occupied pixels over pixels inside the drum circle (eq. 20)\n"
    "  angle_deg    angle to the horizontal of a line fitted to the free surface\n"
    "               over the central 60 %% of its width\n"
    "Prints one JSON object. --mask writes the binarised image for checking.\n";

static int parse_pair(const char *s, double *a, double *b)
{
    char *end;
    *a = strtod(s, &end);
    if (end == s || *end != ',') return 1;
    const char *p = end + 1;
    *b = strtod(p, &end);
    return end == p || *end != '\0';
}

int cal_cmd_measure(int argc, char **argv)
{
    static const struct option opts[] = {{"center", required_argument, 0, 'c'}, {"radius", required_argument, 0, 'r'},
                                         {"invert", no_argument, 0, 'i'},       {"closing", required_argument, 0, 'k'},
                                         {"mask", required_argument, 0, 'm'},   {"help", no_argument, 0, 'h'},
                                         {0}};
    double cx = NAN, cy = NAN, radius = NAN;
    int invert = 0, closing = 3, c;
    const char *mask = NULL;
    while ((c = getopt_long(argc, argv, "c:r:ik:m:h", opts, NULL)) != -1) {
        if (c == 'h') return printf(measure_help), 0;
        if (c == 'c' && parse_pair(optarg, &cx, &cy)) return fprintf(stderr, "granucal measure: --center X,Y\n"), 2;
        if (c == 'r') radius = atof(optarg);
        if (c == 'i') invert = 1;
        if (c == 'k') closing = atoi(optarg);
        if (c == 'm') mask = optarg;
        if (c == '?') return fprintf(stderr, measure_help), 2;
    }
    if (optind != argc - 1 || isnan(cx) || !(radius > 0) || closing < 0)
        return fprintf(stderr, measure_help), 2;
    char err[1024];
    double threshold = 0;
    exp_raster *r = exp_read_photo(argv[optind], cx, cy, radius, invert, &threshold, err, sizeof err);
    if (!r) return fprintf(stderr, "granucal measure: %s\n", err), 1;
    exp_angle a;
    int bad = exp_raster_close(r, closing);
    double csa = exp_raster_csa_percent(r, radius);
    int no_surface = exp_raster_surface_angle(r, radius, 0.6, &a);
    if (mask && exp_write_raster_png(mask, r, err, sizeof err)) fprintf(stderr, "granucal measure: %s\n", err), bad = 1;
    printf("{\"photo\": \"%s\", \"angle_deg\": %.3f, \"surface_fit_sd_px\": %.3f, \"csa_percent\": %.3f, "
           "\"threshold\": %.0f, \"closing_px\": %d, \"surface_found\": %s}\n",
           argv[optind], no_surface ? NAN : fabs(a.angle_deg), a.residual_sd, csa, threshold, closing,
           no_surface ? "false" : "true");
    exp_raster_free(r);
    return bad || no_surface;
}
