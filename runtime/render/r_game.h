/* The plain game renderer: lit capsule fighters on a ring, and a HUD with
 * health bars, round timer, round wins and announcements.
 *
 * It reads game state and never writes it.  Draws interpolate between the
 * previous and the current tick (alpha 0..1) so a window running faster or
 * slower than 60 Hz still moves smoothly.  The renderer-core work turns
 * this into the HDR/IBL pass graph; the contract stays: state in, pixels
 * out, into whatever framebuffer is bound. */
#ifndef R_GAME_H
#define R_GAME_H

#include "../game/g_game.h"
#include "../util/rs_err.h"
#include "r_math.h"

typedef struct r_game r_game;

/* Needs a current GL context. */
r_game *r_game_create(rs_err *err);
void r_game_destroy(r_game *r);

/* Draws into the bound framebuffer, viewport 0,0,w,h. */
void r_game_draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h);

/* The camera r_game_draw used for this state (tests project with it). */
r_mat4 r_game_camera(const g_state *st, int w, int h, r_vec3 *eye);

/* Fighter colours, for tests that look for them. */
extern const float r_fighter_color[2][3];

#endif
