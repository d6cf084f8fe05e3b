#include "r_quality.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

/* The table `ringside bench quality` chose (docs/accuracy.md has the
 * measurement).  Zero in a knob is its full-quality default. */
const r_preset r_presets[R_PRESETS] = {
    {"draft", 1.0, {.shadow_size = 512, .sil_size = 256, .mask_half = true, .lspsm_size = 1024, .water_grid = 32},
     34.0, "1 pixel drawn per output pixel, small maps: previews"},
    {"standard", 1.0, {.aa = R_AA_FXAA, .mask_half = true}, 38.0, "1 pixel per output pixel, FXAA: the default"},
    {"high", 3.0, {0}, 44.0, "3x3 pixels per output pixel"},
    {"reference", 4.0, {0}, 0.0, "4x4 pixels per output pixel, every knob at full: the measure"},
};

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

const char *r_quality_describe(double scale, const r_quality *q, char *buf, int n)
{
    char sh[16] = "1024", si[16] = "512", ls[16] = "default", fo[16] = "default", wa[16] = "default";
    if (q->shadow_size)
        snprintf(sh, sizeof sh, "%d", q->shadow_size);
    if (q->sil_size)
        snprintf(si, sizeof si, "%d", q->sil_size);
    if (q->lspsm_size)
        snprintf(ls, sizeof ls, "%d", q->lspsm_size);
    if (q->fog_size)
        snprintf(fo, sizeof fo, "%d", q->fog_size);
    if (q->water_grid)
        snprintf(wa, sizeof wa, "%d", q->water_grid);
    snprintf(buf, (size_t)n, "scale %g, aa %s, shadow %s, silhouette %s, mask %s, bloom %d, lspsm %s, fog %s, water %s",
             scale, q->aa == R_AA_FXAA ? "fxaa" : "off", sh, si, q->mask_half ? "half" : "full",
             q->bloom_levels ? q->bloom_levels : 2, ls, fo, wa);
    return buf;
}

static bool range(int v, int lo, int hi, const char *what, rs_err *err)
{
    if (v != 0 && (v < lo || v > hi))
        return rs_fail(err, 1, "quality: %s %d is out of range (%d..%d, or 0 for the default)", what, v, lo, hi);
    return true;
}

bool r_quality_check(const r_quality *q, rs_err *err)
{
    return range(q->shadow_size, 128, 4096, "shadow map size", err) && range(q->sil_size, 64, 2048, "silhouette size", err) &&
           range(q->bloom_levels, 1, 2, "bloom levels", err) && range(q->lspsm_size, 256, 4096, "LSPSM map size", err) &&
           range(q->fog_size, 64, 1024, "fog map size", err) && range(q->water_grid, 16, 256, "water grid", err) &&
           (q->aa == R_AA_OFF || q->aa == R_AA_FXAA ? true : rs_fail(err, 1, "quality: unknown anti-aliasing %d", (int)q->aa));
}
