// SPDX-License-Identifier: MIT
#include "dem_h5_errors.h"

#include <stdio.h>

dem_h5_quiet dem_h5_quiet_begin(void)
{
    dem_h5_quiet q = {NULL, NULL};
    H5Eget_auto2(H5E_DEFAULT, &q.func, &q.data);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    return q;
}

void dem_h5_quiet_end(dem_h5_quiet q) { H5Eset_auto2(H5E_DEFAULT, q.func, q.data); }

typedef struct text_buf {
    char *buf;
    size_t len;
} text_buf;

// Walking upward, entry 0 is the innermost one.
static herr_t innermost_error(unsigned n, const H5E_error2_t *e, void *ctx)
{
    text_buf *t = ctx;
    if (n == 0 && e->desc) snprintf(t->buf, t->len, "%s", e->desc);
    return 0;
}

void dem_h5_reason(char *buf, size_t len)
{
    text_buf t = {buf, len};
    buf[0] = '\0';
    H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost_error, &t);
    // Keep the message on one line (write failures embed a ctime() stamp).
    for (char *c = buf; *c; c++)
        if (*c == '\n' || *c == '\t') *c = ' ';
}
