/* Snow (docs/effects.md, "Snow"): fresh snow over the ring top that keeps
 * the fighters' footprints for the match.
 *
 *   snow_map         (PRE)      the displacement map, R_SNOW_MAP^2 R32F over
 *                               the ring top (RES_SNOW, persistent).  On a
 *                               reset it is copied from the "untouched"
 *                               height texture; on ticks with contacts every
 *                               bone capsule that dips into the snow is
 *                               stamped into it with a MIN blend: each texel
 *                               goes down to the capsule's underside, but
 *                               never below the "fully trampled" minimum
 *                               texture, so the snow is never flat.
 *   snow_light       (PRE)      fake subsurface scattering, step 1: the
 *                               snow's diffuse and specular lighting in
 *                               texture space, one texel per point of the
 *                               surface (weaker specular inside dents), the
 *                               key light's share apart for the fighters'
 *                               shadow (snow_light.frag)
 *   snow_light_blur  (PRE)      step 2: blurred (r_blur_into): light bleeds
 *                               through the snow (RES_SNOW_LIGHT)
 *   snow_surface     (SURFACE)  a grid over the ring top displaced by the
 *                               map in the vertex shader; fresh and trampled
 *                               colours blended by how far the vertex is
 *                               pressed down, times the blurred light
 *                               (step 3)
 *
 * The map follows game ticks only (r_fx.h): a frame stamps the contacts of
 * frame.caps and frame.caps_prev (this tick and the one before; the MIN
 * blend makes stamping twice harmless), so a video drawn at 60 or 30
 * frames a second gets the same prints.  Larger gaps lose the skipped
 * ticks' contacts; a seek restarts from untouched snow. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../game/g_game.h"
#include "fx_snow_tex.h"
#include "fx_local.h"
#include "../render/r_shader.h"

extern const r_fx_module fx_snow_module;
#define SNOW(r) ((struct fx_snow_state *)r_fx_state((r), &fx_snow_module))

#define SNOW_LIGHT 256              /* texture-space lighting texels per side: r_quality.snow_light overrides it */
/* The surface grid: a vertex on every `col`-th map texel along x; along z
 * on every texel row within `band` rows of the fight line (z = 0: about
 * +-0.5 m on a 4 m ring), where the fighters' bones reach and prints need
 * the detail, and on every `far`-th row beyond, where the snow stays
 * untouched drifts (their fine ripples come from the texture-space
 * lighting, not the geometry).  Two levels, chosen as the fighters' mesh
 * is (r_fx_mesh_lod: coarse below 540 rows drawn): the fine grid, 16.5k
 * triangles where a uniform grid of every other texel has 34k, and the
 * coarse one with every 4th column, 8.4k: on llvmpipe the triangles cost
 * more than the pixels (snow_surface 10.4-11.8 -> 8.3 ms a frame
 * single-threaded at 640x360), and at 640x360 its frames are 53 dB from
 * the fine grid's. */
static const struct snow_grid_lod {
    int col, band, far;
} snow_grid_lod[R_FIGHTER_LODS] = {[R_FIGHTER_COARSE] = {4, 16, 8}, [R_FIGHTER_FINE] = {2, 16, 8}};
#define MAX_STAMPS (4 * G_BONES)    /* both fighters, this tick and the one before */
#define COLOR_TILE 0.8f             /* metres per repeat of the colour textures */
#define DETAIL_TILE 2.0f            /* metres per repeat of the crust normal map: lumps of ~8 cm, which
                                       the 3 cm texels of the default lighting can hold */

enum { S_RESET, S_STAMP, S_LIGHT, S_KEY, S_SURFACE, S_PROGS };

