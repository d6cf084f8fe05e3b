#include "r_game.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../gl/rgl.h"
#include "r_font.h"
#include "r_ibl.h"
#include "r_mesh.h"
#include "r_shader.h"
#include "r_tex.h"
#include "r_tone.h"
#include "r_local.h"

const float r_fighter_color[2][3] = {{0.80f, 0.16f, 0.12f}, {0.14f, 0.32f, 0.85f}};
static const float skin[3] = {0.85f, 0.66f, 0.52f};

static const char *const res_names[] = {"env",    "shadow map",  "silhouette",  "depth",       "shadow mask",
                                        "hdr",    "bloom",       "sun visibility", "output",   "flare",
                                        "fog map", "water",      "water reflection", "under water", "snow",
                                        "snow light", "lspsm map"};

/* ---- helpers ---- */

GLint r_loc(GLuint p, const char *name)
{
    return gl.GetUniformLocation(p, name);
}

void r_upload_mesh(const r_mesh_data *m, GLuint *vao, GLuint *vbo, GLuint *ibo)
{
    gl.GenVertexArrays(1, vao);
    gl.BindVertexArray(*vao);
    gl.GenBuffers(1, vbo);
    gl.BindBuffer(GL_ARRAY_BUFFER, *vbo);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)(m->nv * sizeof(r_vertex)), m->v, GL_STATIC_DRAW);
    gl.GenBuffers(1, ibo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, *ibo);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(m->ni * sizeof(unsigned)), m->idx, GL_STATIC_DRAW);
    const GLsizei st = sizeof(r_vertex);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, pos));
    gl.EnableVertexAttribArray(1);
    gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, normal));
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, tangent));
    gl.EnableVertexAttribArray(3);
    gl.VertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, uv));
    gl.EnableVertexAttribArray(4);
    gl.VertexAttribPointer(4, 1, GL_FLOAT, GL_FALSE, st, (void *)offsetof(r_vertex, bone));
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
}

void r_free_mesh(GLuint *vao, GLuint *vbo, GLuint *ibo)
{
    if (*vao)
        gl.DeleteVertexArrays(1, vao);
    if (*vbo)
        gl.DeleteBuffers(1, vbo);
    if (*ibo)
        gl.DeleteBuffers(1, ibo);
    *vao = *vbo = *ibo = 0;
}

GLuint r_tex2d(GLenum ifmt, int w, int h, GLenum fmt, GLenum type, const void *px, GLenum filter, GLenum wrap)
{
    GLuint t;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl.TexImage2D(GL_TEXTURE_2D, 0, (GLint)ifmt, w, h, 0, fmt, type, px);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, (GLint)filter);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter == GL_LINEAR_MIPMAP_LINEAR ? GL_LINEAR : (GLint)filter);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, (GLint)wrap);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, (GLint)wrap);
    return t;
}

GLuint r_fbo_for(GLuint color, int level, GLuint depth)
{
    GLuint f;
    gl.GenFramebuffers(1, &f);
    gl.BindFramebuffer(GL_FRAMEBUFFER, f);
    if (color)
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color, level);
    else {
        GLenum none = GL_NONE;
        gl.DrawBuffers(1, &none);
        gl.ReadBuffer(GL_NONE);
    }
    if (depth)
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
    return f;
}

static GLuint cube_tex(int n, float *const face[6], int levels)
{
    GLuint t;
    gl.GenTextures(1, &t);
    gl.BindTexture(GL_TEXTURE_CUBE_MAP, t);
    for (int f = 0; f < 6; f++)
        gl.TexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + (GLenum)f, 0, GL_RGB16F, n, n, 0, GL_RGB, GL_FLOAT, face[f]);
    gl.TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, levels > 1 ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    gl.TexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    if (levels > 1)
        gl.GenerateMipmap(GL_TEXTURE_CUBE_MAP);
    gl.BindTexture(GL_TEXTURE_CUBE_MAP, 0);
    return t;
}

void r_bind_tex(GLuint p, const char *name, int unit, GLenum target, GLuint t)
{
    gl.ActiveTexture(GL_TEXTURE0 + (GLenum)unit);
    gl.BindTexture(target, t);
    gl.Uniform1i(r_loc(p, name), unit);
}

void r_bind_ibl(r_game *r, GLuint p)
{
    static const char *names[R_IBL_MAPS][2] = {{"u_diffuse_off", "u_diffuse_on"},
                                               {"u_spec16_off", "u_spec16_on"},
                                               {"u_spec128_off", "u_spec128_on"}};
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 2; k++)
            r_bind_tex(p, names[m][k], 8 + m * 2 + k, GL_TEXTURE_CUBE_MAP, r->ibl_tex[m][k]);
}

void r_fullscreen(r_game *r)
{
    gl.BindVertexArray(r->empty_vao);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

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
        return rs_fail(err, 1, "out of memory for the ring mesh");
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
    r->hdr_format = r->opts.hdr_format >= 0 ? (r_hdr_format)r->opts.hdr_format : st->hdr_format;
    if (r->opts.mask && r->hdr_format != R_HDR_RGBA16F)
        return rs_fail(err, 1, "--mask needs an alpha channel: the r11g11b10f HDR format has none (use rgba16f)");
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
    if (!r->opts.quiet && !ibl.from_cache && ibl.ms > 500)
        fprintf(stderr, "ringside: %s: prefiltered the environment in %.1f s (cached for next time)\n", st->name,
                ibl.ms / 1000);
    for (int m = 0; m < R_IBL_MAPS; m++)
        for (int k = 0; k < 2; k++)
            r->ibl_tex[m][k] = cube_tex(ibl.size[m], ibl.map[m][k], 1);
    memcpy(r->key_dir, ibl.key_dir, sizeof r->key_dir);
    r_ibl_free(&ibl);
    r_env sky = {0};
    if (!r_env_build(st, SKY_SIZE, &sky, err))
        return false;
    r->sky_tex = cube_tex(sky.size, sky.face, 1);
    r_env_free(&sky);
    /* the ring has the size of the match's stage (r_game_draw), which a
     * --stage-file look for another game stage does not change */
    if (!build_ring(r, game_stage >= 0 ? game_stage : st->game_index, err))
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
                    r->b4_tex[1], r->b8_tex[0], r->b8_tex[1], r->sunvis_tex, r->fl_tex};
    GLuint fbo[] = {r->hdr_fbo, r->depth_fbo, r->mask_fbo[0], r->mask_fbo[1], r->b2_fbo, r->b4_fbo[0],
                    r->b4_fbo[1], r->b8_fbo[0], r->b8_fbo[1], r->sunvis_fbo, r->fl_fbo};
    for (size_t i = 0; i < sizeof tex / sizeof tex[0]; i++)
        if (tex[i])
            gl.DeleteTextures(1, &tex[i]);
    for (size_t i = 0; i < sizeof fbo / sizeof fbo[0]; i++)
        if (fbo[i])
            gl.DeleteFramebuffers(1, &fbo[i]);
    r->hdr_tex = r->depth_tex = r->b2_tex = r->sunvis_tex = r->fl_tex = 0;
    r->hdr_fbo = r->depth_fbo = r->b2_fbo = r->sunvis_fbo = r->fl_fbo = 0;
    memset(r->mask_tex, 0, sizeof r->mask_tex), memset(r->mask_fbo, 0, sizeof r->mask_fbo);
    memset(r->b4_tex, 0, sizeof r->b4_tex), memset(r->b4_fbo, 0, sizeof r->b4_fbo);
    memset(r->b8_tex, 0, sizeof r->b8_tex), memset(r->b8_fbo, 0, sizeof r->b8_fbo);
    r->tw = r->th = 0;
}

