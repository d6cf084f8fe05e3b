#include "r_game.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../gl/rgl.h"
#include "r_ibl.h"
#include "r_mesh.h"
#include "r_shader.h"
#include "r_tex.h"
#include "r_tone.h"
#include "r_local.h"
#include "../util/rs_log.h"

static bool build_look_programs(r_game *r, rs_err *err);

static const char *const core_res_names[R_RES_CORE] = {"env", "shadow map", "silhouette", "depth", "shadow mask",
                                                       "hdr", "bloom", "sun visibility", "output", "flare"};

/* ---- the look: stage, environment, IBL ---- */

static void free_look(r_game *r)
{
    for (int m = 0; m < R_IBL_MAPS; m++)
        gl.DeleteTextures(2, r->ibl_tex[m]);
    gl.DeleteTextures(1, &r->sky_tex);
    memset(r->ibl_tex, 0, sizeof r->ibl_tex);
    r->sky_tex = 0;
    r_free_mesh(&r->ring_vao, &r->ring_vbo, &r->ring_ibo);
    r->have_stage = false;
}

static bool build_ring(r_game *r, int game_stage, rs_err *err)
{
    float e = fx_to_float(g_stages[game_stage].ring_half);
    r_mesh_data m = {0};
    /* among buildings the ring stands on a plinth in a paved square that
     * reaches past the shadow range (r_city.h) */
    bool city = r->stage.buildings > 0;
    float g = city ? 160.0f : 40.0f;
    const float lo[3] = {-e, city ? -3.0f : -0.6f, -e}, hi[3] = {e, 0.0f, e};
    const float glo[3] = {-g, -3.3f, -g}, ghi[3] = {g, -3.0f, g}; /* the ground far below */
    if (!r_mesh_box(&m, lo, hi) || !r_mesh_box(&m, glo, ghi)) {
        r_mesh_free(&m);
        return rs_fail(err, R_ERR_NOMEM, "out of memory for the ring mesh");
    }
    r_free_mesh(&r->ring_vao, &r->ring_vbo, &r->ring_ibo);
    r_upload_mesh(&m, &r->ring_vao, &r->ring_vbo, &r->ring_ibo);
    r->ring_count = (GLsizei)m.ni;
    r->ring_stage = game_stage;
    r_mesh_free(&m);
    return true;
}

static bool load_look(r_game *r, const r_stage *st, int game_stage, rs_err *err)
{
    free_look(r);
    r->stage = *st;
    r->hdr_format = r->opts.hdr_format == R_GAME_HDR_R11G11B10F ? R_HDR_R11G11B10F
                    : r->opts.hdr_format == R_GAME_HDR_RGBA16F  ? R_HDR_RGBA16F
                                                                : st->hdr_format;
    if (r->opts.mask && r->hdr_format != R_HDR_RGBA16F)
        return rs_fail(err, R_ERR_OPTIONS, "--mask needs an alpha channel: the r11g11b10f HDR format has none (use rgba16f)");
    r_ibl_params ip;
    r_ibl_default_params(&ip);
    r_ibl ibl = {0};
    const char *cache = r->opts.cache_dir ? r->opts.cache_dir : r_ibl_cache_dir();
    if (!r_ibl_build(st, &ip, cache, &ibl, err)) {
        if (err && st->env_path[0]) { /* say which stage asked for the file */
            char msg[sizeof err->msg];
            snprintf(msg, sizeof msg, "stage '%s': environment: %s", st->name, err->msg);
            snprintf(err->msg, sizeof err->msg, "%s", msg);
        }
        return false;
    }
    if (!r->opts.quiet && !ibl.from_cache && ibl.ms > 500 && rs_log_on(RS_LOG_INFO))
        fprintf(stderr, "ringside: %s: prefiltered the environment in %.1f s (cached for next time)\n", st->name,
                ibl.ms / 1000);
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 2; k++)
            r->ibl_tex[m][k] = r_cube_tex(ibl.size[m], ibl.map[m][k], 1);
    memcpy(r->key_dir, ibl.key_dir, sizeof r->key_dir);
    r_ibl_free(&ibl);
    r_env sky = {0};
    if (!r_env_build(st, SKY_SIZE, &sky, err))
        return false;
    r->sky_tex = r_cube_tex(sky.size, sky.face, 1);
    r_env_free(&sky);
    /* the ring has the size of the match's stage (r_game_draw), which a
     * --stage-file look for another game stage does not change */
    if (!build_ring(r, game_stage >= 0 ? game_stage : st->game_index, err))
        return false;
    if (!build_look_programs(r, err))
        return false;
    r->stage_game = game_stage;
    r->have_stage = true;
    r->have_last = false; /* the simulations restart on a new look */
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->load && !r_fx_modules[i]->load(r, err)) {
            r->have_stage = false;
            return false;
        }
    RGL_CHECK("load_look");
    return true;
}

bool r_game_set_stage(r_game *r, const r_stage *st, rs_err *err)
{
    return load_look(r, st, -1, err);
}

bool r_game_prepare(r_game *r, int game_stage, rs_err *err)
{
    if (r->have_stage && (r->stage_game == game_stage || r->stage_game == -1 || r->opts.stage_file))
        return true;
    r_stage st;
    bool ok = r->opts.stage_file ? r_stage_load(&st, r->opts.stage_file, err) : r_stage_for_game(&st, game_stage, err);
    return ok && load_look(r, &st, r->opts.stage_file ? -1 : game_stage, err);
}

const r_stage *r_game_stage(const r_game *r)
{
    return r->have_stage ? &r->stage : NULL;
}

/* ---- screen targets ---- */

