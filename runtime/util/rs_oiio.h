/* rs_oiio: the C face of OpenImageIO (C++ only).  It sits in util because
 * both the engine (IBL environment maps, runtime/render/r_ibl.c) and
 * capture (image sequences, the accuracy benchmark's reference resize) use
 * it.
 *
 * OpenImageIO lives in a plugin, BUILD/ringside-oiio.so
 * (runtime/util/rs_oiio_plugin.cpp, the one C++ file in ringside), which
 * runtime/util/rs_oiio_load.c loads with dlopen the first time one of these
 * functions runs: linked into the program, OpenImageIO's ~260 libraries
 * cost every process about 0.25 s at start, and most never read or write
 * an image file.  The plugin is looked for beside the program, in
 * ../lib/ringside/ from it (make install), and one folder up (the test
 * programs in BUILD/tests); RINGSIDE_OIIO_PLUGIN names it outright.
 * Without RS_HAVE_OIIO (configure found no OpenImageIO) every function
 * fails with RS_OIIO_ERR_NOT_BUILT; without the plugin file, with
 * RS_OIIO_ERR_NO_PLUGIN, saying where it looked. */
#ifndef RS_OIIO_H
#define RS_OIIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rs_err.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RS_OIIO_ERRORS(X)                                                  \
    X(OK, "ok")                                                            \
    X(NOT_BUILT, "this build has no OpenImageIO")                          \
    X(NO_PLUGIN, "the OpenImageIO plugin could not be loaded")             \
    X(READ, "the image could not be read")                                 \
    X(WRITE, "the image could not be written")                             \
    X(FORMAT, "not a 2-D image of a size we accept")                       \
    X(RESIZE, "the resize failed")                                         \
    X(MEMORY, "out of memory")

typedef enum rs_oiio_error {
#define X(id, text) RS_OIIO_ERR_##id,
    RS_OIIO_ERRORS(X)
#undef X
        RS_OIIO_ERR_COUNT
} rs_oiio_error;

const char *rs_oiio_error_text(rs_oiio_error e);

/* Resizes an RGBA8 image (rows top-down) with ImageBufAlgo::resize and its
 * default filter for downsizing (lanczos3); out: w*h*4 floats in 0..255. */
bool rs_oiio_resize(const uint8_t *rgba, int sw, int sh, float *out, int w, int h, rs_err *err);

/* Writes an RGBA8 image (rows top-down) in the format of the extension
 * `ext` (".png", ".exr", ".tif") to `path`, whatever path's own name.
 * Encoded in memory, then written with every write() and the close()
 * checked: false, with the path and the system's reason ("No space left on
 * device"), and no file left, when any fails. */
bool rs_oiio_write(const char *path, const char *ext, int w, int h, const uint8_t *rgba, rs_err *err);

/* Reads the first subimage of an image file as float RGB (rows top-down):
 * the first three channels, or channel 0 as grey when there are fewer.
 * *rgb is malloc'd, w*h*3 floats; values are as stored, without colour
 * conversion (NaN and Inf included: the caller decides).  Images over 16384 x 16384 are
 * refused so user data cannot make us allocate without bound. */
#define RS_OIIO_MAX_SIDE 16384
bool rs_oiio_read_float(const char *path, int *w, int *h, float **rgb, rs_err *err);

/* Loads the plugin now: true when the functions above can work, else
 * false with the reason (RS_OIIO_ERR_NOT_BUILT or _NO_PLUGIN).  An output
 * calls it when it opens, so a missing plugin is an error before the
 * first frame is drawn. */
bool rs_oiio_ready(rs_err *err);

/* "OpenImageIO 2.4.7" (this loads the plugin), or why there is none. */
const char *rs_oiio_version(void);

/* The plugin's interface version: rs_oiio_plugin_abi() must return it. */
#define RS_OIIO_PLUGIN_ABI 2

#ifdef __cplusplus
}
#endif

#endif