struct fx_snow_state {
    GLuint prog[S_PROGS];
    GLuint map_tex, map_fbo;              /* the displacement map (RES_SNOW) */
    GLuint untouched_tex, trampled_tex;   /* heights, same size as the map */
    float half;                           /* the ring half-size they were made for; 0: none yet */
    GLuint light_tex, light_fbo, tmp_tex, tmp_fbo; /* RES_SNOW_LIGHT, and the blur's half way */
    int light_size;                       /* their side: r_quality.snow_light or SNOW_LIGHT */
    GLuint key_tex, key_fbo;              /* 1x1: the key light's colour (snow_key.frag) */
    GLuint color_tex, detail_tex;
    GLuint grid_vao[R_FIGHTER_LODS], grid_vbo[R_FIGHTER_LODS], grid_ibo[R_FIGHTER_LODS]; /* snow_grid_lod's levels */
    GLsizei grid_count[R_FIGHTER_LODS];
    int grid_drawn;                       /* triangles of the grid the last frame drew */
    bool keep_ring_top;                   /* tests: the scene draws the ring's top face after all */
    r_fx_capsule stamp[MAX_STAMPS];       /* this frame's contacts (need_map) */
    int nstamp;
};

static float ring_half(const r_game *r)
{
    int st = r_game_ring_stage(r) >= 0 ? r_game_ring_stage(r) : r_fx_stage(r)->game_index;
    return st >= 0 && st < G_STAGES ? fx_to_float(g_stages[st].ring_half) : 4.0f;
}

/* ---- creation ---- */

static GLuint color_tex(void (*make)(uint8_t *, int), uint8_t *px, GLenum ifmt, GLenum fmt)
{
    make(px, R_SNOW_TEX);
    GLuint t = r_tex2d(ifmt, R_SNOW_TEX, R_SNOW_TEX, fmt, GL_UNSIGNED_BYTE, px, GL_LINEAR_MIPMAP_LINEAR, GL_REPEAT);
    gl.GenerateMipmap(GL_TEXTURE_2D);
    /* one mip level a fetch: half the texel reads of trilinear on llvmpipe */
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
    return t;
}

/* One axis of the grid: map texel indices, with the ring's edge (-1 and
 * R_SNOW_MAP: the edge texel's height) and the skirt's foot (-2 and
 * R_SNOW_MAP + 1: the ring top) at the ends.  Returns the count. */
static int grid_axis(short *out, bool rows, const struct snow_grid_lod *l)
{
    int n = 0;
    out[n++] = -2, out[n++] = -1;
    for (int k = 0; k < R_SNOW_MAP; k++) {
        int from_centre = abs(2 * k + 1 - R_SNOW_MAP) / 2; /* texels from the map's middle line */
        bool keep = rows ? from_centre < l->band || k % l->far == l->far / 2 : k % l->col == l->col / 2;
        if (keep)
            out[n++] = (short)k;
    }
    out[n++] = R_SNOW_MAP, out[n++] = R_SNOW_MAP + 1;
    return n;
}

/* The grid over the ring top: one vertex attribute, the (column, row)
 * codes of grid_axis; snow_surface.vert makes positions from the map. */