int r_half(int v, int k)
{
    v >>= k;
    return v > 0 ? v : 1;
}

static bool make_targets(r_game *r, int w, int h, rs_err *err)
{
    if (r->tw == w && r->th == h && r->tw > 0 && r->tfmt == r->hdr_format)
        return true;
    free_targets(r);
    GLenum hdr_fmt = r->hdr_format == R_HDR_R11G11B10F ? GL_R11F_G11F_B10F : GL_RGBA16F;
    r->hdr_tex = r_tex2d(hdr_fmt, w, h, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    r->depth_tex = r_tex2d(GL_DEPTH24_STENCIL8, w, h, GL_DEPTH_STENCIL, GL_UNSIGNED_INT_24_8, NULL, GL_NEAREST,
                         GL_CLAMP_TO_EDGE);
    r->hdr_fbo = r_fbo_for(r->hdr_tex, 0, r->depth_tex);
    GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    r->depth_fbo = r_fbo_for(0, 0, r->depth_tex);
    for (int i = 0; i < 2; i++) {
        r->mask_tex[i] = r_tex2d(GL_R8, w, h, GL_RED, GL_UNSIGNED_BYTE, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        r->mask_fbo[i] = r_fbo_for(r->mask_tex[i], 0, 0);
        r->b4_tex[i] = r_tex2d(GL_RGBA16F, r_half(w, 2), r_half(h, 2), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        r->b4_fbo[i] = r_fbo_for(r->b4_tex[i], 0, 0);
        r->b8_tex[i] = r_tex2d(GL_RGBA16F, r_half(w, 3), r_half(h, 3), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
        r->b8_fbo[i] = r_fbo_for(r->b8_tex[i], 0, 0);
    }
    r->b2_tex = r_tex2d(GL_RGBA16F, r_half(w, 1), r_half(h, 1), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    r->b2_fbo = r_fbo_for(r->b2_tex, 0, 0);
    r->sunvis_tex = r_tex2d(GL_R16F, 1, 1, GL_RED, GL_FLOAT, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
    r->sunvis_fbo = r_fbo_for(r->sunvis_tex, 0, 0);
    r->fl_tex = r_tex2d(GL_RGBA16F, r_half(w, 2), r_half(h, 2), GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    r->fl_fbo = r_fbo_for(r->fl_tex, 0, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    if (st != GL_FRAMEBUFFER_COMPLETE) {
        free_targets(r);
        return rs_fail(err, 1, "%dx%d HDR target (%s) incomplete (%s)", w, h,
                       hdr_fmt == GL_RGBA16F ? "rgba16f" : "r11g11b10f", rgl_enum_name(st));
    }
    r->tw = w, r->th = h, r->tfmt = r->hdr_format;
    RGL_CHECK("make_targets");
    return true;
}

/* ---- per-frame set-up ---- */

static void bone_matrices(const g_state *prev, const g_state *cur, int i, float alpha, float out[16][16])
{
    g_capsule a[G_BONES], b[G_BONES];
    g_fighter_capsules(cur, i, b);
    if (prev && prev->tick + 1 == cur->tick)
        g_fighter_capsules(prev, i, a);
    else
        memcpy(a, b, sizeof a);
    float facing = (float)cur->f[i].facing;
    for (int k = 0; k < G_BONES; k++) {
        float ax = fx_to_float(a[k].ax) + (fx_to_float(b[k].ax) - fx_to_float(a[k].ax)) * alpha;
        float ay = fx_to_float(a[k].ay) + (fx_to_float(b[k].ay) - fx_to_float(a[k].ay)) * alpha;
        float bx = fx_to_float(a[k].bx) + (fx_to_float(b[k].bx) - fx_to_float(a[k].bx)) * alpha;
        float by = fx_to_float(a[k].by) + (fx_to_float(b[k].by) - fx_to_float(a[k].by)) * alpha;
        r_vec3 d = r_norm(r_v3(bx - ax, by - ay, 0));
        if (d.x == 0 && d.y == 0)
            d = r_v3(1, 0, 0);
        float *m = out[k];
        memset(m, 0, 16 * sizeof(float));
        m[0] = d.x, m[1] = d.y;   /* x axis: along the bone */
        m[4] = -d.y, m[5] = d.x;  /* y axis */
        m[10] = 1;                /* z axis */
        m[12] = ax, m[13] = ay, m[14] = fx_to_float(b[k].z) * facing;
        m[15] = 1;
    }
}

void r_game_camera_parts(const g_state *st, int w, int h, r_mat4 *view, r_mat4 *proj, r_vec3 *eye_out)
{
    float x0 = fx_to_float(st->f[0].x), x1 = fx_to_float(st->f[1].x);
    float mid = (x0 + x1) / 2, gap = x1 > x0 ? x1 - x0 : x0 - x1;
    float dist = 4.2f + gap * 0.9f;
    r_vec3 at = r_v3(mid, 1.0f, 0), eye = r_v3(mid, 1.7f, dist);
    if (eye_out)
        *eye_out = eye;
    *proj = r_perspective(0.75f, (float)w / (float)h, 0.1f, 200.0f);
    *view = r_look_at(eye, at, r_v3(0, 1, 0));
}

r_mat4 r_game_camera(const g_state *st, int w, int h, r_vec3 *eye_out)
{
    r_mat4 view, proj;
    r_game_camera_parts(st, w, h, &view, &proj, eye_out);
    return r_mul(proj, view);
}

/* The screen rectangle the fighters can cover: the world box round their
 * bones (each bone's origin +-0.4 m, which holds the longest limb's far
 * end too) projected, plus MASK_REACH pixels.  The shadow mask is 1
 * (lit) outside it, so its passes draw only inside (a scissor). */
#define MASK_REACH 8 /* grow 1 px + blur 4 px, with room to spare */
static void fighter_box(frame *f, const float lo[3], const float hi[3])
{
    float x0 = 1e9f, y0 = 1e9f, x1 = -1e9f, y1 = -1e9f;
    bool whole = false;
    for (int k = 0; k < 8 && !whole; k++) {
        r_vec3 c = r_v3(k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]);
        float x, y;
        if (!r_project(f->vp, c, f->w, f->h, &x, &y)) {
            whole = true; /* a corner behind the camera: no safe bound */
            break;
        }
        x0 = fminf(x0, x), y0 = fminf(y0, y), x1 = fmaxf(x1, x), y1 = fmaxf(y1, y);
    }
    if (whole || !(x0 <= x1) || !(y0 <= y1)) {
        f->fig_box[0] = f->fig_box[1] = 0, f->fig_box[2] = f->w, f->fig_box[3] = f->h;
        return;
    }
    float bx0 = fmaxf(floorf(x0) - MASK_REACH, 0), by0 = fmaxf(floorf(y0) - MASK_REACH, 0);
    float bx1 = fminf(ceilf(x1) + MASK_REACH, (float)f->w), by1 = fminf(ceilf(y1) + MASK_REACH, (float)f->h);
    f->fig_box[0] = (int)bx0, f->fig_box[1] = (int)by0;
    f->fig_box[2] = bx1 > bx0 ? (int)(bx1 - bx0) : 0, f->fig_box[3] = by1 > by0 ? (int)(by1 - by0) : 0;
}

/* The key light's orthographic projection, fitted round both fighters. */
static void light_setup(r_game *r, frame *f)
{
    /* the direction the IBL's key-light area is centred on (the sun, or
     * the brightest light of the environment): shadows take away exactly
     * the light the key-on/key-off maps differ by */
    const float *key = r->key_dir;
    float len = sqrtf(key[0] * key[0] + key[1] * key[1] + key[2] * key[2]);
    r_vec3 L = len > 1e-6f && isfinite(len) ? r_v3(key[0] / len, key[1] / len, key[2] / len) : r_v3(0, 1, 0);
    if (L.y < 0.05f) /* a key at or below the horizon: lift it so the shadow still lands */
        L = r_norm(r_v3(L.x, 0.05f, L.z));
    f->light_dir = L;
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    for (int i = 0; i < 2; i++)
        for (int k = 0; k < G_BONES; k++) {
            const float *m = f->bones[i][k];
            float p[3] = {m[12], m[13], m[14]};
            for (int a = 0; a < 3; a++) {
                lo[a] = fminf(lo[a], p[a] - 0.4f);
                hi[a] = fmaxf(hi[a], p[a] + 0.4f);
            }
        }
    fighter_box(f, lo, hi);
    r_vec3 c = r_v3((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2);
    float rad = 0.5f * sqrtf((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                             (hi[2] - lo[2]) * (hi[2] - lo[2]));
    r_vec3 up = fabsf(L.y) > 0.95f ? r_v3(0, 0, 1) : r_v3(0, 1, 0);
    r_vec3 from = r_v3(c.x + L.x * 20, c.y + L.y * 20, c.z + L.z * 20);
    /* depth range reaches the far ground so the silhouette projects onto it */
    f->light = r_mul(r_ortho(-rad, rad, -rad, rad, 20 - rad - 1, 20 + 40), r_look_at(from, c, up));
}

static void world_capsules(const g_state *st, int i, r_fx_capsule out[G_BONES])
{
    g_capsule c[G_BONES];
    g_fighter_capsules(st, i, c);
    float facing = (float)st->f[i].facing;
    for (int k = 0; k < G_BONES; k++) {
        float z = fx_to_float(c[k].z) * facing;
        out[k] = (r_fx_capsule){{fx_to_float(c[k].ax), fx_to_float(c[k].ay), z},
                                {fx_to_float(c[k].bx), fx_to_float(c[k].by), z},
                                fx_to_float(c[k].r)};
    }
}

/* What the stage effects see (r_fx.h): whole ticks, and how many passed. */
static void fx_setup(r_game *r, frame *f)
{
    const g_state *cur = f->cur, *prev = f->prev && f->prev->tick + 1 == cur->tick ? f->prev : cur;
    for (int i = 0; i < 2; i++) {
        world_capsules(cur, i, f->caps[i]);
        world_capsules(prev, i, f->caps_prev[i]);
        bone_matrices(NULL, prev, i, 1.0f, f->bones_prev[i]);
        bone_matrices(NULL, cur, i, 1.0f, f->bones_tick[i]);
    }
    r_mat4 proj;
    r_game_camera_parts(prev, f->w, f->h, &f->view_prev, &proj, NULL);
    r_game_camera_parts(cur, f->w, f->h, &f->view, &f->proj, NULL);
    uint64_t t = cur->tick;
    if (!r->have_last || t < r->last_tick || t - r->last_tick > R_FX_MAX_GAP)
        f->reset = true, f->steps = 1;
    else
        f->steps = (int)(t - r->last_tick);
    r->have_last = true;
    r->last_tick = t;
}

static void frame_setup(r_game *r, frame *f)
{
    const g_state *cur = f->cur;
    f->vp = r_game_camera(cur, f->w, f->h, &f->eye);
    f->inv_vp = r_invert(f->vp);
    for (int i = 0; i < 2; i++) {
        bone_matrices(f->prev, cur, i, f->alpha, f->bones[i]);
        for (int k = 0; k < G_BONES; k++) {
            bool is_skin = k == G_HEAD || k == G_NECK || k == G_L_FOREARM || k == G_R_FOREARM;
            memcpy(f->colors[i][k], is_skin ? skin : r_fighter_color[i], 3 * sizeof(float));
            f->colors[i][k][3] = is_skin ? 0.25f : 1.0f;
        }
        g_capsule caps[G_BONES];
        g_fighter_capsules(cur, i, caps);
        fx wx, wy;
        g_skel_waist(caps, &wx, &wy);
        f->waist[i] = r_v3(fx_to_float(wx), fx_to_float(wy), 0);
    }
    light_setup(r, f);
    fx_setup(r, f);
    /* lightning and the KO moment drop saturation for a flash */
    float flash = cur->flash > 0 ? (float)cur->flash / 8.0f : 0.0f;
    if (cur->phase == G_PHASE_ROUND_END && cur->round_result == G_RES_KO && cur->phase_ticks < 10)
        flash = fmaxf(flash, 1.0f - (float)cur->phase_ticks / 10.0f);
    f->flash = flash > 1 ? 1 : flash;
    f->saturation = r->stage.saturation * (1 - f->flash);
    f->exposure = r->stage.exposure;
    /* is the sun on screen? */
    f->sun_on_screen = false;
    if (r->stage.sun && r->stage.flare && r->stage.sun_intensity > 0) {
        r_vec3 s = r_v3(f->eye.x + r->stage.sun_dir[0] * 150, f->eye.y + r->stage.sun_dir[1] * 150,
                        f->eye.z + r->stage.sun_dir[2] * 150);
        float x, y;
        if (r_project(f->vp, s, f->w, f->h, &x, &y) && x >= 0 && y >= 0 && x < f->w && y < f->h) {
            f->sun_on_screen = true;
            f->sun_px[0] = x, f->sun_px[1] = y;
        }
    }
}

/* ---- passes ---- */

bool r_ran(const frame *f, r_game *r, const char *name)
{
    (void)f;
    int i = r_graph_find(&r->graph, name);
    return i >= 0 && (r->graph.ran_now & ((r_graph_mask)1 << i));
}

static bool need_always(void *u)
{
    (void)u;
    return true;
}

static bool need_shadows(void *u)
{
    r_game *r = u;
    return r->stage.shadows;
}

static bool need_bloom(void *u)
{
    r_game *r = u;
    return r->stage.bloom > 0;
}

static bool need_sun(void *u)
{
    r_game *r = u;
    return r->f.sun_on_screen;
}

static bool need_hud(void *u)
{
    r_game *r = u;
    return !r->opts.no_hud && !r->opts.mask;
}

void r_draw_fighters(r_game *r, GLuint p)
{
    gl.BindVertexArray(r->fighter_vao);
    for (int i = 0; i < 2; i++) {
        gl.UniformMatrix4fv(r_loc(p, "u_bones"), G_BONES, GL_FALSE, &r->f.bones[i][0][0]);
        gl.Uniform4fv(r_loc(p, "u_bone_color"), G_BONES, &r->f.colors[i][0][0]);
        gl.Uniform1i(r_loc(p, "u_fighter"), i);
        gl.DrawElements(GL_TRIANGLES, r->fighter_count, GL_UNSIGNED_INT, NULL);
    }
}

static void light_view_draw(r_game *r, GLuint p)
{
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, r->f.light.m);
    r_draw_fighters(r, p);
}

static void run_shadow_map(void *u)
{
    r_game *r = u;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->shadow_fbo);
    gl.Viewport(0, 0, SHADOW_SIZE, SHADOW_SIZE);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.Clear(GL_DEPTH_BUFFER_BIT);
    gl.Enable(GL_POLYGON_OFFSET_FILL);
    gl.PolygonOffset(2.0f, 4.0f);
    gl.Disable(GL_CULL_FACE);
    light_view_draw(r, r->prog[P_DEPTH]);
    gl.Disable(GL_POLYGON_OFFSET_FILL);
}

static void run_silhouette(void *u)
{
    r_game *r = u;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->sil_fbo[0]);
    gl.Viewport(0, 0, SIL_SIZE, SIL_SIZE);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.ClearColor(0, 0, 0, 0);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    light_view_draw(r, r->prog[P_SIL]);
}

void r_blur_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy)
{
    GLuint p = r->prog[P_BLUR];
    gl.BindFramebuffer(GL_FRAMEBUFFER, dst_fbo);
    gl.Viewport(0, 0, w, h);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, src_tex);
    gl.Uniform2f(r_loc(p, "u_dir"), dx / (float)w, dy / (float)h);
    gl.Uniform1f(r_loc(p, "u_lod"), (float)lod);
    r_fullscreen(r);
}

void r_down_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float threshold, float scale)
{
    GLuint p = r->prog[P_DOWN];
    gl.BindFramebuffer(GL_FRAMEBUFFER, dst_fbo);
    gl.Viewport(0, 0, w, h);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, src_tex);
    gl.Uniform1f(r_loc(p, "u_lod"), (float)lod);
    gl.Uniform1f(r_loc(p, "u_threshold"), threshold);
    gl.Uniform1f(r_loc(p, "u_scale"), scale);
    r_fullscreen(r);
}

/* Blurred mipmap projection shadow: level k = blur(downsample(level k-1)),
 * for 4 levels.  Each draw reads one level while writing another (or the
 * same level of the other texture); BASE/MAX_LEVEL restrict what the
 * sampler can see to the level read, so there is no feedback loop, and
 * the shaders then address it as level 0. */
static void restrict_level(GLuint tex, int k)
{
    gl.BindTexture(GL_TEXTURE_2D, tex);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, k);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, k);
}

