/* runtime/render/r_game: the plain renderer on llvmpipe (EGL and OSMesa).
 *
 * Golden image tests/golden/game_dojo_1200.ppm (320x180, the dojo demo at
 * tick 1200).  Tolerance: a pixel "differs" when any channel is more than
 * 24 off; at most 1% of pixels may differ.  That absorbs rasteriser and
 * float differences between drivers (edges, specular) while a missing
 * fighter, a wrong camera or a broken HUD moves far more than 1%.
 * T_GOLDEN_UPDATE=1 rewrites the golden (look at it before committing). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_img.h"
#include "t.h"

enum { W = 320, H = 180 };
#define GOLDEN RS_SOURCE_DIR "/tests/golden/game_dojo_1200.ppm"

static void state_at(uint64_t tick, g_state *prev, g_state *cur)
{
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_read(RS_SOURCE_DIR "/demos/dojo.rsr", &rp, &e), "%s", e.msg);
    T_ASSERT(tick <= rp.ticks);
    g_init(cur, rp.stage, rp.seed);
    for (uint64_t t = 0; t < tick; t++) {
        *prev = *cur;
        g_step(cur, &rp.inputs[2 * t], NULL);
    }
    rp_free(&rp);
}

/* Renders into an RGBA8 + depth FBO and reads back top-down. */
static void render(const g_state *prev, const g_state *cur, uint8_t *px)
{
    rs_err e = {0};
    r_game *r = r_game_create(&e);
    T_ASSERTF(r, "%s", e.msg);
    GLuint fbo, rb[2];
    gl.GenFramebuffers(1, &fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.GenRenderbuffers(2, rb);
    gl.BindRenderbuffer(GL_RENDERBUFFER, rb[0]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, W, H);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb[0]);
    gl.BindRenderbuffer(GL_RENDERBUFFER, rb[1]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, W, H);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, rb[1]);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    rgl_error_reset();
    r_game_draw(r, prev, cur, 1.0f, W, H);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, W, H, GL_RGBA, GL_UNSIGNED_BYTE, px);
    rs_flip_rows(px, W, H, 4);
    T_EQ(rgl_error_count(), 0);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.DeleteFramebuffers(1, &fbo);
    gl.DeleteRenderbuffers(2, rb);
    r_game_destroy(r);
}

static const uint8_t *at(const uint8_t *px, int x, int y_from_bottom)
{
    return px + ((size_t)(H - 1 - y_from_bottom) * W + (size_t)x) * 4;
}

static void golden_on(const char *backend)
{
    plat *p = t_context(backend);
    g_state prev, cur;
    state_at(1200, &prev, &cur);
    static uint8_t px[W * H * 4];
    render(&prev, &cur, px);
    if (getenv("T_GOLDEN_UPDATE") && !strcmp(backend, "egl")) {
        rs_err e = {0};
        T_ASSERTF(rs_pnm_write(GOLDEN, W, H, 4, px, &e), "%s", e.msg);
    }
    rs_image g;
    rs_err e = {0};
    T_ASSERTF(rs_pnm_read(GOLDEN, &g, &e), "%s", e.msg);
    T_ASSERT(g.w == W && g.h == H && g.channels == 3);
    int bad = 0;
    for (int i = 0; i < W * H; i++)
        for (int c = 0; c < 3; c++)
            if (abs((int)px[4 * i + c] - (int)g.px[3 * i + c]) > 24) {
                bad++;
                break;
            }
    rs_image_free(&g);
    T_ASSERTF(bad <= W * H / 100, "%s: %d of %d pixels differ from the golden by more than 24", backend, bad, W * H);
    plat_destroy(p);
}

static void t_golden_egl(void) { golden_on("egl"); }
static void t_golden_osmesa(void) { golden_on("osmesa"); }

static void t_fighters_where_the_camera_says(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    state_at(1200, &prev, &cur);
    static uint8_t px[W * H * 4];
    render(&prev, &cur, px);
    r_mat4 vp = r_game_camera(&cur, W, H, NULL);
    for (int i = 0; i < 2; i++) {
        g_capsule c[G_BONES];
        g_fighter_capsules(&cur, i, c);
        /* the middle of the chest capsule */
        r_vec3 chest = r_v3(fx_to_float(c[G_CHEST].ax + c[G_CHEST].bx) / 2, fx_to_float(c[G_CHEST].ay + c[G_CHEST].by) / 2,
                            0.0f);
        float sx, sy;
        T_ASSERT(r_project(vp, chest, W, H, &sx, &sy));
        const uint8_t *q = at(px, (int)sx, (int)sy);
        int main = i == 0 ? q[0] : q[2], other = i == 0 ? q[2] : q[0];
        T_ASSERTF(main > other + 40, "fighter %d's chest at (%.0f,%.0f) is %u,%u,%u", i + 1, sx, sy, q[0], q[1], q[2]);
    }
    plat_destroy(p);
}

static void t_hud_shows_health_and_intro(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    state_at(30, &prev, &cur); /* intro: "ROUND 1", full health */
    static uint8_t px[W * H * 4];
    render(&prev, &cur, px);
    /* P1's bar spans 5%..41% of the width, 3%..6.2% from the top: full health is bright orange-yellow */
    const uint8_t *bar = px + ((size_t)(H * 45 / 1000) * W + W / 4) * 4;
    T_ASSERTF(bar[0] > 200 && bar[1] > 150 && bar[2] < 80, "health bar pixel %u,%u,%u", bar[0], bar[1], bar[2]);
    /* the announcement band (38%..48% of the height) holds gold text */
    int gold = 0;
    for (int y = H * 38 / 100; y < H * 50 / 100; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *q = px + ((size_t)y * W + x) * 4;
            gold += q[0] > 230 && q[1] > 180 && q[2] < 90;
        }
    T_ASSERTF(gold > 100, "no announcement text (%d gold pixels)", gold);
    /* and after the intro, no announcement */
    state_at(200, &prev, &cur);
    render(&prev, &cur, px);
    int gold2 = 0;
    for (int y = H * 38 / 100; y < H * 50 / 100; y++)
        for (int x = 0; x < W; x++) {
            const uint8_t *q = px + ((size_t)y * W + x) * 4;
            gold2 += q[0] > 230 && q[1] > 180 && q[2] < 90;
        }
    T_ASSERTF(gold2 < gold / 4, "announcement still shown during the fight (%d)", gold2);
    plat_destroy(p);
}

static void t_drawing_leaves_state_alone(void)
{
    plat *p = t_context("egl");
    g_state prev, cur;
    state_at(900, &prev, &cur);
    uint64_t h0 = g_hash(&prev), h1 = g_hash(&cur);
    static uint8_t px[W * H * 4];
    render(&prev, &cur, px);
    T_EQ(g_hash(&prev), h0);
    T_EQ(g_hash(&cur), h1);
    plat_destroy(p);
}

T_MAIN({"golden_egl", t_golden_egl}, {"golden_osmesa", t_golden_osmesa},
       {"fighters_where_the_camera_says", t_fighters_where_the_camera_says},
       {"hud_shows_health_and_intro", t_hud_shows_health_and_intro},
       {"drawing_leaves_state_alone", t_drawing_leaves_state_alone})
