// SPDX-License-Identifier: MIT
#include "exp_common.h"

#include <stdarg.h>
#include <stdio.h>

const char *exp_version(void) { return DEM_VERSION; }

int exp_fail(char *err, size_t len, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, len, fmt, ap);
    va_end(ap);
    return 1;
}
