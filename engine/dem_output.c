// SPDX-License-Identifier: MIT
/// @file dem_output.c
/// HDF5 frames + XDMF sidecar; layout in dem_output.h.
#include "dem_output.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include <hdf5.h>

#include "dem_h5_errors.h"

// Vector arrays go to HDF5 as N×3 doubles straight from the view, no copy.
_Static_assert(sizeof(dem_vec3) == 3 * sizeof(double), "dem_vec3 must be three packed doubles");

enum { DIAG_COLUMNS = 11 };
static const char DIAG_COLUMN_NAMES[] = "time,step,granules,contacts,wall_contacts,coordination,"
                                        "coordination_walls,ke_translational,ke_rotational,"
                                        "max_overlap_ratio,potential_elastic";
static const char DIAG_COLUMN_UNITS[] = "s,1,1,1,1,1,1,J,J,1,J";

// 16384 rows × 3 doubles = 384 KiB: inside HDF5's default 1 MiB chunk cache,
// and still few chunks (13) for the paper's 200,000-granule drum.
#define FRAME_CHUNK_ROWS 16384
// One diagnostics row per frame; small chunks keep short runs small.
#define DIAG_CHUNK_ROWS 256
#define DEFLATE_LEVEL 4

/// What the XDMF sidecar needs to know of each frame.
typedef struct frame_info {
    double time;
    size_t count;
} frame_info;

struct dem_h5_writer {
    hid_t file;   // the temporary HDF5 file
    hid_t frames; // group /frames
    hid_t diag;   // dataset /diagnostics
    char *h5_path, *h5_tmp, *xmf_path, *xmf_tmp;
    frame_info *frame;
    size_t frame_count, frame_cap;
    int failed; // an HDF5 write failed: the file can no longer be trusted
    char error[2048];
};

// ---------------------------------------------------------------------------
// Errors

static void put_message(char *err, size_t err_len, const char *msg)
{
    if (err && err_len > 0)
        snprintf(err, err_len, "%s", msg);
}

// Message "'<file>': <what>[: <reason>]" into w->error.
static void set_error(dem_h5_writer *w, const char *file, const char *reason, const char *fmt, va_list ap)
{
    if (w->failed)
        return; // the first failure names the cause; later ones are its echoes
    char what[512];
    vsnprintf(what, sizeof what, fmt, ap);
    if (reason && reason[0])
        snprintf(w->error, sizeof w->error, "'%s': %s: %s", file, what, reason);
    else
        snprintf(w->error, sizeof w->error, "'%s': %s", file, what);
}

// An HDF5 call failed. Call before any other HDF5 call, which would clear
// the error stack. Marks the writer failed. Returns -1.
static int fail_h5(dem_h5_writer *w, const char *fmt, ...)
{
    char reason[512];
    dem_h5_reason(reason, sizeof reason);
    va_list ap;
    va_start(ap, fmt);
    set_error(w, w->h5_path, reason, fmt, ap);
    va_end(ap);
    w->failed = 1;
    return -1;
}

// A system call on `file` failed (errno set). Returns -1.
static int fail_sys(dem_h5_writer *w, const char *file, const char *fmt, ...)
{
    const char *reason = strerror(errno);
    va_list ap;
    va_start(ap, fmt);
    set_error(w, file, reason, fmt, ap);
    va_end(ap);
    w->failed = 1;
    return -1;
}

// A bad argument: nothing was written, so the file stays usable. Returns -1.
static int fail_arg(dem_h5_writer *w, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    set_error(w, w->h5_path, NULL, fmt, ap);
    va_end(ap);
    return -1;
}

// ---------------------------------------------------------------------------
// Writer lifetime

static char *concat(const char *a, const char *b)
{
    size_t la = strlen(a), lb = strlen(b);
    char *s = malloc(la + lb + 1);
    if (s) {
        memcpy(s, a, la);
        memcpy(s + la, b, lb + 1);
    }
    return s;
}

// "<path without .h5>.xmf"; a path not ending in .h5 gets ".xmf" appended.
static char *xmf_path_for(const char *h5_path)
{
    size_t n = strlen(h5_path);
    if (n > 3 && strcmp(h5_path + n - 3, ".h5") == 0)
        n -= 3;
    char *s = malloc(n + sizeof ".xmf");
    if (s) {
        memcpy(s, h5_path, n);
        memcpy(s + n, ".xmf", sizeof ".xmf");
    }
    return s;
}

