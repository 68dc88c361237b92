// SPDX-License-Identifier: MIT
// `granucal simulate FILE.yaml`: the command's options and the dispatch. An
// experiment config (drum, compression, silo, cylinder, incline) goes to its
// runner, experiments/NAME/exp_NAME_runner.h, through simulate_runners;
// anything else is an explicit scene (exp_scene_runner.h).
#include <stdio.h>
#include <stdlib.h>

#include "cal_case_runs.h"
#include "cal_commands.h"
#include "cal_options.h"
#include "exp_compress_config.h"
#include "exp_compress_runner.h"
#include "exp_cylinder_config.h"
#include "exp_cylinder_runner.h"
#include "exp_drum_config.h"
#include "exp_drum_runner.h"
#include "exp_incline_config.h"
#include "exp_incline_runner.h"
#include "exp_scene.h"
#include "exp_scene_runner.h"
#include "exp_silo_config.h"
#include "exp_silo_runner.h"

static const char simulate_synopsis[] =
    "usage: granucal simulate SCENE.yaml [--set KEY=VALUE ...] [--rpm-list LIST] [--out DIR]\n"
    "                         [--checkpoint-every S]\n"
    "\n"
    "A drum experiment (a file that starts `experiment: drum`, e.g. configs/drum.yaml):\n"
    "fills the drum by bed volume, turns the settled bed rigidly by start_tilt_deg\n"
    "(20; a drum turns a level bed that far before it first avalanches), turns the\n"
    "drum until the angle and the occupied area are statistically steady (or\n"
    "max_time), and prints one JSON object with angle_deg,\n"
    "csa_percent, their spreads, steady, simulated_time_s, wall_time_s, granules and\n"
    "particle_steps; DIR (default results/runs/drum) gets result.json and result.h5.\n"
    "--set overrides a field: rpm, mu_s, mu_r, k_n, xi, wall (granules or a material),\n"
    "lambda, seed, fill, slice_depth, max_time, start_tilt_deg. --rpm-list\n"
    "4,40,80,105,116 turns one settled bed at each speed (results in\n"
    "DIR/rpm_<speed>/, one JSON with \"runs\"). Each turn saves its state to\n"
    "DIR[/rpm_<speed>]/checkpoint.h5 every --checkpoint-every S of wall time (default\n"
    "120, 0: never); the same command after a kill resumes the turn there (the bed is\n"
    "settled again) and ends as the uninterrupted run would, bit for bit.\n"
    "Examples:\n"
    "  granucal simulate configs/drum.yaml --set rpm=40 --set wall=PTFE\n"
    "  granucal simulate configs/drum.yaml --rpm-list 4,40,80,105,116\n"
    "\n"
    "The poured cylinder (`experiment: cylinder`, configs/cylinder.yaml; section 4.1):\n"
    "pours into the 100 x 40 mm container, strikes off at the rim, settles, and prints\n"
    "one JSON object with granules, coordination (granule-granule contacts per\n"
    "granule), coordination_interior, wall_contacts_per_granule, solid_fraction,\n"
    "simulated_time_s, wall_time_s and dt_s; DIR (default results/runs/cylinder) gets\n"
    "result.json and result.h5. --set overrides k_n, mu_s, mu_r, xi, lambda, seed,\n"
    "diameter, depth, density. Example:\n"
    "  granucal simulate configs/cylinder.yaml --set k_n=800 --set seed=2\n"
    "\n"
    "A sphere on an inclined plane (`experiment: incline`, configs/incline.yaml): one\n"
    "granule let go on a plane tilted by angle_deg; prints its measured acceleration\n"
    "and regime (rest, rolling, sliding) beside the textbook answer; DIR (default\n"
    "results/runs/incline) gets result.json and result.h5. --set overrides angle_deg,\n"
    "mu_s, mu_r, k_n, xi, diameter, density, duration. Example:\n"
    "  granucal simulate configs/incline.yaml --set angle_deg=40 --set mu_s=0.1\n"
    "\n"
    "The confined compression test (configs/compression.yaml) and the silo discharge\n"
    "(configs/silo.yaml) take --set and --out the same way (see those files).\n";

