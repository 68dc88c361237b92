// SPDX-License-Identifier: MIT
/// @file exp_image.h
/// Pictures of the drum face: render a simulated drum to PNG (like the
/// paper's Fig. 14), and read a photograph of a real drum into the same raster
/// the simulation is measured on, so both are measured by one code path.
#ifndef EXP_IMAGE_H
#define EXP_IMAGE_H

#include <stddef.h>

#include "dem_world.h"
#include "exp_face_measure.h"

/// Colour granules by diameter or by speed.
typedef enum exp_colour_by { EXP_COLOUR_SIZE = 0, EXP_COLOUR_SPEED = 1 } exp_colour_by;

/// Write the drum face (granules projected along z, drum circle drawn) as
/// an RGB PNG of `width` pixels square. 0 on success, else a message.
int exp_render_drum_png(const char *path, const dem_world *w, double drum_radius, int width, exp_colour_by colour,
                        char *err, size_t len);

/// Read a photograph (PNG, any colour type) and binarise it inside the drum
/// circle (centre cx, cy and radius in pixels; y of the image grows
/// downwards): the powder is dark on a lighter drum by default (`invert`
/// for light powder), threshold by Otsu's method over the pixels inside the
/// circle. The raster uses 1 unit = 1 pixel, centred on the drum, y up.
exp_raster *exp_read_photo(const char *path, double cx, double cy, double radius, int invert, double *threshold,
                           char *err, size_t len);

/// Read a PNG of any colour type as 8-bit grey (libpng's conversion),
/// row-major, image y downwards: w × h bytes to free. NULL with a message
/// naming the file when it cannot be read or decoded.
unsigned char *exp_read_gray_png(const char *path, int *w, int *h, char *err, size_t len);

/// Otsu's threshold over a 256-bin histogram: the grey level that
/// separates the two classes with the largest between-class variance.
int exp_otsu_threshold(const unsigned long hist[256]);

/// Write 8-bit pixels (1 channel: grey, 3: RGB) as a PNG, through a
/// temporary file renamed into place. 0, else a message naming the file.
int exp_write_png(const char *path, const unsigned char *pixels, int w, int h, int channels, char *err, size_t len);

/// Write a raster as a greyscale PNG (occupied black), for inspection.
int exp_write_raster_png(const char *path, const exp_raster *r, char *err, size_t len);

#endif
