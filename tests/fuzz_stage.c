/* libFuzzer target for stage files (runtime/render/r_stage.c: the stages/ files
 * and --stage-file): `make fuzz` builds it, seeds are the .stage files of stages/ and
 * tests/fuzz/stage/.  The input is a stage file.  A refusal must be one of
 * the parser's ids with a one-line "fuzz.stage:LINE: ..." message (or
 * "fuzz.stage: ..." for a missing key or the size limit).  What is
 * accepted must hold the bounds docs/stages.md gives (r_stage.h's
 * comments), and write out (r_stage_format, snprintf rules) to a file that
 * parses to the same stage and writes out the same again. */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/game/g_game.h"
#include "../runtime/render/r_stage.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* No '/' in the name: a relative environment path resolves to itself, so
 * the written file names the same one. */
#define PATH "fuzz.stage"

static bool within(const float *v, int n, float lo, float hi)
{
    for (int i = 0; i < n; i++)
        if (!(v[i] >= lo && v[i] <= hi))
            return false;
    return true;
}

static bool unit(const float *v)
{
    return fabs(sqrt((double)v[0] * v[0] + (double)v[1] * v[1] + (double)v[2] * v[2]) - 1) < 1e-5;
}

static bool light_ok(const r_paint_light *l)
{
    return unit(l->dir) && within(l->color, 3, 0, R_HALF_MAX) && within(&l->intensity, 1, 0, R_HALF_MAX) &&
           within(&l->size_deg, 1, 0.5f, 90);
}

static void check_bounds(const r_stage *st)
{
    size_t n = strlen(st->name);
    bool ok = n >= 1 && n <= 31 && strspn(st->name, "abcdefghijklmnopqrstuvwxyz0123456789_-") == n &&
              st->game_index >= 0 && st->game_index < G_STAGES && !strcmp(st->game, g_stages[st->game_index].name) &&
              within(&st->env_rotate_deg, 1, -360, 360) && within(&st->env_scale, 1, 0, R_HALF_MAX) &&
              within(st->sky_zenith, 3, 0, R_HALF_MAX) && within(st->sky_horizon, 3, 0, R_HALF_MAX) &&
              within(st->ground, 3, 0, R_HALF_MAX) && unit(st->sun_dir) && within(st->sun_color, 3, 0, R_HALF_MAX) &&
              within(&st->sun_intensity, 1, 0, R_HALF_MAX) && within(&st->sun_size_deg, 1, 0.05f, 20) &&
              light_ok(&st->key) && light_ok(&st->counter) && within(&st->key_area_deg, 1, 1, 90) &&
              within(st->ring_color, 3, 0, 1) && within(&st->exposure, 1, 0.001f, 1000) &&
              within(&st->gamma, 1, 0.1f, 10) && within(&st->saturation, 1, 0, 10) && within(&st->bloom, 1, 0, 10) &&
              within(&st->bloom_threshold, 1, 0, R_HALF_MAX) && st->buildings >= 0 &&
              st->buildings <= R_STAGE_MAX_BUILDINGS && st->buildings_seed >= 0 && st->buildings_seed <= 1 << 24 &&
              within(&st->afterimage_stretch, 1, 1, 8) && within(&st->afterimage_speed, 1, 0, 1000) &&
              (st->hdr_format == R_HDR_RGBA16F || st->hdr_format == R_HDR_R11G11B10F) &&
              (st->afterimage == R_AFTERIMAGE_OFF || st->afterimage == R_AFTERIMAGE_VIEW ||
               st->afterimage == R_AFTERIMAGE_WORLD);
    if (!ok)
        abort();
}

static char *written(const r_stage *st, int *len)
{
    *len = r_stage_format(st, NULL, 0);
    char *text = malloc((size_t)*len + 1);
    if (r_stage_format(st, text, (size_t)*len + 1) != *len || strlen(text) != (size_t)*len)
        abort();
    return text;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    r_stage st;
    rs_err err = {0};
    if (!r_stage_parse(&st, PATH, (const char *)data, size, &err)) {
        if (RS_ERR_MODULE(err.code) != RS_ERR_MOD_R_STAGE || strncmp(err.msg, PATH ":", strlen(PATH) + 1) != 0 ||
            strchr(err.msg, '\n'))
            abort();
        return 0;
    }
    check_bounds(&st);
    int n1, n2;
    char *one = written(&st, &n1);
    r_stage again;
    if (!r_stage_parse(&again, PATH, one, (size_t)n1, &err))
        abort(); /* what was accepted writes out to a file it refuses: err.msg says why */
    char *two = written(&again, &n2);
    if (n1 != n2 || memcmp(one, two, (size_t)n1) != 0)
        abort();
    free(one);
    free(two);
    return 0;
}
