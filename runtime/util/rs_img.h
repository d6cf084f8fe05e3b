/* Image files for the smoke render, screenshots, attract stills, charts,
 * tests and goldens.
 *
 * PNG goes through libpng (a dependency of every build, tools/configure.sh),
 * zlib level RS_PNG_LEVEL, no row filter: the choice is measured in
 * rs_img.c.  Binary PPM/PGM (P5/P6) is read and written by hand for golden
 * images.  EXR and TIFF sequences belong to capture's OpenImageIO sink.
 *
 * Pixels are 8-bit, rows top-down, `channels` of 1 (grey), 3 (RGB) or
 * 4 (RGBA), tightly packed. */
#ifndef RS_IMG_H
#define RS_IMG_H

#include <stdbool.h>
#include <stdint.h>

#include "rs_err.h"

/* zlib level of every PNG ringside writes, OpenImageIO's sequences included */
#define RS_PNG_LEVEL 6

enum { RS_IMG_ERR_IO = 1, RS_IMG_ERR_FORMAT, RS_IMG_ERR_ARG };

typedef struct rs_image {
    int w, h, channels;
    uint8_t *px;
} rs_image;

bool rs_png_write(const char *path, int w, int h, int channels, const uint8_t *px, rs_err *err);
/* PPM (channels 3) or PGM (channels 1); RGBA is written as PPM without alpha. */
bool rs_pnm_write(const char *path, int w, int h, int channels, const uint8_t *px, rs_err *err);
bool rs_pnm_read(const char *path, rs_image *img, rs_err *err);
/* Chooses PNG or PPM/PGM from the extension (.png, .ppm, .pgm). */
bool rs_image_write(const char *path, int w, int h, int channels, const uint8_t *px, rs_err *err);
void rs_image_free(rs_image *img);

/* Reverses the row order in place (GL reads bottom-up). */
void rs_flip_rows(uint8_t *px, int w, int h, int channels);

#endif