static bool build_grid(struct fx_snow_state *s, int lod)
{
    short cols[R_SNOW_MAP + 4], rows[R_SNOW_MAP + 4];
    int nc = grid_axis(cols, false, &snow_grid_lod[lod]), nr = grid_axis(rows, true, &snow_grid_lod[lod]);
    size_t count = (size_t)(nc - 1) * (size_t)(nr - 1) * 6;
    short *v = malloc((size_t)nc * (size_t)nr * 2 * sizeof *v);
    unsigned *idx = malloc(count * sizeof *idx), *o = idx;
    if (!v || !idx) {
        free(v), free(idx);
        return false;
    }
    for (int j = 0; j < nr; j++)
        for (int i = 0; i < nc; i++)
            v[2 * (j * nc + i)] = cols[i], v[2 * (j * nc + i) + 1] = rows[j];
    for (int j = 0; j + 1 < nr; j++)
        for (int i = 0; i + 1 < nc; i++) {
            unsigned a = (unsigned)(j * nc + i), b = a + (unsigned)nc; /* b: the next row, +z */
            /* counter-clockwise seen from +y (and from outside on the skirt) */
            unsigned q[6] = {a, b, a + 1, a + 1, b, b + 1};
            memcpy(o, q, sizeof q);
            o += 6;
        }
    gl.GenVertexArrays(1, &s->grid_vao[lod]);
    gl.BindVertexArray(s->grid_vao[lod]);
    gl.GenBuffers(1, &s->grid_vbo[lod]);
    gl.BindBuffer(GL_ARRAY_BUFFER, s->grid_vbo[lod]);
    gl.BufferData(GL_ARRAY_BUFFER, (GLsizeiptr)((size_t)nc * nr * 2 * sizeof *v), v, GL_STATIC_DRAW);
    gl.EnableVertexAttribArray(0);
    gl.VertexAttribIPointer(0, 2, GL_SHORT, 0, NULL);
    gl.GenBuffers(1, &s->grid_ibo[lod]);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, s->grid_ibo[lod]);
    gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, (GLsizeiptr)(count * sizeof *idx), idx, GL_STATIC_DRAW);
    gl.BindVertexArray(0);
    gl.BindBuffer(GL_ARRAY_BUFFER, 0);
    free(v), free(idx);
    s->grid_count[lod] = (GLsizei)count;
    return true;
}

static void snow_destroy(r_game *r)
{
    struct fx_snow_state *s = SNOW(r);
    if (!s)
        return;
    for (int i = 0; i < S_PROGS; i++)
        gl.DeleteProgram(s->prog[i]);
    GLuint tex[] = {s->map_tex, s->untouched_tex, s->trampled_tex, s->light_tex, s->tmp_tex, s->key_tex, s->color_tex,
                    s->detail_tex};
    GLuint fbo[] = {s->map_fbo, s->light_fbo, s->tmp_fbo, s->key_fbo};
    gl.DeleteTextures((GLsizei)(sizeof tex / sizeof tex[0]), tex);
    gl.DeleteFramebuffers((GLsizei)(sizeof fbo / sizeof fbo[0]), fbo);
    gl.DeleteBuffers(R_FIGHTER_LODS, s->grid_vbo);
    gl.DeleteBuffers(R_FIGHTER_LODS, s->grid_ibo);
    gl.DeleteVertexArrays(R_FIGHTER_LODS, s->grid_vao);
    free(s);
    r_fx_set_state(r, &fx_snow_module, NULL);
}

