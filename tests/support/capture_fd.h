// SPDX-License-Identifier: MIT
// What a piece of code writes to stdout or stderr, caught in a temporary file
// for a test to read: capture_begin before the call, capture_end after it.
#ifndef GRANUCAL_TEST_CAPTURE_FD_H
#define GRANUCAL_TEST_CAPTURE_FD_H

#include <stdio.h>
#include <unistd.h>

typedef struct capture_fd {
    int fd;      ///< 1 (stdout) or 2 (stderr)
    int saved;   ///< the descriptor it had before, restored at the end
    FILE *file;  ///< where it writes meanwhile
} capture_fd;

// 0 if fd now writes to a temporary file, -1 if it could not be redirected.
static inline int capture_begin(capture_fd *c, int fd)
{
    c->fd = fd, c->file = tmpfile(), c->saved = -1;
    if (!c->file) return -1;
    fflush(fd == 1 ? stdout : stderr);
    c->saved = dup(fd);
    if (c->saved < 0 || dup2(fileno(c->file), fd) < 0) return -1;
    return 0;
}

// fd restored; what it wrote meanwhile in said (at most len - 1 bytes, ended by '\0').
static inline void capture_end(capture_fd *c, char *said, size_t len)
{
    fflush(c->fd == 1 ? stdout : stderr);
    if (c->saved >= 0) dup2(c->saved, c->fd), close(c->saved);
    size_t got = 0;
    if (c->file) rewind(c->file), got = fread(said, 1, len - 1, c->file), fclose(c->file);
    said[got] = '\0';
}

#endif