static void run_silhouette_mips(void *u)
{
    r_game *r = u;
    gl.Disable(GL_DEPTH_TEST);
    for (int k = 1; k < SIL_LEVELS; k++) {
        int n = SIL_SIZE >> k;
        restrict_level(r->sil_tex, k - 1);
        r_down_into(r, r->sil_fbo[k], r->sil_tex, 0, n, n, -1, 1);
        restrict_level(r->sil_tex, k);
        r_blur_into(r, r->sil_tmp_fbo[k], r->sil_tex, 0, n, n, 1, 0);
        restrict_level(r->sil_tmp, k);
        r_blur_into(r, r->sil_fbo[k], r->sil_tmp, 0, n, n, 0, 1);
    }
    gl.BindTexture(GL_TEXTURE_2D, r->sil_tex);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_BASE_LEVEL, 0);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, SIL_LEVELS - 1);
}

void r_camera_uniforms(r_game *r, GLuint p)
{
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, r->f.vp.m);
    gl.Uniform3f(r_loc(p, "u_eye"), r->f.eye.x, r->f.eye.y, r->f.eye.z);
}

/* SSFSM step 1b: the fighters' depth as the camera sees them */
static void run_z_prepass(void *u)
{
    r_game *r = u;
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->depth_fbo);
    gl.Viewport(0, 0, r->f.w, r->f.h);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.ClearDepth(1.0);
    gl.Clear(GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    r_camera_uniforms(r, r->prog[P_DEPTH]);
    r_draw_fighters(r, r->prog[P_DEPTH]);
}