static bool snow_create(r_game *r, rs_err *err)
{
    struct fx_snow_state *s = calloc(1, sizeof *s);
    if (!s)
        return rs_fail(err, R_ERR_NOMEM, "out of memory for the snow");
    r_fx_set_state(r, &fx_snow_module, s);
    char stamps[64];
    snprintf(stamps, sizeof stamps, "#define MAX_STAMPS %d\n", MAX_STAMPS);
    const struct {
        int id;
        const char *vs, *fs, *defines;
    } d[] = {
        {S_RESET, "cap_fullscreen.vert", "snow_reset.frag", NULL},
        {S_STAMP, "snow_stamp.vert", "snow_stamp.frag", stamps},
        {S_LIGHT, "snow_light.vert", "snow_light.frag", NULL},
        {S_KEY, "cap_fullscreen.vert", "snow_key.frag", NULL},
        {S_SURFACE, "snow_surface.vert", "snow_surface.frag", NULL},
    };
    for (size_t i = 0; i < sizeof d / sizeof d[0]; i++)
        if (!(s->prog[d[i].id] = r_program(&(r_program_desc){.vs = d[i].vs, .fs = d[i].fs, .defines = d[i].defines}, err)))
            return false;

    const int n = R_SNOW_MAP, nl = s->light_size = r_fx_quality(r)->snow_light > 0 ? r_fx_quality(r)->snow_light : SNOW_LIGHT;
    s->map_tex = r_tex2d(GL_R32F, n, n, GL_RED, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    s->map_fbo = r_fbo_for(s->map_tex, 0, 0);
    GLenum st_map = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    s->untouched_tex = r_tex2d(GL_R32F, n, n, GL_RED, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    s->trampled_tex = r_tex2d(GL_R32F, n, n, GL_RED, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    s->tmp_tex = r_tex2d(GL_RGBA16F, nl, nl, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    s->tmp_fbo = r_fbo_for(s->tmp_tex, 0, 0);
    s->light_tex = r_tex2d(GL_RGBA16F, nl, nl, GL_RGBA, GL_FLOAT, NULL, GL_LINEAR, GL_CLAMP_TO_EDGE);
    s->light_fbo = r_fbo_for(s->light_tex, 0, 0);
    GLenum st_light = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
    s->key_tex = r_tex2d(GL_RGBA16F, 1, 1, GL_RGBA, GL_FLOAT, NULL, GL_NEAREST, GL_CLAMP_TO_EDGE);
    s->key_fbo = r_fbo_for(s->key_tex, 0, 0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);

    uint8_t *px = malloc((size_t)R_SNOW_TEX * R_SNOW_TEX * 4);
    if (!px || !build_grid(s, R_FIGHTER_COARSE) || !build_grid(s, R_FIGHTER_FINE)) {
        free(px);
        return rs_fail(err, R_ERR_NOMEM, "out of memory for the snow");
    }
    s->color_tex = color_tex(fx_snow_tex_colors, px, GL_RG8, GL_RG);
    s->detail_tex = color_tex(fx_snow_tex_detail_normals, px, GL_RGBA8, GL_RGBA);
    free(px);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    if (st_map != GL_FRAMEBUFFER_COMPLETE || st_light != GL_FRAMEBUFFER_COMPLETE)
        return rs_fail(err, R_ERR_TARGET, "snow: the R32F height map (%s) or the RGBA16F light target (%s) cannot be drawn into",
                       rgl_enum_name(st_map), rgl_enum_name(st_light));
    RGL_CHECK("snow_create");
    return true;
}

/* The untouched and trampled heights for a ring of this size. */
static bool make_heights(struct fx_snow_state *s, float half, rs_err *err)
{
    const int n = R_SNOW_MAP;
    float *h = malloc((size_t)n * n * sizeof *h);
    if (!h)
        return rs_fail(err, R_ERR_NOMEM, "out of memory for the snow");
    fx_snow_tex_untouched(h, n, half);
    gl.BindTexture(GL_TEXTURE_2D, s->untouched_tex);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, n, n, GL_RED, GL_FLOAT, h);
    fx_snow_tex_trampled(h, n, half);
    gl.BindTexture(GL_TEXTURE_2D, s->trampled_tex);
    gl.TexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, n, n, GL_RED, GL_FLOAT, h);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    free(h);
    s->half = half;
    return true;
}

static bool snow_load(r_game *r, rs_err *err)
{
    /* the map itself restarts on the first frame (load_look resets the ticks) */
    return !r_fx_stage(r)->snow || make_heights(SNOW(r), ring_half(r), err);
}

/* ---- snow_map: reset and footprints ---- */

/* Bone capsules that dip below the highest untouched snow; the stamp
 * shader finds, texel by texel, how far each actually reaches under the
 * snow there. */
static void add_contacts(struct fx_snow_state *s, const r_fx_capsule caps[2][G_BONES], const r_fx_capsule prev[2][G_BONES])
{
    r_fx_contact c[2 * G_BONES];
    int n = r_fx_contacts(caps, prev, R_SNOW_UNTOUCHED_HI, c, 2 * G_BONES);
    for (int k = 0; k < n && s->nstamp < MAX_STAMPS; k++) {
        const r_fx_capsule *cap = &caps[c[k].fighter][c[k].bone];
        bool finite = isfinite(cap->r) && cap->r > 0;
        for (int a = 0; a < 3; a++)
            finite = finite && isfinite(cap->a[a]) && isfinite(cap->b[a]);
        if (finite)
            s->stamp[s->nstamp++] = *cap;
    }
}

static bool need_map(void *u)
{
    r_game *r = u;
    struct fx_snow_state *s = SNOW(r);
    if (!r_fx_stage(r)->snow || !s)
        return false;
    /* the contacts are found here so that a tick without any costs no pass */
    s->nstamp = 0;
    const frame *f = r_fx_frame(r);
    if (f->steps > 0) {
        add_contacts(s, f->caps, f->caps_prev);
        add_contacts(s, f->caps_prev, f->caps_prev);
    }
    return f->reset || s->half != ring_half(r) || s->nstamp > 0;
}

static void stamp(r_game *r, const r_fx_capsule *caps, int n)
{
    struct fx_snow_state *s = SNOW(r);
    GLuint p = s->prog[S_STAMP];
    float a[MAX_STAMPS][4], b[MAX_STAMPS][3];
    gl.UseProgram(p);
    gl.Uniform1f(r_loc(p, "u_half"), s->half);
    r_bind_tex(p, "u_trampled", 0, GL_TEXTURE_2D, s->trampled_tex);
    gl.Enable(GL_BLEND);
    gl.BlendEquation(GL_MIN); /* the snow only ever goes down */
    gl.BlendFunc(GL_ONE, GL_ONE);
    gl.BindVertexArray(r_fx_core_gl(r).empty_vao);
    for (int done = 0; done < n;) {
        int m = n - done < MAX_STAMPS ? n - done : MAX_STAMPS;
        for (int k = 0; k < m; k++) {
            const r_fx_capsule *c = &caps[done + k];
            memcpy(a[k], c->a, sizeof c->a), a[k][3] = c->r;
            memcpy(b[k], c->b, sizeof c->b);
        }
        gl.Uniform4fv(r_loc(p, "u_cap_a"), m, &a[0][0]);
        gl.Uniform3fv(r_loc(p, "u_cap_b"), m, &b[0][0]);
        gl.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, m);
        done += m;
    }
    gl.BlendEquation(GL_FUNC_ADD);
    gl.Disable(GL_BLEND);
}

static void map_target(struct fx_snow_state *s)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, s->map_fbo);
    gl.Viewport(0, 0, R_SNOW_MAP, R_SNOW_MAP);
    gl.Disable(GL_SCISSOR_TEST);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_BLEND);
}