static const char simulate_epilogue[] =
    "An explicit scene (granules and walls listed one by one) writes, in DIR\n"
    "(default results/runs/<scene name>):\n"
    "  trajectory.csv  every granule every output_interval, columns\n"
    "                  t,id,x,y,z,vx,vy,vz,wx,wy,wz (SI units; id = the granule's\n"
    "                  1-based position in the scene file)\n"
    "  result.h5       the same frames with diagnostics (contacts, coordination\n"
    "                  number, kinetic energy, overlap), plus result.xmf for ParaView\n"
    "  result.json     the summary printed on stdout\n"
    "\n"
    "The time step is the scene's `dt`, checked against the engine's stability\n"
    "limit (a step above it is refused), or, when `dt` is 0 or absent, chosen by\n"
    "the engine; the choice and the reason are printed on stderr.\n"
    "\n"
    "Example (the paper's verification test, Appendix A.1):\n"
    "  granucal simulate configs/scenes/verification_two_particles.yaml\n";

// What `granucal simulate` hands every runner: the options as given.
typedef struct simulate_args {
    int n_sets;
    char **sets;     // --set KEY=VALUE overrides
    const char *out; // --out DIR, or NULL for the runner's default
    const char *rpm_list;
    double checkpoint_every_s;
} simulate_args;

// The experiments' runners, one per experiment and all of one shape: load
// the config into its definition (exp_NAME_load, its message on stderr) and
// hand it to the experiment's runner, exp_NAME_simulate(def, out_dir, ...)
// (experiments/NAME/exp_NAME_runner.h), which knows nothing of calib. The
// drum's takes what only it has: --rpm-list, read here, and
// --checkpoint-every, its checkpoints labelled with the calibration's record
// key (drum_key).
static int load_failed(const char *err) { return fprintf(stderr, "granucal simulate: %s\n", err), 1; }

// The plain scene (granules and walls listed one by one): the runner when no
// experiment claims the file.
static int run_scene_file(const char *path, const simulate_args *a)
{
    if (a->n_sets > 0) return fprintf(stderr, "granucal simulate: --set applies to experiment configs only\n"), 2;
    char err[1024];
    exp_scene *s = exp_scene_load(path, err, sizeof err);
    if (!s) return load_failed(err);
    int rc = exp_scene_simulate(s, a->out, path);
    exp_scene_free(s);
    return rc;
}


static int parse_rpm_list(const char *list, double *rpm, int cap, char *err, size_t len)
{
    int n = 0;
    const char *p = list;
    while (*p && n < cap) {
        char *end;
        double v = strtod(p, &end);
        if (end == p || !(v >= 0 && v <= 1000) || (*end && *end != ','))
            return snprintf(err, len, "--rpm-list '%s': expected numbers in [0, 1000] separated by commas", list), -1;
        rpm[n++] = v;
        p = *end ? end + 1 : end;
    }
    return n;
}

// A drum turn's checkpoint label: the calibration's record key of the same
// run (a drum filled and turned with one pair, at run->rpm).
static void drum_key(const exp_drum_def *def, const exp_drum_run_opts *run, char *out, size_t len)
{
    const cal_drum_case whole = {.def = *def, .fill = *def, .run = *run};
    cal_drum_key(&whole, run->rpm, out, len);
}

