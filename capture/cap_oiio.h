/* The C face of OpenImageIO (C++ only): the one C++ file in ringside,
 * capture/cap_oiio.cpp.  Available when configure finds OpenImageIO
 * (RS_HAVE_OIIO); otherwise these return false with a message. */
#ifndef CAP_OIIO_H
#define CAP_OIIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Resizes an RGBA8 image (rows top-down) with ImageBufAlgo::resize and its
 * default filter for downsizing (lanczos3); out: w*h*4 floats in 0..255. */
bool cap_oiio_resize(const uint8_t *rgba, int sw, int sh, float *out, int w, int h, char *err, size_t errn);

/* Writes an RGBA8 image (rows top-down) in the format of the extension
 * `ext` (".png", ".exr", ".tif") to `path`, whatever path's own name. */
bool cap_oiio_write(const char *path, const char *ext, int w, int h, const uint8_t *rgba, char *err, size_t errn);

/* Reads the first subimage of an image file as float RGB (rows top-down):
 * the first three channels, or channel 0 as grey when there are fewer.
 * *rgb is malloc'd, w*h*3 floats; values are as stored, without colour
 * conversion (NaN and Inf included: the caller decides).  Images over 16384 x 16384 are
 * refused so user data cannot make us allocate without bound. */
#define CAP_OIIO_MAX_SIDE 16384
bool cap_oiio_read_float(const char *path, int *w, int *h, float **rgb, char *err, size_t errn);

/* "OpenImageIO 2.4.7", or a note that it is not built in. */
const char *cap_oiio_version(void);

#ifdef __cplusplus
}
#endif

#endif
