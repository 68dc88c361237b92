// SPDX-License-Identifier: MIT
// Engine-private: HDF5's own error printing silenced around the engine's
// HDF5 calls (dem_output.c, dem_checkpoint.c), and the innermost reason of a
// failure as one line for the engine's own message.
#ifndef DEM_H5_ERRORS_H
#define DEM_H5_ERRORS_H

#include <stddef.h>

#include <hdf5.h>

// HDF5's automatic printing goes to stderr from deep inside the library; we
// report ourselves instead. Saved and restored so other HDF5 users in the
// process keep whatever handler they chose.
typedef struct dem_h5_quiet {
    H5E_auto2_t func;
    void *data;
} dem_h5_quiet;

dem_h5_quiet dem_h5_quiet_begin(void);
void dem_h5_quiet_end(dem_h5_quiet q);

// The most specific reason of the last failure (for a failed create it
// carries the file name and errno text), on one line. Call before any other
// HDF5 call, which would clear the error stack.
void dem_h5_reason(char *buf, size_t len);

#endif
