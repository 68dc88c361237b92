// SPDX-License-Identifier: MIT
// granucal: the command line.
#include <stdio.h>
#include <string.h>

#include "exp_common.h"

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "--version") == 0) {
        printf("granucal %s\n", exp_version());
        return 0;
    }
    fprintf(stderr, "usage: granucal COMMAND ...\n");
    return 2;
}
