#include "r_quality.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The table `ringside bench quality` chose (docs/accuracy.md has the
 * measurement).  Zero in a knob is its full-quality default. */
const r_preset r_presets[R_PRESETS] = {
    {"draft", 1.0, {.mask_half = true, .shadow_size = 512, .lspsm_size = 1024, .water_grid = 32, .snow_light = 128, .scene_pct = 60, .lspsm_static = 2048},
     34.0, "the scene at 60% size, the cheaper maps: previews"},
    {"standard", 1.0, {.mask_half = true, .shadow_size = 512, .lspsm_size = 1024, .lspsm_static = 2048, .water_grid = 32, .snow_light = 128, .stage_scene = true},
     38.0, "the stage's scene size, the cheaper maps: the default"},
    {"high", 2.0, {.mask_half = true, .shadow_size = 512, .lspsm_size = 1024, .water_grid = 32, .snow_light = 128}, 44.0,
     "2x2 pixels drawn per output pixel"},
    {"reference", 4.0, {0}, 0.0, "4x4, every knob at full: the measure"},
};

int r_scene_pct(const r_quality *q, int stage_pct)
{
    if (q->scene_pct)
        return q->scene_pct;
    return q->stage_scene && stage_pct > 0 ? stage_pct : 100;
}

void r_scene_size(int pct, int w, int h, int *sw, int *sh)
{
    *sw = w, *sh = h;
    if (pct < 100 && w > 0 && h > 0) {
        *sw = (int)(((long)w * pct + 50) / 100), *sh = (int)(((long)h * pct + 50) / 100);
        *sw = *sw > 0 ? *sw : 1, *sh = *sh > 0 ? *sh : 1;
    }
}

const r_preset *r_preset_named(const char *name)
{
    for (int i = 0; i < R_PRESETS; i++)
        if (name && !strcmp(name, r_presets[i].name))
            return &r_presets[i];
    return NULL;
}

const char *r_preset_list(void)
{
    return "draft, standard, high or reference";
}

void r_preset_render_size(const r_preset *p, int w, int h, int max, int *rw, int *rh)
{
    double s = p->scale < 1 ? 1 : p->scale;
    if (w * s > max)
        s = (double)max / w;
    if (h * s > max)
        s = (double)max / h;
    if (s < 1)
        s = 1;
    *rw = (int)lround(w * s);
    *rh = (int)lround(h * s);
}
