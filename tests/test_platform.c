/* runtime/platform and runtime/gl: contexts on every backend, the
 * automatic fallback, error ids, the loader and debug error reporting. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "t.h"

static void check_core_33(const char *backend)
{
    plat *p = t_context(backend);
    T_ASSERT(strcmp(plat_backend_name(p), backend) == 0);
    T_ASSERTF(glcaps.major > 3 || (glcaps.major == 3 && glcaps.minor >= 3), "got GL %d.%d", glcaps.major,
              glcaps.minor);
    T_ASSERT(glcaps.core);
    T_ASSERT(glcaps.vendor && glcaps.renderer && glcaps.version && glcaps.glsl);
    T_ASSERT(glcaps.max_texture_size >= 4096);
    /* GL 3.3 core guarantees these; the probes must find them */
    T_ASSERT(glcaps.fences);
    T_ASSERT(glcaps.timer_query);
    T_ASSERT(glcaps.float_rt);
    T_ASSERT(gl.GetError() == GL_NO_ERROR);
    plat_destroy(p);
}

static void t_egl_core(void) { check_core_33("egl"); }
static void t_osmesa_core(void) { check_core_33("osmesa"); }

static void t_auto_prefers_egl(void)
{
    if (!plat_backend_built("egl"))
        T_SKIP_INSTALL("egl not built in");
    rs_err e = {0};
    plat *p = plat_create(NULL, &e);
    T_ASSERTF(p, "%s", e.msg);
    T_ASSERT(strcmp(plat_backend_name(p), "egl") == 0);
    T_ASSERT(plat_fallback_reason(p)[0] == 0);
    plat_destroy(p);
}

static void t_auto_falls_back_to_osmesa(void)
{
    if (!plat_backend_built("egl") || !plat_backend_built("osmesa"))
        T_SKIP_INSTALL("needs egl and osmesa");
    /* libglvnd finds no EGL vendor: EGL cannot give a context */
    setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/vendor.json", 1);
    setenv("__EGL_VENDOR_LIBRARY_DIRS", "/nonexistent", 1);
    rs_err e = {0};
    plat *p = plat_create(&(plat_desc){.backend = "auto"}, &e);
    T_ASSERTF(p, "%s", e.msg);
    T_ASSERT(strcmp(plat_backend_name(p), "osmesa") == 0);
    T_CONTAINS(plat_fallback_reason(p), "egl:");
    T_ASSERT(glcaps.core);
    plat_destroy(p);
}

static void t_egl_forced_failure_is_one_line(void)
{
    if (!plat_backend_built("egl"))
        T_SKIP_INSTALL("egl not built in");
    setenv("__EGL_VENDOR_LIBRARY_FILENAMES", "/nonexistent/vendor.json", 1);
    setenv("__EGL_VENDOR_LIBRARY_DIRS", "/nonexistent", 1);
    rs_err e = {0};
    T_ASSERT(!plat_create(&(plat_desc){.backend = "egl"}, &e));
    T_ASSERT(e.code == PLAT_ERR_NO_DEVICE || e.code == PLAT_ERR_CONTEXT);
    T_CONTAINS(e.msg, "egl:");
    T_ASSERT(!strchr(e.msg, '\n'));
}

static void t_bad_device_index(void)
{
    if (!plat_backend_built("egl"))
        T_SKIP_INSTALL("egl not built in");
    setenv("RINGSIDE_EGL_DEVICE", "99", 1);
    rs_err e = {0};
    T_ASSERT(!plat_create(&(plat_desc){.backend = "egl"}, &e));
    T_EQ(e.code, PLAT_ERR_NO_DEVICE);
    T_CONTAINS(e.msg, "RINGSIDE_EGL_DEVICE=99");
}

static void t_unknown_backend(void)
{
    rs_err e = {0};
    T_ASSERT(!plat_create(&(plat_desc){.backend = "vulkan"}, &e));
    T_EQ(e.code, PLAT_ERR_UNKNOWN_BACKEND);
    T_CONTAINS(e.msg, "unknown backend 'vulkan'");
    T_ASSERT(strcmp(plat_error_text(PLAT_ERR_NO_DISPLAY), "no display for a window") == 0);
}

static void t_glfw_without_display(void)
{
    if (!plat_backend_built("glfw"))
        T_SKIP_INSTALL("glfw not built in");
    unsetenv("DISPLAY");
    unsetenv("WAYLAND_DISPLAY");
    rs_err e = {0};
    T_ASSERT(!plat_create(&(plat_desc){.backend = "glfw", .hidden = true}, &e));
    T_EQ(e.code, PLAT_ERR_NO_DISPLAY);
    T_CONTAINS(e.msg, "glfw: cannot open a window");
    T_CONTAINS(e.msg, "xvfb-run");
    T_ASSERT(!strchr(e.msg, '\n'));
}

