/* Afterimage motion blur (docs/effects.md, "Afterimage motion blur"), on
 * every stage: fast limbs leave a stretched, translucent copy of themselves
 * along their path.
 *
 * The technique draws each moving model twice, first the stretched copy
 * (depth test on, depth write off), then the model.  Here the models are
 * already drawn by "scene", which marks their pixels in the stencil
 * (R_STENCIL_FIGHTER); the copy is drawn after the sky with the stencil
 * test keeping it off those pixels, which is the same picture as drawing
 * it first.  The pass runs only on frames where some bone moves through
 * the world faster than the stage's afterimage_speed, and only those bones
 * are drawn.  Nothing in it is pixel-sized: the copy is placed in metres
 * and its fade is in bone radii, so it looks the same at any render size. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fx_local.h"
#include "../render/r_shader.h"

extern const r_fx_module fx_afterimage_module;
#define AFTERIMAGE(r) ((struct fx_afterimage_state *)r_fx_state((r), &fx_afterimage_module))

#define OPACITY 0.6f /* the copy's alpha at rest; the speed fade scales it */

typedef struct fx_afterimage_state {
    GLuint prog;
    float radius[16]; /* per bone: the mesh's largest vertex distance from the bone origin */
    float fast[2][16];
    bool any_fast;    /* this frame */
} fx_afterimage_state;

