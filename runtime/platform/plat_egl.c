/* Headless EGL: no window system, render into FBOs.
 *
 * Display choice, first that gives a context wins:
 *   1. a hardware device through the EGL device platform
 *      (EGL_EXT_device_enumeration + EGL_EXT_platform_device): how NVIDIA's
 *      driver runs headless, and Mesa on a machine with a DRM device;
 *   2. Mesa's surfaceless platform (EGL_MESA_platform_surfaceless): llvmpipe
 *      on machines without a GPU;
 *   3. a software device (EGL_MESA_device_software) on the device platform.
 * RINGSIDE_EGL_DEVICE=N forces device N of the enumeration.
 * Plain eglGetDisplay(EGL_DEFAULT_DISPLAY) is never used: without X it fails
 * or picks a platform by guesswork. */
#ifdef RS_HAVE_EGL /* configure.sh found the library; otherwise this file is empty */

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "plat_local.h"

#ifndef EGL_PLATFORM_SURFACELESS_MESA
#define EGL_PLATFORM_SURFACELESS_MESA 0x31DD
#endif

#define MAX_DEVICES 16

/* eglGetPlatformDisplayEXT returns the same EGLDisplay for the same device,
 * and eglTerminate ends it for every context on it.  Count our users per
 * display and terminate with the last one. */
static struct {
    EGLDisplay dpy;
    int users;
} displays[MAX_DEVICES + 1];

static void display_ref(EGLDisplay dpy)
{
    int free_slot = -1;
    for (int i = 0; i <= MAX_DEVICES; i++) {
        if (displays[i].users && displays[i].dpy == dpy) {
            displays[i].users++;
            return;
        }
        if (!displays[i].users && free_slot < 0)
            free_slot = i;
    }
    if (free_slot >= 0) {
        displays[free_slot].dpy = dpy;
        displays[free_slot].users = 1;
    }
}

/* true when this was the last user */
static bool display_unref(EGLDisplay dpy)
{
    for (int i = 0; i <= MAX_DEVICES; i++)
        if (displays[i].users && displays[i].dpy == dpy)
            return --displays[i].users == 0;
    return true;
}

typedef struct egl_impl {
    EGLDisplay dpy;
    bool counted; /* display_ref() was called */
    EGLContext ctx;
    EGLSurface surf; /* 1x1 pbuffer only when surfaceless contexts are missing */
} egl_impl;

static bool has_ext(const char *list, const char *name)
{
    if (!list)
        return false;
    size_t n = strlen(name);
    for (const char *s = list; (s = strstr(s, name)) != NULL; s += n)
        if ((s == list || s[-1] == ' ') && (s[n] == ' ' || s[n] == 0))
            return true;
    return false;
}

static const char *egl_error_name(EGLint e)
{
    switch (e) {
    case EGL_SUCCESS: return "EGL_SUCCESS";
    case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
    case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
    case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
    case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
    case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
    case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
    case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
    case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
    case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
    case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
    default: return "EGL error";
    }
}

/* Context on an initialised display; fills im->ctx (and a pbuffer if the
 * display cannot make a context current without a surface). */
