/* Stage description files: what a stage looks like and which render
 * passes it needs (docs/stages.md).  Text, one "key = value" per line, '#'
 * starts a comment.  Every error is "FILE:LINE: message".
 *
 * The game rules of a stage (ring size, storm) live in g_stages; a stage
 * file names the game stage it dresses with `game = NAME`.  ringside looks
 * for <data>/stages/<game stage name>.stage unless given --stage-file. */
#ifndef R_STAGE_H
#define R_STAGE_H

#include <stdbool.h>
#include <stddef.h>

#include "../util/rs_err.h"

#define R_STAGE_MAX_BYTES (64u * 1024u)
#define R_STAGE_MAX_BUILDINGS 48
#define R_HALF_MAX 65504.0f /* largest finite fp16: the bound of every HDR value */

/* Error ids (rs_err.h).  Every message still reads "FILE:LINE: ...". */
#define R_STAGE_ERRORS(X)                                                                          \
    X(FILE, "cannot read the stage file (missing, too large, no data directory, out of memory)")  \
    X(SYNTAX, "a line is not 'key = value', or holds a NUL byte")                                  \
    X(UNKNOWN_KEY, "unknown key")                                                                   \
    X(DUPLICATE_KEY, "a key is set twice")                                                          \
    X(MISSING_KEY, "a required key (name, game) is missing")                                       \
    X(VALUE, "a value of the wrong form (not a number, not one of the words allowed)")             \
    X(RANGE, "a number outside the range of its key")                                              \
    X(GAME, "no such game stage, or the file dresses another one")

typedef enum r_stage_error {
    R_STAGE_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_R_STAGE),
#define X(id, text) R_STAGE_ERR_##id,
    R_STAGE_ERRORS(X)
#undef X
        R_STAGE_ERR_END
} r_stage_error;

const char *r_stage_error_text(int code);

typedef enum r_hdr_format { R_HDR_RGBA16F, R_HDR_R11G11B10F } r_hdr_format;

/* A light painted into the procedural environment (a soft bright disc). */
typedef struct r_paint_light {
    float dir[3];    /* towards the light, unit length (the parser normalises) */
    float color[3];  /* linear RGB, 0..65504 */
    float intensity; /* radiance multiplier at the centre; 0 = none */
    float size_deg;  /* angular radius of the disc, 0.5..90 */
} r_paint_light;

/* Afterimage velocity: in view space (camera motion blurs too), in world
 * space (only the fighters' own motion), or none. */
typedef enum r_afterimage { R_AFTERIMAGE_OFF, R_AFTERIMAGE_VIEW, R_AFTERIMAGE_WORLD } r_afterimage;

typedef struct r_stage {
    char name[32];
    char game[32];  /* a g_stages name */
    int game_index; /* its index in g_stages */

    /* environment: procedural (env_path "") or an .hdr/.exr file */
    char env_path[1024];  /* resolved against the stage file's directory */
    float env_rotate_deg; /* yaw of a loaded environment, -360..360 */
    float env_scale;      /* multiplier of a loaded environment, 0..65504 */
    float sky_zenith[3], sky_horizon[3], ground[3]; /* procedural sky, linear */
    bool sun;
    float sun_dir[3];     /* towards the sun, unit length */
    float sun_color[3];
    float sun_intensity;  /* irradiance at normal incidence, 0..65504 */
    float sun_size_deg;   /* angular diameter, 0.05..20 */
    r_paint_light key, counter;
    float key_area_deg;   /* half-angle of the key-light area, 1..90 */

    float ring_color[3];  /* albedo, 0..1 */

    /* tone map (docs/renderer.md, "Tone map, bloom, flare") */
    float exposure;       /* 0.001..1000 */
    float gamma;          /* 0.1..10 */
    float saturation;     /* 0..10 */
    float bloom;          /* strength 0..10, 0 = no bloom passes */
    float bloom_threshold;/* HDR level where bloom starts, 0..65504 */
    bool flare;           /* sun flare when the sun is on screen */
    bool shadows;         /* SSFSM + blurred mipmap projection shadows */
    r_hdr_format hdr_format;
    /* the scene's size at the standard quality, percent of the output's
     * (r_quality.stage_scene), 50..100: the smallest that keeps this
     * stage inside standard's error budget (docs/accuracy.md) */
    int standard_scene_pct;

    /* stage effects (docs/effects.md) */
    bool water, snow, fog, holes;
    /* light space perspective shadow maps over the whole stage (docs/effects.md,
     * "Shadows in a large world"): the key light's shadows of the buildings (and the fighters) */
    bool lspsm;
    int buildings;        /* how many buildings stand round the ring, 0..R_STAGE_MAX_BUILDINGS */
    int buildings_seed;   /* their layout (r_city.h), 0..2^24 */
    r_afterimage afterimage;  /* motion blur of fast limbs (docs/effects.md, "Afterimage motion blur") */
    float afterimage_stretch; /* old position = cur - stretch * V, 1..8 */
    float afterimage_speed;   /* m/s a bone must move at to leave an afterimage */
} r_stage;

/* The defaults documented in docs/stages.md (a plain outdoor look). */
void r_stage_defaults(r_stage *st);

/* Parses text (len bytes, need not be NUL-terminated); `path` is used in
 * messages and to resolve a relative environment path.  On failure *st is
 * unspecified and err holds "path:line: message". */
bool r_stage_parse(r_stage *st, const char *path, const char *text, size_t len, rs_err *err);
bool r_stage_load(r_stage *st, const char *path, rs_err *err);

/* Loads <data>/stages/<g_stages[game_index].name>.stage. */
bool r_stage_for_game(r_stage *st, int game_index, rs_err *err);

/* Writes the stage back as a stage file (every key, canonical form):
 * parse(format(st)) == st.  Returns the length (snprintf rules). */
int r_stage_format(const r_stage *st, char *out, size_t n);

#endif