static void t_glfw_window(void)
{
    if (!getenv("DISPLAY") || !*getenv("DISPLAY"))
        T_SKIP_ENV("no DISPLAY (tests/test_cli.sh covers glfw under xvfb-run)");
    plat *p = t_context("glfw");
    int w, h;
    plat_size(p, &w, &h);
    T_ASSERT(w > 0 && h > 0);
    T_ASSERT(plat_window(p) != NULL);
    T_ASSERT(plat_poll(p));
    plat_present(p);
    plat_destroy(p);
}

static void t_loader_fills_table(void)
{
    plat *p = t_context("egl");
    /* every required entry is non-NULL; spot-check a few across the list */
    T_ASSERT(gl.Clear && gl.ReadPixels && gl.FenceSync && gl.QueryCounter && gl.BlitFramebuffer);
    T_ASSERT(gl.MapBufferRange && gl.UnmapBuffer && gl.CreateShader && gl.UniformMatrix4fv);
    T_ASSERT(!glcaps.buffer_storage || gl.BufferStorage);
    GLint n = 0;
    gl.GetIntegerv(GL_NUM_EXTENSIONS, &n);
    T_ASSERT(n > 0);
    const char *last = (const char *)gl.GetStringi(GL_EXTENSIONS, (GLuint)n - 1);
    T_ASSERTF(rgl_has_extension(last), "%s not found", last);
    T_ASSERT(!rgl_has_extension("GL_RINGSIDE_no_such_extension"));
    plat_destroy(p);
}

static void t_debug_callback_counts_errors(void)
{
    plat *p = t_context("egl");
    if (!glcaps.khr_debug)
        T_SKIP_ENV("no KHR_debug");
    rgl_error_reset();
    gl.BindTexture(0xdead, 0); /* GL_INVALID_ENUM */
    T_ASSERTF(rgl_error_count() >= 1, "the debug callback saw no error");
    plat_destroy(p);
}

static void t_check_counts_without_callback(void)
{
    if (!plat_backend_built("osmesa"))
        T_SKIP_INSTALL("osmesa not built in");
    rs_err e = {0};
    plat *p = plat_create(&(plat_desc){.backend = "osmesa"}, &e);
    T_ASSERTF(p, "%s", e.msg);
    rgl_error_reset();
    gl.BindTexture(0xdead, 0);
    T_ASSERT(!rgl_check("test"));
    T_EQ(rgl_error_count(), 1);
    T_ASSERT(rgl_check("test"));
    plat_destroy(p);
}

static void t_two_egl_contexts(void)
{
    /* both share one EGLDisplay: destroying one must not end the other */
    plat *a = t_context("egl");
    plat *b = t_context("egl");
    plat_destroy(b);
    T_ASSERT(plat_make_current(a));
    T_ASSERT(rgl_load((rgl_getproc)(void (*)(void))plat_proc, a, 3, 3, false, NULL));
    gl.ClearColor(0, 0, 0, 0);
    T_EQ(gl.GetError(), GL_NO_ERROR);
    plat_destroy(a);
}

static void t_two_backends_in_turn(void)
{
    /* the loader is refilled for each context: EGL, then OSMesa, then EGL */
    if (!plat_backend_built("osmesa"))
        T_SKIP_INSTALL("osmesa not built in");
    const char *order[] = {"egl", "osmesa", "egl"};
    for (int i = 0; i < 3; i++) {
        plat *p = t_context(order[i]);
        gl.ClearColor(0, 0, 0, 0);
        T_ASSERT(gl.GetError() == GL_NO_ERROR);
        plat_destroy(p);
    }
}

T_MAIN({"egl_core", t_egl_core}, {"osmesa_core", t_osmesa_core}, {"auto_prefers_egl", t_auto_prefers_egl},
       {"auto_falls_back_to_osmesa", t_auto_falls_back_to_osmesa},
       {"egl_forced_failure_is_one_line", t_egl_forced_failure_is_one_line}, {"bad_device_index", t_bad_device_index},
       {"unknown_backend", t_unknown_backend}, {"glfw_without_display", t_glfw_without_display},
       {"glfw_window", t_glfw_window}, {"loader_fills_table", t_loader_fills_table},
       {"debug_callback_counts_errors", t_debug_callback_counts_errors},
       {"check_counts_without_callback", t_check_counts_without_callback},
       {"two_egl_contexts", t_two_egl_contexts}, {"two_backends_in_turn", t_two_backends_in_turn})
