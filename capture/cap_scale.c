#include "cap_scale.h"
#include "cap_sink.h" /* CAP_ERRORS */

#include <stdlib.h>
#include <string.h>

#include "../runtime/render/r_shader.h"

static const char *const names[CAP_FILTERS] = {"box", "bilinear", "nearest", "lanczos3"};

const char *cap_filter_name(cap_filter f)
{
    return (unsigned)f < CAP_FILTERS ? names[f] : "?";
}

bool cap_filter_parse(const char *s, cap_filter *f)
{
    for (int i = 0; i < CAP_FILTERS; i++)
        if (!strcmp(s, names[i])) {
            *f = (cap_filter)i;
            return true;
        }
    return false;
}

struct cap_scaler {
    cap_filter f;
    int sw, sh, w, h;
    GLuint prog, vao, linear, read_fbo;
    GLuint mid_fbo, mid_tex; /* lanczos: after the horizontal pass */
    GLint u_src, u_src_size, u_dst_size, u_axis, u_flip;
};

cap_scaler *cap_scaler_create(cap_filter f, int sw, int sh, int w, int h, rs_err *err)
{
    cap_scaler *s = calloc(1, sizeof *s);
    if (!s) {
        rs_fail(err, CAP_ERR_NOMEM, "out of memory");
        return NULL;
    }
    *s = (cap_scaler){.f = f, .sw = sw, .sh = sh, .w = w, .h = h};
    gl.GenVertexArrays(1, &s->vao);
    gl.GenFramebuffers(1, &s->read_fbo);
    if (f == CAP_FILTER_BOX) {
        bool two = sw == 2 * w && sh == 2 * h;
        s->prog = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "cap_box.frag",
                                              .defines = two ? "#define FACTOR2 1\n" : NULL},
                            err);
    } else if (f == CAP_FILTER_LANCZOS3) {
        s->prog = r_program(&(r_program_desc){.vs = "cap_fullscreen.vert", .fs = "cap_lanczos.frag"}, err);
        gl.GenTextures(1, &s->mid_tex);
        gl.BindTexture(GL_TEXTURE_2D, s->mid_tex);
        /* float between the passes: negative lobes must survive */
        gl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, w, sh, 0, GL_RGBA, GL_FLOAT, NULL);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.BindTexture(GL_TEXTURE_2D, 0);
        gl.GenFramebuffers(1, &s->mid_fbo);
        gl.BindFramebuffer(GL_FRAMEBUFFER, s->mid_fbo);
        gl.FramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, s->mid_tex, 0);
        GLenum st = gl.CheckFramebufferStatus(GL_FRAMEBUFFER);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        if (st != GL_FRAMEBUFFER_COMPLETE) {
            rs_fail(err, CAP_ERR_GL, "lanczos3: RGBA16F %dx%d target incomplete (%s)", w, sh, rgl_enum_name(st));
            cap_scaler_destroy(s);
            return NULL;
        }
    }
    if ((f == CAP_FILTER_BOX || f == CAP_FILTER_LANCZOS3) && !s->prog) {
        cap_scaler_destroy(s);
        return NULL;
    }
    if (s->prog) {
        s->u_src = gl.GetUniformLocation(s->prog, "u_src");
        s->u_src_size = gl.GetUniformLocation(s->prog, "u_src_size");
        s->u_dst_size = gl.GetUniformLocation(s->prog, "u_dst_size");
        s->u_axis = gl.GetUniformLocation(s->prog, "u_axis");
        s->u_flip = gl.GetUniformLocation(s->prog, "u_flip");
    }
    gl.GenSamplers(1, &s->linear);
    gl.SamplerParameteri(s->linear, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.SamplerParameteri(s->linear, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.SamplerParameteri(s->linear, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl.SamplerParameteri(s->linear, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    return s;
}

static void pass(cap_scaler *s, GLuint src, int sw, int sh, GLuint fbo, int w, int h, int ax, int ay, int flip)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    gl.Viewport(0, 0, w, h);
    gl.UseProgram(s->prog);
    gl.BindTexture(GL_TEXTURE_2D, src);
    gl.Uniform1i(s->u_src, 0);
    gl.Uniform2i(s->u_src_size, sw, sh);
    gl.Uniform2i(s->u_dst_size, s->w, s->h);
    if (s->u_axis >= 0)
        gl.Uniform2i(s->u_axis, ax, ay);
    if (s->u_flip >= 0)
        gl.Uniform1i(s->u_flip, flip);
    gl.DrawArrays(GL_TRIANGLES, 0, 3);
}

void cap_scaler_run(cap_scaler *s, GLuint src, GLuint dst_fbo)
{
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.Disable(GL_CULL_FACE);
    gl.ActiveTexture(GL_TEXTURE0);
    if (s->f == CAP_FILTER_BILINEAR || s->f == CAP_FILTER_NEAREST) {
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, s->read_fbo);
        gl.FramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, src, 0);
        gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, dst_fbo);
        /* destination rows swapped: the picture's top lands in row 0 */
        gl.BlitFramebuffer(0, 0, s->sw, s->sh, 0, s->h, s->w, 0, GL_COLOR_BUFFER_BIT,
                           s->f == CAP_FILTER_BILINEAR ? GL_LINEAR : GL_NEAREST);
        gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
        return;
    }
    gl.BindVertexArray(s->vao);
    gl.BindSampler(0, s->linear); /* only the 2x box path filters; texelFetch ignores it */
    if (s->f == CAP_FILTER_BOX) {
        pass(s, src, s->sw, s->sh, dst_fbo, s->w, s->h, 0, 0, 1);
    } else {
        pass(s, src, s->sw, s->sh, s->mid_fbo, s->w, s->sh, 1, 0, 0);
        pass(s, s->mid_tex, s->w, s->sh, dst_fbo, s->w, s->h, 0, 1, 1);
    }
    gl.BindSampler(0, 0);
    gl.BindTexture(GL_TEXTURE_2D, 0);
    gl.BindVertexArray(0);
    gl.UseProgram(0);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

void cap_scaler_destroy(cap_scaler *s)
{
    if (!s)
        return;
    gl.DeleteProgram(s->prog);
    gl.DeleteVertexArrays(1, &s->vao);
    gl.DeleteFramebuffers(1, &s->read_fbo);
    if (s->mid_fbo)
        gl.DeleteFramebuffers(1, &s->mid_fbo);
    if (s->mid_tex)
        gl.DeleteTextures(1, &s->mid_tex);
    if (s->linear)
        gl.DeleteSamplers(1, &s->linear);
    free(s);
}