static void run_map(void *u)
{
    r_game *r = u;
    struct fx_snow_state *s = SNOW(r);
    bool reset = r_fx_frame(r)->reset;
    if (s->half != ring_half(r)) { /* the ring changed size under the same look */
        if (!make_heights(s, ring_half(r), NULL))
            return;
        reset = true;
    }
    map_target(s);
    if (reset) { /* fresh snow: the untouched heights */
        GLuint p = s->prog[S_RESET];
        gl.UseProgram(p);
        r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, s->untouched_tex);
        r_fullscreen(r);
    }
    if (s->nstamp > 0)
        stamp(r, s->stamp, s->nstamp);
}

/* ---- snow_light, snow_light_blur: fake subsurface scattering ---- */

static bool need_snow(void *u)
{
    r_game *r = u;
    return r_fx_stage(r)->snow && SNOW(r);
}

static void run_light(void *u)
{
    r_game *r = u;
    struct fx_snow_state *s = SNOW(r);
    GLuint p = s->prog[S_LIGHT];
    gl.BindFramebuffer(GL_FRAMEBUFFER, s->light_fbo);
    gl.Viewport(0, 0, s->light_size, s->light_size);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_BLEND);
    gl.UseProgram(p);
    r_bind_tex(p, "u_map", 0, GL_TEXTURE_2D, s->map_tex);
    r_bind_tex(p, "u_untouched", 1, GL_TEXTURE_2D, s->untouched_tex);
    r_bind_tex(p, "u_trampled", 2, GL_TEXTURE_2D, s->trampled_tex);
    r_bind_tex(p, "u_detail", 3, GL_TEXTURE_2D, s->detail_tex);
    r_bind_ibl(r, p);
    gl.Uniform1f(r_loc(p, "u_half"), s->half);
    gl.Uniform1f(r_loc(p, "u_detail_tile"), DETAIL_TILE);
    gl.Uniform2f(r_loc(p, "u_size"), (float)s->light_size, (float)s->light_size);
    const frame *f = r_fx_frame(r);
    gl.Uniform3f(r_loc(p, "u_eye"), f->eye.x, f->eye.y, f->eye.z);
    gl.Uniform3f(r_loc(p, "u_light_dir"), f->light_dir.x, f->light_dir.y, f->light_dir.z);
    r_fullscreen(r);
    /* and the key light's colour for the surface, once */
    p = s->prog[S_KEY];
    gl.BindFramebuffer(GL_FRAMEBUFFER, s->key_fbo);
    gl.Viewport(0, 0, 1, 1);
    gl.UseProgram(p);
    r_bind_ibl(r, p);
    gl.Uniform3f(r_loc(p, "u_light_dir"), f->light_dir.x, f->light_dir.y, f->light_dir.z);
    r_fullscreen(r);
}