/* The bound mask buffer: all 1 (lit), then draws limited to the fighters' box. */
static void mask_clear_and_scissor(r_game *r)
{
    gl.Disable(GL_SCISSOR_TEST);
    gl.ClearColor(1, 1, 1, 1);
    gl.Clear(GL_COLOR_BUFFER_BIT);
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(r->f.fig_box[0], r->f.fig_box[1], r->f.fig_box[2], r->f.fig_box[3]);
}

static void run_shadow_mask(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_MASK];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->mask_fbo[0]);
    gl.Viewport(0, 0, r->f.w, r->f.h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    mask_clear_and_scissor(r);
    gl.UseProgram(p);
    r_bind_tex(p, "u_depth", 0, GL_TEXTURE_2D, r->depth_tex);
    r_bind_tex(p, "u_shadow_map", 1, GL_TEXTURE_2D, r->shadow_tex);
    gl.UniformMatrix4fv(r_loc(p, "u_inv_view_proj"), 1, GL_FALSE, r->f.inv_vp.m);
    gl.UniformMatrix4fv(r_loc(p, "u_light_proj"), 1, GL_FALSE, r->f.light.m);
    gl.Uniform2f(r_loc(p, "u_size"), (float)r->f.w, (float)r->f.h);
    gl.Uniform1f(r_loc(p, "u_bias"), 0.0015f);
    r_fullscreen(r);
    gl.Disable(GL_SCISSOR_TEST);
}

/* SSFSM step 3: grow dark by a pixel, then blur (mask 0 -> 1 -> 0 -> 1) */
static void run_mask_filter(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_GROW];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->mask_fbo[1]);
    gl.Viewport(0, 0, r->f.w, r->f.h);
    mask_clear_and_scissor(r);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, r->mask_tex[0]);
    r_fullscreen(r);
    /* outside the box both buffers hold 1, so the blur reads the truth there */
    r_blur_into(r, r->mask_fbo[0], r->mask_tex[1], 0, r->f.w, r->f.h, 1, 0);
    r_blur_into(r, r->mask_fbo[1], r->mask_tex[0], 0, r->f.w, r->f.h, 0, 1);
    gl.Disable(GL_SCISSOR_TEST);
    r->mask_final = 1;
}

static void run_scene(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    bool shadows = r_ran(f, r, "mask_filter") && r_ran(f, r, "silhouette_mips");
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->hdr_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl.ClearColor(0, 0, 0, 0);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthMask(GL_TRUE);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.Disable(GL_BLEND);
    bool prepass = r_ran(f, r, "z_prepass");
    /* the holes pass (techniques D, steps 1-3) cleared and drew already */
    bool holes = r_ran(f, r, "holes");
    if (!holes)
        gl.Clear(GL_COLOR_BUFFER_BIT | (prepass ? 0 : GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT));

    /* fighters: over their own z-prepass depth when it ran */
    GLuint p = r->prog[P_FIGHTER];
    gl.DepthFunc(prepass ? GL_LEQUAL : GL_LESS);
    r_camera_uniforms(r, p);
    r_bind_ibl(r, p);
    r_bind_tex(p, "u_normal_map", 0, GL_TEXTURE_2D, r->normal_tex);
    r_bind_tex(p, "u_spec_map", 1, GL_TEXTURE_2D, r->spec_tex);
    r_bind_tex(p, "u_mask", 2, GL_TEXTURE_2D, r->mask_tex[r->mask_final]);
    gl.Uniform1i(r_loc(p, "u_shadows"), shadows);
    r_fx_fog_bind(r, p, 6);
    r_fx_lspsm_bind(r, p, 4);
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    /* stencil bit R_STENCIL_FIGHTER marks the fighters' pixels: copies
     * drawn later (afterimages) stay behind the models, as if drawn first */
    gl.Enable(GL_STENCIL_TEST);
    gl.StencilMask(R_STENCIL_FIGHTER);
    gl.StencilFunc(GL_ALWAYS, R_STENCIL_FIGHTER, R_STENCIL_FIGHTER);
    gl.StencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
    r_draw_fighters(r, p);
    gl.Disable(GL_STENCIL_TEST);
    gl.StencilMask(0xFF);

    /* the ring and the ground, with the projected silhouette */
    p = r->prog[P_STAGE];
    gl.DepthFunc(GL_LESS);
    r_stage_uniforms(r, p, r->stage.buildings > 0 ? 1 : 0);
    gl.BindVertexArray(r->ring_vao);
    if (!holes) {
        gl.DrawElements(GL_TRIANGLES, r->ring_count, GL_UNSIGNED_INT, NULL);
        return;
    }
    /* with holes (techniques D, steps 5 and 6): the indestructible parts,
     * then the ring top's colour only where its own depth is still there
     * (the holes pass put the craters' depth in the rest) */
    gl.DrawElements(GL_TRIANGLES, R_RING_TOP_FIRST, GL_UNSIGNED_INT, NULL);
    gl.DrawElements(GL_TRIANGLES, r->ring_count - R_RING_TOP_FIRST - 6, GL_UNSIGNED_INT,
                    (const void *)((R_RING_TOP_FIRST + 6) * sizeof(unsigned)));
    gl.DepthFunc(GL_EQUAL);
    gl.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT, (const void *)(R_RING_TOP_FIRST * sizeof(unsigned)));
    gl.DepthFunc(GL_LESS);
}