static void writer_free(dem_h5_writer *w)
{
    free(w->h5_path);
    free(w->h5_tmp);
    free(w->xmf_path);
    free(w->xmf_tmp);
    free(w->frame);
    free(w);
}

static dem_h5_writer *writer_alloc(const char *h5_path)
{
    dem_h5_writer *w = calloc(1, sizeof *w);
    if (!w)
        return NULL;
    w->file = w->frames = w->diag = H5I_INVALID_HID;
    w->h5_path = concat(h5_path, "");
    w->h5_tmp = concat(h5_path, ".tmp");
    w->xmf_path = xmf_path_for(h5_path);
    w->xmf_tmp = w->xmf_path ? concat(w->xmf_path, ".tmp") : NULL;
    if (!w->h5_path || !w->h5_tmp || !w->xmf_path || !w->xmf_tmp) {
        writer_free(w);
        return NULL;
    }
    return w;
}

// Close every handle; returns -1 if a close failed (a close can flush
// buffered chunks, so a full disk may first show here).
static int close_handles(dem_h5_writer *w)
{
    int rc = 0;
    if (w->diag >= 0 && H5Dclose(w->diag) < 0)
        rc = fail_h5(w, "cannot close /diagnostics");
    if (w->frames >= 0 && H5Gclose(w->frames) < 0 && rc == 0)
        rc = fail_h5(w, "cannot close /frames");
    if (w->file >= 0 && H5Fclose(w->file) < 0 && rc == 0)
        rc = fail_h5(w, "cannot close '%s'", w->h5_tmp);
    w->diag = w->frames = w->file = H5I_INVALID_HID;
    return rc;
}

// HDF5 1.10 frees a file whose closing flush fails yet keeps its id, and
// then crashes at exit (HDFFV-11052, fixed in 1.14.1); a full disk makes
// exactly that flush fail. The file is about to be deleted, so swap its
// descriptor for an anonymous in-memory file where the last metadata writes
// land harmlessly (sparse: only those few pages take memory).
static void redirect_doomed_file(const dem_h5_writer *w)
{
    int *fd = NULL;
    if (w->file < 0 || H5Fget_vfd_handle(w->file, H5P_DEFAULT, (void **)&fd) < 0 || !fd)
        return;
    char name[64];
    snprintf(name, sizeof name, "/granucal-dem-output-%ld-%p", (long)getpid(), (const void *)w);
    int scratch = shm_open(name, O_RDWR | O_CREAT | O_EXCL, 0600);
    if (scratch < 0)
        return; // no /dev/shm: fall back to closing the real file
    shm_unlink(name);
    dup2(scratch, *fd);
    close(scratch);
}

// Abandon the output: nothing under the final names changes.
static void discard(dem_h5_writer *w)
{
    if (w->failed)
        redirect_doomed_file(w);
    close_handles(w);
    remove(w->h5_tmp);
    remove(w->xmf_tmp);
}

// ---------------------------------------------------------------------------
// Attributes

static int write_attribute(dem_h5_writer *w, hid_t obj, const char *where, const char *name, hid_t file_type,
                           hid_t mem_type, const void *value)
{
    int rc = 0;
    hid_t space = H5Screate(H5S_SCALAR);
    if (space < 0)
        return fail_h5(w, "cannot create dataspace for attribute %s of %s", name, where);
    hid_t a = H5Acreate2(obj, name, file_type, space, H5P_DEFAULT, H5P_DEFAULT);
    if (a < 0)
        rc = fail_h5(w, "cannot create attribute %s of %s", name, where);
    else if (H5Awrite(a, mem_type, value) < 0)
        rc = fail_h5(w, "cannot write attribute %s of %s", name, where);
    if (a >= 0)
        H5Aclose(a);
    H5Sclose(space);
    return rc;
}

// Fixed-length UTF-8 string (reports and file names may hold "Δt", "µm").
static int write_string_attribute(dem_h5_writer *w, hid_t obj, const char *where, const char *name,
                                  const char *value)
{
    hid_t type = H5Tcopy(H5T_C_S1);
    if (type < 0)
        return fail_h5(w, "cannot create string type for attribute %s of %s", name, where);
    int rc = 0;
    if (H5Tset_size(type, strlen(value) + 1) < 0 || H5Tset_strpad(type, H5T_STR_NULLTERM) < 0 ||
        H5Tset_cset(type, H5T_CSET_UTF8) < 0)
        rc = fail_h5(w, "cannot set string type for attribute %s of %s", name, where);
    if (rc == 0)
        rc = write_attribute(w, obj, where, name, type, type, value);
    H5Tclose(type);
    return rc;
}

