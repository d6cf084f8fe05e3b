/* The thin GL layer under the renderer: meshes, textures, framebuffers,
 * uniforms, the fullscreen triangle and the blur/downsample draws the
 * passes share (declared in r_local.h). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "r_local.h"

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

GLuint r_cube_tex(int n, float *const face[6], int levels)
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

int r_half(int v, int k)
{
    v >>= k;
    return v > 0 ? v : 1;
}

void r_blur_setup(GLuint p, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, dst_fbo);
    gl.Viewport(0, 0, w, h);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, src_tex);
    gl.Uniform2f(r_loc(p, "u_dir"), dx / (float)w, dy / (float)h);
    gl.Uniform1f(r_loc(p, "u_lod"), (float)lod);
}

/* blur.frag's kernel as texel weights, for a step of k texels (0 < k <= 1):
 * each paired bilinear fetch at offset o k splits its weight between
 * texels floor(o k) and the next, and the fetches on both sides of the
 * centre add into it.  w[0..4]; returns how far it reaches (1..4). */
int r_blur_kernel(float k, float w[5])
{
    static const float w0 = 0.2042f, wi[2] = {0.3040f, 0.0931f}, oi[2] = {1.3846f, 3.2308f};
    int reach = 1;
    memset(w, 0, 5 * sizeof *w);
    w[0] = w0;
    for (int i = 0; i < 2; i++) {
        float o = oi[i] * k;
        int j = (int)floorf(o);
        float f = o - (float)j;
        w[j] += wi[i] * (1 - f) * (j == 0 ? 2 : 1);
        w[j + 1] += wi[i] * f;
        if (f > 0 && j + 1 > reach)
            reach = j + 1;
        else if (j > reach)
            reach = j;
    }
    return reach;
}

void r_blur_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy)
{
    r_blur_setup(r->prog[P_BLUR], dst_fbo, src_tex, lod, w, h, dx, dy);
    r_fullscreen(r);
}

/* The same blur reading each texel once (blur.frag's REACH variants), for
 * steps of at most a texel along one axis on 8-bit targets, clamped at the
 * edge or with a zero border (zero_border: as src_tex's sampler has it);
 * other steps take r_blur_into's bilinear pairs. */
void r_blur_texels_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float dx, float dy,
                        bool zero_border)
{
    float k = dx != 0 ? dx : dy;
    if ((dx == 0) == (dy == 0) || !(k > 0 && k <= 1)) {
        r_blur_into(r, dst_fbo, src_tex, lod, w, h, dx, dy);
        return;
    }
    float kw[5];
    int reach = r_blur_kernel(k, kw);
    GLuint p = r->prog[P_BLUR_TEXELS + reach - 1];
    r_blur_setup(p, dst_fbo, src_tex, lod, w, h, dx, dy);
    gl.Uniform2i(r_loc(p, "u_axis"), dx != 0, dy != 0);
    gl.Uniform1fv(r_loc(p, "u_w"), reach + 1, kw);
    gl.Uniform1i(r_loc(p, "u_zero_border"), zero_border);
    r_fullscreen(r);
}

void r_blur_rgbe_setup(GLuint p, GLuint dst_fbo, GLuint src_tex, int w, int h, bool across)
{
    float kw[5];
    int reach = r_blur_kernel(1, kw); /* 4: blur.frag's RGBE variants are REACH 4 */
    r_blur_setup(p, dst_fbo, src_tex, 0, w, h, across, !across);
    gl.Uniform2i(r_loc(p, "u_axis"), across, !across);
    gl.Uniform1fv(r_loc(p, "u_w"), reach + 1, kw);
    gl.Uniform1i(r_loc(p, "u_zero_border"), 0);
}

void r_down_into(r_game *r, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float threshold, float scale)
{
    r_down_with(r, r->prog[P_DOWN], dst_fbo, src_tex, lod, w, h, threshold, scale);
}

void r_down_with(r_game *r, GLuint p, GLuint dst_fbo, GLuint src_tex, int lod, int w, int h, float threshold, float scale)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, dst_fbo);
    gl.Viewport(0, 0, w, h);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, src_tex);
    gl.Uniform1f(r_loc(p, "u_lod"), (float)lod);
    gl.Uniform2f(r_loc(p, "u_dst"), (float)w, (float)h);
    gl.Uniform1f(r_loc(p, "u_threshold"), threshold);
    gl.Uniform1f(r_loc(p, "u_scale"), scale);
    r_fullscreen(r);
}
