/* An offscreen target for the game renderer: an RGBA8 colour texture
 * (which capture reads from) and a depth-stencil renderbuffer.  Used by
 * every headless path: play --headless, render, the benchmarks. */
#ifndef R_TARGET_H
#define R_TARGET_H

#include <stdbool.h>
#include <stdint.h>

#include "../gl/rgl.h"
#include "../util/rs_err.h"

typedef struct r_target {
    GLuint fbo, tex, depth;
    int w, h;
} r_target;

bool r_target_create(r_target *t, int w, int h, rs_err *err);
void r_target_destroy(r_target *t);

/* Reads framebuffer `fbo` (0: the window's back buffer) into px, top row
 * first: channels 3 (RGB) or 4 (RGBA), w x h. */
void r_read_pixels(GLuint fbo, int w, int h, int channels, uint8_t *px);

#endif