static void free_targets(r_game *r)
{
    GLuint tex[] = {r->hdr_tex, r->depth_tex, r->mask_tex[0], r->mask_tex[1], r->b2_tex, r->b4_tex[0],
                    r->b4_tex[1], r->b8_tex[0], r->b8_tex[1], r->sunvis_tex, r->fl_tex, r->ldr_tex, r->luma_tex,
                    r->sc_tex, r->glow_tex, r->bc_tex};
    GLuint fbo[] = {r->hdr_fbo, r->depth_fbo, r->mask_fbo[0], r->mask_fbo[1], r->b2_fbo, r->b4_fbo[0],
                    r->b4_fbo[1], r->b8_fbo[0], r->b8_fbo[1], r->sunvis_fbo, r->fl_fbo, r->ldr_fbo, r->sc_fbo,
                    r->glow_fbo, r->bc_fbo};
    for (size_t i = 0; i < sizeof tex / sizeof tex[0]; i++)
        if (tex[i])
            gl.DeleteTextures(1, &tex[i]);
    for (int i = 0; i < BLOOM_XSTEPS; i++)
        if (r->bx_tex[i])
            gl.DeleteTextures(1, &r->bx_tex[i]), gl.DeleteFramebuffers(1, &r->bx_fbo[i]), r->bx_tex[i] = r->bx_fbo[i] = 0;
    for (size_t i = 0; i < sizeof fbo / sizeof fbo[0]; i++)
        if (fbo[i])
            gl.DeleteFramebuffers(1, &fbo[i]);
    r->hdr_tex = r->depth_tex = r->b2_tex = r->sunvis_tex = r->fl_tex = 0;
    r->hdr_fbo = r->depth_fbo = r->b2_fbo = r->sunvis_fbo = r->fl_fbo = 0;
    r->ldr_tex = r->ldr_fbo = r->luma_tex = r->sc_tex = r->sc_fbo = r->glow_tex = r->glow_fbo = 0;
    r->bc_tex = r->bc_fbo = 0;
    memset(r->mask_tex, 0, sizeof r->mask_tex), memset(r->mask_fbo, 0, sizeof r->mask_fbo);
    memset(r->b4_tex, 0, sizeof r->b4_tex), memset(r->b4_fbo, 0, sizeof r->b4_fbo);
    memset(r->b8_tex, 0, sizeof r->b8_tex), memset(r->b8_fbo, 0, sizeof r->b8_fbo);
    r->tw = r->th = 0;
}


