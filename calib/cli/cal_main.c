// SPDX-License-Identifier: MIT
// granucal: the command line.
#include <stdio.h>
#include <string.h>

#include "cal_commands.h"
#include "exp_common.h"

static const char main_help[] =
    "granucal: calibrate a DEM powder model (linear spring-dashpot with sliding and\n"
    "rolling friction) from rotating-drum experiments, after Tiscar et al. (2019).\n"
    "\n"
    "usage: granucal COMMAND [options]\n"
    "\n"
    "commands:\n"
    "  calibrate [CONFIG]    the calibration: stiffness, granule-granule friction, each\n"
    "                        wall material; writes the parameter table (Table 3)\n"
    "  simulate SCENE.yaml   run one scene file (e.g. the paper's verification test,\n"
    "                        configs/scenes/verification_two_particles.yaml) or a\n"
    "                        drum experiment (configs/drum.yaml)\n"
    "  measure PHOTO.png     angle of repose and occupied area of a drum photograph\n"
    "  study fidelity        what accuracy costs in time: the drum over a ladder of\n"
    "                        scale factors, depths and run lengths, error vs wall time\n"
    "  synthesize [CONFIG]   drum data made by a tier's own drum at known pairs: the\n"
    "                        data of a twin experiment (calibrate --data DIR)\n"
    "  --version             print the version\n"
    "\n"
    "Run `granucal COMMAND --help` for the options of a command.\n";

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
} command;

static const command commands[] = {{"simulate", cal_cmd_simulate}, {"measure", cal_cmd_measure}, {"calibrate", cal_cmd_calibrate},
                                   {"study", cal_cmd_study}, {"synthesize", cal_cmd_synthesize}};

int main(int argc, char **argv)
{
    if (argc < 2 || strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0) {
        fputs(main_help, argc < 2 ? stderr : stdout);
        return argc < 2 ? 2 : 0;
    }
    if (strcmp(argv[1], "--version") == 0) return printf("granucal %s\n", exp_version()), 0;
    for (size_t k = 0; k < sizeof commands / sizeof *commands; ++k)
        if (strcmp(argv[1], commands[k].name) == 0) return commands[k].run(argc - 1, argv + 1);
    fprintf(stderr, "granucal: unknown command '%s'; see `granucal --help`\n", argv[1]);
    return 2;
}