void r_begin_opaque(r_game *r)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->hdr_fbo);
    gl.Viewport(0, 0, r->f.w, r->f.h);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_TRUE);
    gl.Enable(GL_CULL_FACE);
    gl.CullFace(GL_BACK);
    gl.Disable(GL_BLEND);
}

void r_stage_uniforms(r_game *r, GLuint p, int material)
{
    frame *f = &r->f;
    r_camera_uniforms(r, p);
    r_bind_ibl(r, p);
    r_bind_tex(p, "u_silhouette", 0, GL_TEXTURE_2D, r->sil_tex);
    gl.Uniform1i(r_loc(p, "u_shadows"), r_ran(f, r, "mask_filter") && r_ran(f, r, "silhouette_mips"));
    r_fx_fog_bind(r, p, 6);
    r_fx_lspsm_bind(r, p, 4);
    gl.Uniform1i(r_loc(p, "u_material"), material);
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    gl.Uniform3fv(r_loc(p, "u_ring_color"), 1, r->stage.ring_color);
    gl.UniformMatrix4fv(r_loc(p, "u_light_proj"), 1, GL_FALSE, f->light.m);
    gl.Uniform3f(r_loc(p, "u_light_dir"), f->light_dir.x, f->light_dir.y, f->light_dir.z);
    float waist[6] = {f->waist[0].x, f->waist[0].y, f->waist[0].z, f->waist[1].x, f->waist[1].y, f->waist[1].z};
    gl.Uniform3fv(r_loc(p, "u_waist"), 2, waist);
    gl.Uniform1f(r_loc(p, "u_lod_start"), 0.6f);
    gl.Uniform1f(r_loc(p, "u_lod_scale"), 1.6f);
}

static void run_sky(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_SKY];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->hdr_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LEQUAL);
    gl.DepthMask(GL_FALSE);
    gl.Disable(GL_CULL_FACE);
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_inv_view_proj"), 1, GL_FALSE, f->inv_vp.m);
    r_bind_tex(p, "u_env", 0, GL_TEXTURE_CUBE_MAP, r->sky_tex);
    const r_stage *st = &r->stage;
    float rad = st->sun_size_deg * 0.5f * 3.14159265f / 180.0f;
    double omega = 2 * 3.14159265358979 * (1 - cos(rad)); /* the disc's solid angle */
    float L = st->sun ? (float)fmin(st->sun_intensity / omega, R_HALF_MAX) : 0.0f;
    gl.Uniform3f(r_loc(p, "u_sun_dir"), st->sun_dir[0], st->sun_dir[1], st->sun_dir[2]);
    gl.Uniform3f(r_loc(p, "u_sun_radiance"), fminf(L * st->sun_color[0], R_HALF_MAX),
                 fminf(L * st->sun_color[1], R_HALF_MAX), fminf(L * st->sun_color[2], R_HALF_MAX));
    gl.Uniform1f(r_loc(p, "u_sun_cos"), cosf(rad));
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    r_fx_fog_bind(r, p, 6);
    r_fullscreen(r);
    gl.DepthMask(GL_TRUE);
}

/* HDR alpha blending: premultiplied colour, destination alpha kept */
static void run_lens(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_LENS];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->hdr_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_FALSE);
    gl.Disable(GL_CULL_FACE);
    gl.Enable(GL_BLEND);
    gl.BlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    r_camera_uniforms(r, p);
    r_bind_ibl(r, p);
    r_fx_fog_bind(r, p, 6);
    gl.Uniform1f(r_loc(p, "u_lens_alpha"), LENS_ALPHA);
    gl.BindVertexArray(r->lens_vao);
    for (int i = 0; i < 2; i++) {
        gl.UniformMatrix4fv(r_loc(p, "u_bones"), G_BONES, GL_FALSE, &f->bones[i][0][0]);
        gl.Uniform1f(r_loc(p, "u_lens_side"), (float)f->cur->f[i].facing);
        gl.DrawElements(GL_TRIANGLES, r->lens_count, GL_UNSIGNED_INT, NULL);
    }
    gl.Disable(GL_BLEND);
    gl.DepthMask(GL_TRUE);
}

static void run_bloom_bright(void *u)
{
    r_game *r = u;
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    r_down_into(r, r->b2_fbo, r->hdr_tex, 0, r_half(r->f.w, 1), r_half(r->f.h, 1), r->stage.bloom_threshold,
              r->f.exposure);
}

static void run_bloom_blur(void *u)
{
    r_game *r = u;
    int w4 = r_half(r->f.w, 2), h4 = r_half(r->f.h, 2), w8 = r_half(r->f.w, 3), h8 = r_half(r->f.h, 3);
    r_down_into(r, r->b4_fbo[0], r->b2_tex, 0, w4, h4, -1, 1);
    r_blur_into(r, r->b4_fbo[1], r->b4_tex[0], 0, w4, h4, 1, 0);
    r_blur_into(r, r->b4_fbo[0], r->b4_tex[1], 0, w4, h4, 0, 1);
    r_down_into(r, r->b8_fbo[0], r->b4_tex[0], 0, w8, h8, -1, 1);
    r_blur_into(r, r->b8_fbo[1], r->b8_tex[0], 0, w8, h8, 1, 0);
    r_blur_into(r, r->b8_fbo[0], r->b8_tex[1], 0, w8, h8, 0, 1);
}

static void run_sun_visibility(void *u)
{
    r_game *r = u;
    GLuint p = r->prog[P_SUNVIS];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->sunvis_fbo);
    gl.Viewport(0, 0, 1, 1);
    gl.Disable(GL_DEPTH_TEST);
    gl.UseProgram(p);
    r_bind_tex(p, "u_depth", 0, GL_TEXTURE_2D, r->depth_tex);
    gl.Uniform2f(r_loc(p, "u_sun"), r->f.sun_px[0], r->f.sun_px[1]);
    gl.Uniform1f(r_loc(p, "u_radius"), r->f.h * 0.012f);
    r_fullscreen(r);
}