static bool make_targets(r_game *r, int w, int h, int ow, int oh, rs_err *err)
{
    if (r->tw == w && r->th == h && r->tow == ow && r->toh == oh && r->tw > 0 && r->tfmt == r->hdr_format)
        return true;
    free_targets(r);
    GLenum hdr_fmt = r->hdr_format == R_HDR_R11G11B10F ? GL_R11F_G11F_B10F : GL_RGBA16F;
    r->hdr_tex = r_tex2d(hdr_fmt, w, h, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    r->depth_tex = r_tex2d(GL_DEPTH24_STENCIL8, w, h, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, NULL, GL_NEAREST,
                         GL_CLAMP_TO_EDGE);
    r->hdr_fbo = r_fbo_for(r->hdr_tex, 0, r->depth_tex);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    r->depth_fbo = r_fbo_for(0, 0, r->depth_tex);
    /* the mask at half size with q.mask_half; bloom levels of fixed row counts (r_post.c) */
    r->mask_w = r->opts.q.mask_half ? r_half(w, 1) : w, r->mask_h = r->opts.q.mask_half ? r_half(h, 1) : h;
    r_bloom_plan(w, h, &r->bloom_steps, &r->b4_w);
    r->b8_w = r_half(r->b4_w, 1);
    for (int i = 0; i < 2; i++) {
        r->mask_tex[i] = r_tex2d(GL_R8, r->mask_w, r->mask_h, GL_RED, GL_UNSIGNED_BYTE, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        r->mask_fbo[i] = r_fbo_for(r->mask_tex[i], 0, 0);
        /* bloom's levels: RGBE in RGBA8, read texel by texel (rgbe_common.glsl) */
        r->b4_tex[i] = r_tex2d(GL_RGBA8, r->b4_w, BLOOM_ROWS, GL_RGBA, GL_UNSIGNED_BYTE, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
        r->b4_fbo[i] = r_fbo_for(r->b4_tex[i], 0, 0);
        r->b8_tex[i] = r_tex2d(GL_RGBA8, r->b8_w, BLOOM_ROWS / 2, GL_RGBA, GL_UNSIGNED_BYTE, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
        r->b8_fbo[i] = r_fbo_for(r->b8_tex[i], 0, 0);
    }
    for (int k = 2; k < r->bloom_steps; k++) {
        r->bx_tex[k - 2] = r_tex2d(GL_RGBA16F, r_half(w, k), r_half(h, k), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR,
                                   GL_CLAMP_TO_EDGE);
        r->bx_fbo[k - 2] = r_fbo_for(r->bx_tex[k - 2], 0, 0);
    }
    /* RGBA32F where the CPU makes it: its upload is then a copy (the tone
     * map's tap of it costs llvmpipe the same) */
    r->glow_tex = r_tex2d(r->cpu_paths ? GL_RGBA32F : GL_RGBA16F, r->b4_w, BLOOM_ROWS, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR,
                          GL_CLAMP_TO_EDGE);
    r->glow_fbo = r_fbo_for(r->glow_tex, 0, 0);
    r->bc_tex = r_tex2d(GL_RGBA32F, r->b4_w, BLOOM_ROWS, GL_RGBA, GL_FLOAT, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
    r->bc_fbo = r_fbo_for(r->bc_tex, 0, 0);
    r->b2_tex = r_tex2d(GL_RGBA16F, r_half(w, 1), r_half(h, 1), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    r->b2_fbo = r_fbo_for(r->b2_tex, 0, 0);
    r->sunvis_tex = r_tex2d(GL_R16F, 1, 1, GL_RED, GL_FLOAT, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
    r->sunvis_fbo = r_fbo_for(r->sunvis_tex, 0, 0);
    r->fl_tex = r_tex2d(GL_RGBA16F, r_half(w, 2), r_half(h, 2), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    r->fl_fbo = r_fbo_for(r->fl_tex, 0, 0);
    if ((w != ow || h != oh) && !r->opts.q.aa) { /* the tone map at the scene's size, then a linear blit up */
        r->sc_tex = r_tex2d(GL_RGBA8, w, h, GL_RGBA, GL_UNSIGNED_BYTE, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        r->sc_fbo = r_fbo_for(r->sc_tex, 0, 0);
    }
    if (r->opts.q.aa) { /* the tone map's image for the AA pass: linear, its walk taps between texels */
        r->ldr_tex = r_tex2d(GL_RGBA8, ow, oh, GL_RGBA, GL_UNSIGNED_BYTE, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        r->ldr_fbo = r_fbo_for(r->ldr_tex, 0, 0);
        /* and its luma beside it, which the AA pass gathers for its early out */
        r->luma_tex = r_tex2d(GL_R8, ow, oh, GL_RED, GL_UNSIGNED_BYTE, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_TEXTURE_2D, r->luma_tex, 0);
        const GLenum two[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
        gl.DrawBuffers(2, two);
        gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        free_targets(r);
        return rs_fail(err, R_ERR_TARGET, "%dx%d HDR target (%s) incomplete (%s)", w, h,
                       hdr_fmt == GL_RGBA16F ? "rgba16f" : "r11g11b10f", rgl_enum_name(st));
    }
    r->tw = w, r->th = h, r->tow = ow, r->toh = oh, r->tfmt = r->hdr_format;
    RGL_CHECK("make_targets");
    return true;
}


/* The programs that do not depend on the look: built once at create. */
static bool build_programs(r_game *r, rs_err *err)
{
    static const struct {
        int id;
        const char *vs, *fs, *defines;
    } d[] = {
        {P_DEPTH, "scene.vert", "light_depth.frag", "#define LIGHT_VIEW 1\n"},
        {P_SIL, "scene.vert", "light_depth.frag", "#define LIGHT_VIEW 1\n#define SILHOUETTE 1\n"},
        {P_MASK, "cap_fullscreen.vert", "shadow_mask.frag", NULL},
        {P_GROW, "cap_fullscreen.vert", "mask_grow.frag", NULL},
        {P_BLUR, "cap_fullscreen.vert", "blur.frag", NULL},
        {P_BLUR_TEXELS, "cap_fullscreen.vert", "blur.frag", "#define REACH 1\n"},
        {P_BLUR_TEXELS + 1, "cap_fullscreen.vert", "blur.frag", "#define REACH 2\n"},
        {P_BLUR_TEXELS + 2, "cap_fullscreen.vert", "blur.frag", "#define REACH 3\n"},
        {P_BLUR_TEXELS + 3, "cap_fullscreen.vert", "blur.frag", "#define REACH 4\n"},
        {P_DOWN, "cap_fullscreen.vert", "downsample.frag", NULL},
        {P_DOWN_RGBE, "cap_fullscreen.vert", "downsample.frag", "#define RGBE_OUT 1\n"},
        {P_DOWN_RGBE_IN, "cap_fullscreen.vert", "downsample.frag", "#define RGBE_IN 1\n#define RGBE_OUT 1\n"},
        {P_BLUR_RGBE, "cap_fullscreen.vert", "blur.frag", "#define REACH 4\n#define RGBE 1\n"},
        {P_SUNVIS, "cap_fullscreen.vert", "sun_vis.frag", NULL},
        {P_FLARE, "cap_fullscreen.vert", "flare.frag", NULL},
        {P_HUD, "hud.vert", "hud.frag", NULL},
        {P_HUD_RECT, "hud.vert", "hud.frag", "#define RECT 1\n"},
        {P_HUD_2TAPS, "hud.vert", "hud.frag", "#define TAPS 2\n"},
        {P_FXAA, "cap_fullscreen.vert", "fxaa.frag", NULL},
        {P_FXAA_MARK, "cap_fullscreen.vert", "fxaa.frag", "#define MARK 1\n"},
        {P_GLOW, "cap_fullscreen.vert", "blur.frag", "#define REACH 4\n#define RGBE 1\n#define GLOW 1\n"},
        {P_GLOW + 1, "cap_fullscreen.vert", "blur.frag", "#define REACH 4\n#define RGBE 1\n#define GLOW 1\n#define LEVEL2 1\n"},
        {P_GLOW + 2, "cap_fullscreen.vert", "blur.frag", "#define REACH 4\n#define RGBE 1\n#define GLOW 1\n#define FLARE 1\n"},
        {P_GLOW + 3, "cap_fullscreen.vert", "blur.frag", "#define REACH 4\n#define RGBE 1\n#define GLOW 1\n#define LEVEL2 1\n#define FLARE 1\n"},
        {P_TONE, "cap_fullscreen.vert", "tonemap.frag", NULL},
        {P_TONE + 1, "cap_fullscreen.vert", "tonemap.frag", "#define GLOW 1\n"},
        {P_TONE + 2, "cap_fullscreen.vert", "tonemap.frag", "#define SCALED 1\n"},
        {P_TONE + 3, "cap_fullscreen.vert", "tonemap.frag", "#define GLOW 1\n#define SCALED 1\n"},
    };
    /* with the AA pass, the tone map writes the luma too (r_aa.c), and the
     * pass's early out gathers it where the GL can (else five fetches) */
    bool aa = r->opts.q.aa == R_AA_FXAA;
    r->aa_gather = aa && !r->opts.aa_plain && (glcaps.major > 3 || rgl_has_extension("GL_ARB_texture_gather"));
    const char *aa_defs = r->aa_gather ? "#define GATHER 1\n" : "";
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) {
        char defs[160];
        bool tone = d[i].id >= P_TONE, fxaa = d[i].id == P_FXAA || d[i].id == P_FXAA_MARK;
        snprintf(defs, sizeof defs, "%s%s%s", d[i].defines ? d[i].defines : "", tone && aa ? "#define AA 1\n" : "",
                 fxaa ? aa_defs : "");
        if (!(r->prog[d[i].id] = r_program(&(r_program_desc){.vs = d[i].vs, .fs = d[i].fs, .defines = defs}, err)))
            return false;
    }
    return true;
}

static void free_look_programs(r_game *r)
{
    for (int i = 0; i < P_LOOK_END; i++) {
        gl.DeleteProgram(r->prog[i]);
        r->prog[i] = 0;
    }
    r->look_defines[0] = 0;
}

/* The look's programs: the scene's, compiled with what the loaded stage
 * uses (SHADOWS, each effect's scene_define, the ring's MATERIAL), so
 * that code for what it does not use is not there at all (r_fx.h says
 * why a uniform test is not enough).  Kept while the defines stay the
 * same from one look to the next. */
static bool build_look_programs(r_game *r, rs_err *err)
{
    char defs[256];
    size_t n = (size_t)snprintf(defs, sizeof defs, "%s", r->stage.shadows ? "#define SHADOWS 1\n" : "");
    for (int m = 0; m < r_fx_nmodules; m++) {
        const char *name = r_fx_modules[m]->scene_define ? r_fx_modules[m]->scene_define(r) : NULL;
        if (name && n < sizeof defs)
            n += (size_t)snprintf(defs + n, sizeof defs - n, "#define %s 1\n", name);
    }
    if (n >= sizeof defs)
        return rs_fail(err, R_ERR_LOOK, "the look's shader defines are longer than %zu bytes", sizeof defs - 1);
    /* the buildings and the craters: only on a look that has them */
    bool buildings = r->stage.buildings > 0, holes = r->stage.holes;
    char key[sizeof defs + 32];
    snprintf(key, sizeof key, "%s/%d%d%d", defs, r_ring_material(r), buildings, holes);
    if (r->prog[P_FIGHTER] && !strcmp(key, r->look_defines))
        return true;
    free_look_programs(r);
    const struct {
        int id;
        const char *vs, *fs, *kind;
        int material;
        bool want;
    } d[] = {
        {P_FIGHTER, "scene.vert", "scene.frag", "FIGHTER", -1, true},
        {P_STAGE, "scene.vert", "scene.frag", "STAGE", r_ring_material(r), true},
        {P_STAGE_BUILDING, "scene.vert", "scene.frag", "STAGE", R_MAT_BUILDING, buildings},
        {P_STAGE_HOLE, "scene.vert", "scene.frag", "STAGE", R_MAT_HOLE, holes},
        {P_LENS, "scene.vert", "lens.frag", "LENS", -1, true},
        {P_SKY, "sky.vert", "sky.frag", NULL, -1, true},
    };
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++) {
        if (!d[i].want)
            continue;
        char all[sizeof defs + 64];
        int k = snprintf(all, sizeof all, "%s", defs);
        if (d[i].kind)
            k += snprintf(all + k, sizeof all - (size_t)k, "#define %s 1\n", d[i].kind);
        if (d[i].material >= 0)
            snprintf(all + k, sizeof all - (size_t)k, "#define MATERIAL %d\n", d[i].material);
        if (!(r->prog[d[i].id] = r_program(&(r_program_desc){.vs = d[i].vs, .fs = d[i].fs, .defines = all}, err))) {
            free_look_programs(r);
            return false;
        }
    }
    snprintf(r->look_defines, sizeof r->look_defines, "%s", key);
    return true;
}

static bool build_graph(r_game *r, rs_err *err)
{
    /* the effects' resources: named and made persistent by their modules */
    uint32_t persistent = RES_PERSISTENT, fx_reads = 0;
    if (r_fx_nmodules > R_FX_MAX_MODULES)
        return rs_fail(err, R_ERR_EFFECTS, "%d stage effects; r_game keeps state for %d", r_fx_nmodules, R_FX_MAX_MODULES);
    memcpy(r->res_names, core_res_names, sizeof core_res_names);
    for (int m = 0; m < r_fx_nmodules; m++) {
        const r_fx_module *mod = r_fx_modules[m];
        for (int k = 0; k < R_FX_MAX_RES && mod->res[k].bit; k++) {
            int b = 0;
            while (b < 32 && mod->res[k].bit != 1u << b)
                b++;
            if (b < R_RES_FX_FIRST || b >= 32 || r->res_names[b])
                return rs_fail(err, R_ERR_EFFECTS, "effect '%s': resource '%s' is not one free bit from %d up", mod->name,
                               mod->res[k].name, R_RES_FX_FIRST);
            r->res_names[b] = mod->res[k].name;
            if (mod->res[k].persistent)
                persistent |= mod->res[k].bit;
        }
        fx_reads |= mod->scene_reads;
    }
    if (r_fx_units() > R_FX_UNIT_END - R_FX_UNIT_FIRST)
        return rs_fail(err, R_ERR_EFFECTS, "the effects' bind hooks want %d texture units; there are %d", r_fx_units(),
                       R_FX_UNIT_END - R_FX_UNIT_FIRST);
    r_graph_init(&r->graph, persistent, r->res_names, 32);
    /* NULL: the stage effects' passes of that phase (r_fx.h) */
    const r_pass *const order[] = {
        &r_shadow_passes[0], &r_shadow_passes[1], &r_shadow_passes[2], &r_shadow_passes[3],
        &r_shadow_passes[4], &r_shadow_passes[5], NULL, &r_scene_pass, NULL, &r_sky_pass, NULL, &r_lens_pass,
        &r_post_passes[0], &r_post_passes[1], &r_post_passes[2], &r_post_passes[3], &r_post_passes[4], &r_aa_pass,
        &r_hud_pass,
    };
    /* The core's passes that only shade the picture: a frame drawn for the
     * effects' history (LSPSM's focus reads the depth buffer) leaves them
     * out.  z_prepass stays (the fighters are drawn over its depth), and so
     * does every effect pass (an effect may step its history there). */
    const r_pass *const shade_only[] = {
        &r_shadow_passes[0], &r_shadow_passes[1], &r_shadow_passes[2], &r_shadow_passes[4], &r_shadow_passes[5],
        &r_sky_pass, &r_lens_pass, &r_post_passes[0], &r_post_passes[1], &r_post_passes[2], &r_post_passes[3],
        &r_post_passes[4], &r_aa_pass, &r_hud_pass,
    };
    r->history_skip = 0;
    int phase = R_FX_PRE;
    for (size_t i = 0; i < sizeof order / sizeof order[0]; i++) {
        if (order[i]) {
            for (size_t k = 0; k < sizeof shade_only / sizeof shade_only[0]; k++)
                if (order[i] == shade_only[k])
                    r->history_skip |= (r_graph_mask)1 << r->graph.n;
            r_pass p = *order[i];
            if (p.run == r_scene_pass.run || p.run == r_sky_pass.run || p.run == r_lens_pass.run)
                p.may_read |= fx_reads; /* what the modules bind into the scene's programs */
            if (!r_graph_add(&r->graph, &p, err))
                return false;
            continue;
        }
        for (int m = 0; m < r_fx_nmodules; m++)
            for (int k = 0; k < r_fx_modules[m]->npass[phase]; k++)
                if (!r_graph_add(&r->graph, &r_fx_modules[m]->pass[phase][k], err))
                    return false;
        phase++;
    }
    return true;
}

/* The knobs this file honours, each 0 (the default) or in its range. */
static bool check_quality(const r_quality *q, rs_err *err)
{
    static const struct {
        const char *name, *what;
        int lo, hi;
    } k[] = {
        {"shadow_size", "the SSFSM light depth map's side", 128, 4096},
        {"sil_size", "the silhouette's side", 64, 2048},
        {"water_grid", "the water surface's quads a side", 16, 256},
        {"fog_size", "the mist's density map's side", 64, 1024},
        {"bloom_levels", "the bloom levels added", 1, 2},
        {"snow_light", "the snow's light map's side", 64, 256},
        {"scene_pct", "the scene's size, percent of the output's", 50, 100},
    };
    const int v[] = {q->shadow_size, q->sil_size, q->water_grid, q->fog_size, q->bloom_levels, q->snow_light, q->scene_pct};
    for (size_t i = 0; i < sizeof k / sizeof k[0]; i++)
        if (v[i] != 0 && (v[i] < k[i].lo || v[i] > k[i].hi))
            return rs_fail(err, R_ERR_QUALITY, "quality: %s %d out of range: %s is %d..%d (0 = default)", k[i].name, v[i],
                           k[i].what, k[i].lo, k[i].hi);
    if (q->aa != R_AA_OFF && q->aa != R_AA_FXAA)
        return rs_fail(err, R_ERR_QUALITY, "quality: aa %d unknown (0 off, 1 fxaa)", (int)q->aa);
    return true;
}

/* Where each bone's triangles start in the fighter mesh's indices
 * (r_mesh_fighter appends the bones' capsules in order): first[b] ..
 * first[b + 1].  A bone with no triangles gets an empty range. */
static void fighter_bone_ranges(const r_mesh_data *m, GLsizei first[G_BONES + 1])
{
    int b = 0;
    first[0] = 0;
    for (size_t t = 0; t + 2 < m->ni; t += 3) {
        int bone = (int)(m->v[m->idx[t]].bone + 0.5f);
        while (b < bone && b < G_BONES)
            first[++b] = (GLsizei)t;
    }
    while (b < G_BONES)
        first[++b] = (GLsizei)m->ni;
}

r_game *r_game_create(rs_err *err)
{
    return r_game_create_opts(NULL, err);
}

r_game *r_game_create_opts(const r_game_opts *o, rs_err *err)
{
    r_game *r = calloc(1, sizeof *r);
    if (!r || !(r->hud = malloc(HUD_MAX_QUADS * 6 * sizeof(hud_vertex)))) {
        free(r);
        rs_fail(err, R_ERR_NOMEM, "out of memory");
        return NULL;
    }
    if (o)
        r->opts = *o;
    if (r->opts.stage_file) {
        snprintf(r->stage_file, sizeof r->stage_file, "%s", r->opts.stage_file);
        r->opts.stage_file = r->stage_file;
    }
    if (!check_quality(&r->opts.q, err)) {
        free(r->hud);
        free(r);
        return NULL;
    }
    r->shadow_size = r->opts.q.shadow_size > 0 ? r->opts.q.shadow_size : SHADOW_SIZE;
    r->sil_size = r->opts.q.sil_size > 0 ? r->opts.q.sil_size : SIL_SIZE;
    r->stage_game = -2;
    r->ring_stage = -1;
    r->cpu_paths = rgl_is_software();
    r->fighter = &r->fighter_lod[R_FIGHTER_FINE]; /* until a frame chooses (select_fighter_mesh) */
    r->lut_size = r->opts.lut_size > 0 ? r->opts.lut_size : R_TONE_LUT_DEFAULT;
    r->lut_size = r->lut_size < R_TONE_LUT_MIN ? R_TONE_LUT_MIN : r->lut_size > R_TONE_LUT_MAX ? R_TONE_LUT_MAX : r->lut_size;
    if (!build_programs(r, err) || !build_graph(r, err)) {
        r_game_destroy(r);
        return NULL;
    }
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->create && !r_fx_modules[i]->create(r, err)) {
            r_game_destroy(r);
            return NULL;
        }
    gl.Enable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    gl.GenVertexArrays(1, &r->empty_vao);

    r_mesh_data m = {0};
    bool ok = true;
    for (int lod = 0; ok && lod < R_FIGHTER_LODS; lod++) {
        struct fighter_mesh *fm = &r->fighter_lod[lod];
        if ((ok = r_mesh_fighter(&m, lod))) {
            r_upload_mesh(&m, &fm->vao, &fm->vbo, &fm->ibo);
            fm->count = (GLsizei)m.ni;
            fighter_bone_ranges(&m, fm->bone_first);
        }
        r_mesh_free(&m);
    }
    if (ok && (ok = r_build_lens(&m))) {
        r_upload_mesh(&m, &r->lens_vao, &r->lens_vbo, &r->lens_ibo);
        r->lens_count = (GLsizei)m.ni;
    }
    r_mesh_free(&m);

    gl.GenVertexArrays(1, &r->hud_vao);
    gl.BindVertexArray(r->hud_vao);
    gl.GenBuffers(1, &r->hud_vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, r->hud_vbo);
    gl.BufferData(GL_ARRAY_BUFFER, HUD_MAX_QUADS * 6 * sizeof(hud_vertex), NULL, GL_STREAM_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(hud_vertex), (void *)0);
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(hud_vertex), (void *)(2 * sizeof(float)));
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(hud_vertex), (void *)(4 * sizeof(float)));
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    r->font_tex = ok ? r_hud_font() : 0;

    /* procedural textures and the tone curve */
    uint8_t *px = malloc((size_t)R_TEX_SIZE * R_TEX_SIZE * 4);
    float *lut = malloc((size_t)r->lut_size * sizeof *lut);
    if (!px || !lut || !r->font_tex || !ok) {
        free(px);
        free(lut);
        rs_fail(err, R_ERR_NOMEM, "out of memory");
        r_game_destroy(r);
        return NULL;
    }
    r_tex_normal_map(px, R_TEX_SIZE);
    r->normal_tex = r_tex2d(GL_RGBA8, R_TEX_SIZE, R_TEX_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px, GL_LINEAR_MIPMAP_LINEAR, GL_REPEAT);
    gl.GenerateMipmap(GL_TEXTURE_2D);
    r_tex_spec_map(px, R_TEX_SIZE);
    r->spec_tex = r_tex2d(GL_RGBA8, R_TEX_SIZE, R_TEX_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px, GL_LINEAR_MIPMAP_LINEAR, GL_REPEAT);
    gl.GenerateMipmap(GL_TEXTURE_2D);
    r_tex_flare(px, R_FLARE_SIZE);
    r->flare_tex = r_tex2d(GL_RGBA8, R_FLARE_SIZE, R_FLARE_SIZE, GL_RGBA, GL_UNSIGNED_BYTE, px, GL_LINEAR, GL_CLAMP_TO_EDGE);
    free(px);
    r_tone_lut(lut, r->lut_size, 2.2); /* rebuilt when the stage's gamma differs */
    r->lut_gamma = 2.2f;
    gl.GenTextures(1, &r->lut_tex);
    gl.BindTexture(GL_TEXTURE_1D, r->lut_tex);
    gl.TexImage1D(GL_TEXTURE_1D, 0, GL_R32F, r->lut_size, 0, GL_RED, GL_FLOAT, lut);
    gl.TexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl.TexParameteri(GL_TEXTURE_1D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    gl.BindTexture(GL_TEXTURE_1D, 0);
    free(lut);

    /* light-space targets */
    gl.GenTextures(1, &r->shadow_tex);
    gl.BindTexture(GL_TEXTURE_2D, r->shadow_tex);
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, r->shadow_size, r->shadow_size, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR); /* 2x2 PCF */
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float one[4] = {1, 1, 1, 1}, zero[4] = {0, 0, 0, 0};
    gl.TexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, one);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    gl.GenFramebuffers(1, &r->shadow_fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->shadow_fbo);
    gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, r->shadow_tex, 0);
    GLenum none = GL_NONE;
    gl.DrawBuffers(1, &none);
    gl.ReadBuffer(GL_NONE);
    GLuint sil[2];
    for (int t = 0; t < 2; t++) {
        gl.GenTextures(1, &sil[t]);
        gl.BindTexture(GL_TEXTURE_2D, sil[t]);
        for (int k = 0; k < SIL_LEVELS; k++)
            gl.TexImage2D(GL_TEXTURE_2D, k, GL_R8, r->sil_size >> k, r->sil_size >> k, 0, GL_RED, GL_UNSIGNED_BYTE, NULL);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, SIL_LEVELS - 1);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR); /* trilinear */
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
        gl.TexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, zero);
    }
    r->sil_tex = sil[0], r->sil_tmp = sil[1];
    for (int k = 0; k < SIL_LEVELS; k++) {
        r->sil_fbo[k] = r_fbo_for(r->sil_tex, k, 0);
        r->sil_tmp_fbo[k] = r_fbo_for(r->sil_tmp, k, 0);
    }
    if (r->shadow_size == r->sil_size && !r->opts.light_apart) { /* one draw of the fighters makes both (r_shadow.c) */
        r->shadow_sil_fbo = r_fbo_for(r->sil_tex, 0, 0);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, r->shadow_tex, 0);
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    RGL_CHECK("r_game_create");
    return r;
}

void r_game_destroy(r_game *r)
{
    if (!r)
        return;
    for (int i = 0; i < r_fx_nmodules; i++)
        if (r_fx_modules[i]->destroy)
            r_fx_modules[i]->destroy(r);
    free_look(r);
    free_targets(r);
    free(r->bloom_buf);
    free(r->sil_buf);
    free(r->mask_buf);
    r_graph_release(&r->graph);
    for (int lod = 0; lod < R_FIGHTER_LODS; lod++)
        r_free_mesh(&r->fighter_lod[lod].vao, &r->fighter_lod[lod].vbo, &r->fighter_lod[lod].ibo);
    r_free_mesh(&r->lens_vao, &r->lens_vbo, &r->lens_ibo);
    gl.DeleteVertexArrays(1, &r->hud_vao);
    gl.DeleteVertexArrays(1, &r->empty_vao);
    gl.DeleteBuffers(1, &r->hud_vbo);
    GLuint tex[] = {r->font_tex, r->normal_tex, r->spec_tex, r->flare_tex, r->lut_tex, r->shadow_tex, r->sil_tex, r->sil_tmp};
    gl.DeleteTextures((GLsizei)(sizeof tex / sizeof tex[0]), tex);
    gl.DeleteFramebuffers(1, &r->shadow_fbo);
    gl.DeleteFramebuffers(1, &r->shadow_sil_fbo);
    gl.DeleteFramebuffers(SIL_LEVELS, r->sil_fbo);
    gl.DeleteFramebuffers(SIL_LEVELS, r->sil_tmp_fbo);
    for (int i = 0; i < P_COUNT; i++)
        gl.DeleteProgram(r->prog[i]);
    free(r->hud);
    free(r);
}

/* ---- the frame ---- */
/* a known state whatever the caller left: every pass sets what it needs on top */
static void known_state(void)
{
    gl.Disable(GL_SCISSOR_TEST);
    gl.Disable(GL_BLEND);
    gl.BlendEquation(GL_FUNC_ADD);
    gl.Disable(GL_STENCIL_TEST);
    gl.Disable(GL_POLYGON_OFFSET_FILL);
    gl.Disable(GL_CULL_FACE);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl.DepthMask(GL_TRUE);
}

/* What r_game_draw leaves bound. */
static void leave_state(GLint out)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)out);
    gl.BindVertexArray(0);
    gl.UseProgram(0);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.DepthMask(GL_TRUE);
    gl.Enable(GL_DEPTH_TEST);
}

