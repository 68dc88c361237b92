// SPDX-License-Identifier: MIT
// HDF5 + XDMF output: frames read back bit-exact, the diagnostics table, the
// temporary-then-rename protocol (also across a killed writer), the sidecar,
// and error messages. Views are built by hand: no dem_world needed.
#include <dirent.h>
#include <float.h>
#include <signal.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <setjmp.h>
#include <cmocka.h>

#include <hdf5.h>

#include "dem_output.h"

enum { MAX_N = 8, DIAG_COLUMNS = 11 };

static const char COLUMNS[] = "time,step,granules,contacts,wall_contacts,coordination,coordination_walls,"
                              "ke_translational,ke_rotational,max_overlap_ratio,potential_elastic";

/// One frame's source data and the view/diagnostics pointing into it.
typedef struct frame_data {
    double time;
    dem_vec3 position[MAX_N], velocity[MAX_N], omega[MAX_N];
    double radius[MAX_N];
    uint64_t id[MAX_N];
    dem_granules_view view;
    dem_diagnostics diag;
} frame_data;

typedef struct fixture {
    char dir[64];
    char h5[128], xmf[128];
} fixture;

// ---------------------------------------------------------------------------
// Helpers

static void make_frame(frame_data *f, int k, size_t n)
{
    memset(f, 0, sizeof *f);
    f->time = 0.25 * k;
    for (size_t i = 0; i < n; i++) {
        double s = (double)(i + 1) + 0.1 * k;
        f->position[i] = dem_v3(s / 3.0, -s * 1e-3, s * 7.1e-5);
        f->velocity[i] = dem_v3(-s / 7.0, s * 1e9, 1.0 / s);
        f->omega[i] = dem_v3(s * 11.0, -s / 13.0, s * 1e-300);
        f->radius[i] = 1e-4 * s / 3.0;
        f->id[i] = 1000u * (uint64_t)k + i;
    }
    // Values a lossy path would mangle: signed zero, subnormal, extremes.
    if (n >= 5) {
        f->position[0].x = -0.0;
        f->velocity[1].y = DBL_MIN / 3.0;
        f->omega[2].z = DBL_MAX;
        f->omega[3].x = -DBL_MAX;
        f->radius[4] = DBL_TRUE_MIN;
        f->id[0] = UINT64_MAX;
        f->id[1] = (uint64_t)1 << 63;
        f->id[2] = 0;
    }
    f->view = (dem_granules_view){.count = n, .position = f->position, .velocity = f->velocity,
                                  .omega = f->omega, .radius = f->radius, .id = f->id};
    f->diag = (dem_diagnostics){.time = f->time, .step = 100000u * (uint64_t)k + 7u, .granules = n,
                                .contacts = 3u + (size_t)k, .wall_contacts = 2u * (size_t)k,
                                .coordination = 4.0 / 3.0 + k, .coordination_walls = 5.0 / 3.0 + k,
                                .ke_translational = 1e-9 * (k + 1) / 7.0, .ke_rotational = 2e-12 / (k + 1),
                                .max_overlap_ratio = 0.01 / 3.0 * k, .potential_elastic = -0.0};
}

static void expected_row(const frame_data *f, double row[DIAG_COLUMNS])
{
    const dem_diagnostics *d = &f->diag;
    double r[DIAG_COLUMNS] = {f->time,           (double)d->step,          (double)d->granules,
                              (double)d->contacts, (double)d->wall_contacts, d->coordination,
                              d->coordination_walls, d->ke_translational,  d->ke_rotational,
                              d->max_overlap_ratio, d->potential_elastic};
    memcpy(row, r, sizeof r);
}

static void path_in(char *out, size_t len, const char *dir, const char *name)
{
    int n = snprintf(out, len, "%s/%s", dir, name);
    assert_true(n > 0 && (size_t)n < len);
}

static int setup(void **state)
{
    fixture *fx = calloc(1, sizeof *fx);
    if (!fx)
        return -1;
    snprintf(fx->dir, sizeof fx->dir, "/tmp/granucal_test_output_XXXXXX");
    if (!mkdtemp(fx->dir)) {
        free(fx);
        return -1;
    }
    snprintf(fx->h5, sizeof fx->h5, "%s/out.h5", fx->dir);
    snprintf(fx->xmf, sizeof fx->xmf, "%s/out.xmf", fx->dir);
    *state = fx;
    return 0;
}

