/* GLFW: a window for the interactive commands (play, attract).
 *
 * GLFW is initialised on the first window and terminated with the last; its
 * error callback writes into a buffer so a failure (no DISPLAY, no GLX) comes
 * back as one line through rs_err instead of GLFW's own stderr output. */
#ifdef RS_HAVE_GLFW /* configure.sh found the library; otherwise this file is empty */

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plat_local.h"

static char last_error[256];
static int live_windows;

static void on_error(int code, const char *msg)
{
    (void)code;
    snprintf(last_error, sizeof last_error, "%s", msg);
}

static bool glfw_create(plat *p, rs_err *err)
{
    glfwSetErrorCallback(on_error);
    last_error[0] = 0;
    if (live_windows == 0 && !glfwInit()) {
        const char *disp = getenv("DISPLAY");
        return rs_fail(err, PLAT_ERR_NO_DISPLAY, "glfw: cannot open a window: %s (DISPLAY=%s; run under X or xvfb-run -a)",
                       last_error[0] ? last_error : "glfwInit failed", disp && *disp ? disp : "unset");
    }
    glfwDefaultWindowHints();
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, p->desc.gl_major);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, p->desc.gl_minor);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
    glfwWindowHint(GLFW_OPENGL_DEBUG_CONTEXT, p->desc.debug ? GLFW_TRUE : GLFW_FALSE);
    glfwWindowHint(GLFW_VISIBLE, p->desc.hidden ? GLFW_FALSE : GLFW_TRUE);
    glfwWindowHint(GLFW_DEPTH_BITS, 24);
    glfwWindowHint(GLFW_STENCIL_BITS, 8);
    GLFWmonitor *mon = p->desc.fullscreen ? glfwGetPrimaryMonitor() : NULL;
    int w = p->desc.width, h = p->desc.height;
    const GLFWvidmode *m = mon ? glfwGetVideoMode(mon) : NULL;
    if (p->desc.fullscreen && !m) {
        if (live_windows == 0)
            glfwTerminate();
        return rs_fail(err, PLAT_ERR_NO_DISPLAY, "glfw: --fullscreen: no monitor or video mode: %s",
                       last_error[0] ? last_error : "unknown error");
    }
    if (m) {
        w = m->width;
        h = m->height;
        glfwWindowHint(GLFW_REFRESH_RATE, m->refreshRate);
    }
    GLFWwindow *win = glfwCreateWindow(w, h, p->desc.title, mon, NULL);
    if (!win) {
        if (live_windows == 0)
            glfwTerminate();
        return rs_fail(err, PLAT_ERR_CONTEXT, "glfw: cannot create a %dx%d window with a GL %d.%d core context: %s", w,
                       h, p->desc.gl_major, p->desc.gl_minor, last_error[0] ? last_error : "unknown error");
    }
    live_windows++;
    p->window = win;
    glfwMakeContextCurrent(win);
    glfwSwapInterval(p->desc.no_vsync ? 0 : 1);
    snprintf(p->detail, sizeof p->detail, "GLFW %s, %dx%d window%s", glfwGetVersionString(), w, h,
             p->desc.no_vsync ? "" : ", vsync");
    return true;
}

static void *glfw_proc(plat *p, const char *name)
{
    (void)p;
    return (void *)glfwGetProcAddress(name);
}

static bool glfw_make_current(plat *p)
{
    glfwMakeContextCurrent(p->window);
    return true;
}

static void glfw_present(plat *p)
{
    glfwSwapBuffers(p->window);
}

static bool glfw_poll(plat *p)
{
    glfwPollEvents();
    return !glfwWindowShouldClose(p->window);
}

static void glfw_size(const plat *p, int *w, int *h)
{
    glfwGetFramebufferSize(p->window, w, h);
}

static void glfw_destroy(plat *p)
{
    if (!p->window)
        return;
    glfwDestroyWindow(p->window);
    p->window = NULL;
    if (--live_windows == 0)
        glfwTerminate();
}

const plat_backend plat_glfw_backend = {
    .name = "glfw",
    .create = glfw_create,
    .proc = glfw_proc,
    .make_current = glfw_make_current,
    .present = glfw_present,
    .poll = glfw_poll,
    .size = glfw_size,
    .destroy = glfw_destroy,
};

#else
typedef int plat_glfw_not_built; /* ISO C wants something in a file */
#endif