static bool draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h, r_graph_mask skip,
                 rs_err *err);

int64_t r_game_history(r_game *r, int game_stage, rs_err *err)
{
    if (!r_game_prepare(r, game_stage, err))
        return -2;
    int64_t h = r_fx_history(r);
    return h == R_FX_FROM_START ? R_GAME_FROM_START : h;
}

void r_game_restart(r_game *r)
{
    r->have_last = false;
}

bool r_game_advance(r_game *r, const g_state *prev, const g_state *cur, int w, int h, uint64_t ahead, bool *drew,
                    rs_err *err)
{
    rs_err skipped = {0}; /* draw() meets the same failure again and reports it */
    if (drew)
        *drew = false;
    bool by_drawing = w <= 0 || h <= 0 || !r_game_prepare(r, cur->stage, &skipped) ||
                      (r->ring_stage != cur->stage && !build_ring(r, cur->stage, &skipped)) || r_fx_needs_frame(r, ahead);
    if (by_drawing) {
        if (drew)
            *drew = true;
        return draw(r, prev, cur, 1.0f, w, h, r->history_skip, err); /* which reports the error, or draws */
    }
    GLint out = 0;
    gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &out);
    known_state();
    frame *f = &r->f;
    memset(f, 0, sizeof *f);
    int sw, sh;
    r_scene_size(r_scene_pct(&r->opts.q, r->stage.standard_scene_pct), w, h, &sw, &sh);
    f->prev = prev, f->cur = cur, f->alpha = 1.0f, f->w = sw, f->h = sh, f->out_w = w, f->out_h = h, f->out_fbo = out;
    r_frame_setup(r, f); /* steps and reset, as a drawn frame counts them */
    r_fx_advance(r);
    leave_state(out);
    RGL_CHECK("r_game_advance");
    return true;
}