static int teardown(void **state)
{
    fixture *fx = *state;
    chmod(fx->dir, 0700);
    DIR *d = opendir(fx->dir);
    if (d) {
        struct dirent *e;
        char p[sizeof fx->dir + sizeof e->d_name + 1];
        while ((e = readdir(d)) != NULL) {
            if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0)
                continue;
            snprintf(p, sizeof p, "%s/%s", fx->dir, e->d_name);
            remove(p);
        }
        closedir(d);
    }
    rmdir(fx->dir);
    free(fx);
    return 0;
}

// How many names in `dir` end in `suffix`.
static int dir_has_suffix(const char *dir, const char *suffix)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int found = 0;
    size_t ls = strlen(suffix);
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        size_t ln = strlen(e->d_name);
        if (ln >= ls && strcmp(e->d_name + ln - ls, suffix) == 0)
            found++;
    }
    closedir(d);
    return found;
}

static int file_exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    assert_int_equal(fseek(f, 0, SEEK_END), 0);
    long n = ftell(f);
    assert_true(n > 0);
    rewind(f);
    char *s = malloc((size_t)n + 1);
    assert_non_null(s);
    assert_int_equal(fread(s, 1, (size_t)n, f), (size_t)n);
    s[n] = '\0';
    fclose(f);
    return s;
}

static void write_frames(const char *h5, frame_data *f, size_t count)
{
    char err[512] = "";
    dem_h5_writer *w = dem_h5_open(h5, err, sizeof err);
    assert_non_null(w);
    for (size_t k = 0; k < count; k++)
        assert_int_equal(dem_h5_write_frame(w, f[k].time, &f[k].view, &f[k].diag), 0);
    assert_int_equal(dem_h5_close(w, err, sizeof err), 0);
}

// ---------------------------------------------------------------------------
// Reading back

/// Read a whole dataset, checking its shape (cols 0: rank 1).
static void read_dataset(hid_t file, const char *path, hid_t mem_type, size_t rows, size_t cols, void *out)
{
    hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
    assert_true(ds >= 0);
    hid_t sp = H5Dget_space(ds);
    int rank = H5Sget_simple_extent_ndims(sp);
    hsize_t dims[2] = {0, 0};
    H5Sget_simple_extent_dims(sp, dims, NULL);
    assert_int_equal(rank, cols ? 2 : 1);
    assert_int_equal(dims[0], rows);
    if (cols)
        assert_int_equal(dims[1], cols);
    if (rows > 0)
        assert_true(H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out) >= 0);
    H5Sclose(sp);
    H5Dclose(ds);
}

static void read_attribute(hid_t obj, const char *name, hid_t mem_type, void *out)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(a >= 0);
    assert_true(H5Aread(a, mem_type, out) >= 0);
    H5Aclose(a);
}

/// A fixed-length string attribute, returned malloc'd.
static char *read_string_attribute(hid_t obj, const char *name)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    assert_true(a >= 0);
    hid_t t = H5Aget_type(a);
    assert_int_equal(H5Tget_class(t), H5T_STRING);
    assert_false(H5Tis_variable_str(t));
    size_t n = H5Tget_size(t);
    char *s = calloc(n + 1, 1);
    assert_non_null(s);
    assert_true(H5Aread(a, t, s) >= 0);
    H5Tclose(t);
    H5Aclose(a);
    return s;
}

// cmocka's memory compare wants a non-empty range; an empty frame compares nothing.
static void assert_bits_equal(const void *got, const void *want, size_t size)
{
    if (size > 0)
        assert_memory_equal(got, want, size);
}

static void assert_double_bits(double got, double want)
{
    assert_memory_equal(&got, &want, sizeof got);
}

