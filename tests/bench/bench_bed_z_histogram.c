// SPDX-License-Identifier: MIT
// Is a drum's bed three-dimensional? (not a test; results/drum_geometry/README.md)
// Reads the last frame of a run's result.h5 and prints, along the drum axis z,
// the granules' extent, a histogram in 15 equal bins over the drum's depth and
// how many granules reach past z = 0 or z = depth (touch an end plate of a
// closed drum). A bed poured on lattice planes shows one or two full bins.
//   build/tests/bench_bed_z_histogram RESULT_H5 DEPTH_M
//   (results/drum_geometry: build/tests/bench_bed_z_histogram results/runs/drum_geometry/slice15/result.h5 0.015)
#include <hdf5.h>
#include <stdio.h>
#include <stdlib.h>

enum { BINS = 15 };

/// Reads dataset /frames/FRAME/NAME (count × cols doubles) into a new array.
static double *read_frame_dataset(hid_t file, const char *frame, const char *name, hsize_t *count)
{
    char path[128];
    snprintf(path, sizeof path, "/frames/%s/%s", frame, name);
    hid_t set = H5Dopen2(file, path, H5P_DEFAULT);
    if (set < 0) {
        fprintf(stderr, "bench_bed_z_histogram: no dataset %s\n", path);
        return NULL;
    }
    hid_t space = H5Dget_space(set);
    hsize_t dims[2] = {0, 1};
    int rank = H5Sget_simple_extent_dims(space, dims, NULL);
    double *data = rank > 0 ? malloc((size_t)(dims[0] * (rank > 1 ? dims[1] : 1)) * sizeof *data) : NULL;
    if (data && H5Dread(set, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0) {
        fprintf(stderr, "bench_bed_z_histogram: cannot read %s\n", path);
        free(data);
        data = NULL;
    }
    *count = dims[0];
    H5Sclose(space);
    H5Dclose(set);
    return data;
}

/// The name of the last frame in /frames (frame names sort in time order).
static int last_frame_name(hid_t file, char *name, size_t size)
{
    hid_t frames = H5Gopen2(file, "/frames", H5P_DEFAULT);
    H5G_info_t info;
    if (frames < 0 || H5Gget_info(frames, &info) < 0 || info.nlinks == 0) {
        fprintf(stderr, "bench_bed_z_histogram: no frames in the file\n");
        if (frames >= 0)
            H5Gclose(frames);
        return -1;
    }
    ssize_t len = H5Lget_name_by_idx(frames, ".", H5_INDEX_NAME, H5_ITER_INC, info.nlinks - 1, name, size,
                                     H5P_DEFAULT);
    H5Gclose(frames);
    return len > 0 ? 0 : -1;
}

static void print_histogram(const char *path, const char *frame, const double *position, const double *radius,
                            hsize_t n, double depth)
{
    int hist[BINS] = {0}, touching = 0;
    double lo = 1e300, hi = -1e300;
    for (hsize_t i = 0; i < n; i++) {
        double z = position[3 * i + 2], r = radius[i];
        lo = z - r < lo ? z - r : lo;
        hi = z + r > hi ? z + r : hi;
        int bin = (int)(z / depth * BINS);
        if (bin >= 0 && bin < BINS)
            hist[bin]++;
        touching += z - r < 0 || z + r > depth;
    }
    printf("%s frame %s: %llu granules, min(z-r) %.5f m, max(z+r) %.5f m, reaching past the plates %d\n", path,
           frame, (unsigned long long)n, lo, hi, touching);
    printf("z histogram (%d bins of %.2f mm):", BINS, depth / BINS * 1e3);
    for (int b = 0; b < BINS; b++)
        printf(" %d", hist[b]);
    printf("\n");
}

int main(int argc, char **argv)
{
    if (argc != 3 || atof(argv[2]) <= 0) {
        fprintf(stderr, "usage: %s RESULT_H5 DEPTH_M (DEPTH_M > 0: the drum's depth along z)\n", argv[0]);
        return 2;
    }
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); // this program says what failed, by name
    hid_t file = H5Fopen(argv[1], H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0) {
        fprintf(stderr, "bench_bed_z_histogram: cannot open %s\n", argv[1]);
        return 1;
    }
    char frame[64];
    hsize_t n = 0, nr = 0;
    double *position = NULL, *radius = NULL;
    int rc = last_frame_name(file, frame, sizeof frame);
    if (rc == 0) {
        position = read_frame_dataset(file, frame, "position", &n);
        radius = read_frame_dataset(file, frame, "radius", &nr);
        rc = position && radius && n == nr ? 0 : -1;
    }
    if (rc == 0)
        print_histogram(argv[1], frame, position, radius, n, atof(argv[2]));
    free(position);
    free(radius);
    H5Fclose(file);
    return rc == 0 ? 0 : 1;
}