bool r_game_draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h, rs_err *err)
{
    return draw(r, prev, cur, alpha, w, h, 0, err);
}

/* The fighter mesh for a frame drawn at h rows: the coarse one below
 * R_FIGHTER_COARSE_ROWS, where its facets are under a pixel (docs/renderer.md,
 * "HDR, materials, mask"), unless the options ask for the fine one. */
static void select_fighter_mesh(r_game *r, int h)
{
    r->fighter = &r->fighter_lod[h < R_FIGHTER_COARSE_ROWS && !r->opts.fine_mesh ? R_FIGHTER_COARSE : R_FIGHTER_FINE];
}

static bool draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h, r_graph_mask skip,
                 rs_err *err)
{
    GLint out = 0;
    gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &out);
    bool ok = w > 0 && h > 0;
    if (!ok)
        rs_fail(err, R_ERR_SIZE, "cannot draw a %dx%d frame", w, h);
    int sw = 0, sh = 0;
    if (ok && (ok = r_game_prepare(r, cur->stage, err))) /* the stage's scene size (r_quality.stage_scene) */
        r_scene_size(r_scene_pct(&r->opts.q, r->stage.standard_scene_pct), w, h, &sw, &sh);
    if (!ok || !make_targets(r, sw, sh, w, h, err)) {
        gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)out);
        if (w > 0 && h > 0) {
            gl.Viewport(0, 0, w, h);
            gl.ClearColor(0, 0, 0, 1);
            gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        }
        return false;
    }
    if (r->ring_stage != cur->stage && !build_ring(r, cur->stage, err))
        return false;
    r_update_lut(r);
    known_state();
    frame *f = &r->f;
    memset(f, 0, sizeof *f);
    f->prev = prev, f->cur = cur, f->alpha = alpha, f->w = sw, f->h = sh, f->out_w = w, f->out_h = h, f->out_fbo = out;
    f->depth_only = skip != 0; /* only r_game_advance skips: a warm-up frame */
    select_fighter_mesh(r, sh);
    r_frame_setup(r, f);
    r->mask_final = 0;
    r_graph_run_skip(&r->graph, r, skip);
    leave_state(out);
    RGL_CHECK("r_game_draw");
    return true;
}

