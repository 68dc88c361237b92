// SPDX-License-Identifier: MIT
// One drum run as `granucal simulate DRUM.yaml --set ...` makes it, with the rolling spring's
// stiffness by a peer's rule instead of the paper's (a diagnostic, not a test; issue 36's open peers
// check): LIGGGHTS 3.8's rolling_friction epsd2 sets k_r = 2.25 mu_r^2 k_t for every pair (its torque
// 2.25 mu_r^2 k_t R*^2 per radian, R* the reduced radius), where the paper (eq. 11) and granucal take
// k_r = k_n. Both limit the torque at mu_r R* |F_n| (eq. 13 and epsd2 alike).
//   usage: bench_drum_rolling RULE DRUM.yaml [KEY=VALUE ...]   RULE: paper | epsd2
// With RULE paper it is `granucal simulate`'s run, to the last digit of its angle and CSA.
// Prints one line: rule, k_r of the granule and wall pairs, angle, CSA, steady, granules.
#include <stdio.h>
#include <string.h>

#include "exp_drum.h"
#include "exp_drum_config.h"

// epsd2's rolling stiffness for a pair (hooke/stiffness: k_t = k_s).
static void epsd2_rolling(dem_contact_params *p) { p->k_r = 2.25 * p->mu_r * p->mu_r * p->k_s; }

int main(int argc, char **argv)
{
    if (argc < 3 || (strcmp(argv[1], "paper") && strcmp(argv[1], "epsd2")))
        return fprintf(stderr, "usage: %s paper|epsd2 DRUM.yaml [KEY=VALUE ...]\n", argv[0]), 2;
    char err[1024];
    exp_drum_yaml *y = exp_drum_config_load(argv[2], argc - 3, argv + 3, err, sizeof err);
    if (!y) return fprintf(stderr, "%s\n", err), 1;
    exp_drum_def d;
    exp_drum_run_opts o;
    if (exp_drum_config_defs(y, &d, &o, err, sizeof err)) return fprintf(stderr, "%s\n", err), 1;
    exp_drum_config_free(y);
    if (!strcmp(argv[1], "epsd2")) epsd2_rolling(&d.granule), epsd2_rolling(&d.wall), epsd2_rolling(&d.end_plate);
    dem_world *w = exp_drum_fill(&d, NULL, NULL, err, sizeof err);
    if (!w) return fprintf(stderr, "%s\n", err), 1;
    exp_drum_result r;
    dem_status st = exp_drum_rotate(w, &d, &o, NULL, NULL, &r);
    printf("rule=%s granule_k_r=%.6g wall_k_r=%.6g status=%s angle_deg=%.17g csa_percent=%.17g steady=%d granules=%zu\n",
           argv[1], d.granule.k_r, d.wall.k_r, st == DEM_OK ? "ok" : dem_world_error(w), r.angle_deg, r.csa_percent,
           r.steady, r.granules);
    dem_world_destroy(w);
    return st != DEM_OK;
}