static void check_frame_attributes(hid_t grp, const frame_data *f)
{
    const dem_diagnostics *d = &f->diag;
    const struct {
        const char *name;
        double want;
    } reals[] = {{"time", f->time},
                 {"coordination", d->coordination},
                 {"coordination_walls", d->coordination_walls},
                 {"ke_translational", d->ke_translational},
                 {"ke_rotational", d->ke_rotational},
                 {"max_overlap_ratio", d->max_overlap_ratio},
                 {"potential_elastic", d->potential_elastic}};
    const struct {
        const char *name;
        uint64_t want;
    } counts[] = {{"step", d->step},
                  {"granules", d->granules},
                  {"contacts", d->contacts},
                  {"wall_contacts", d->wall_contacts}};
    for (size_t i = 0; i < sizeof reals / sizeof reals[0]; i++) {
        double v;
        read_attribute(grp, reals[i].name, H5T_NATIVE_DOUBLE, &v);
        assert_double_bits(v, reals[i].want);
    }
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++) {
        uint64_t v;
        read_attribute(grp, counts[i].name, H5T_NATIVE_UINT64, &v);
        assert_int_equal(v, counts[i].want);
    }
}

static void check_frame(hid_t file, size_t index, const frame_data *f)
{
    char base[64], p[96];
    snprintf(base, sizeof base, "/frames/%06zu", index);
    size_t n = f->view.count;
    dem_vec3 v[MAX_N];
    double r[MAX_N];
    uint64_t id[MAX_N];

    snprintf(p, sizeof p, "%s/position", base);
    read_dataset(file, p, H5T_NATIVE_DOUBLE, n, 3, v);
    assert_bits_equal(v, f->position, n * sizeof v[0]);
    snprintf(p, sizeof p, "%s/velocity", base);
    read_dataset(file, p, H5T_NATIVE_DOUBLE, n, 3, v);
    assert_bits_equal(v, f->velocity, n * sizeof v[0]);
    snprintf(p, sizeof p, "%s/omega", base);
    read_dataset(file, p, H5T_NATIVE_DOUBLE, n, 3, v);
    assert_bits_equal(v, f->omega, n * sizeof v[0]);
    snprintf(p, sizeof p, "%s/radius", base);
    read_dataset(file, p, H5T_NATIVE_DOUBLE, n, 0, r);
    assert_bits_equal(r, f->radius, n * sizeof r[0]);
    snprintf(p, sizeof p, "%s/id", base);
    read_dataset(file, p, H5T_NATIVE_UINT64, n, 0, id);
    assert_bits_equal(id, f->id, n * sizeof id[0]);

    hid_t grp = H5Gopen2(file, base, H5P_DEFAULT);
    assert_true(grp >= 0);
    check_frame_attributes(grp, f);
    H5Gclose(grp);
}

static void check_diagnostics(hid_t file, const frame_data *f, size_t count)
{
    double got[8][DIAG_COLUMNS], want[DIAG_COLUMNS];
    assert_true(count <= 8);
    read_dataset(file, "/diagnostics", H5T_NATIVE_DOUBLE, count, DIAG_COLUMNS, got);
    for (size_t k = 0; k < count; k++) {
        expected_row(&f[k], want);
        assert_memory_equal(got[k], want, sizeof want);
    }
    hid_t ds = H5Dopen2(file, "/diagnostics", H5P_DEFAULT);
    assert_true(ds >= 0);
    char *cols = read_string_attribute(ds, "columns");
    assert_string_equal(cols, COLUMNS);
    free(cols);
    H5Dclose(ds);
}

// Non-empty frame datasets are chunked and deflated; empty ones contiguous.
static void check_layout(hid_t file, const char *path, int compressed)
{
    hid_t ds = H5Dopen2(file, path, H5P_DEFAULT);
    assert_true(ds >= 0);
    hid_t dcpl = H5Dget_create_plist(ds);
    assert_true(dcpl >= 0);
    assert_int_equal(H5Pget_layout(dcpl), compressed ? H5D_CHUNKED : H5D_CONTIGUOUS);
    unsigned flags = 0, level = 0;
    size_t nvalues = 1;
    herr_t found = H5Pget_filter_by_id2(dcpl, H5Z_FILTER_DEFLATE, &flags, &nvalues, &level, 0, NULL, NULL);
    if (compressed) {
        assert_true(found >= 0);
        assert_int_equal(level, 4);
    } else {
        assert_int_equal(H5Pget_nfilters(dcpl), 0);
    }
    H5Pclose(dcpl);
    H5Dclose(ds);
}