static void run_tonemap(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    bool bloom = r_ran(f, r, "bloom_blur"), flare = r_ran(f, r, "flare");
    GLuint p = r->prog[P_TONE + (bloom ? 1 : 0) + (flare ? 2 : 0)];
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.UseProgram(p);
    r_bind_tex(p, "u_hdr", 0, GL_TEXTURE_2D, r->hdr_tex);
    r_bind_tex(p, "u_lut", 1, GL_TEXTURE_1D, r->lut_tex);
    gl.Uniform1i(r_loc(p, "u_lut_size"), r->lut_size);
    gl.Uniform1f(r_loc(p, "u_lut_inv_power"), (float)(1.0 / r_tone_index_power(r->lut_gamma)));
    gl.Uniform1f(r_loc(p, "u_exposure"), f->exposure);
    gl.Uniform1f(r_loc(p, "u_saturation"), f->saturation);
    gl.Uniform1i(r_loc(p, "u_write_mask"), r->opts.mask);
    if (bloom) {
        r_bind_tex(p, "u_bloom0", 2, GL_TEXTURE_2D, r->b4_tex[0]);
        r_bind_tex(p, "u_bloom1", 3, GL_TEXTURE_2D, r->b8_tex[0]);
        gl.Uniform1f(r_loc(p, "u_bloom"), r->stage.bloom);
    }
    if (flare)
        r_bind_tex(p, "u_flare_img", 4, GL_TEXTURE_2D, r->fl_tex);
    r_fullscreen(r);
}

/* The flare image (glow and ghosts along the axis through the centre,
 * scaled by the sun's visibility) at quarter size: it is smooth, and six
 * flare-texture taps per output pixel cost more than the rest of the tone
 * map (13 of 19 ms at 1280x720 on llvmpipe).  The tone map taps it once. */
static void run_flare(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_FLARE];
    gl.BindFramebuffer(GL_FRAMEBUFFER, r->fl_fbo);
    gl.Viewport(0, 0, r_half(f->w, 2), r_half(f->h, 2));
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.UseProgram(p);
    r_bind_tex(p, "u_flare", 0, GL_TEXTURE_2D, r->flare_tex);
    r_bind_tex(p, "u_sun_vis", 1, GL_TEXTURE_2D, r->sunvis_tex);
    gl.Uniform2f(r_loc(p, "u_size"), (float)r_half(f->w, 2), (float)r_half(f->h, 2));
    gl.Uniform2f(r_loc(p, "u_sun_uv"), f->sun_px[0] / (float)f->w, f->sun_px[1] / (float)f->h);
    const float *c = r->stage.sun_color;
    float k = fminf(r->stage.sun_intensity * 0.08f, 50.0f) * f->exposure;
    gl.Uniform3f(r_loc(p, "u_flare_color"), c[0] * k, c[1] * k, c[2] * k);
    gl.Uniform1f(r_loc(p, "u_aspect"), (float)f->w / (float)f->h);
    r_fullscreen(r);
}

/* ---- HUD ---- */
static void quad(r_game *r, float x, float y, float w, float h, const float c[4], float u0, float v0, float u1, float v1)
{
    if (r->nhud + 6 > HUD_MAX_QUADS * 6)
        return;
    hud_vertex q[4] = {{x, y, u0, v0, c[0], c[1], c[2], c[3]},
                       {x + w, y, u1, v0, c[0], c[1], c[2], c[3]},
                       {x + w, y + h, u1, v1, c[0], c[1], c[2], c[3]},
                       {x, y + h, u0, v1, c[0], c[1], c[2], c[3]}};
    const int order[6] = {0, 1, 2, 0, 2, 3};
    for (int k = 0; k < 6; k++)
        r->hud[r->nhud++] = q[order[k]];
}

static void rect(r_game *r, float x, float y, float w, float h, const float c[4])
{
    quad(r, x, y, w, h, c, -1, -1, -1, -1);
}

static float text_width(const char *s, float px)
{
    return (float)strlen(s) * 6 * px - px;
}

/* Text with a drop shadow; px is the size of one font pixel. */
static void text(r_game *r, const char *s, float x, float y, float px, const float c[4])
{
    static const float shadow[4] = {0, 0, 0, 1};
    for (int pass = 0; pass < 2; pass++) {
        float cx = x + (pass ? 0 : px * 0.6f), cy = y + (pass ? 0 : px * 0.6f);
        for (const char *p = s; *p; p++, cx += 6 * px) {
            int g = -1;
            for (int k = 0; k < R_FONT_GLYPHS; k++)
                if (r_font_glyphs[k].c == *p)
                    g = k;
            if (g < 0 || *p == ' ')
                continue;
            float u0 = (float)(g * 6) / (6 * R_FONT_GLYPHS), u1 = (float)(g * 6 + 6) / (6 * R_FONT_GLYPHS);
            quad(r, cx, cy, 6 * px, 8 * px, pass ? c : shadow, u0, 0, u1, 1);
        }
    }
}

static void centered(r_game *r, const char *s, int w, float y, float px, const float c[4])
{
    text(r, s, (w - text_width(s, px)) / 2, y, px, c);
}

static void build_hud(r_game *r, const g_state *st, int w, int h)
{
    r->nhud = 0;
    float unit = h / 100.0f; /* HUD sizes scale with the window height */
    const float back[4] = {0.05f, 0.05f, 0.07f, 1}, white[4] = {1, 1, 1, 1}, gold[4] = {1, 0.8f, 0.2f, 1};
    float bar_w = w * 0.36f, bar_h = 3.2f * unit, top = 3 * unit;
    for (int i = 0; i < 2; i++) {
        float x = i == 0 ? w * 0.05f : w * 0.95f - bar_w;
        float frac = (float)st->f[i].health / G_MAX_HEALTH;
        float fill[4] = {1.0f, 0.25f + 0.6f * frac, 0.1f, 1};
        rect(r, x - 0.4f * unit, top - 0.4f * unit, bar_w + 0.8f * unit, bar_h + 0.8f * unit, back);
        float fw = bar_w * frac;
        rect(r, i == 0 ? x + bar_w - fw : x, top, fw, bar_h, fill); /* bars drain towards the centre */
        const float *col = r_fighter_color[i];
        const float name_c[4] = {col[0] + 0.2f, col[1] + 0.2f, col[2] + 0.2f, 1};
        text(r, i == 0 ? "P1" : "P2", i == 0 ? x : x + bar_w - text_width("P2", 0.5f * unit), top + bar_h + 1.2f * unit,
             0.5f * unit, name_c);
        for (int k = 0; k < G_ROUNDS_TO_WIN; k++) { /* round wins */
            float px = i == 0 ? x + bar_w - (k + 1) * 3 * unit : x + k * 3 * unit;
            rect(r, px, top + bar_h + 1.2f * unit, 2.2f * unit, 2.2f * unit, k < st->f[i].rounds_won ? gold : back);
        }
    }
    char buf[32];
    int secs = (st->round_timer + G_HZ - 1) / G_HZ;
    snprintf(buf, sizeof buf, "%02d", secs > 99 ? 99 : secs);
    centered(r, buf, w, 1.5f * unit, 0.9f * unit, white);

    const char *msg = NULL;
    switch (st->phase) {
    case G_PHASE_INTRO:
        snprintf(buf, sizeof buf, st->phase_ticks < 60 ? "ROUND %d" : "FIGHT!", st->round);
        msg = buf;
        break;
    case G_PHASE_ROUND_END:
        msg = st->round_result == G_RES_KO         ? "K.O."
              : st->round_result == G_RES_RING_OUT ? "RING OUT"
              : st->round_result == G_RES_TIME     ? (st->round_winner ? "TIME" : "DRAW")
                                                   : "DRAW";
        break;
    case G_PHASE_MATCH_END:
        if (st->match_winner > 0)
            snprintf(buf, sizeof buf, "P%d WINS", st->match_winner);
        else
            snprintf(buf, sizeof buf, "DRAW GAME");
        msg = buf;
        break;
    default: break;
    }
    if (msg)
        centered(r, msg, w, 38 * unit, 1.6f * unit, gold);
}

