// SPDX-License-Identifier: MIT
/// @file config_variant.h
/// The tests of a config loader's located errors: a copy of a shipped config
/// with one key's line replaced by a bad one.
#ifndef CONFIG_VARIANT_H
#define CONFIG_VARIANT_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/// Copy `src` to a new file made from the mkstemp template `tmp` (its name is
/// left there), the line that starts with `key` replaced by `line` (with
/// its newline). Returns that line's number (1-based), 0 when no line starts
/// with `key`, -1 when a file cannot be opened.
static inline int config_variant(const char *src, const char *key, const char *line, char *tmp)
{
    int fd = mkstemp(tmp);
    FILE *in = fopen(src, "r"), *out = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!in || !out) return in ? fclose(in) : 0, out ? fclose(out) : 0, -1;
    char buf[512];
    int n = 0, bad_line = 0;
    while (fgets(buf, sizeof buf, in)) {
        ++n;
        if (strncmp(buf, key, strlen(key)) == 0) snprintf(buf, sizeof buf, "%s\n", line), bad_line = n;
        fputs(buf, out);
    }
    fclose(in), fclose(out);
    return bad_line;
}

#endif
