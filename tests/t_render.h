/* What the GL tests of the renderer share: a demo replay simulated to a
 * tick, and an RGBA8 + depth/stencil framebuffer to draw into. */
#ifndef T_RENDER_H
#define T_RENDER_H

#include <stdbool.h>
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

/* A game renderer for tests (no IBL cache, quiet; mask: HDR alpha = the
 * fighters' mask).  Fails the test when it cannot be made. */
struct r_game *t_game_new(bool mask);
/* The same with these options (NULL: all default); cache_dir and quiet are
 * the tests' whatever o says. */
struct r_game_opts;
struct r_game *t_game_opts(const struct r_game_opts *o);
/* One w x h frame into f, failing the test on any GL or pass-graph error. */
void t_draw(struct r_game *r, const t_fb *f, const g_state *prev, const g_state *cur, int w, int h);
/* The same, then f's RGBA8 pixels into px (w * h * 4; NULL: none), the
 * top row first when top_down, else as GL reads them (bottom row first). */
void t_draw_read(struct r_game *r, const t_fb *f, const g_state *prev, const g_state *cur, int w, int h, uint8_t *px,
                 bool top_down);
/* One w x h picture of demo at tick the way render makes it: the `history`
 * ticks before it advanced first (the effects' simulations have that much
 * past; r_game_advance draws a frame only where an effect needs it), with
 * options o (NULL: default); RGBA top row first. */
void t_picture(const char *demo, uint64_t tick, uint64_t history, const struct r_game_opts *o, int w, int h,
               uint8_t *px);
/* Did the pass run in the frame drawn last (fails the test on a bad name)? */
bool t_pass_ran(struct r_game *r, const char *name);
/* r_game_read_buffer into a new w x h x channels array (free() it). */
float *t_read(struct r_game *r, const char *what, int channels, int w, int h);
/* The brightest look a stage file allows: every light, the sky and the
 * ground at the fp16 maximum, exposure 1000 (the fp16 stress tests). */
struct r_stage;
void t_stage_extremes(struct r_stage *st);
/* With T_DUMP=DIR: an HDR buffer (rgba, bottom-up) as DIR/NAME.ppm, v/(1+v) and gamma 2.2. */
void t_dump_hdr(const char *name, const float *px, int w, int h);

#endif
