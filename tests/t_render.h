/* What the GL tests of the renderer share: a demo replay simulated to a
 * tick, and an RGBA8 + depth/stencil framebuffer to draw into. */
#ifndef T_RENDER_H
#define T_RENDER_H

#include <stdint.h>

#include "../runtime/game/g_game.h"
#include "../runtime/gl/rgl.h"

/* demos/<demo>.rsr simulated to `tick`: *cur at tick, *prev one before
 * (equal at tick 0).  Fails the test when the demo is missing or short. */
void t_state_at(const char *demo, uint64_t tick, g_state *prev, g_state *cur);

typedef struct t_fb {
    GLuint fbo, rb[2];
} t_fb;

void t_fb_make(t_fb *f, int w, int h);
void t_fb_free(t_fb *f);

#endif
