/* Post-process anti-aliasing (r_quality.aa, docs/renderer.md "Quality
 * knobs"): with FXAA on, the tone map writes r->ldr_tex (the render's
 * size) instead of the output, with its luma beside it (r->luma_tex), and
 * this pass filters it into the output before the HUD, which stays sharp.
 * Off, the pass is not needed and the tone map writes the output as it
 * always did.
 *
 * Most of a frame is flat, and FXAA returns a flat pixel untouched.  So,
 * where the output has a stencil buffer: the image is copied into the
 * output (a blit), a marking pass (fxaa.frag's MARK: a conservative
 * version of the filter's own flatness test on the 8-bit luma, two
 * gathers a pixel) sets the stencil on the pixels that may be edges, and
 * the filter runs with the stencil test, which a software rasteriser
 * applies before shading whole blocks.  The bytes are those of one full
 * pass (r_game_opts.aa_plain, which the tests compare against): on
 * llvmpipe at 640x360 the pass takes 2.8 instead of 4.4 ms (dojo).
 * Without a stencil buffer (a window made without one) it is one full
 * pass. */
#include "r_local.h"

static bool need_aa(void *u)
{
    r_game *r = u;
    return r->opts.q.aa == R_AA_FXAA;
}

/* 8 stencil bits on the bound draw framebuffer (0: the window's) */
static bool has_stencil(GLint fbo)
{
    GLenum att = fbo ? GL_STENCIL_ATTACHMENT : GL_STENCIL;
    GLint type = GL_NONE, bits = 0;
    gl.GetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, att, GL_FRAMEBUFFER_ATTACHMENT_OBJECT_TYPE, &type);
    if (type == GL_NONE)
        return false;
    gl.GetFramebufferAttachmentParameteriv(GL_DRAW_FRAMEBUFFER, att, GL_FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE, &bits);
    return bits >= 1;
}

static void run_fxaa(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_FXAA];
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    bool marked = !r->opts.aa_plain && has_stencil(f->out_fbo);
    if (marked) {
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, r->ldr_fbo);
        gl.ReadBuffer(GL_COLOR_ATTACHMENT0);
        gl.BlitFramebuffer(0, 0, f->out_w, f->out_h, 0, 0, f->out_w, f->out_h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    }
    gl.Viewport(0, 0, f->out_w, f->out_h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    if (marked) {
        GLuint m = r->prog[P_FXAA_MARK];
        gl.Enable(GL_STENCIL_TEST);
        gl.StencilMask(0xFF);
        gl.ClearStencil(0);
        gl.Clear(GL_STENCIL_BUFFER_BIT);
        gl.StencilFunc(GL_ALWAYS, 1, 0xFF);
        gl.StencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
        gl.ColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
        gl.UseProgram(m);
        r_bind_tex(m, "u_luma", 1, GL_TEXTURE_2D, r->luma_tex);
        r_fullscreen(r);
        gl.ColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        gl.StencilFunc(GL_EQUAL, 1, 0xFF);
        gl.StencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
    }
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, r->ldr_tex);
    r_fullscreen(r);
    if (marked) {
        gl.Disable(GL_STENCIL_TEST);
        gl.StencilFunc(GL_ALWAYS, 0, 0xFF);
    }
}

/* Reads and writes "output": the tone map's image in ldr_tex in, the
 * filtered image in the output framebuffer out. */
const r_pass r_aa_pass = {"fxaa", RES_OUT, RES_OUT, need_aa, run_fxaa, 0};