static void run_hud(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_HUD];
    build_hud(r, f->cur, f->w, f->h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.UseProgram(p);
    gl.Uniform2f(r_loc(p, "u_screen"), (float)f->w, (float)f->h);
    r_bind_tex(p, "u_font", 0, GL_TEXTURE_2D, r->font_tex);
    gl.BindVertexArray(r->hud_vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, r->hud_vbo);
    gl.BufferSubData(GL_ARRAY_BUFFER, 0, (GLsizeiptr)(r->nhud * sizeof(hud_vertex)), r->hud);
    gl.DrawArrays(GL_TRIANGLES, 0, r->nhud);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
}

/* ---- creation ---- */

static GLuint build_font(void)
{
    /* one row of 6x8 cells (a blank column and row between glyphs) */
    enum { CW = 6, CH = 8 };
    int w = CW * R_FONT_GLYPHS;
    uint8_t *px = calloc((size_t)w * CH, 1);
    if (!px)
        return 0;
    for (int g = 0; g < R_FONT_GLYPHS; g++)
        for (int y = 0; y < R_FONT_H; y++)
            for (int x = 0; x < R_FONT_W; x++)
                if (r_font_glyphs[g].rows[y] & (0x10 >> x))
                    px[(size_t)y * w + g * CW + x] = 255;
    GLuint t = r_tex2d(GL_R8, w, CH, GL_RED, GL_UNSIGNED_BYTE, px, GL_NEAREST, GL_CLAMP_TO_EDGE);
    free(px);
    return t;
}

/* The visor: part of a cylinder round the head bone, centred on the
 * bone's -y side (the face of a fighter facing +x; the shader mirrors it). */
static bool build_lens(r_mesh_data *m)
{
    const int seg = 16, rows = 4;
    const float rad = 0.128f, x0 = 0.07f, x1 = 0.17f, span = 1.3f;
    m->v = calloc((size_t)(seg + 1) * (rows + 1), sizeof *m->v);
    m->idx = calloc((size_t)seg * rows * 6, sizeof *m->idx);
    if (!m->v || !m->idx)
        return false;
    for (int j = 0; j <= rows; j++)
        for (int i = 0; i <= seg; i++) {
            float a = -span / 2 + span * (float)i / seg; /* angle from -y towards z */
            r_vertex *v = &m->v[m->nv++];
            v->normal[0] = 0, v->normal[1] = -cosf(a), v->normal[2] = sinf(a);
            v->pos[0] = x0 + (x1 - x0) * (float)j / rows;
            v->pos[1] = rad * v->normal[1];
            v->pos[2] = rad * v->normal[2];
            v->tangent[0] = 1, v->tangent[3] = 1;
            v->uv[0] = (float)i / seg, v->uv[1] = (float)j / rows;
            v->bone = G_HEAD;
        }
    for (int j = 0; j < rows; j++)
        for (int i = 0; i < seg; i++) {
            unsigned a = (unsigned)(j * (seg + 1) + i), b = a + (unsigned)seg + 1;
            unsigned q[6] = {a, a + 1, b, a + 1, b + 1, b};
            memcpy(m->idx + m->ni, q, sizeof q);
            m->ni += 6;
        }
    return true;
}

static bool build_programs(r_game *r, rs_err *err)
{
    static const struct {
        int id;
        const char *vs, *fs, *defines;
    } d[] = {
        {P_FIGHTER, "scene.vert", "scene.frag", "#define FIGHTER 1\n"},
        {P_STAGE, "scene.vert", "scene.frag", "#define STAGE 1\n"},
        {P_LENS, "scene.vert", "lens.frag", "#define LENS 1\n"},
        {P_DEPTH, "scene.vert", "light_depth.frag", "#define LIGHT_VIEW 1\n"},
        {P_SIL, "scene.vert", "light_depth.frag", "#define LIGHT_VIEW 1\n#define SILHOUETTE 1\n"},
        {P_SKY, "sky.vert", "sky.frag", NULL},
        {P_MASK, "cap_fullscreen.vert", "shadow_mask.frag", NULL},
        {P_GROW, "cap_fullscreen.vert", "mask_grow.frag", NULL},
        {P_BLUR, "cap_fullscreen.vert", "blur.frag", NULL},
        {P_DOWN, "cap_fullscreen.vert", "downsample.frag", NULL},
        {P_SUNVIS, "cap_fullscreen.vert", "sun_vis.frag", NULL},
        {P_FLARE, "cap_fullscreen.vert", "flare.frag", NULL},
        {P_HUD, "hud.vert", "hud.frag", NULL},
        {P_TONE, "cap_fullscreen.vert", "tonemap.frag", NULL},
        {P_TONE + 1, "cap_fullscreen.vert", "tonemap.frag", "#define BLOOM 1\n"},
        {P_TONE + 2, "cap_fullscreen.vert", "tonemap.frag", "#define FLARE 1\n"},
        {P_TONE + 3, "cap_fullscreen.vert", "tonemap.frag", "#define BLOOM 1\n#define FLARE 1\n"},
    };
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++)
        if (!(r->prog[d[i].id] = r_program(&(r_program_desc){.vs = d[i].vs, .fs = d[i].fs, .defines = d[i].defines}, err)))
            return false;
    return true;
}

