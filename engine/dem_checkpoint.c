// SPDX-License-Identifier: MIT
/// @file dem_checkpoint.c
/// A world's whole state to and from HDF5 (see dem_checkpoint.h).
///
/// Layout: `/world_state`, the world's fixed-size part as bytes (every
/// pointer zeroed), guarded by the root attribute `layout` (the sizes of the
/// engine's structures and this format's number); one 1-D dataset per array,
/// holding only the entries in use (granules, listed pairs, near granules);
/// the caller's arrays under `/caller/`; the run's `key` as a root attribute.
/// Per-step scratch that every force evaluation rewrites before reading
/// (the implicit solve's) is not saved, as dem_world_clone does not copy it.
#include "dem_checkpoint.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <hdf5.h>
#include <hdf5_hl.h>

#include "dem_h5_errors.h"
#include "dem_state_internal.h"

// Bump when the meaning of a saved array changes without a change of size
// in the structures named in layout_text.
#define CHECKPOINT_FORMAT 1

_Static_assert(sizeof(size_t) == sizeof(uint64_t), "size_t arrays are saved as uint64");
_Static_assert(sizeof(dem_vec3) == 3 * sizeof(double), "dem_vec3 must be three packed doubles");
_Static_assert(sizeof(dem_pair_constants) == 2 * sizeof(double), "pair constants are saved as two doubles");

static void layout_text(char *out, size_t len)
{
    snprintf(out, len,
             "granucal checkpoint format %d, engine %s: dem_world %zu, dem_wall %zu, dem_world_def %zu, "
             "dem_neighbor_list %zu, dem_contact_coeffs %zu, dem_imp_stats %zu bytes",
             CHECKPOINT_FORMAT, DEM_VERSION, sizeof(dem_world), sizeof(dem_wall), sizeof(dem_world_def),
             sizeof(dem_neighbor_list), sizeof(dem_contact_coeffs), sizeof(dem_imp_stats));
}

typedef struct ck_file {
    hid_t f;
    const char *path;
    char *err;
    size_t len;
    int failed;
} ck_file;

static int ck_fail(ck_file *c, const char *what, const char *name)
{
    if (c->failed) return -1;
    char reason[512];
    dem_h5_reason(reason, sizeof reason);
    snprintf(c->err, c->len, "checkpoint '%s': %s %s%s%s", c->path, what, name, reason[0] ? ": " : "", reason);
    c->failed = 1;
    return -1;
}

// ---- writing ----------------------------------------------------------------

static void put(ck_file *c, const char *name, hid_t type, size_t count, const void *data)
{
    static const uint64_t none = 0;
    hsize_t dims[1] = {count};
    if (!c->failed && H5LTmake_dataset(c->f, name, 1, dims, type, count ? data : &none) < 0)
        ck_fail(c, "cannot write", name);
}

static void put_doubles(ck_file *c, const char *name, size_t count, const void *data)
{
    put(c, name, H5T_NATIVE_DOUBLE, count, data);
}

// Every pointer of the fixed-size part zeroed: they mean nothing in another
// process (and a file should not differ by where malloc put things), and a
// damaged file's bytes must never reach free().
static void zero_pointers(dem_world *s)
{
    s->pos = s->vel = s->omg = s->frc = s->trq = s->pos_at_build = NULL;
    s->rad = s->mass = s->inertia = s->inv_mass = s->inv_inertia = s->damp = s->acc = NULL;
    s->id = NULL, s->fixed = NULL;
    s->pair_f = s->pair_ti = s->pair_tj = s->pair_n = NULL, s->pair_g = NULL;
    s->rev_start = s->rev_pair = NULL;
    memset(&s->nl_old, 0, sizeof s->nl_old);
    s->imp = NULL;
    s->nl.start = NULL, s->nl.j = s->nl.row = NULL, s->nl.constants = NULL, s->nl.hist = NULL;
    for (int k = 0; k < DEM_MAX_WALLS; ++k) s->walls[k].hist = NULL, s->walls[k].near = NULL, s->walls[k].force = NULL, s->walls[k].def.name = NULL;
}

