/* Quality presets (docs/accuracy.md, "Quality presets"): a render scale
 * (render pixels per output pixel, per axis) and the renderer's knobs
 * (r_quality, r_game.h) under one name, draft | standard | high |
 * reference.  `ringside bench quality` measures every knob's cost and
 * error against the reference and prints the fastest combination inside
 * each preset's error budget; the table in r_quality.c is what it chose,
 * and the bench says when the measurement disagrees with it. */
#ifndef R_QUALITY_H
#define R_QUALITY_H

#include <stdbool.h>

#include "r_game.h"

typedef enum r_preset_id { R_PRESET_DRAFT, R_PRESET_STANDARD, R_PRESET_HIGH, R_PRESET_REFERENCE, R_PRESETS } r_preset_id;

#define R_PRESET_DEFAULT R_PRESET_STANDARD
#define R_RENDER_MAX 8192 /* the largest render size per axis a preset asks for */

typedef struct r_preset {
    const char *name;
    double scale;      /* render size = output size x scale (per axis), >= 1 */
    r_quality q;
    double budget_db;  /* chosen as the fastest measured combination whose PSNR against the
                          reference is at least this on every stage; 0: the reference itself */
    const char *what;  /* one line for --help */
} r_preset;

extern const r_preset r_presets[R_PRESETS];

/* The preset of this name, or NULL. */
const r_preset *r_preset_named(const char *name);
/* "draft, standard, high or reference" for messages. */
const char *r_preset_list(void);
/* The render size for an output of w x h: the scale, reduced (the same on
 * both axes) where it would pass max on either axis, never below 1. */
void r_preset_render_size(const r_preset *p, int w, int h, int max, int *rw, int *rh);

#endif
