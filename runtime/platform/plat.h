/* plat: a GL context from one of three backends behind one contract.
 *
 *   egl     headless, the default for every non-interactive command: the
 *           EGL device platform (NVIDIA and Mesa hardware drivers) or Mesa's
 *           surfaceless platform (llvmpipe).  Renders into FBOs only.
 *   osmesa  software fallback, chosen with --backend osmesa or
 *           automatically when EGL cannot give a context.
 *   glfw    a window under X (or Xvfb) for play and attract; vsync on.
 *
 * plat_create makes the context current and loads the GL table (rgl.h), so
 * after it returns gl.* calls work and glcaps says what the context can do.
 * Every backend gives a core profile context of at least GL 3.3; newer
 * features are optional (see glcaps). */
#ifndef PLAT_H
#define PLAT_H

#include <stdbool.h>

#include "../util/rs_err.h"

#define PLAT_ERRORS(X)                                                                   \
    X(OK, "ok")                                                                          \
    X(UNKNOWN_BACKEND, "unknown backend")                                                \
    X(NOT_BUILT, "backend not built into this binary")                                   \
    X(NO_DISPLAY, "no display for a window")                                             \
    X(NO_DEVICE, "no EGL display or device")                                             \
    X(CONTEXT, "context creation failed")                                                \
    X(GL, "the context is not usable (version, profile or functions)")                  \
    X(NO_BACKEND, "no backend could create a context")

typedef enum plat_error {
#define X(id, text) PLAT_ERR_##id,
    PLAT_ERRORS(X)
#undef X
        PLAT_ERR_COUNT
} plat_error;

const char *plat_error_text(plat_error e);

/* Zero means default for every field. */
typedef struct plat_desc {
    const char *backend; /* "egl", "osmesa", "glfw"; NULL or "auto": egl, then osmesa */
    int width, height;   /* window size (glfw); 0 -> 1280x720.  Headless: unused */
    const char *title;   /* window title; NULL -> "ringside" */
    bool hidden;         /* glfw: do not show the window (info, tests) */
    bool fullscreen;     /* glfw: primary monitor, its current mode */
    bool no_vsync;       /* glfw: swap interval 0 */
    bool debug;          /* debug context + KHR_debug logging; RINGSIDE_GL_DEBUG=1 sets it */
    int gl_major, gl_minor; /* minimum version; 0 -> 3.3 */
} plat_desc;

typedef struct plat plat;

plat *plat_create(const plat_desc *desc, rs_err *err);
void plat_destroy(plat *p);

const char *plat_backend_name(const plat *p);
/* Backend details: EGL platform and device, OSMesa version, GLFW version. */
const char *plat_detail(const plat *p);
/* Why the automatic choice fell back to OSMesa; "" when it did not. */
const char *plat_fallback_reason(const plat *p);

void *plat_proc(plat *p, const char *name);
bool plat_make_current(plat *p);
/* Shows the frame (glfw: swap buffers); headless: nothing to do. */
void plat_present(plat *p);
/* Processes window events; false once the user asked to close. */
bool plat_poll(plat *p);
/* Default framebuffer size in pixels (glfw window); 0x0 when headless. */
void plat_size(const plat *p, int *w, int *h);
/* The GLFWwindow * for input code, or NULL on headless backends. */
void *plat_window(const plat *p);

/* Names of the backends compiled into this binary, e.g. "egl osmesa glfw". */
const char *plat_built_backends(void);
bool plat_backend_built(const char *name);

#endif
