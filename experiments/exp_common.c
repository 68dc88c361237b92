// SPDX-License-Identifier: MIT
#include "exp_common.h"

const char *exp_version(void) { return DEM_VERSION; }