int r_game_ring_stage(const r_game *r)
{
    return r->ring_stage;
}

r_graph *r_game_graph(r_game *r)
{
    return &r->graph;
}

static void print_frame(void *user, uint64_t frame_no, r_graph_mask ran_mask, const double *gpu, const double *cpu)
{
    r_game *r = user;
    if (!r->per_frame || !r->passes_out)
        return;
    fprintf(r->passes_out, "frame %llu:", (unsigned long long)frame_no);
    for (int i = 0; i < r->graph.n; i++)
        if (ran_mask & ((r_graph_mask)1 << i))
            fprintf(r->passes_out, " %s %.3f", r->graph.pass[i].name, gpu ? gpu[i] : cpu[i]);
    fprintf(r->passes_out, " ms%s; skipped:", gpu ? "" : " (cpu)");
    int skipped = 0;
    for (int i = 0; i < r->graph.n; i++)
        if (!(ran_mask & ((r_graph_mask)1 << i)))
            fprintf(r->passes_out, " %s", r->graph.pass[i].name), skipped++;
    fprintf(r->passes_out, "%s\n", skipped ? "" : " none");
}

void r_game_passes(r_game *r, bool per_frame, FILE *out)
{
    r->per_frame = per_frame;
    r->passes_out = out;
    r_graph_timing(&r->graph, print_frame, r);
}