static bool make_context(plat *p, egl_impl *im, char *why, size_t whyn)
{
    EGLint major = 0, minor = 0;
    if (!eglInitialize(im->dpy, &major, &minor)) {
        snprintf(why, whyn, "eglInitialize: %s", egl_error_name(eglGetError()));
        return false;
    }
    display_ref(im->dpy);
    im->counted = true;
    const char *ext = eglQueryString(im->dpy, EGL_EXTENSIONS);
    bool v15 = major > 1 || (major == 1 && minor >= 5);
    if (!v15 && !has_ext(ext, "EGL_KHR_create_context")) {
        snprintf(why, whyn, "EGL %d.%d without EGL_KHR_create_context cannot make a core context", major, minor);
        return false;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
        snprintf(why, whyn, "eglBindAPI(EGL_OPENGL_API): %s (no desktop GL on this display)",
                 egl_error_name(eglGetError()));
        return false;
    }
    bool surfaceless = has_ext(ext, "EGL_KHR_surfaceless_context");
    EGLConfig cfg = (EGLConfig)0;
    if (!surfaceless || !has_ext(ext, "EGL_KHR_no_config_context")) {
        static const EGLint cattr[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                       EGL_RED_SIZE,     8,               EGL_GREEN_SIZE,      8,
                                       EGL_BLUE_SIZE,    8,               EGL_NONE};
        EGLint n = 0;
        if (!eglChooseConfig(im->dpy, cattr, &cfg, 1, &n) || n < 1) {
            snprintf(why, whyn, "no EGL config for desktop GL with pbuffers");
            return false;
        }
    }
    EGLint attr[16], k = 0;
    attr[k++] = EGL_CONTEXT_MAJOR_VERSION_KHR;
    attr[k++] = p->desc.gl_major;
    attr[k++] = EGL_CONTEXT_MINOR_VERSION_KHR;
    attr[k++] = p->desc.gl_minor;
    attr[k++] = EGL_CONTEXT_OPENGL_PROFILE_MASK_KHR;
    attr[k++] = EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT_KHR;
    if (p->desc.debug) {
        /* the KHR flag where the extension is present, EGL 1.5's own otherwise */
        bool khr = has_ext(ext, "EGL_KHR_create_context");
        attr[k++] = khr ? EGL_CONTEXT_FLAGS_KHR : EGL_CONTEXT_OPENGL_DEBUG;
        attr[k++] = khr ? EGL_CONTEXT_OPENGL_DEBUG_BIT_KHR : EGL_TRUE;
    }
    attr[k] = EGL_NONE;
    im->ctx = eglCreateContext(im->dpy, cfg, EGL_NO_CONTEXT, attr);
    if (im->ctx == EGL_NO_CONTEXT) {
        snprintf(why, whyn, "eglCreateContext(GL %d.%d core): %s", p->desc.gl_major, p->desc.gl_minor,
                 egl_error_name(eglGetError()));
        return false;
    }
    if (!surfaceless) {
        static const EGLint sattr[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
        im->surf = eglCreatePbufferSurface(im->dpy, cfg, sattr);
        if (im->surf == EGL_NO_SURFACE) {
            snprintf(why, whyn, "eglCreatePbufferSurface: %s", egl_error_name(eglGetError()));
            return false;
        }
    }
    if (!eglMakeCurrent(im->dpy, im->surf, im->surf, im->ctx)) {
        snprintf(why, whyn, "eglMakeCurrent: %s", egl_error_name(eglGetError()));
        return false;
    }
    snprintf(p->detail + strlen(p->detail), sizeof p->detail - strlen(p->detail), ", EGL %d.%d", major, minor);
    return true;
}

static void release(egl_impl *im)
{
    if (im->dpy == EGL_NO_DISPLAY)
        return;
    if (eglGetCurrentContext() == im->ctx)
        eglMakeCurrent(im->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (im->surf != EGL_NO_SURFACE)
        eglDestroySurface(im->dpy, im->surf);
    if (im->ctx != EGL_NO_CONTEXT)
        eglDestroyContext(im->dpy, im->ctx);
    if (!im->counted || display_unref(im->dpy))
        eglTerminate(im->dpy);
    im->counted = false;
    im->dpy = EGL_NO_DISPLAY;
    im->ctx = EGL_NO_CONTEXT;
    im->surf = EGL_NO_SURFACE;
}

static void device_name(EGLDeviceEXT dev, PFNEGLQUERYDEVICESTRINGEXTPROC qstr, char *out, size_t n)
{
    const char *dext = qstr(dev, EGL_EXTENSIONS);
    const char *file = has_ext(dext, "EGL_EXT_device_drm") ? qstr(dev, EGL_DRM_DEVICE_FILE_EXT) : NULL;
    if (has_ext(dext, "EGL_MESA_device_software"))
        snprintf(out, n, "software");
    else if (file)
        snprintf(out, n, "%s", file);
    else if (has_ext(dext, "EGL_NV_device_cuda"))
        snprintf(out, n, "NVIDIA CUDA device");
    else
        snprintf(out, n, "hardware");
}

static bool egl_create(plat *p, rs_err *err)
{
    egl_impl *im = calloc(1, sizeof *im);
    if (!im)
        return rs_fail(err, PLAT_ERR_CONTEXT, "egl: out of memory");
    im->dpy = EGL_NO_DISPLAY;
    im->ctx = EGL_NO_CONTEXT;
    im->surf = EGL_NO_SURFACE;
    p->impl = im;

    const char *cext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!cext) {
        free(im);
        return rs_fail(err, PLAT_ERR_NO_DEVICE,
                       "egl: no EGL client extensions (libEGL missing a vendor, or older than EGL 1.5)");
    }
    PFNEGLGETPLATFORMDISPLAYEXTPROC get_dpy =
        (PFNEGLGETPLATFORMDISPLAYEXTPROC)eglGetProcAddress("eglGetPlatformDisplayEXT");
    PFNEGLQUERYDEVICESEXTPROC qdev = (PFNEGLQUERYDEVICESEXTPROC)eglGetProcAddress("eglQueryDevicesEXT");
    PFNEGLQUERYDEVICESTRINGEXTPROC qstr =
        (PFNEGLQUERYDEVICESTRINGEXTPROC)eglGetProcAddress("eglQueryDeviceStringEXT");
    if (!get_dpy || !has_ext(cext, "EGL_EXT_platform_base")) {
        free(im);
        return rs_fail(err, PLAT_ERR_NO_DEVICE, "egl: EGL_EXT_platform_base is missing; cannot pick a headless display");
    }

    EGLDeviceEXT devs[MAX_DEVICES];
    EGLint ndev = 0;
    bool device_platform = qdev && qstr && has_ext(cext, "EGL_EXT_device_enumeration") &&
                           has_ext(cext, "EGL_EXT_platform_device");
    if (device_platform && !qdev(MAX_DEVICES, devs, &ndev))
        ndev = 0;

    /* candidates: hardware devices, surfaceless, software devices */
    struct cand {
        EGLenum platform;
        void *native;
        char name[96];
    } cands[MAX_DEVICES + 1];
    int nc = 0;
    const char *force = getenv("RINGSIDE_EGL_DEVICE");
    if (force && *force) {
        char *end;
        long i = strtol(force, &end, 10);
        if (*end || i < 0 || i >= ndev) {
            free(im);
            return rs_fail(err, PLAT_ERR_NO_DEVICE, "egl: RINGSIDE_EGL_DEVICE=%s: expected a device index 0..%d", force,
                           ndev - 1);
        }
        cands[nc].platform = EGL_PLATFORM_DEVICE_EXT;
        cands[nc].native = devs[i];
        char dn[64];
        device_name(devs[i], qstr, dn, sizeof dn);
        snprintf(cands[nc++].name, sizeof cands[0].name, "device %ld (%s)", i, dn);
    } else {
        for (int pass = 0; pass < 2; pass++) {
            for (EGLint i = 0; i < ndev; i++) {
                char dn[64];
                device_name(devs[i], qstr, dn, sizeof dn);
                bool sw = strcmp(dn, "software") == 0;
                if (sw != (pass == 1))
                    continue;
                cands[nc].platform = EGL_PLATFORM_DEVICE_EXT;
                cands[nc].native = devs[i];
                snprintf(cands[nc++].name, sizeof cands[0].name, "device %d (%s)", (int)i, dn);
            }
            if (pass == 0 && has_ext(cext, "EGL_MESA_platform_surfaceless")) {
                cands[nc].platform = EGL_PLATFORM_SURFACELESS_MESA;
                cands[nc].native = EGL_DEFAULT_DISPLAY;
                snprintf(cands[nc++].name, sizeof cands[0].name, "surfaceless");
            }
        }
    }
    if (nc == 0) {
        free(im);
        return rs_fail(err, PLAT_ERR_NO_DEVICE,
                       "egl: no EGL device and no Mesa surfaceless platform (client extensions: %s)", cext);
    }

    char whys[512] = "";
    for (int i = 0; i < nc; i++) {
        im->dpy = get_dpy(cands[i].platform, cands[i].native, NULL);
        char why[160] = "no display";
        snprintf(p->detail, sizeof p->detail, "%s", cands[i].name);
        if (im->dpy != EGL_NO_DISPLAY && make_context(p, im, why, sizeof why))
            return true;
        release(im);
        size_t l = strlen(whys);
        snprintf(whys + l, sizeof whys - l, "%s%s: %s", l ? "; " : "", cands[i].name, why);
    }
    free(im);
    p->impl = NULL;
    return rs_fail(err, PLAT_ERR_CONTEXT, "egl: no display gave a GL %d.%d core context (%s)", p->desc.gl_major,
                   p->desc.gl_minor, whys);
}

static void *egl_proc(plat *p, const char *name)
{
    (void)p;
    /* EGL 1.5 / EGL_KHR_get_all_proc_addresses: core functions too */
    return (void *)eglGetProcAddress(name);
}

static bool egl_make_current(plat *p)
{
    egl_impl *im = p->impl;
    return eglMakeCurrent(im->dpy, im->surf, im->surf, im->ctx);
}

static void egl_present(plat *p)
{
    (void)p;
}

static bool egl_poll(plat *p)
{
    (void)p;
    return true;
}

static void egl_destroy(plat *p)
{
    egl_impl *im = p->impl;
    if (!im)
        return;
    release(im);
    free(im);
    p->impl = NULL;
}

const plat_backend plat_egl_backend = {
    .name = "egl",
    .create = egl_create,
    .proc = egl_proc,
    .make_current = egl_make_current,
    .present = egl_present,
    .poll = egl_poll,
    .destroy = egl_destroy,
};

#else
typedef int plat_egl_not_built; /* ISO C wants something in a file */
#endif