static int write_frame_attributes(dem_h5_writer *w, hid_t grp, const char *where, double time,
                                  const dem_diagnostics *d)
{
    const struct {
        const char *name;
        double value;
    } reals[] = {
        {"time", time},
        {"coordination", d->coordination},
        {"coordination_walls", d->coordination_walls},
        {"ke_translational", d->ke_translational},
        {"ke_rotational", d->ke_rotational},
        {"max_overlap_ratio", d->max_overlap_ratio},
        {"potential_elastic", d->potential_elastic},
    };
    const struct {
        const char *name;
        uint64_t value;
    } counts[] = {
        {"step", d->step},
        {"granules", (uint64_t)d->granules},
        {"contacts", (uint64_t)d->contacts},
        {"wall_contacts", (uint64_t)d->wall_contacts},
    };
    for (size_t i = 0; i < sizeof reals / sizeof reals[0]; i++)
        if (write_attribute(w, grp, where, reals[i].name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &reals[i].value))
            return -1;
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++)
        if (write_attribute(w, grp, where, counts[i].name, H5T_STD_U64LE, H5T_NATIVE_UINT64, &counts[i].value))
            return -1;
    return 0;
}

// ---------------------------------------------------------------------------
// Datasets

// Chunked + shuffled + deflated when there is data; an empty dataset stays
// contiguous because a chunk dimension of 0 is invalid.
static hid_t frame_dataset_plan(size_t rows, int rank, hsize_t cols)
{
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (dcpl < 0 || rows == 0)
        return dcpl;
    hsize_t chunk[2] = {rows < FRAME_CHUNK_ROWS ? rows : FRAME_CHUNK_ROWS, cols};
    // Shuffle groups the bytes of doubles by significance, which deflate
    // compresses far better; both are lossless.
    if (H5Pset_chunk(dcpl, rank, chunk) < 0 || H5Pset_shuffle(dcpl) < 0 || H5Pset_deflate(dcpl, DEFLATE_LEVEL) < 0) {
        H5Pclose(dcpl);
        return H5I_INVALID_HID;
    }
    return dcpl;
}