void r_game_report(r_game *r, FILE *out)
{
    r_graph_flush(&r->graph);
    char scene[48] = ""; /* the scene drawn smaller (r_quality.scene_pct, the stage's size) */
    if (r->tw != r->tow || r->th != r->toh)
        snprintf(scene, sizeof scene, ", the scene at %dx%d", r->tw, r->th);
    fprintf(out, "passes (stage %s, %dx%d%s, %llu frames; gpu: %s%s):\n", r->have_stage ? r->stage.name : "-", r->tow, r->toh,
            scene, (unsigned long long)r->graph.frame, r->graph.gpu_timer ? "GL_TIMESTAMP queries" : "not available, cpu only",
            r->graph.serial ? "; software renderer: glFinish after each pass, cpu ms = wall time" : "");
    r_graph_report(&r->graph, out);
}

bool r_game_set_cpu_paths(r_game *r, bool cpu)
{
    bool was = r->cpu_paths;
    r->cpu_paths = cpu;
    return was;
}

bool r_game_read_buffer(r_game *r, const char *name, float *out, int *w, int *h)
{
    GLuint tex = 0;
    int tw = r->tw, th = r->th, level = 0;
    if (!strcmp(name, "hdr"))
        tex = r->hdr_tex;
    else if (!strcmp(name, "bloom"))
        tex = r->glow_tex, tw = r->b4_w, th = BLOOM_ROWS;
    else if (!strcmp(name, "mask"))
        tex = r->mask_tex[r->mask_final], tw = r->mask_w, th = r->mask_h;
    else if (!strncmp(name, "silhouette", 10) && (!name[10] || (name[10] >= '1' && name[10] < '0' + SIL_LEVELS && !name[11]))) {
        level = name[10] ? name[10] - '0' : 0; /* "silhouette2": blurred level 2 */
        tex = r->sil_tex, tw = r->sil_size >> level, th = r->sil_size >> level;
    }
    GLenum fmt = GL_RGBA;
    if (!strcmp(name, "depth")) /* one float per pixel, window depth */
        tex = r->depth_tex, fmt = GL_DEPTH_COMPONENT;
    if (!strcmp(name, "shadow")) /* the SSFSM light depth map, one float per texel */
        tex = r->shadow_tex, fmt = GL_DEPTH_COMPONENT, tw = th = r->shadow_size;
    if (!tex)
        return false;
    if (w)
        *w = tw;
    if (h)
        *h = th;
    if (out) {
        gl.BindTexture(GL_TEXTURE_2D, tex);
        gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
        gl.GetTexImage(GL_TEXTURE_2D, level, fmt, GL_FLOAT, out);
        gl.BindTexture(GL_TEXTURE_2D, 0);
    }
    return true;
}