static hsize_t frame_count(hid_t file)
{
    hid_t g = H5Gopen2(file, "/frames", H5P_DEFAULT);
    assert_true(g >= 0);
    H5G_info_t info;
    assert_true(H5Gget_info(g, &info) >= 0);
    H5Gclose(g);
    return info.nlinks;
}

static void xmf_must_contain(const char *xmf, const char *fmt, ...)
{
    char needle[256];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(needle, sizeof needle, fmt, ap);
    va_end(ap);
    if (!strstr(xmf, needle))
        fail_msg("sidecar lacks \"%s\"", needle);
}

// ---------------------------------------------------------------------------
// Tests

static void test_three_frames_round_trip(void **state)
{
    fixture *fx = *state;
    static frame_data f[3];
    make_frame(&f[0], 0, 5);
    make_frame(&f[1], 1, 5);
    make_frame(&f[2], 2, 4); // a granule removed between frames
    write_frames(fx->h5, f, 3);

    assert_int_equal(dir_has_suffix(fx->dir, ".tmp"), 0);
    assert_true(file_exists(fx->h5));
    assert_true(file_exists(fx->xmf));

    hid_t file = H5Fopen(fx->h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(frame_count(file), 3);
    for (size_t k = 0; k < 3; k++)
        check_frame(file, k, &f[k]);
    check_diagnostics(file, f, 3);
    check_layout(file, "/frames/000001/position", 1);
    check_layout(file, "/frames/000002/id", 1);
    H5Fclose(file);

    char *xmf = slurp(fx->xmf);
    xmf_must_contain(xmf, "CollectionType=\"Temporal\"");
    const char *datasets[] = {"position", "velocity", "omega", "radius", "id"};
    for (size_t k = 0; k < 3; k++) {
        for (size_t i = 0; i < 5; i++)
            xmf_must_contain(xmf, "out.h5:/frames/%06zu/%s</DataItem>", k, datasets[i]);
        xmf_must_contain(xmf, "<Time Value=\"%.17g\"/>", f[k].time);
        xmf_must_contain(xmf, "TopologyType=\"Polyvertex\" NumberOfElements=\"%zu\"", f[k].view.count);
        xmf_must_contain(xmf, "<DataItem Dimensions=\"%zu 3\"", f[k].view.count);
    }
    xmf_must_contain(xmf, "<Geometry GeometryType=\"XYZ\">");
    xmf_must_contain(xmf, "<Attribute Name=\"radius\" AttributeType=\"Scalar\"");
    xmf_must_contain(xmf, "<Attribute Name=\"velocity\" AttributeType=\"Vector\"");
    xmf_must_contain(xmf, "<Attribute Name=\"omega\" AttributeType=\"Vector\"");
    xmf_must_contain(xmf, "<Attribute Name=\"id\"");
    // The sidecar must point at the final file, never the temporary one.
    assert_null(strstr(xmf, ".tmp"));
    assert_null(strstr(xmf, fx->dir));
    free(xmf);
}

static void test_empty_frame(void **state)
{
    fixture *fx = *state;
    static frame_data f[2];
    make_frame(&f[0], 0, 0);
    f[0].view.position = NULL; // an empty view may carry no arrays at all
    f[0].view.velocity = f[0].view.omega = NULL;
    f[0].view.radius = NULL;
    f[0].view.id = NULL;
    make_frame(&f[1], 1, 2);
    write_frames(fx->h5, f, 2);

    hid_t file = H5Fopen(fx->h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    check_frame(file, 0, &f[0]);
    check_frame(file, 1, &f[1]);
    check_diagnostics(file, f, 2);
    check_layout(file, "/frames/000000/position", 0);
    check_layout(file, "/frames/000001/position", 1);
    H5Fclose(file);

    char *xmf = slurp(fx->xmf);
    assert_null(strstr(xmf, "/frames/000000/position"));
    xmf_must_contain(xmf, "out.h5:/frames/000001/position");
    free(xmf);
}

static void test_root_string_attributes(void **state)
{
    fixture *fx = *state;
    char err[512] = "";
    dem_h5_writer *w = dem_h5_open(fx->h5, err, sizeof err);
    assert_non_null(w);
    assert_int_equal(dem_h5_write_attribute_string(w, "engine_version", "0.0.1"), 0);
    assert_int_equal(dem_h5_write_attribute_string(w, "dt_report", "Δt = 0.6·Δt_crit, m_min = 1 µg"), 0);
    assert_int_equal(dem_h5_write_attribute_string(w, "features", ""), 0);
    assert_int_equal(dem_h5_write_attribute_string(w, "engine_version", "0.1.0"), 0); // replaces
    assert_int_equal(dem_h5_close(w, err, sizeof err), 0);

    hid_t file = H5Fopen(fx->h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    char *s = read_string_attribute(file, "engine_version");
    assert_string_equal(s, "0.1.0");
    free(s);
    s = read_string_attribute(file, "dt_report");
    assert_string_equal(s, "Δt = 0.6·Δt_crit, m_min = 1 µg");
    free(s);
    s = read_string_attribute(file, "features");
    assert_string_equal(s, "");
    free(s);
    assert_int_equal(frame_count(file), 0);
    check_diagnostics(file, NULL, 0);
    H5Fclose(file);
}

static void test_open_bad_directory(void **state)
{
    fixture *fx = *state;
    char path[256], err[512] = "";
    path_in(path, sizeof path, fx->dir, "no_such_dir/out.h5");
    assert_null(dem_h5_open(path, err, sizeof err));
    if (!strstr(err, path))
        fail_msg("message does not name %s: %s", path, err);

    if (geteuid() == 0) // root writes into a read-only directory anyway
        return;
    char ro[256];
    path_in(ro, sizeof ro, fx->dir, "read_only");
    assert_int_equal(mkdir(ro, 0500), 0);
    path_in(path, sizeof path, ro, "out.h5");
    err[0] = '\0';
    assert_null(dem_h5_open(path, err, sizeof err));
    if (!strstr(err, path))
        fail_msg("message does not name %s: %s", path, err);
    rmdir(ro);
}

static void test_bad_arguments_leave_writer_usable(void **state)
{
    fixture *fx = *state;
    static frame_data f[2];
    make_frame(&f[0], 0, 5);
    char err[512] = "";
    dem_h5_writer *w = dem_h5_open(fx->h5, err, sizeof err);
    assert_non_null(w);
    assert_string_equal(dem_h5_error(w), "");
    assert_int_not_equal(dem_h5_write_frame(w, 0.0, NULL, &f[0].diag), 0);
    assert_non_null(strstr(dem_h5_error(w), fx->h5));
    f[1] = f[0];
    f[1].view.radius = NULL;
    assert_int_not_equal(dem_h5_write_frame(w, 0.0, &f[1].view, &f[1].diag), 0);
    assert_int_not_equal(dem_h5_write_attribute_string(w, NULL, "x"), 0);
    assert_int_equal(dem_h5_write_frame(w, f[0].time, &f[0].view, &f[0].diag), 0);
    assert_int_equal(dem_h5_close(w, err, sizeof err), 0);
    assert_int_equal(dem_h5_close(NULL, err, sizeof err), 0);

    hid_t file = H5Fopen(fx->h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(frame_count(file), 1);
    check_frame(file, 0, &f[0]);
    check_diagnostics(file, f, 1);
    H5Fclose(file);
}

// A writer killed before dem_h5_close leaves the previous complete output
// under the final names; only the .tmp files show the aborted run.
static void test_killed_run_keeps_previous_output(void **state)
{
    fixture *fx = *state;
    static frame_data f[3];
    make_frame(&f[0], 0, 5);
    make_frame(&f[1], 1, 5);
    make_frame(&f[2], 2, 5);
    write_frames(fx->h5, f, 1);
    char *xmf_before = slurp(fx->xmf);

    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        dem_h5_writer *w = dem_h5_open(fx->h5, NULL, 0);
        if (!w)
            _exit(2);
        for (int k = 0; k < 3; k++)
            if (dem_h5_write_frame(w, f[k].time, &f[k].view, &f[k].diag))
                _exit(3);
        raise(SIGKILL);
        _exit(4);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);

    assert_true(dir_has_suffix(fx->dir, ".h5.tmp") == 1);
    hid_t file = H5Fopen(fx->h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(frame_count(file), 1);
    check_frame(file, 0, &f[0]);
    check_diagnostics(file, f, 1);
    H5Fclose(file);
    char *xmf_after = slurp(fx->xmf);
    assert_string_equal(xmf_after, xmf_before);
    free(xmf_after);
    free(xmf_before);

    // The next complete run replaces both and sweeps its own .tmp names.
    write_frames(fx->h5, f, 3);
    assert_int_equal(dir_has_suffix(fx->dir, ".tmp"), 0);
    file = H5Fopen(fx->h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    assert_true(file >= 0);
    assert_int_equal(frame_count(file), 3);
    check_diagnostics(file, f, 3);
    H5Fclose(file);
}

// Child: with the file size limit far below one frame, an HDF5 write must
// fail, and close must report it by file name and leave nothing behind.
// (A disk-full run exits cleanly; under a size limit even the in-memory
// file that takes the doomed file's last flush is refused, and HDF5 1.10
// then crashes in its exit handler, so the child leaves by _exit.)
static int write_past_size_limit(const char *h5)
{
    enum { BIG = 50000 };
    static dem_vec3 v[BIG];
    static double r[BIG];
    static uint64_t id[BIG];
    uint64_t x = 88172645463325252u; // xorshift: data that deflate cannot shrink
    for (size_t i = 0; i < BIG; i++) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        v[i] = dem_v3((double)x, (double)(x >> 3), (double)(x >> 5));
        r[i] = (double)(x >> 7);
        id[i] = x;
    }
    dem_granules_view g = {.count = BIG, .position = v, .velocity = v, .omega = v, .radius = r, .id = id};
    dem_diagnostics d = {.granules = BIG};
    struct rlimit lim = {64 * 1024, 64 * 1024};
    signal(SIGXFSZ, SIG_IGN); // turn the signal into EFBIG from write()
    if (setrlimit(RLIMIT_FSIZE, &lim) != 0)
        return 10;
    char err[512] = "";
    dem_h5_writer *w = dem_h5_open(h5, err, sizeof err);
    if (!w)
        return 11;
    int failed = 0;
    for (int k = 0; k < 4 && !failed; k++)
        failed = dem_h5_write_frame(w, k, &g, &d) != 0;
    if (failed && !strstr(dem_h5_error(w), h5))
        return 12;
    if (dem_h5_close(w, err, sizeof err) == 0)
        return 13;
    if (!strstr(err, h5))
        return 14;
    return 0;
}

static void test_write_failure_is_reported(void **state)
{
    fixture *fx = *state;
    fflush(NULL);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0)
        _exit(write_past_size_limit(fx->h5));
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
    assert_false(file_exists(fx->h5));
    assert_false(file_exists(fx->xmf));
    assert_int_equal(dir_has_suffix(fx->dir, ".tmp"), 0);
}

static void test_sidecar_name_without_h5_suffix(void **state)
{
    fixture *fx = *state;
    static frame_data f[1];
    make_frame(&f[0], 0, 3);
    char path[256], xmf[256];
    path_in(path, sizeof path, fx->dir, "run.hdf5");
    path_in(xmf, sizeof xmf, fx->dir, "run.hdf5.xmf");
    write_frames(path, f, 1);
    assert_true(file_exists(path));
    assert_true(file_exists(xmf));
    char *s = slurp(xmf);
    xmf_must_contain(s, ">run.hdf5:/frames/000000/id</DataItem>");
    free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test_setup_teardown(test_three_frames_round_trip, setup, teardown),
        cmocka_unit_test_setup_teardown(test_empty_frame, setup, teardown),
        cmocka_unit_test_setup_teardown(test_root_string_attributes, setup, teardown),
        cmocka_unit_test_setup_teardown(test_open_bad_directory, setup, teardown),
        cmocka_unit_test_setup_teardown(test_bad_arguments_leave_writer_usable, setup, teardown),
        cmocka_unit_test_setup_teardown(test_killed_run_keeps_previous_output, setup, teardown),
        cmocka_unit_test_setup_teardown(test_write_failure_is_reported, setup, teardown),
        cmocka_unit_test_setup_teardown(test_sidecar_name_without_h5_suffix, setup, teardown),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