static void put_world(ck_file *c, const dem_world *w)
{
    dem_world s = *w;
    zero_pointers(&s);
    put(c, "world_state", H5T_NATIVE_UCHAR, sizeof s, &s);

    size_t n = w->n, pairs = w->nl.count;
    put_doubles(c, "pos", 3 * n, w->pos), put_doubles(c, "vel", 3 * n, w->vel), put_doubles(c, "omg", 3 * n, w->omg);
    put_doubles(c, "frc", 3 * n, w->frc), put_doubles(c, "trq", 3 * n, w->trq);
    put_doubles(c, "pos_at_build", 3 * n, w->pos_at_build);
    put_doubles(c, "rad", n, w->rad), put_doubles(c, "mass", n, w->mass), put_doubles(c, "inertia", n, w->inertia);
    put_doubles(c, "inv_mass", n, w->inv_mass), put_doubles(c, "inv_inertia", n, w->inv_inertia);
    put_doubles(c, "damp", 6 * n, w->damp), put_doubles(c, "acc", 6 * n, w->acc);
    put(c, "id", H5T_NATIVE_UINT64, n, w->id);
    put(c, "fixed", H5T_NATIVE_UCHAR, n, w->fixed);
    put_doubles(c, "pair_f", 3 * pairs, w->pair_f), put_doubles(c, "pair_ti", 3 * pairs, w->pair_ti);
    put_doubles(c, "pair_tj", 3 * pairs, w->pair_tj), put_doubles(c, "pair_n", 3 * pairs, w->pair_n);
    put_doubles(c, "pair_g", pairs, w->pair_g);
    put(c, "rev_pair", H5T_NATIVE_UINT64, pairs, w->rev_pair);
    if (w->rev_start) put(c, "rev_start", H5T_NATIVE_UINT64, n + 1, w->rev_start);
    if (w->nl.start) put(c, "nl_start", H5T_NATIVE_UINT64, w->nl.rows + 1, w->nl.start);
    put(c, "nl_j", H5T_NATIVE_UINT32, pairs, w->nl.j), put(c, "nl_row", H5T_NATIVE_UINT32, pairs, w->nl.row);
    put_doubles(c, "nl_constants", 2 * pairs, w->nl.constants);
    put_doubles(c, "nl_hist", pairs * (size_t)w->nl.hist_len, w->nl.hist);
    for (int k = 0; k < w->n_walls; ++k) {
        char name[32];
        snprintf(name, sizeof name, "wall%d_hist", k);
        put_doubles(c, name, n * (size_t)w->walls[k].hist_len, w->walls[k].hist);
        snprintf(name, sizeof name, "wall%d_near", k);
        put(c, name, H5T_NATIVE_UINT32, w->walls[k].near_count, w->walls[k].near);
        snprintf(name, sizeof name, "wall%d_force", k);
        put_doubles(c, name, 3 * w->walls[k].near_count, w->walls[k].force);
    }
}

