/* Shared helpers of the renderer's GL tests (t_render.h). */
#include "t_render.h"

#include <stdio.h>

#include "../runtime/replay/rp.h"
#include "t.h"

void t_state_at(const char *demo, uint64_t tick, g_state *prev, g_state *cur)
{
    char path[1024];
    snprintf(path, sizeof path, RS_SOURCE_DIR "/demos/%s.rsr", demo);
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(rp_read(path, &rp, &e), "%s", e.msg);
    T_ASSERT(tick <= rp.ticks);
    g_init(cur, rp.stage, rp.seed);
    *prev = *cur;
    for (uint64_t t = 0; t < tick; t++) {
        *prev = *cur;
        g_step(cur, &rp.inputs[2 * t], NULL);
    }
    rp_free(&rp);
}

void t_fb_make(t_fb *f, int w, int h)
{
    gl.GenFramebuffers(1, &f->fbo);
    gl.BindFramebuffer(GL_FRAMEBUFFER, f->fbo);
    gl.GenRenderbuffers(2, f->rb);
    gl.BindRenderbuffer(GL_RENDERBUFFER, f->rb[0]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, f->rb[0]);
    gl.BindRenderbuffer(GL_RENDERBUFFER, f->rb[1]);
    gl.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, w, h);
    gl.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER, f->rb[1]);
    T_EQ(gl.CheckFramebufferStatus(GL_FRAMEBUFFER), GL_FRAMEBUFFER_COMPLETE);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

void t_fb_free(t_fb *f)
{
    gl.DeleteFramebuffers(1, &f->fbo);
    gl.DeleteRenderbuffers(2, f->rb);
}
