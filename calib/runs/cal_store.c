// SPDX-License-Identifier: MIT
// Result store: YAML records read back with libcyaml (see cal_store.h).
#include "cal_store.h"

#include <cyaml/cyaml.h>
#include <dirent.h>
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cal_files.h"
#include "exp_atomic_file.h"
#include "exp_common.h"
#include "exp_yaml.h"

#define REC_FLOAT(key, member) CYAML_FIELD_FLOAT(key, CYAML_FLAG_OPTIONAL, cal_record, member)
static const cyaml_schema_field_t record_fields[] = {
    CYAML_FIELD_STRING_PTR("key", CYAML_FLAG_POINTER, cal_record, key, 1, 4096),
    CYAML_FIELD_STRING_PTR("status", CYAML_FLAG_POINTER, cal_record, status, 1, 32),
    CYAML_FIELD_STRING_PTR("reason", CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL, cal_record, reason, 0, 1024),
    REC_FLOAT("angle_deg", angle_deg), REC_FLOAT("angle_sd_deg", angle_sd_deg), REC_FLOAT("csa_percent", csa_percent),
    REC_FLOAT("csa_sd_percent", csa_sd_percent), REC_FLOAT("coordination", coordination),
    REC_FLOAT("coordination_interior", coordination_interior),
    REC_FLOAT("wall_contacts_per_granule", wall_contacts_per_granule), REC_FLOAT("solid_fraction", solid_fraction),
    CYAML_FIELD_BOOL("steady", CYAML_FLAG_OPTIONAL, cal_record, steady), REC_FLOAT("simulated_time_s", simulated_time_s),
    REC_FLOAT("wall_time_s", wall_time_s), REC_FLOAT("dt_s", dt_s), REC_FLOAT("particle_steps", particle_steps),
    REC_FLOAT("fill_wall_time_s", fill_wall_time_s), REC_FLOAT("peak_rss_mb", peak_rss_mb),
    REC_FLOAT("dt_margin_min", dt_margin_min), CYAML_FIELD_INT("dt_lowered", CYAML_FLAG_OPTIONAL, cal_record, dt_lowered),
    CYAML_FIELD_BOOL("retry", CYAML_FLAG_OPTIONAL, cal_record, retry),
    CYAML_FIELD_STRING_PTR("writer", CYAML_FLAG_POINTER | CYAML_FLAG_OPTIONAL, cal_record, writer, 0, 256),
    // Required: the last line cal_store_put writes, so a record cut short at a line's end lacks it.
    CYAML_FIELD_INT("granules", CYAML_FLAG_DEFAULT, cal_record, granules), CYAML_FIELD_END};
static const cyaml_schema_value_t record_schema = {CYAML_VALUE_MAPPING(CYAML_FLAG_POINTER, cal_record, record_fields)};

// This run, as written into every record: "host:pid".
static const char *this_run(void)
{
    static char id[128];
    if (!id[0]) {
        char host[64];
        exp_host_name(host);
        snprintf(id, sizeof id, "%s:%ld", host, (long)getpid());
    }
    return id;
}

void cal_store_hash(const char *key, char out[17])
{
    uint64_t h = 1469598103934665603ULL; // FNV-1a 64
    for (const unsigned char *p = (const unsigned char *)key; *p; ++p) h = (h ^ *p) * 1099511628211ULL;
    snprintf(out, 17, "%016" PRIx64, h);
}

void cal_store_path(const char *dir, const char *key, char *out, size_t len)
{
    char hash[17];
    cal_store_hash(key, hash);
    snprintf(out, len, "%s/%s.yaml", dir, hash);
}

// 1 if the file's last byte is a line break, as every record cal_store_put
// writes: one cut short within a line lacks it (even where the YAML parses).
static int ends_with_newline(const char *path)
{
    FILE *f = fopen(path, "rb");
    int last = EOF;
    if (f && fseek(f, -1, SEEK_END) == 0) last = fgetc(f);
    if (f) fclose(f);
    return last == '\n';
}

enum { DAMAGED = -2 };

// The record in file `path` (which exists) into *out: 0, or DAMAGED.
static int load_file(const char *path, cal_record *out, char *err, size_t len)
{
    if (!ends_with_newline(path)) return exp_fail(err, len, "%s: cut short (no line break at its end)", path), DAMAGED;
    cal_record *r = NULL;
    if (exp_yaml_load(path, &record_schema, (void **)&r, "a damaged store record", err, len)) return DAMAGED;
    *out = *r;
    free(r); // the strings now belong to *out
    return 0;
}

// A retry record another run wrote: its process was killed, so it counts as absent.
static int retry_of_another_run(const cal_record *r)
{
    return r->retry && (!r->writer || strcmp(r->writer, this_run()) != 0);
}

// cal_store_get, with a damaged record (cut short, not YAML, a field
// missing) told apart as DAMAGED from a record of another key (-1).
static int load_record(const char *dir, const char *key, cal_record *out, char *err, size_t len)
{
    char path[1200];
    cal_store_path(dir, key, path, sizeof path);
    memset(out, 0, sizeof *out);
    if (access(path, F_OK) != 0) return 1;
    if (load_file(path, out, err, len)) return DAMAGED;
    if (strcmp(out->key, key) != 0) {
        cal_record_free(out);
        return exp_fail(err, len, "%s: holds a different simulation (hash collision); delete it", path), -1;
    }
    if (retry_of_another_run(out)) {
        cal_record_free(out); // an earlier run's process was killed: run it again
        return 1;
    }
    return 0;
}