static void run_light_blur(void *u)
{
    r_game *r = u;
    struct fx_snow_state *s = SNOW(r);
    /* the same reach in metres at any size: steps of SNOW_LIGHT's texels */
    int n = s->light_size;
    float k = (float)n / SNOW_LIGHT;
    r_blur_into(r, s->tmp_fbo, s->light_tex, 0, n, n, k, 0);
    r_blur_into(r, s->light_fbo, s->tmp_tex, 0, n, n, 0, k);
}

/* ---- snow_surface ---- */

static void run_surface(void *u)
{
    r_game *r = u;
    struct fx_snow_state *s = SNOW(r);
    const frame *f = r_fx_frame(r);
    GLuint p = s->prog[S_SURFACE];
    r_begin_opaque(r);
    r_camera_uniforms(r, p);
    r_bind_tex(p, "u_map", 0, GL_TEXTURE_2D, s->map_tex);
    r_bind_tex(p, "u_untouched", 1, GL_TEXTURE_2D, s->untouched_tex);
    r_bind_tex(p, "u_trampled", 2, GL_TEXTURE_2D, s->trampled_tex);
    r_bind_tex(p, "u_light", 3, GL_TEXTURE_2D, s->light_tex);
    r_bind_tex(p, "u_colors", 4, GL_TEXTURE_2D, s->color_tex);
    r_bind_tex(p, "u_silhouette", 5, GL_TEXTURE_2D, r_fx_core_gl(r).sil_tex);
    r_bind_tex(p, "u_key", 7, GL_TEXTURE_2D, s->key_tex);
    gl.Uniform1f(r_loc(p, "u_half"), s->half);
    gl.Uniform1f(r_loc(p, "u_color_tile"), COLOR_TILE);
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    /* the fighters' blurred silhouette falls on the snow as on the ring (run_scene) */
    gl.Uniform1i(r_loc(p, "u_shadows"), r_ran(f, r, "silhouette_mips"));
    r_light_uniforms(p, f);
    gl.Uniform1f(r_loc(p, "u_sil_top"), SIL_LEVELS - 1);
    int lod = r_fx_mesh_lod(r);
    gl.BindVertexArray(s->grid_vao[lod]);
    gl.DrawElements(GL_TRIANGLES, s->grid_count[lod], GL_UNSIGNED_INT, NULL);
    s->grid_drawn = s->grid_count[lod] / 3;
    gl.BindVertexArray(0);
}

/* ---- test hooks (fx_snow_tex.h) ---- */

void fx_snow_test_keep_ring_top(r_game *r, bool keep)
{
    if (SNOW(r))
        SNOW(r)->keep_ring_top = keep;
}