static bool build_graph(r_game *r, rs_err *err)
{
    r_graph_init(&r->graph, RES_PERSISTENT, res_names, (int)(sizeof res_names / sizeof res_names[0]));
    const r_pass passes[] = {
        {"shadow_map", RES_ENV, RES_SHADOW, need_shadows, run_shadow_map, 0},
        {"silhouette", RES_ENV, RES_SIL, need_shadows, run_silhouette, 0},
        {"silhouette_mips", RES_SIL, RES_SIL, need_shadows, run_silhouette_mips, 0},
        {"z_prepass", RES_ENV, RES_DEPTH, need_shadows, run_z_prepass, 0},
        {"shadow_mask", RES_DEPTH | RES_SHADOW, RES_MASK, need_shadows, run_shadow_mask, 0},
        {"mask_filter", RES_MASK, RES_MASK, need_shadows, run_mask_filter, 0},
        {NULL, R_FX_PRE, 0, NULL, NULL, 0},
        {"scene", RES_ENV, RES_HDR | RES_DEPTH, need_always, run_scene, RES_MASK | RES_SIL | RES_FOGMAP | RES_LSPSM},
        {NULL, R_FX_SURFACE, 0, NULL, NULL, 0},
        {"sky", RES_ENV | RES_DEPTH, RES_HDR, need_always, run_sky, RES_FOGMAP},
        {NULL, R_FX_TRANSLUCENT, 0, NULL, NULL, 0},
        {"lens", RES_ENV | RES_DEPTH | RES_HDR, RES_HDR, need_always, run_lens, RES_FOGMAP},
        {"bloom_bright", RES_HDR, RES_BLOOM, need_bloom, run_bloom_bright, 0},
        {"bloom_blur", RES_BLOOM, RES_BLOOM, need_bloom, run_bloom_blur, 0},
        {"sun_visibility", RES_DEPTH, RES_SUNVIS, need_sun, run_sun_visibility, 0},
        {"flare", RES_SUNVIS, RES_FLARE, need_sun, run_flare, 0},
        {"tonemap", RES_HDR | RES_ENV, RES_OUT, need_always, run_tonemap, RES_BLOOM | RES_FLARE},
        {"hud", RES_OUT, RES_OUT, need_hud, run_hud, 0},
    };
    /* a row without a name: the stage effects' passes of that phase (r_fx.h) */
    for (size_t i = 0; i < sizeof passes / sizeof passes[0]; i++) {
        if (passes[i].name) {
            if (!r_graph_add(&r->graph, &passes[i], err))
                return false;
            continue;
        }
        int phase = (int)passes[i].reads;
        for (int m = 0; m < r_fx_nmodules; m++)
            for (int k = 0; k < r_fx_modules[m]->npass[phase]; k++)
                if (!r_graph_add(&r->graph, &r_fx_modules[m]->pass[phase][k], err))
                    return false;
    }
    return true;
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
        rs_fail(err, 1, "out of memory");
        return NULL;
    }
    if (o)
        r->opts = *o;
    else
        r->opts.hdr_format = -1;
    if (r->opts.stage_file) {
        snprintf(r->stage_file, sizeof r->stage_file, "%s", r->opts.stage_file);
        r->opts.stage_file = r->stage_file;
    }
    r->stage_game = -2;
    r->ring_stage = -1;
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
    bool ok = r_mesh_fighter(&m);
    if (ok) {
        r_upload_mesh(&m, &r->fighter_vao, &r->fighter_vbo, &r->fighter_ibo);
        r->fighter_count = (GLsizei)m.ni;
    }
    r_mesh_free(&m);
    if (ok && (ok = build_lens(&m))) {
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
    r->font_tex = ok ? build_font() : 0;

    /* procedural textures and the tone curve */
    uint8_t *px = malloc((size_t)R_TEX_SIZE * R_TEX_SIZE * 4);
    float *lut = malloc((size_t)r->lut_size * sizeof *lut);
    if (!px || !lut || !r->font_tex || !ok) {
        free(px);
        free(lut);
        rs_fail(err, 1, "out of memory");
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
    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, SHADOW_SIZE, SHADOW_SIZE, 0, GL_DEPTH_COMPONENT, GL_FLOAT, NULL);
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
            gl.TexImage2D(GL_TEXTURE_2D, k, GL_R8, SIL_SIZE >> k, SIL_SIZE >> k, 0, GL_RED, GL_UNSIGNED_BYTE, NULL);
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
    r_graph_release(&r->graph);
    r_free_mesh(&r->fighter_vao, &r->fighter_vbo, &r->fighter_ibo);
    r_free_mesh(&r->lens_vao, &r->lens_vbo, &r->lens_ibo);
    gl.DeleteVertexArrays(1, &r->hud_vao);
    gl.DeleteVertexArrays(1, &r->empty_vao);
    gl.DeleteBuffers(1, &r->hud_vbo);
    GLuint tex[] = {r->font_tex, r->normal_tex, r->spec_tex, r->flare_tex, r->lut_tex, r->shadow_tex, r->sil_tex, r->sil_tmp};
    gl.DeleteTextures((GLsizei)(sizeof tex / sizeof tex[0]), tex);
    gl.DeleteFramebuffers(1, &r->shadow_fbo);
    gl.DeleteFramebuffers(SIL_LEVELS, r->sil_fbo);
    gl.DeleteFramebuffers(SIL_LEVELS, r->sil_tmp_fbo);
    for (int i = 0; i < P_COUNT; i++)
        gl.DeleteProgram(r->prog[i]);
    free(r->hud);
    free(r);
}

/* ---- the frame ---- */

static void update_lut(r_game *r)
{
    if (r->stage.gamma == r->lut_gamma)
        return;
    float *lut = malloc((size_t)r->lut_size * sizeof *lut);
    if (!lut)
        return;
    r_tone_lut(lut, r->lut_size, r->stage.gamma);
    gl.BindTexture(GL_TEXTURE_1D, r->lut_tex);
    gl.TexSubImage1D(GL_TEXTURE_1D, 0, 0, r->lut_size, GL_RED, GL_FLOAT, lut);
    gl.BindTexture(GL_TEXTURE_1D, 0);
    free(lut);
    r->lut_gamma = r->stage.gamma;
}

bool r_game_draw(r_game *r, const g_state *prev, const g_state *cur, float alpha, int w, int h)
{
    GLint out = 0;
    gl.GetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &out);
    rs_err err = {0};
    if (w <= 0 || h <= 0)
        rs_fail(&err, 1, "cannot draw a %dx%d frame", w, h);
    if (err.msg[0] || !r_game_prepare(r, cur->stage, &err) || !make_targets(r, w, h, &err)) {
        snprintf(r->error, sizeof r->error, "%s", err.msg);
        gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)out);
        if (w > 0 && h > 0) {
            gl.Viewport(0, 0, w, h);
            gl.ClearColor(0, 0, 0, 1);
            gl.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        }
        return false;
    }
    if (r->ring_stage != cur->stage && !build_ring(r, cur->stage, &err)) {
        snprintf(r->error, sizeof r->error, "%s", err.msg);
        return false;
    }
    update_lut(r);
    /* a known state whatever the caller left: every pass sets what it needs on top */
    gl.Disable(GL_SCISSOR_TEST);
    gl.Disable(GL_BLEND);
    gl.BlendEquation(GL_FUNC_ADD);
    gl.Disable(GL_STENCIL_TEST);
    gl.Disable(GL_POLYGON_OFFSET_FILL);
    gl.Disable(GL_CULL_FACE);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    gl.DepthMask(GL_TRUE);
    frame *f = &r->f;
    memset(f, 0, sizeof *f);
    f->prev = prev, f->cur = cur, f->alpha = alpha, f->w = w, f->h = h, f->out_fbo = out;
    frame_setup(r, f);
    r->mask_final = 0;
    r_graph_run(&r->graph, r);
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)out);
    gl.BindVertexArray(0);
    gl.UseProgram(0);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.DepthMask(GL_TRUE);
    gl.Enable(GL_DEPTH_TEST);
    RGL_CHECK("r_game_draw");
    return true;
}

int r_game_ring_stage(const r_game *r)
{
    return r->ring_stage;
}

const char *r_game_error(const r_game *r)
{
    return r->error;
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
    fprintf(out, "passes (stage %s, %dx%d, %llu frames; gpu: %s%s):\n", r->have_stage ? r->stage.name : "-", r->tw, r->th,
            (unsigned long long)r->graph.frame, r->graph.gpu_timer ? "GL_TIMESTAMP queries" : "not available, cpu only",
            r->graph.serial ? "; software renderer: glFinish after each pass, cpu ms = wall time" : "");
    r_graph_report(&r->graph, out);
}

bool r_game_read_buffer(r_game *r, const char *name, float *out, int *w, int *h)
{
    GLuint tex = 0;
    int tw = r->tw, th = r->th, level = 0;
    if (!strcmp(name, "hdr"))
        tex = r->hdr_tex;
    else if (!strcmp(name, "bloom"))
        tex = r->b4_tex[0], tw = r_half(r->tw, 2), th = r_half(r->th, 2);
    else if (!strcmp(name, "mask"))
        tex = r->mask_tex[r->mask_final];
    else if (!strncmp(name, "silhouette", 10) && (!name[10] || (name[10] >= '1' && name[10] < '0' + SIL_LEVELS && !name[11]))) {
        level = name[10] ? name[10] - '0' : 0; /* "silhouette2": blurred level 2 */
        tex = r->sil_tex, tw = SIL_SIZE >> level, th = SIL_SIZE >> level;
    }
    GLenum fmt = GL_RGBA;
    if (!strcmp(name, "depth")) /* one float per pixel, window depth */
        tex = r->depth_tex, fmt = GL_DEPTH_COMPONENT;
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