static int write_file(const dem_world *w, ck_file *c, const char *key, const dem_checkpoint_array *extra, int n_extra)
{
    char layout[512];
    layout_text(layout, sizeof layout);
    if (H5LTset_attribute_string(c->f, "/", "layout", layout) < 0) return ck_fail(c, "cannot write", "layout");
    if (H5LTset_attribute_string(c->f, "/", "key", key) < 0) return ck_fail(c, "cannot write", "key");
    put_world(c, w);
    hid_t g = c->failed ? H5I_INVALID_HID : H5Gcreate2(c->f, "caller", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (!c->failed && g < 0) return ck_fail(c, "cannot create", "/caller");
    for (int k = 0; k < n_extra && !c->failed; ++k) {
        hsize_t dims[1] = {extra[k].count};
        static const double none = 0;
        if (H5LTmake_dataset_double(g, extra[k].name, 1, dims, extra[k].count ? extra[k].data : &none) < 0)
            ck_fail(c, "cannot write", extra[k].name);
    }
    if (g >= 0) H5Gclose(g);
    return c->failed ? -1 : 0;
}

// The temporary a checkpoint is written under before it is renamed into place.
static int temporary_of(const char *path, char *out, size_t len)
{
    return snprintf(out, len, "%s.tmp", path) >= (int)len;
}

void dem_checkpoint_remove(const char *path)
{
    char tmp[4096];
    remove(path);
    if (!temporary_of(path, tmp, sizeof tmp)) remove(tmp);
}

int dem_checkpoint_write(const dem_world *w, const char *path, const char *key, const dem_checkpoint_array *extra,
                         int n_extra, char *err, size_t len)
{
    char tmp[4096];
    if (temporary_of(path, tmp, sizeof tmp)) return snprintf(err, len, "checkpoint '%s': path too long", path), 1;
    dem_h5_quiet q = dem_h5_quiet_begin();
    ck_file c = {H5Fcreate(tmp, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), path, err, len, 0};
    if (c.f < 0) ck_fail(&c, "cannot create", tmp);
    else write_file(w, &c, key, extra, n_extra);
    if (c.f >= 0 && H5Fclose(c.f) < 0) ck_fail(&c, "cannot close", tmp);
    dem_h5_quiet_end(q);
    if (!c.failed && rename(tmp, path) != 0) snprintf(err, len, "checkpoint '%s': cannot rename '%s' into place", path, tmp), c.failed = 1;
    if (c.failed) unlink(tmp);
    return c.failed;
}

// ---- reading ----------------------------------------------------------------

// The entries of saved array `name` into *count; 0, or −1 (the file fails) if it is not there.
static int array_length(ck_file *c, const char *name, size_t *count)
{
    hsize_t dims[1] = {0};
    H5T_class_t cls;
    size_t size;
    if (H5LTget_dataset_info(c->f, name, dims, &cls, &size) < 0) return ck_fail(c, "has no array", name);
    *count = (size_t)dims[0];
    return 0;
}

// A saved array of exactly `count` entries of `type` into `dst`.
static void get(ck_file *c, const char *name, hid_t type, size_t count, void *dst)
{
    size_t saved;
    if (c->failed || array_length(c, name, &saved)) return;
    if (saved != count) {
        snprintf(c->err, c->len, "checkpoint '%s': array %s holds %zu entries, the world needs %zu (damaged file)",
                 c->path, name, saved, count);
        c->failed = 1;
        return;
    }
    if (count && H5LTread_dataset(c->f, name, type, dst) < 0) ck_fail(c, "cannot read", name);
}

static void *alloc_or_fail(ck_file *c, size_t bytes)
{
    void *p = c->failed ? NULL : calloc(1, bytes ? bytes : 1);
    if (!p && !c->failed) snprintf(c->err, c->len, "checkpoint '%s': out of memory", c->path), c->failed = 1;
    return p;
}

// Allocate `cap` entries of `width` bytes and read the first `count`.
static void *get_new(ck_file *c, const char *name, hid_t type, size_t count, size_t cap, size_t width)
{
    void *p = alloc_or_fail(c, cap * width);
    get(c, name, type, count * (width / H5Tget_size(type)), p);
    return p;
}

static void get_arrays(ck_file *c, dem_world *w)
{
    size_t n = w->n, cap = n ? n : 1, pairs = w->nl.count, pcap = pairs ? pairs : 1;
    const hid_t D = H5T_NATIVE_DOUBLE;
    w->cap = cap, w->pair_cap = pcap;
    w->pos = get_new(c, "pos", D, n, cap, sizeof(dem_vec3)), w->vel = get_new(c, "vel", D, n, cap, sizeof(dem_vec3));
    w->omg = get_new(c, "omg", D, n, cap, sizeof(dem_vec3)), w->frc = get_new(c, "frc", D, n, cap, sizeof(dem_vec3));
    w->trq = get_new(c, "trq", D, n, cap, sizeof(dem_vec3));
    w->pos_at_build = get_new(c, "pos_at_build", D, n, cap, sizeof(dem_vec3));
    w->rad = get_new(c, "rad", D, n, cap, sizeof(double)), w->mass = get_new(c, "mass", D, n, cap, sizeof(double));
    w->inertia = get_new(c, "inertia", D, n, cap, sizeof(double));
    w->inv_mass = get_new(c, "inv_mass", D, n, cap, sizeof(double));
    w->inv_inertia = get_new(c, "inv_inertia", D, n, cap, sizeof(double));
    w->damp = get_new(c, "damp", D, n, cap, 6 * sizeof(double)), w->acc = get_new(c, "acc", D, n, cap, 6 * sizeof(double));
    w->id = get_new(c, "id", H5T_NATIVE_UINT64, n, cap, sizeof(uint64_t));
    w->fixed = get_new(c, "fixed", H5T_NATIVE_UCHAR, n, cap, 1);
    w->pair_f = get_new(c, "pair_f", D, pairs, pcap, sizeof(dem_vec3));
    w->pair_ti = get_new(c, "pair_ti", D, pairs, pcap, sizeof(dem_vec3));
    w->pair_tj = get_new(c, "pair_tj", D, pairs, pcap, sizeof(dem_vec3));
    w->pair_n = get_new(c, "pair_n", D, pairs, pcap, sizeof(dem_vec3));
    w->pair_g = get_new(c, "pair_g", D, pairs, pcap, sizeof(double));
    w->rev_pair = get_new(c, "rev_pair", H5T_NATIVE_UINT64, pairs, pcap, sizeof(size_t));
    if (!c->failed && H5LTfind_dataset(c->f, "rev_start"))
        w->rev_start = get_new(c, "rev_start", H5T_NATIVE_UINT64, n + 1, n + 1, sizeof(size_t));
    dem_neighbor_list *nl = &w->nl;
    size_t hl = (size_t)(nl->hist_len ? nl->hist_len : 1);
    nl->cap = pcap, nl->hist_cap = pcap * hl;
    if (!c->failed && H5LTfind_dataset(c->f, "nl_start"))
        nl->start = get_new(c, "nl_start", H5T_NATIVE_UINT64, nl->rows + 1, nl->rows + 1, sizeof(size_t));
    nl->j = get_new(c, "nl_j", H5T_NATIVE_UINT32, pairs, pcap, sizeof(uint32_t));
    nl->row = get_new(c, "nl_row", H5T_NATIVE_UINT32, pairs, pcap, sizeof(uint32_t));
    nl->constants = get_new(c, "nl_constants", D, pairs, pcap, sizeof(dem_pair_constants));
    nl->hist = alloc_or_fail(c, nl->hist_cap * sizeof(double));
    get(c, "nl_hist", D, pairs * (size_t)nl->hist_len, nl->hist);
    for (int k = 0; k < w->n_walls; ++k) {
        dem_wall *wall = &w->walls[k];
        char name[32];
        wall->def.name = wall->name;
        snprintf(name, sizeof name, "wall%d_hist", k);
        wall->hist = alloc_or_fail(c, cap * (size_t)(wall->hist_len ? wall->hist_len : 1) * sizeof(double));
        get(c, name, D, n * (size_t)wall->hist_len, wall->hist);
        snprintf(name, sizeof name, "wall%d_near", k);
        wall->near = get_new(c, name, H5T_NATIVE_UINT32, wall->near_count, cap, sizeof(uint32_t));
        snprintf(name, sizeof name, "wall%d_force", k);
        wall->force = get_new(c, name, D, wall->near_count, cap, sizeof(dem_vec3));
        wall->near_cap = cap;
    }
}

// The root attribute `name` into out; 0, or non-zero if absent or too long.
static int get_text(ck_file *c, const char *name, char *out, size_t len)
{
    hsize_t dims[1];
    H5T_class_t cls;
    size_t size;
    if (H5LTget_attribute_info(c->f, "/", name, dims, &cls, &size) < 0 || size >= len) return 1;
    return H5LTget_attribute_string(c->f, "/", name, out) < 0;
}

// Counts that size the allocations, checked before any is made (the arrays'
// own lengths are checked against them as they are read).
static int plausible(const dem_world *w)
{
    if (w->n_walls < 0 || w->n_walls > DEM_MAX_WALLS || w->n >= UINT32_MAX || w->nl.rows > w->n) return 0;
    if (w->nl.hist_len < 0 || w->nl.hist_len > 64 || w->nl.count > (size_t)UINT32_MAX * 64) return 0;
    for (int k = 0; k < w->n_walls; ++k)
        if (w->walls[k].hist_len < 0 || w->walls[k].hist_len > 64 || w->walls[k].near_count > w->n) return 0;
    return 1;
}

static dem_world *read_world(ck_file *c, const char *key)
{
    char want[512], got[4096];
    layout_text(want, sizeof want);
    if (get_text(c, "layout", got, sizeof got) || strcmp(got, want) != 0) {
        snprintf(c->err, c->len, "checkpoint '%s' was written by another build of the engine (%.200s), not this one",
                 c->path, got);
        c->failed = 1;
        return NULL;
    }
    if (get_text(c, "key", got, sizeof got) || strcmp(got, key) != 0) {
        snprintf(c->err, c->len, "checkpoint '%s' is of another run", c->path);
        c->failed = 1;
        return NULL;
    }
    dem_world *w = alloc_or_fail(c, sizeof *w);
    get(c, "world_state", H5T_NATIVE_UCHAR, sizeof *w, w);
    if (c->failed) return free(w), NULL;
    zero_pointers(w);
    if (!plausible(w)) {
        snprintf(c->err, c->len, "checkpoint '%s': its counts are out of range (damaged file)", c->path);
        c->failed = 1;
        return free(w), NULL;
    }
    get_arrays(c, w);
    if (c->failed) return dem_world_destroy(w), NULL;
    return w;
}

static void read_extra(ck_file *c, dem_checkpoint_array *extra, int n_extra)
{
    for (int k = 0; k < n_extra && !c->failed; ++k) {
        char name[256];
        snprintf(name, sizeof name, "/caller/%s", extra[k].name);
        if (array_length(c, name, &extra[k].count)) return;
        extra[k].data = alloc_or_fail(c, extra[k].count * sizeof(double));
        if (extra[k].count && !c->failed && H5LTread_dataset_double(c->f, name, extra[k].data) < 0)
            ck_fail(c, "cannot read", name);
    }
}

int dem_checkpoint_read(dem_world *w, const char *path, const char *key, dem_checkpoint_array *extra, int n_extra,
                        char *err, size_t len)
{
    for (int k = 0; k < n_extra; ++k) extra[k].data = NULL, extra[k].count = 0;
    if (access(path, F_OK) != 0) return snprintf(err, len, "no checkpoint at '%s'", path), 1;
    dem_h5_quiet q = dem_h5_quiet_begin();
    ck_file c = {H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT), path, err, len, 0};
    dem_world *loaded = NULL;
    if (c.f < 0) ck_fail(&c, "cannot open", "it as HDF5");
    else loaded = read_world(&c, key);
    read_extra(&c, extra, n_extra);
    if (c.f >= 0) H5Fclose(c.f);
    dem_h5_quiet_end(q);
    if (c.failed) return dem_world_destroy(loaded), -1;
    // Swap the loaded state in; the old one goes with the husk.
    dem_world old = *w;
    *w = *loaded;
    *loaded = old;
    dem_world_destroy(loaded);
    for (int k = 0; k < w->n_walls; ++k) w->walls[k].def.name = w->walls[k].name;
    return 0;
}
