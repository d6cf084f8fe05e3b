/* Post-process anti-aliasing (r_quality.aa, docs/renderer.md "Quality
 * knobs"): with FXAA on, the tone map writes r->ldr_tex (the render's
 * size) instead of the output, and this pass filters it into the output
 * before the HUD, which stays sharp.  Off, the pass is not needed and the
 * tone map writes the output as it always did. */
#include "r_local.h"

static bool need_aa(void *u)
{
    r_game *r = u;
    return r->opts.q.aa == R_AA_FXAA;
}

static void run_fxaa(void *u)
{
    r_game *r = u;
    frame *f = &r->f;
    GLuint p = r->prog[P_FXAA];
    gl.BindFramebuffer(GL_FRAMEBUFFER, (GLuint)f->out_fbo);
    gl.Viewport(0, 0, f->w, f->h);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_BLEND);
    gl.UseProgram(p);
    r_bind_tex(p, "u_src", 0, GL_TEXTURE_2D, r->ldr_tex);
    r_fullscreen(r);
}

/* Reads and writes "output": the tone map's image in ldr_tex in, the
 * filtered image in the output framebuffer out. */
const r_pass r_aa_pass = {"fxaa", RES_OUT, RES_OUT, need_aa, run_fxaa, 0};
