// SPDX-License-Identifier: MIT
// A main for the fuzz targets without libFuzzer (any compiler): feeds every
// regular file of the directories (or files) named on the command line to
// LLVMFuzzerTestOneInput, in name order. Run under ASan + UBSan (the
// GRANUCAL_SANITIZE build) it replays the corpus: a broken invariant aborts
// naming the input, a leak is reported at exit. Exit 1 if no input was found
// (a missing corpus must not pass).
#include <dirent.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int replay_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f) return perror(path), 1;
    size_t cap = 4096, size = 0, n;
    uint8_t *data = malloc(cap);
    while (data && (n = fread(data + size, 1, cap - size, f)) > 0) {
        size += n;
        if (size == cap) {
            uint8_t *grown = realloc(data, cap *= 2);
            if (!grown) free(data);
            data = grown;
        }
    }
    int bad = ferror(f) || !data;
    fclose(f);
    if (bad) return fprintf(stderr, "%s: cannot read\n", path), free(data), 1;
    fprintf(stderr, "replay %s (%zu bytes)\n", path, size);
    LLVMFuzzerTestOneInput(data, size);
    free(data);
    return 0;
}

static int by_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

// Replays the regular files of `dir`; returns how many, or -1 on an error.
static int replay_dir(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d) return perror(dir), -1;
    char **names = NULL;
    size_t count = 0;
    struct dirent *e;
    while ((e = readdir(d))) {
        if (e->d_name[0] == '.') continue;
        char **grown = realloc(names, (count + 1) * sizeof *names);
        if (!grown) break;
        names = grown;
        size_t len = strlen(dir) + strlen(e->d_name) + 2;
        if (!(names[count] = malloc(len))) break;
        snprintf(names[count++], len, "%s/%s", dir, e->d_name);
    }
    closedir(d);
    qsort(names, count, sizeof *names, by_name);
    int replayed = 0, failed = 0;
    for (size_t k = 0; k < count; ++k) {
        struct stat st;
        if (stat(names[k], &st) == 0 && S_ISREG(st.st_mode)) {
            if (replay_file(names[k])) failed = 1;
            else replayed++;
        }
        free(names[k]);
    }
    free(names);
    return failed ? -1 : replayed;
}

int main(int argc, char **argv)
{
    if (argc < 2) return fprintf(stderr, "usage: %s DIR|FILE...\n", argv[0]), 2;
    int total = 0;
    for (int k = 1; k < argc; ++k) {
        struct stat st;
        if (stat(argv[k], &st) != 0) return perror(argv[k]), 1;
        int n = S_ISDIR(st.st_mode) ? replay_dir(argv[k]) : replay_file(argv[k]) ? -1 : 1;
        if (n < 0) return 1;
        total += n;
    }
    printf("replayed %d inputs: every loader accepted or refused them with a message naming the file\n", total);
    if (total == 0) return fprintf(stderr, "no inputs found: the corpus is missing\n"), 1;
    return 0;
}
