/* The scene: the fighters and the ring ("scene"), the sky and the
 * translucent visors ("lens"), and the helpers every scene draw shares
 * (camera uniforms, the stage program's uniforms, the fighters' draw).
 * The stage effects bind their maps through r_fx_bind (r_fx.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "r_local.h"

static bool need_always(void *u)
{
    (void)u;
    return true;
}

void r_draw_fighters(r_game *r, GLuint p)
{
    gl.BindVertexArray(r->fighter->vao);
    for (int i = 0; i < 2; i++) {
        gl.UniformMatrix4fv(r_loc(p, "u_bones"), G_BONES, GL_FALSE, &r->f.bones[i][0][0]);
        gl.Uniform4fv(r_loc(p, "u_bone_color"), G_BONES, &r->f.colors[i][0][0]);
        gl.Uniform1i(r_loc(p, "u_fighter"), i);
        gl.DrawElements(GL_TRIANGLES, r->fighter->count, GL_UNSIGNED_INT, NULL);
    }
}

void r_camera_uniforms(r_game *r, GLuint p)
{
    gl.UseProgram(p);
    gl.UniformMatrix4fv(r_loc(p, "u_view_proj"), 1, GL_FALSE, r->f.vp.m);
    gl.Uniform3f(r_loc(p, "u_eye"), r->f.eye.x, r->f.eye.y, r->f.eye.z);
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
    /* an effect may have cleared and drawn already (the holes' stencil volumes) */
    if (!r_fx_scene_cleared(r))
        gl.Clear(GL_COLOR_BUFFER_BIT | (prepass ? 0 : GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT));

    if (f->depth_only) { /* a warm-up frame: the depth, with no shading (r_local.h) */
        GLuint d = r->prog[P_DEPTH];
        gl.DepthFunc(GL_LEQUAL);
        gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        r_camera_uniforms(r, d);
        r_draw_fighters(r, d);
        gl.DepthFunc(GL_LESS);
        gl.BindVertexArray(r->ring_vao);
        if (!r_fx_draw_ring(r))
            gl.DrawElements(GL_TRIANGLES, r->ring_count, GL_UNSIGNED_INT, NULL);
        gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        return;
    }
    /* fighters: over their own z-prepass depth when it ran */
    GLuint p = r->prog[P_FIGHTER];
    gl.DepthFunc(prepass ? GL_LEQUAL : GL_LESS);
    r_camera_uniforms(r, p);
    r_bind_ibl(r, p);
    r_bind_tex(p, "u_normal_map", 0, GL_TEXTURE_2D, r->normal_tex);
    r_bind_tex(p, "u_spec_map", 1, GL_TEXTURE_2D, r->spec_tex);
    r_bind_tex(p, "u_mask", 2, GL_TEXTURE_2D, r->mask_tex[r->mask_final]);
    gl.Uniform2f(r_loc(p, "u_mask_uv"), 1.0f / (float)f->w, 1.0f / (float)f->h);
    gl.Uniform1i(r_loc(p, "u_shadows"), shadows);
    r_fx_bind(r, p, R_FX_BIND_SCENE);
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

    /* the effects' opaque surfaces' depth first (r_fx.h, scene_depth), so
     * the ground they hide is not shaded */
    gl.DepthFunc(GL_LESS);
    gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    r_camera_uniforms(r, r->prog[P_DEPTH]);
    r_fx_scene_depth(r, r->prog[P_DEPTH]);
    gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);

    /* the ring and the ground, with the projected silhouette */
    r_stage_program(r, r_ring_material(r));
    gl.BindVertexArray(r->ring_vao);
    /* an effect may draw the ring in its own order (the holes: r_fx.h) */
    if (!r_fx_draw_ring(r))
        gl.DrawElements(GL_TRIANGLES, r->ring_count, GL_UNSIGNED_INT, NULL);
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