int fx_snow_grid_drawn(r_game *r)
{
    struct fx_snow_state *s = SNOW(r);
    return s ? s->grid_drawn : 0;
}

int fx_snow_light_size(r_game *r)
{
    struct fx_snow_state *s = SNOW(r);
    return s ? s->light_size : 0;
}

bool fx_snow_read(r_game *r, const char *which, float *out)
{
    struct fx_snow_state *s = SNOW(r);
    if (!s)
        return false;
    GLuint t = !strcmp(which, "map")         ? s->map_tex
               : !strcmp(which, "untouched") ? s->untouched_tex
               : !strcmp(which, "trampled")  ? s->trampled_tex
               : !strcmp(which, "light")     ? s->light_tex
                                             : 0;
    if (!t)
        return false;
    gl.BindTexture(GL_TEXTURE_2D, t);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.GetTexImage(GL_TEXTURE_2D, 0, t == s->light_tex ? GL_RGBA : GL_RED, GL_FLOAT, out);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    return true;
}

void fx_snow_stamp(r_game *r, const r_fx_capsule *caps, int n)
{
    struct fx_snow_state *s = SNOW(r);
    if (!s || !s->half || n <= 0)
        return;
    map_target(s);
    stamp(r, caps, n);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

/* ---- the module ---- */

static const r_pass pre[] = {
    {"snow_map", RES_ENV, RES_SNOW, need_map, run_map, 0},
    {"snow_light", RES_ENV | RES_SNOW, RES_SNOW_LIGHT, need_snow, run_light, 0},
    {"snow_light_blur", RES_SNOW_LIGHT, RES_SNOW_LIGHT, need_snow, run_light_blur, 0},
};
static const r_pass surface[] = {
    {"snow_surface", RES_ENV | RES_SNOW | RES_SNOW_LIGHT | RES_HDR | RES_DEPTH, RES_HDR | RES_DEPTH, need_snow, run_surface,
     RES_SIL},
};

/* History: the displacement map (map_tex), reset to the untouched
 * heights and then only ever lowered by the contacts of each tick: a
 * footprint stays for the rest of the sequence, so every tick since the
 * reset counts.  snow_advance is the snow_map pass (its need() finds the
 * tick's contacts); the light maps are made from it each frame. */
static void snow_advance(r_game *r)
{
    if (need_map(r))
        run_map(r);
}

/* Inside "scene": the ring without its top face, which the snow surface
 * covers whole (its grid spans the top and its skirt walls come down to
 * the top's edges, and no height is below the top), so the scene does not
 * shade the pixels the snow then draws over.  A warm-up frame (depth only)
 * draws no snow, so it keeps the top. */
static bool snow_draw_ring(r_game *r)
{
    if (!need_snow(r) || r_fx_frame(r)->depth_only || SNOW(r)->keep_ring_top)
        return false;
    GLsizei n = r_fx_core_gl(r).ring_count;
    gl.DrawElements(GL_TRIANGLES, R_RING_TOP_FIRST, GL_UNSIGNED_INT, NULL);
    gl.DrawElements(GL_TRIANGLES, n - R_RING_TOP_FIRST - 6, GL_UNSIGNED_INT,
                    (const void *)((R_RING_TOP_FIRST + 6) * sizeof(unsigned)));
    return true;
}

static int snow_warmup(r_game *r)
{
    return need_snow(r) ? R_FX_FROM_START : R_FX_STATELESS;
}

const r_fx_module fx_snow_module = {
    .name = "snow", .create = snow_create, .destroy = snow_destroy, .load = snow_load,
    .pass = {pre, surface, NULL}, .npass = {3, 1, 0},
    .res = {{RES_SNOW, "snow", true}, {RES_SNOW_LIGHT, "snow light", false}},
    .draw_ring = snow_draw_ring, .warmup = snow_warmup, .advance = snow_advance,
};