static bool create(r_game *r, rs_err *err)
{
    fx_afterimage_state *a = calloc(1, sizeof *a);
    if (!a)
        return rs_fail(err, R_ERR_NOMEM, "out of memory");
    r_fx_set_state(r, &fx_afterimage_module, a);
    a->prog = r_program(&(r_program_desc){.vs = "afterimage.vert", .fs = "afterimage.frag"}, err);
    if (!a->prog)
        return false;
    r_mesh_data m = {0};
    if (!r_mesh_fighter(&m, R_FIGHTER_FINE)) { /* the coarse one has the same extent */
        r_mesh_free(&m);
        return rs_fail(err, R_ERR_NOMEM, "out of memory for the fighter mesh");
    }
    for (size_t i = 0; i < m.nv; i++) {
        int b = (int)(m.v[i].bone + 0.5f);
        if (b < 0 || b >= 16)
            continue;
        const float *p = m.v[i].pos;
        float d = sqrtf(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        if (d > a->radius[b])
            a->radius[b] = d;
    }
    r_mesh_free(&m);
    for (int b = 0; b < 16; b++)
        if (!(a->radius[b] > 0.01f))
            a->radius[b] = 0.01f;
    return true;
}

static void destroy(r_game *r)
{
    fx_afterimage_state *a = AFTERIMAGE(r);
    if (!a)
        return;
    gl.DeleteProgram(a->prog);
    free(a);
    r_fx_set_state(r, &fx_afterimage_module, NULL);
}

/* A point of a bone (t metres along its x axis) through matrix v. */
static r_vec3 bone_point(const float m[16], float t, const r_mat4 *v)
{
    float p[3] = {m[12] + m[0] * t, m[13] + m[1] * t, m[14] + m[2] * t};
    if (!v)
        return r_v3(p[0], p[1], p[2]);
    const float *a = v->m;
    return r_v3(a[0] * p[0] + a[4] * p[1] + a[8] * p[2] + a[12], a[1] * p[0] + a[5] * p[1] + a[9] * p[2] + a[13],
                a[2] * p[0] + a[6] * p[1] + a[10] * p[2] + a[14]);
}

/* How fast a bone moves through the world, m/s: the faster of its origin
 * and its far end (a forearm swung round the elbow barely moves at its
 * origin).  0 for NaN. */
static float bone_speed(const float cur[16], const float prev[16], float len)
{
    float v = 0;
    for (int e = 0; e < 2; e++) {
        r_vec3 d = r_sub(bone_point(cur, e * len, NULL), bone_point(prev, e * len, NULL));
        v = fmaxf(v, sqrtf(r_dot(d, d)) * (float)G_HZ);
    }
    return isfinite(v) ? v : 0.0f;
}

static bool needed(void *u)
{
    r_game *r = u;
    fx_afterimage_state *a = AFTERIMAGE(r);
    if (!a || r_fx_stage(r)->afterimage == R_AFTERIMAGE_OFF)
        return false;
    a->any_fast = false;
    const frame *f = r_fx_frame(r);
    float thr = r_fx_stage(r)->afterimage_speed;
    /* Which bones leave a copy is the fighter's own motion in either mode:
     * measured in view space, a fighter standing still while the camera
     * followed the other one (a pan or zoom of 3 m/s at a head's far end)
     * left a translucent copy beside its head and body.  The view mode
     * still smears the fast bones along their view-space path. */
    for (int i = 0; i < 2; i++)
        for (int b = 0; b < G_BONES; b++) {
            float v = bone_speed(f->bones_tick[i][b], f->bones_prev[i][b], a->radius[b]);
            a->fast[i][b] = v > thr ? 1.0f : 0.0f;
            a->any_fast |= v > thr;
        }
    return a->any_fast;
}

static void run(void *u)
{
    r_game *r = u;
    fx_afterimage_state *a = AFTERIMAGE(r);
    const frame *f = r_fx_frame(r);
    GLuint p = a->prog;
    r_fx_gl core = r_fx_core_gl(r);
    gl.BindFramebuffer(GL_FRAMEBUFFER, core.hdr_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Enable(GL_DEPTH_TEST);
    gl.DepthFunc(GL_LESS);
    gl.DepthMask(GL_FALSE);
    gl.Disable(GL_CULL_FACE); /* the stretched copy turns some faces round */
    gl.Enable(GL_STENCIL_TEST);
    gl.StencilMask(0);
    gl.StencilFunc(GL_NOTEQUAL, R_STENCIL_FIGHTER, R_STENCIL_FIGHTER);
    gl.Enable(GL_BLEND);
    gl.BlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
    gl.UseProgram(p);
    r_bind_ibl(r, p);
    gl.UniformMatrix4fv(r_loc(p, "u_view"), 1, GL_FALSE, f->view.m);
    gl.UniformMatrix4fv(r_loc(p, "u_view_prev"), 1, GL_FALSE, f->view_prev.m);
    gl.UniformMatrix4fv(r_loc(p, "u_proj"), 1, GL_FALSE, f->proj.m);
    gl.Uniform1fv(r_loc(p, "u_radius"), 16, a->radius);
    gl.Uniform1f(r_loc(p, "u_stretch"), r_fx_stage(r)->afterimage_stretch);
    gl.Uniform1i(r_loc(p, "u_world"), r_fx_stage(r)->afterimage == R_AFTERIMAGE_WORLD);
    gl.Uniform1f(r_loc(p, "u_opacity"), OPACITY);
    gl.BindVertexArray(core.fighter_vao);
    for (int i = 0; i < 2; i++) {
        gl.UniformMatrix4fv(r_loc(p, "u_bones"), G_BONES, GL_FALSE, &f->bones[i][0][0]);
        gl.UniformMatrix4fv(r_loc(p, "u_bones_prev"), G_BONES, GL_FALSE, &f->bones_prev[i][0][0]);
        gl.UniformMatrix4fv(r_loc(p, "u_bones_tick"), G_BONES, GL_FALSE, &f->bones_tick[i][0][0]);
        gl.Uniform4fv(r_loc(p, "u_bone_color"), G_BONES, &f->colors[i][0][0]);
        gl.Uniform1fv(r_loc(p, "u_fast"), 16, a->fast[i]);
        /* only the fast bones' triangles, in the mesh's order (the others
         * would be clipped by the vertex shader after it ran on them:
         * about 0.7 ms a frame single-threaded at 640x360) */
        if (core.whole_meshes) {
            gl.DrawElements(GL_TRIANGLES, core.fighter_count, GL_UNSIGNED_INT, NULL);
            continue;
        }
        for (int b = 0; b < G_BONES;) {
            if (!a->fast[i][b]) {
                b++;
                continue;
            }
            int e = b + 1;
            while (e < G_BONES && a->fast[i][e])
                e++;
            GLsizei first = core.fighter_bone_first[b], n = core.fighter_bone_first[e] - first;
            gl.DrawElements(GL_TRIANGLES, n, GL_UNSIGNED_INT, (const void *)((size_t)first * sizeof(GLuint)));
            b = e;
        }
    }
    gl.Disable(GL_BLEND);
    gl.Disable(GL_STENCIL_TEST);
    gl.StencilMask(0xFF);
    gl.DepthMask(GL_TRUE);
}

static const r_pass passes[] = {
    {"afterimage", RES_ENV | RES_DEPTH | RES_HDR, RES_HDR, needed, run, 0},
};

/* History: none of its own.  The previous matrices are those of the game
 * state one tick before (frame.bones_prev, view_prev: r_frame.c), which the
 * caller hands r_game_draw as `prev`; a frame is a function of the two
 * game states alone. */
const r_fx_module fx_afterimage_module = {
    .name = "afterimage", .create = create, .destroy = destroy,
    .pass = {[R_FX_TRANSLUCENT] = passes}, .npass = {[R_FX_TRANSLUCENT] = 1},
};