void r_light_uniforms(GLuint p, const frame *f)
{
    gl.UniformMatrix4fv(r_loc(p, "u_light_proj"), 1, GL_FALSE, f->light.m);
    gl.Uniform3f(r_loc(p, "u_light_dir"), f->light_dir.x, f->light_dir.y, f->light_dir.z);
    float waist[6] = {f->waist[0].x, f->waist[0].y, f->waist[0].z, f->waist[1].x, f->waist[1].y, f->waist[1].z};
    gl.Uniform3fv(r_loc(p, "u_waist"), 2, waist);
    gl.Uniform1f(r_loc(p, "u_lod_start"), 0.6f);
    gl.Uniform1f(r_loc(p, "u_lod_scale"), 1.6f);
}

void r_sun_uniforms(GLuint p, const r_stage *st)
{
    float rad = st->sun_size_deg * 0.5f * 3.14159265f / 180.0f;
    double omega = 2 * 3.14159265358979 * (1 - cos(rad)); /* the disc's solid angle */
    float L = st->sun ? (float)fmin(st->sun_intensity / omega, R_HALF_MAX) : 0.0f;
    gl.Uniform3f(r_loc(p, "u_sun_dir"), st->sun_dir[0], st->sun_dir[1], st->sun_dir[2]);
    gl.Uniform3f(r_loc(p, "u_sun_radiance"), fminf(L * st->sun_color[0], R_HALF_MAX),
                 fminf(L * st->sun_color[1], R_HALF_MAX), fminf(L * st->sun_color[2], R_HALF_MAX));
    gl.Uniform1f(r_loc(p, "u_sun_cos"), cosf(rad));
}

int r_ring_material(const r_game *r)
{
    return r->stage.buildings > 0 ? R_MAT_PAVED : R_MAT_PLANKS;
}

GLuint r_stage_program(r_game *r, int material)
{
    frame *f = &r->f;
    GLuint p = r->prog[material == R_MAT_BUILDING ? P_STAGE_BUILDING : material == R_MAT_HOLE ? P_STAGE_HOLE : P_STAGE];
    r_camera_uniforms(r, p);
    r_bind_ibl(r, p);
    r_bind_tex(p, "u_silhouette", 0, GL_TEXTURE_2D, r->sil_tex);
    gl.Uniform1i(r_loc(p, "u_shadows"), r_ran(f, r, "mask_filter") && r_ran(f, r, "silhouette_mips"));
    r_fx_bind(r, p, R_FX_BIND_SCENE);
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    gl.Uniform3fv(r_loc(p, "u_ring_color"), 1, r->stage.ring_color);
    r_light_uniforms(p, f);
    return p;
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
    r_sun_uniforms(p, &r->stage);
    gl.Uniform1f(r_loc(p, "u_flash"), f->flash);
    r_fx_bind(r, p, R_FX_BIND_SKY);
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
    r_fx_bind(r, p, R_FX_BIND_LENS);
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

/* The visor: part of a cylinder round the head bone, centred on the
 * bone's -y side (the face of a fighter facing +x; the shader mirrors it).
 * Its radius is inside the head's polygon (radius 0.11, 20 sides: 0.1086
 * at a side's middle), so from any view it covers only the head: a visor
 * floating outside the head (it was 0.128) showed edge-on, beside the head,
 * as a bright strip of Fresnel reflection over the background.  scene.vert
 * pulls its depth in front of the face. */
bool r_build_lens(r_mesh_data *m)
{
    const int seg = 16, rows = 4;
    const float rad = 0.105f, x0 = 0.07f, x1 = 0.17f, span = 1.3f;
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

/* may_read: the effects' maps are added by r_game.c's build_graph (each
 * module's scene_reads, r_fx.h) */
const r_pass r_scene_pass = {"scene", RES_ENV, RES_HDR | RES_DEPTH, need_always, run_scene, RES_MASK | RES_SIL};
const r_pass r_sky_pass = {"sky", RES_ENV | RES_DEPTH, RES_HDR, need_always, run_sky, 0};
const r_pass r_lens_pass = {"lens", RES_ENV | RES_DEPTH | RES_HDR, RES_HDR, need_always, run_lens, 0};