static int run_drum(const char *path, const simulate_args *a)
{
    char err[1024];
    exp_drum_yaml *y = exp_drum_config_load(path, a->n_sets, a->sets, err, sizeof err);
    if (!y) return load_failed(err);
    double rpm[CAL_CASE_MAX_RPM];
    exp_drum_simulate_opts o = {.rpm = rpm, .checkpoint_every_s = a->checkpoint_every_s, .key = drum_key};
    o.n_rpm = a->rpm_list ? parse_rpm_list(a->rpm_list, rpm, CAL_CASE_MAX_RPM, err, sizeof err) : 0;
    int rc = o.n_rpm < 0 ? (fprintf(stderr, "granucal simulate: %s\n", err), 2) : exp_drum_simulate(y, a->out, &o);
    exp_drum_config_free(y);
    return rc;
}
static int run_compress(const char *path, const simulate_args *a)
{
    char err[1400];
    exp_compress_def d;
    if (exp_compress_load(path, a->n_sets, a->sets, &d, err, sizeof err)) return load_failed(err);
    return exp_compress_simulate(&d, a->out);
}
static int run_silo(const char *path, const simulate_args *a)
{
    char err[1400];
    exp_silo_def d;
    if (exp_silo_load(path, a->n_sets, a->sets, &d, err, sizeof err)) return load_failed(err);
    return exp_silo_simulate(&d, a->out);
}
static int run_cylinder(const char *path, const simulate_args *a)
{
    char err[1400];
    exp_cylinder_def d;
    if (exp_cylinder_load(path, a->n_sets, a->sets, &d, err, sizeof err)) return load_failed(err);
    return exp_cylinder_simulate(&d, a->out);
}
static int run_incline(const char *path, const simulate_args *a)
{
    char err[1400];
    exp_incline_def d;
    if (exp_incline_load(path, a->n_sets, a->sets, &d, err, sizeof err)) return load_failed(err);
    return exp_incline_simulate(&d, a->out);
}

// Every experiment `granucal simulate` runs: the first whose `claims` knows
// the file (its first key, `experiment: NAME`) runs it; a file none claims
// is a plain scene.
static const struct simulate_runner {
    int (*claims)(const char *path);
    int (*run)(const char *path, const simulate_args *a);
} simulate_runners[] = {
    {exp_is_drum_config, run_drum},
    {exp_is_compress_config, run_compress},
    {exp_is_silo_config, run_silo},
    {exp_is_cylinder_config, run_cylinder},
    {exp_is_incline_config, run_incline},
};

enum { MAX_SETS = 64 };

int cal_cmd_simulate(int argc, char **argv)
{
    char *sets[MAX_SETS];
    simulate_args a = {.sets = sets, .checkpoint_every_s = CAL_CHECKPOINT_EVERY_S};
    cal_option out = cal_option_out(&a.out, "results folder (default results/runs/<experiment or scene name>)");
    out.short_name = 'o'; // -o has always been taken here
    const cal_option table[] = {
        {.name = "set", .short_name = 's', .kind = CAL_OPT_LIST, .list = sets, .count = &a.n_sets, .max = MAX_SETS,
         .value = "KEY=VALUE", .help = "override a field of an experiment config (repeatable; the keys: above)"},
        {.name = "rpm-list", .kind = CAL_OPT_TEXT, .text = &a.rpm_list, .value = "LIST",
         .help = "a drum: turn one settled bed at each speed of LIST (4,40,80)"},
        out,
        cal_option_checkpoint_every(&a.checkpoint_every_s, "a drum: wall seconds between a turn's checkpoints "
                                                           "(default 120; 0: none)"),
    };
    const cal_command_line line = {.command = "simulate", .synopsis = simulate_synopsis, .epilogue = simulate_epilogue,
                                   .options = table, .n_options = sizeof table / sizeof *table,
                                   .operand = "SCENE.yaml", .min_operands = 1, .max_operands = 1};
    char **operands;
    int n_operands, status = cal_options_parse(&line, argc, argv, &operands, &n_operands);
    if (status) return status < 0 ? 0 : status;
    const char *path = operands[0];
    for (size_t k = 0; k < sizeof simulate_runners / sizeof *simulate_runners; ++k)
        if (simulate_runners[k].claims(path)) return simulate_runners[k].run(path, &a);
    return run_scene_file(path, &a);
}