/// rows × cols (cols == 0: a vector of rows) of `mem_type` from `data`.
static int write_dataset(dem_h5_writer *w, hid_t grp, const char *where, const char *name, hid_t file_type,
                         hid_t mem_type, size_t rows, hsize_t cols, const void *data)
{
    int rank = cols ? 2 : 1;
    hsize_t dims[2] = {rows, cols};
    int rc = 0;
    hid_t space = H5Screate_simple(rank, dims, NULL);
    if (space < 0)
        return fail_h5(w, "cannot create dataspace for %s/%s", where, name);
    hid_t dcpl = frame_dataset_plan(rows, rank, cols);
    hid_t dset = H5I_INVALID_HID;
    if (dcpl < 0)
        rc = fail_h5(w, "cannot set chunking and compression for %s/%s", where, name);
    else if ((dset = H5Dcreate2(grp, name, file_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT)) < 0)
        rc = fail_h5(w, "cannot create dataset %s/%s", where, name);
    else if (rows > 0 && H5Dwrite(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
        rc = fail_h5(w, "cannot write dataset %s/%s", where, name);
    if (dset >= 0 && H5Dclose(dset) < 0 && rc == 0)
        rc = fail_h5(w, "cannot close dataset %s/%s", where, name);
    if (dcpl >= 0)
        H5Pclose(dcpl);
    H5Sclose(space);
    return rc;
}

static int write_granules(dem_h5_writer *w, hid_t grp, const char *where, const dem_granules_view *g)
{
    size_t n = g->count;
    if (write_dataset(w, grp, where, "position", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, 3, g->position) ||
        write_dataset(w, grp, where, "velocity", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, 3, g->velocity) ||
        write_dataset(w, grp, where, "omega", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, 3, g->omega) ||
        write_dataset(w, grp, where, "radius", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, n, 0, g->radius) ||
        write_dataset(w, grp, where, "id", H5T_STD_U64LE, H5T_NATIVE_UINT64, n, 0, g->id))
        return -1;
    return 0;
}

// /diagnostics: 0 rows to start, extended by one per frame.
static int create_diagnostics(dem_h5_writer *w)
{
    hsize_t dims[2] = {0, DIAG_COLUMNS}, maxdims[2] = {H5S_UNLIMITED, DIAG_COLUMNS};
    hsize_t chunk[2] = {DIAG_CHUNK_ROWS, DIAG_COLUMNS};
    int rc = 0;
    hid_t space = H5Screate_simple(2, dims, maxdims);
    hid_t dcpl = H5Pcreate(H5P_DATASET_CREATE);
    if (space < 0 || dcpl < 0 || H5Pset_chunk(dcpl, 2, chunk) < 0 || H5Pset_deflate(dcpl, DEFLATE_LEVEL) < 0)
        rc = fail_h5(w, "cannot set up /diagnostics");
    else if ((w->diag = H5Dcreate2(w->file, "diagnostics", H5T_IEEE_F64LE, space, H5P_DEFAULT, dcpl,
                                   H5P_DEFAULT)) < 0)
        rc = fail_h5(w, "cannot create /diagnostics");
    else if (write_string_attribute(w, w->diag, "/diagnostics", "columns", DIAG_COLUMN_NAMES) ||
             write_string_attribute(w, w->diag, "/diagnostics", "units", DIAG_COLUMN_UNITS))
        rc = -1;
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (space >= 0)
        H5Sclose(space);
    return rc;
}

static int append_diagnostics(dem_h5_writer *w, double time, const dem_diagnostics *d)
{
    // Counts as doubles: exact below 2^53, far beyond any step count here.
    const double row[DIAG_COLUMNS] = {
        time,          (double)d->step,       (double)d->granules,   (double)d->contacts,
        (double)d->wall_contacts, d->coordination, d->coordination_walls, d->ke_translational,
        d->ke_rotational, d->max_overlap_ratio, d->potential_elastic,
    };
    hsize_t r = w->frame_count;
    hsize_t dims[2] = {r + 1, DIAG_COLUMNS}, start[2] = {r, 0}, count[2] = {1, DIAG_COLUMNS};
    int rc = 0;
    if (H5Dset_extent(w->diag, dims) < 0)
        return fail_h5(w, "cannot extend /diagnostics to %llu rows", (unsigned long long)(r + 1));
    hid_t file_space = H5Dget_space(w->diag);
    hid_t mem_space = H5Screate_simple(2, count, NULL);
    if (file_space < 0 || mem_space < 0 ||
        H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
        H5Dwrite(w->diag, H5T_NATIVE_DOUBLE, mem_space, file_space, H5P_DEFAULT, row) < 0)
        rc = fail_h5(w, "cannot write row %llu of /diagnostics", (unsigned long long)r);
    if (mem_space >= 0)
        H5Sclose(mem_space);
    if (file_space >= 0)
        H5Sclose(file_space);
    return rc;
}

// ---------------------------------------------------------------------------
// Public API: open, frames, attributes

static int create_file(dem_h5_writer *w)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    // Strong close: closing the file closes anything an error path left open.
    // sec2 named explicitly: redirect_doomed_file relies on its handle being
    // a POSIX descriptor.
    if (fapl < 0 || H5Pset_fapl_sec2(fapl) < 0 || H5Pset_fclose_degree(fapl, H5F_CLOSE_STRONG) < 0) {
        int rc = fail_h5(w, "cannot set up file access");
        if (fapl >= 0)
            H5Pclose(fapl);
        return rc;
    }
    w->file = H5Fcreate(w->h5_tmp, H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    int rc = w->file < 0 ? fail_h5(w, "cannot create '%s'", w->h5_tmp) : 0;
    H5Pclose(fapl);
    if (rc)
        return rc;
    w->frames = H5Gcreate2(w->file, "frames", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (w->frames < 0)
        return fail_h5(w, "cannot create /frames");
    return create_diagnostics(w);
}

dem_h5_writer *dem_h5_open(const char *h5_path, char *err, size_t err_len)
{
    if (!h5_path || !h5_path[0]) {
        put_message(err, err_len, "dem_h5_open: no file name given");
        return NULL;
    }
    dem_h5_writer *w = writer_alloc(h5_path);
    if (!w) {
        if (err && err_len > 0)
            snprintf(err, err_len, "'%s': out of memory", h5_path);
        return NULL;
    }
    dem_h5_quiet q = dem_h5_quiet_begin();
    int rc = create_file(w);
    if (rc)
        discard(w);
    dem_h5_quiet_end(q);
    if (rc) {
        put_message(err, err_len, w->error);
        writer_free(w);
        return NULL;
    }
    return w;
}

static int check_frame_args(dem_h5_writer *w, const dem_granules_view *g, const dem_diagnostics *d)
{
    if (!g || !d)
        return fail_arg(w, "frame %zu: granules view and diagnostics are required", w->frame_count);
    if (g->count > 0 && (!g->position || !g->velocity || !g->omega || !g->radius || !g->id))
        return fail_arg(w, "frame %zu: %zu granules but an array of the view is NULL", w->frame_count, g->count);
    return 0;
}

static int reserve_frame(dem_h5_writer *w)
{
    if (w->frame_count < w->frame_cap)
        return 0;
    size_t cap = w->frame_cap ? 2 * w->frame_cap : 64;
    frame_info *f = realloc(w->frame, cap * sizeof *f);
    if (!f)
        return fail_arg(w, "frame %zu: out of memory", w->frame_count);
    w->frame = f;
    w->frame_cap = cap;
    return 0;
}

static int write_frame(dem_h5_writer *w, double time, const dem_granules_view *g, const dem_diagnostics *d)
{
    // Six digits sort in order up to a million frames; beyond, names grow.
    char name[32], where[48];
    snprintf(name, sizeof name, "%06zu", w->frame_count);
    snprintf(where, sizeof where, "/frames/%s", name);
    hid_t grp = H5Gcreate2(w->frames, name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (grp < 0)
        return fail_h5(w, "cannot create group %s", where);
    int rc = write_granules(w, grp, where, g);
    if (rc == 0)
        rc = write_frame_attributes(w, grp, where, time, d);
    if (H5Gclose(grp) < 0 && rc == 0)
        rc = fail_h5(w, "cannot close group %s", where);
    if (rc == 0)
        rc = append_diagnostics(w, time, d);
    return rc;
}

int dem_h5_write_frame(dem_h5_writer *w, double time, const dem_granules_view *g, const dem_diagnostics *d)
{
    if (!w)
        return -1;
    if (w->failed)
        return -1; // keep the first message: it names the real cause
    if (check_frame_args(w, g, d) || reserve_frame(w))
        return -1;
    dem_h5_quiet q = dem_h5_quiet_begin();
    int rc = write_frame(w, time, g, d);
    dem_h5_quiet_end(q);
    if (rc)
        return rc;
    w->frame[w->frame_count++] = (frame_info){time, g->count};
    return 0;
}

int dem_h5_write_attribute_string(dem_h5_writer *w, const char *name, const char *value)
{
    if (!w)
        return -1;
    if (w->failed)
        return -1;
    if (!name || !name[0] || !value)
        return fail_arg(w, "root attribute: name and value are required");
    dem_h5_quiet q = dem_h5_quiet_begin();
    int rc = 0;
    // Setting a name again replaces it (H5Acreate2 refuses an existing name).
    htri_t exists = H5Aexists(w->file, name);
    if (exists < 0)
        rc = fail_h5(w, "cannot look up root attribute %s", name);
    else if (exists > 0 && H5Adelete(w->file, name) < 0)
        rc = fail_h5(w, "cannot replace root attribute %s", name);
    if (rc == 0)
        rc = write_string_attribute(w, w->file, "/", name, value);
    dem_h5_quiet_end(q);
    return rc;
}

const char *dem_h5_error(const dem_h5_writer *w) { return w ? w->error : "no HDF5 writer"; }

// ---------------------------------------------------------------------------
// XDMF sidecar

static const char *base_name(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

static void xml_escaped(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/// <DataItem> for dataset /frames/<frame>/<dataset> of rows × cols (cols 0: a vector).
static void xmf_data_item(FILE *f, const char *h5_name, const char *frame, const char *dataset, size_t rows,
                          int cols, const char *number_type)
{
    fprintf(f, "          <DataItem Dimensions=\"%zu", rows);
    if (cols)
        fprintf(f, " %d", cols);
    fprintf(f, "\" NumberType=\"%s\" Precision=\"8\" Format=\"HDF\">", number_type);
    xml_escaped(f, h5_name);
    fprintf(f, ":/frames/%s/%s</DataItem>\n", frame, dataset);
}

static void xmf_attribute(FILE *f, const char *h5_name, const char *frame, const char *dataset, size_t rows,
                          int cols, const char *number_type)
{
    fprintf(f, "        <Attribute Name=\"%s\" AttributeType=\"%s\" Center=\"Node\">\n", dataset,
            cols ? "Vector" : "Scalar");
    xmf_data_item(f, h5_name, frame, dataset, rows, cols, number_type);
    fputs("        </Attribute>\n", f);
}

static void xmf_frame(FILE *f, const char *h5_name, size_t index, const frame_info *fi)
{
    char frame[32];
    snprintf(frame, sizeof frame, "%06zu", index);
    if (fi->count == 0) {
        // Zero-length DataItems trip XDMF readers; an empty frame is skipped.
        fprintf(f, "      <!-- frame %s at t = %.17g s has no granules -->\n", frame, fi->time);
        return;
    }
    fprintf(f, "      <Grid Name=\"frame_%s\" GridType=\"Uniform\">\n", frame);
    fprintf(f, "        <Time Value=\"%.17g\"/>\n", fi->time);
    fprintf(f, "        <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\" NodesPerElement=\"1\"/>\n",
            fi->count);
    fputs("        <Geometry GeometryType=\"XYZ\">\n", f);
    xmf_data_item(f, h5_name, frame, "position", fi->count, 3, "Float");
    fputs("        </Geometry>\n", f);
    xmf_attribute(f, h5_name, frame, "radius", fi->count, 0, "Float");
    xmf_attribute(f, h5_name, frame, "velocity", fi->count, 3, "Float");
    xmf_attribute(f, h5_name, frame, "omega", fi->count, 3, "Float");
    // Declared signed: XDMF 2 readers know no 64-bit unsigned type, and ids
    // from dem_world_add_granule are non-negative int64 values.
    xmf_attribute(f, h5_name, frame, "id", fi->count, 0, "Int");
    fputs("      </Grid>\n", f);
}

static void xmf_document(FILE *f, const dem_h5_writer *w)
{
    const char *h5_name = base_name(w->h5_path);
    fputs("<?xml version=\"1.0\" ?>\n"
          "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
          "<Xdmf Version=\"3.0\">\n"
          "  <Domain>\n"
          "    <Grid Name=\"granules\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
          f);
    for (size_t i = 0; i < w->frame_count; i++)
        xmf_frame(f, h5_name, i, &w->frame[i]);
    fputs("    </Grid>\n"
          "  </Domain>\n"
          "</Xdmf>\n",
          f);
}

static int write_xmf(dem_h5_writer *w)
{
    FILE *f = fopen(w->xmf_tmp, "w");
    if (!f)
        return fail_sys(w, w->xmf_path, "cannot create '%s'", w->xmf_tmp);
    xmf_document(f, w);
    int bad = ferror(f);
    if (fclose(f) != 0 || bad)
        return fail_sys(w, w->xmf_path, "cannot write '%s'", w->xmf_tmp);
    return 0;
}

// ---------------------------------------------------------------------------
// Close

// Renaming a closed file is atomic, so the final name holds either the old
// file or the complete new one. (No fsync: that guards against power loss,
// not a killed run, and would stall every short calibration run.)
static int finish(dem_h5_writer *w)
{
    if (w->failed)
        return -1;
    if (write_xmf(w) || close_handles(w))
        return -1;
    if (rename(w->h5_tmp, w->h5_path) != 0)
        return fail_sys(w, w->h5_path, "cannot rename '%s' into place", w->h5_tmp);
    if (rename(w->xmf_tmp, w->xmf_path) != 0)
        return fail_sys(w, w->xmf_path, "cannot rename '%s' into place", w->xmf_tmp);
    return 0;
}

int dem_h5_close(dem_h5_writer *w, char *err, size_t err_len)
{
    if (!w)
        return 0;
    dem_h5_quiet q = dem_h5_quiet_begin();
    int rc = finish(w);
    if (rc) {
        discard(w);
        put_message(err, err_len, w->error);
    }
    dem_h5_quiet_end(q);
    writer_free(w);
    return rc;
}
