/* The smoke scene: a fixed test picture drawn through shaders/smoke.* into
 * an RGBA8 FBO.  Every edge is placed so no pixel centre lies on it, which
 * makes the picture exact on any conforming rasteriser: r_smoke_reference
 * computes the same image on the CPU, and tests compare them byte for byte.
 *
 * It is what `ringside smoke` renders (and `make demo` until the game
 * renderer lands) and what `bench platform` times. */
#ifndef R_SMOKE_H
#define R_SMOKE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../util/rs_err.h"

#define R_SMOKE_MIN_SIZE 16

typedef struct r_smoke r_smoke;

/* Needs a current context (plat_create).  w, h >= R_SMOKE_MIN_SIZE. */
r_smoke *r_smoke_create(int w, int h, rs_err *err);
void r_smoke_draw(r_smoke *s);
/* Reads the FBO into rgba (w*h*4 bytes, rows top-down).  Blocks until the
 * GPU has finished drawing (glReadPixels into client memory). */
void r_smoke_read(r_smoke *s, uint8_t *rgba);
void r_smoke_destroy(r_smoke *s);

/* The exact expected picture, rows top-down. */
void r_smoke_reference(int w, int h, uint8_t *rgba);

/* Number of RGBA pixels that differ; *first gets the index of the first. */
size_t r_smoke_compare(const uint8_t *got, const uint8_t *want, int w, int h, size_t *first);

#endif
