/* runtime/render/r_smoke: a known picture rendered headless on EGL and on
 * OSMesa must equal its CPU reference byte for byte (tolerance 0: every
 * edge avoids pixel centres, and colours are k/255). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_smoke.h"
#include "../runtime/util/rs_img.h"
#include "t.h"

static void render_equals_reference(const char *backend, int w, int h)
{
    plat *p = t_context(backend);
    rs_err e = {0};
    r_smoke *s = r_smoke_create(w, h, &e);
    T_ASSERTF(s, "%s", e.msg);
    uint8_t *got = malloc((size_t)w * h * 4), *want = malloc((size_t)w * h * 4);
    rgl_error_reset();
    r_smoke_draw(s);
    r_smoke_read(s, got);
    T_EQ(rgl_error_count(), 0);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    r_smoke_reference(w, h, want);
    size_t bad = 0, first = 0;
    for (size_t i = 0; i < (size_t)w * h; i++)
        if (memcmp(got + 4 * i, want + 4 * i, 4) && !bad++)
            first = i;
    T_ASSERTF(bad == 0, "%s %dx%d: %zu pixels differ, first at (%zu,%zu): got %u,%u,%u,%u want %u,%u,%u,%u", backend,
              w, h, bad, first % w, first / w, got[4 * first], got[4 * first + 1], got[4 * first + 2],
              got[4 * first + 3], want[4 * first], want[4 * first + 1], want[4 * first + 2], want[4 * first + 3]);
    free(got);
    free(want);
    r_smoke_destroy(s);
    plat_destroy(p);
}

static void t_egl_720p(void) { render_equals_reference("egl", 1280, 720); }
static void t_osmesa_720p(void) { render_equals_reference("osmesa", 1280, 720); }
static void t_egl_odd_size(void) { render_equals_reference("egl", 97, 61); }
static void t_osmesa_odd_size(void) { render_equals_reference("osmesa", 97, 61); }
static void t_egl_tall(void) { render_equals_reference("egl", 33, 517); }

/* The reference itself is pinned by a golden file, so a change to the
 * scene (and to its reference with it) cannot pass unnoticed. */
static void t_reference_matches_golden(void)
{
    rs_image g;
    rs_err e = {0};
    T_ASSERTF(rs_pnm_read(RS_SOURCE_DIR "/tests/golden/smoke_160x90.ppm", &g, &e), "%s", e.msg);
    T_EQ(g.w, 160);
    T_EQ(g.h, 90);
    uint8_t ref[160 * 90 * 4];
    r_smoke_reference(160, 90, ref);
    for (int i = 0; i < 160 * 90; i++)
        T_ASSERTF(!memcmp(g.px + 3 * i, ref + 4 * i, 3), "golden differs at pixel (%d,%d)", i % 160, i / 160);
    rs_image_free(&g);
}

static void t_compare_finds_one_pixel(void)
{
    /* the comparison that `ringside smoke` uses must see a single wrong
     * channel of a single pixel, and say where */
    enum { W = 64, H = 48 };
    static uint8_t a[W * H * 4], b[W * H * 4];
    r_smoke_reference(W, H, a);
    memcpy(b, a, sizeof a);
    size_t first;
    T_EQ(r_smoke_compare(a, b, W, H, &first), 0);
    b[(17 * W + 33) * 4 + 2] ^= 1;
    T_EQ(r_smoke_compare(a, b, W, H, &first), 1);
    T_EQ(first, 17 * W + 33);
    b[(3 * W + 5) * 4 + 3] ^= 0x80;
    T_EQ(r_smoke_compare(a, b, W, H, &first), 2);
    T_EQ(first, 3 * W + 5);
}

static void t_draw_leaves_no_fbo_bound(void)
{
    plat *p = t_context("egl");
    rs_err e = {0};
    r_smoke *s = r_smoke_create(32, 32, &e);
    T_ASSERT(s);
    r_smoke_draw(s);
    GLint draw = -1, read = -1, pack = 0;
    gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw);
    gl.GetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read);
    T_EQ(draw, 0);
    T_EQ(read, 0);
    uint8_t px[32 * 32 * 4];
    r_smoke_read(s, px);
    gl.GetIntegerv(GL_PACK_ALIGNMENT, &pack);
    T_EQ(pack, 4);
    r_smoke_destroy(s);
    plat_destroy(p);
}

static void t_bad_sizes(void)
{
    plat *p = t_context("egl");
    rs_err e = {0};
    T_ASSERT(!r_smoke_create(8, 100, &e));
    T_CONTAINS(e.msg, "8x100 out of range");
    T_ASSERT(!r_smoke_create(100, glcaps.max_texture_size + 1, &e));
    plat_destroy(p);
}

T_MAIN({"egl_720p", t_egl_720p}, {"osmesa_720p", t_osmesa_720p}, {"egl_odd_size", t_egl_odd_size},
       {"osmesa_odd_size", t_osmesa_odd_size}, {"egl_tall", t_egl_tall},
       {"reference_matches_golden", t_reference_matches_golden}, {"compare_finds_one_pixel", t_compare_finds_one_pixel},
       {"draw_leaves_no_fbo_bound", t_draw_leaves_no_fbo_bound},
       {"bad_sizes", t_bad_sizes})