int cal_store_get(const char *dir, const char *key, cal_record *out, char *err, size_t len)
{
    int got = load_record(dir, key, out, err, len);
    return got == DAMAGED ? -1 : got;
}

int cal_store_peek(const char *dir, const char *key, cal_record *out, char *err, size_t len)
{
    int got = load_record(dir, key, out, err, len);
    return got == DAMAGED ? 1 : got;
}

int cal_store_lookup(const char *dir, const char *key, cal_record *out, char *err, size_t len)
{
    int got = load_record(dir, key, out, err, len);
    if (got != DAMAGED) return got;
    char why[1024], path[1200], aside[1300], hash[17];
    snprintf(why, sizeof why, "%s", err);
    why[strcspn(why, "\n")] = 0;
    cal_store_path(dir, key, path, sizeof path);
    cal_store_hash(key, hash);
    snprintf(aside, sizeof aside, "%s/damaged", dir);
    if (cal_mkdirs(aside, err, len)) return -1;
    snprintf(aside, sizeof aside, "%s/damaged/%s.yaml", dir, hash);
    // Another rank may have moved it first (ENOENT): absent to both, run once by the one it is dealt to.
    if (rename(path, aside) != 0 && errno != ENOENT)
        return exp_fail(err, len, "%s is damaged and cannot be moved aside to %s: %s", path, aside, strerror(errno)), -1;
    fprintf(stderr, "granucal: damaged store record moved to %s (%s); its simulation runs again\n", aside, why);
    return 1;
}

// YAML single-quoted scalar: quotes doubled, line breaks flattened.
static void put_quoted(FILE *f, const char *name, const char *s)
{
    fprintf(f, "%s: '", name);
    for (; s && *s; ++s) {
        if (*s == '\'') fputs("''", f);
        else fputc(*s == '\n' || *s == '\r' ? ' ' : *s, f);
    }
    fputs("'\n", f);
}

int cal_store_put(const char *dir, const cal_record *r, char *err, size_t len)
{
    char path[1200];
    cal_store_path(dir, r->key, path, sizeof path);
    exp_atomic_file a;
    if (exp_atomic_open(&a, path, err, len)) return 1;
    put_quoted(a.f, "key", r->key);
    put_quoted(a.f, "status", r->status);
    put_quoted(a.f, "reason", r->reason ? r->reason : "");
    put_quoted(a.f, "writer", this_run());
    fprintf(a.f, "retry: %s\n", r->retry ? "true" : "false");
    fprintf(a.f,
            "angle_deg: %.17g\nangle_sd_deg: %.17g\ncsa_percent: %.17g\ncsa_sd_percent: %.17g\n"
            "coordination: %.17g\ncoordination_interior: %.17g\nwall_contacts_per_granule: %.17g\n"
            "solid_fraction: %.17g\nsteady: %s\nsimulated_time_s: %.17g\nwall_time_s: %.6g\ndt_s: %.17g\n"
            "particle_steps: %.17g\nfill_wall_time_s: %.6g\npeak_rss_mb: %.6g\ndt_margin_min: %.6g\ndt_lowered: %d\n"
            "granules: %d\n",
            r->angle_deg, r->angle_sd_deg, r->csa_percent, r->csa_sd_percent, r->coordination,
            r->coordination_interior, r->wall_contacts_per_granule, r->solid_fraction, r->steady ? "true" : "false",
            r->simulated_time_s, r->wall_time_s, r->dt_s, r->particle_steps, r->fill_wall_time_s, r->peak_rss_mb,
            isfinite(r->dt_margin_min) ? r->dt_margin_min : 0, r->dt_lowered, r->granules); // YAML 0, not nan: unchecked
    return exp_atomic_commit(&a, err, len);
}

// A record's file name: 16 hex digits and ".yaml" (not a partial write, a
// turned bed, nor the damaged/ folder).
static int record_file_name(const char *name)
{
    return strlen(name) == 21 && strspn(name, "0123456789abcdef") == 16 && strcmp(name + 16, ".yaml") == 0;
}

int cal_store_each(const char *dir, void (*visit)(const cal_record *r, void *ctx), void *ctx, char *err, size_t len)
{
    DIR *d = opendir(dir);
    if (!d) return errno == ENOENT ? 0 : (exp_fail(err, len, "%s: cannot read the store: %s", dir, strerror(errno)), -1);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));) {
        char path[1300], why[1024];
        cal_record r;
        if (!record_file_name(e->d_name)) continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        memset(&r, 0, sizeof r);
        if (load_file(path, &r, why, sizeof why)) continue; // damaged: the run that needs it deals with it
        if (!retry_of_another_run(&r)) visit(&r, ctx), ++n;
        cal_record_free(&r);
    }
    closedir(d);
    return n;
}

void cal_record_free(cal_record *r)
{
    free(r->key), free(r->status), free(r->reason), free(r->writer);
    r->key = r->status = r->reason = r->writer = NULL;
}

double cal_record_cost_s(const cal_record *r) { return r->wall_time_s + r->fill_wall_time_s; }

int cal_record_usable(const cal_record *r) { return r->status && strcmp(r->status, "failed") != 0; }
