/* rs_oiio: OpenImageIO, loaded when first used (rs_oiio.h says why).
 *
 * DESIGN: one pthread_once loads the plugin and resolves its five entry
 * points; a failure is remembered with its message and every later call
 * returns it (one dlopen attempt a process).  The plugin's errors come back
 * in an rs_err it filled; rs_fail copies them here, folding OpenImageIO's
 * multi-line messages into one line.  The handle is never closed, so a
 * leak inside OpenImageIO keeps its library's name for tests/lsan.supp. */
#include "rs_oiio.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef RS_HAVE_OIIO
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <pthread.h>
#include <unistd.h>

#define PLUGIN "ringside-oiio.so"

static struct {
    pthread_once_t once;
    bool ok;
    char why[600];
    char version[64];
    int (*abi)(void);
    bool (*resize)(const uint8_t *, int, int, float *, int, int, rs_err *);
    bool (*encode)(const char *, int, int, const uint8_t *, uint8_t **, size_t *, rs_err *);
    bool (*read_float)(const char *, int *, int *, float **, rs_err *);
    const char *(*version_of)(void);
} P = {.once = PTHREAD_ONCE_INIT};

/* The plugin's path: RINGSIDE_OIIO_PLUGIN, or the first that exists of
 * beside the program (BUILD/), make install's lib/ringside and one folder
 * up (BUILD/tests/).  *label is how messages name it.  NULL with P.why set
 * when there is none. */
static const char *find(char *path, size_t n, const char **label)
{
    const char *env = getenv("RINGSIDE_OIIO_PLUGIN");
    if (env && *env) {
        *label = "RINGSIDE_OIIO_PLUGIN=";
        snprintf(path, n, "%s", env);
        if (access(path, F_OK) == 0)
            return path;
        snprintf(P.why, sizeof P.why, "RINGSIDE_OIIO_PLUGIN=%s: no such file", env);
        return NULL;
    }
    *label = "";
    char exe[PATH_MAX], tried[3 * (PATH_MAX + 64)] = "";
    ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (len <= 0) {
        snprintf(P.why, sizeof P.why, "cannot find the program's folder (/proc/self/exe) to look for %s", PLUGIN);
        return NULL;
    }
    exe[len] = 0;
    char *slash = strrchr(exe, '/');
    if (slash)
        *slash = 0;
    const char *where[] = {"%s/" PLUGIN, "%s/../lib/ringside/" PLUGIN, "%s/../" PLUGIN};
    for (size_t i = 0; i < sizeof where / sizeof *where; i++) {
        snprintf(path, n, where[i], exe);
        if (access(path, F_OK) == 0)
            return path;
        size_t t = strlen(tried);
        snprintf(tried + t, sizeof tried - t, "%s%s", t ? ", " : "", path);
    }
    snprintf(P.why, sizeof P.why, "%s not found (looked at %s; RINGSIDE_OIIO_PLUGIN names it)", PLUGIN, tried);
    return NULL;
}

static void load(void)
{
    char path[PATH_MAX + 64];
    const char *label;
    if (!find(path, sizeof path, &label))
        return;
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h) {
        const char *e = dlerror();
        snprintf(P.why, sizeof P.why, "%s%s: %s", label, path, e ? e : "cannot load");
        return;
    }
    *(void **)&P.abi = dlsym(h, "rs_oiio_plugin_abi");
    *(void **)&P.resize = dlsym(h, "rs_oiio_plugin_resize");
    *(void **)&P.encode = dlsym(h, "rs_oiio_plugin_encode");
    *(void **)&P.read_float = dlsym(h, "rs_oiio_plugin_read_float");
    *(void **)&P.version_of = dlsym(h, "rs_oiio_plugin_version");
    if (!P.abi || !P.resize || !P.encode || !P.read_float || !P.version_of) {
        snprintf(P.why, sizeof P.why, "%s is not ringside's OpenImageIO plugin (an entry point is missing)", path);
        return;
    }
    if (P.abi() != RS_OIIO_PLUGIN_ABI) {
        snprintf(P.why, sizeof P.why, "%s has interface %d, this program needs %d (a plugin of another build?)",
                 path, P.abi(), RS_OIIO_PLUGIN_ABI);
        return;
    }
    snprintf(P.version, sizeof P.version, "%s", P.version_of());
    P.ok = true;
}

static bool loaded(rs_err *err)
{
    pthread_once(&P.once, load);
    if (!P.ok && err)
        rs_fail(err, RS_OIIO_ERR_NO_PLUGIN, "OpenImageIO: %s", P.why);
    return P.ok;
}

/* the plugin's message, through rs_fail (one line) */
static bool pass_on(bool ok, const rs_err *e, rs_err *err)
{
    if (!ok)
        rs_fail(err, e->code ? e->code : RS_OIIO_ERR_READ, "%s", e->msg);
    return ok;
}

bool rs_oiio_resize(const uint8_t *rgba, int sw, int sh, float *out, int w, int h, rs_err *err)
{
    rs_err e = {0};
    return loaded(err) && pass_on(P.resize(rgba, sw, sh, out, w, h, &e), &e, err);
}

/* n bytes to a new file at path, every write() and the close() checked
 * (a full disk, a quota, a network filesystem that fails at close); on
 * failure the file is removed and the message gives the system's reason. */
static bool write_all(const char *path, const uint8_t *p, size_t n, rs_err *err)
{
    int fd = open(path, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0)
        return rs_fail(err, RS_OIIO_ERR_WRITE, "%s: %s", path, strerror(errno));
    int e = 0;
    while (n > 0 && !e) {
        ssize_t k = write(fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            e = k < 0 ? errno : EIO;
        else
            p += k, n -= (size_t)k;
    }
    if (close(fd) != 0 && !e)
        e = errno;
    if (!e)
        return true;
    unlink(path);
    return rs_fail(err, RS_OIIO_ERR_WRITE, "%s: %s", path, strerror(e));
}

bool rs_oiio_write(const char *path, const char *ext, int w, int h, const uint8_t *rgba, rs_err *err)
{
    rs_err e = {0};
    uint8_t *bytes = NULL;
    size_t n = 0;
    if (!loaded(err) || !pass_on(P.encode(ext, w, h, rgba, &bytes, &n, &e), &e, err))
        return false;
    bool ok = write_all(path, bytes, n, err);
    free(bytes);
    return ok;
}

bool rs_oiio_read_float(const char *path, int *w, int *h, float **rgb, rs_err *err)
{
    rs_err e = {0};
    *rgb = NULL;
    return loaded(err) && pass_on(P.read_float(path, w, h, rgb, &e), &e, err);
}

bool rs_oiio_ready(rs_err *err)
{
    return loaded(err);
}

const char *rs_oiio_version(void)
{
    return loaded(NULL) ? P.version : P.why;
}

#else

bool rs_oiio_resize(const uint8_t *rgba, int sw, int sh, float *out, int w, int h, rs_err *err)
{
    (void)rgba, (void)sw, (void)sh, (void)out, (void)w, (void)h;
    return rs_fail(err, RS_OIIO_ERR_NOT_BUILT, "this build has no OpenImageIO (install libopenimageio-dev and rebuild)");
}

bool rs_oiio_write(const char *path, const char *ext, int w, int h, const uint8_t *rgba, rs_err *err)
{
    (void)ext, (void)w, (void)h, (void)rgba;
    return rs_fail(err, RS_OIIO_ERR_NOT_BUILT, "%s: this build has no OpenImageIO, so no image sequences", path);
}

bool rs_oiio_read_float(const char *path, int *w, int *h, float **rgb, rs_err *err)
{
    (void)w, (void)h;
    *rgb = NULL;
    return rs_fail(err, RS_OIIO_ERR_NOT_BUILT,
                   "%s: built without OpenImageIO, so no image environments (install libopenimageio-dev and rebuild)",
                   path);
}

bool rs_oiio_ready(rs_err *err)
{
    return rs_fail(err, RS_OIIO_ERR_NOT_BUILT, "this build has no OpenImageIO (install libopenimageio-dev and rebuild)");
}

const char *rs_oiio_version(void)
{
    return "no OpenImageIO in this build";
}

#endif

const char *rs_oiio_error_text(rs_oiio_error e)
{
    static const char *const text[] = {
#define X(id, t) t,
        RS_OIIO_ERRORS(X)
#undef X
    };
    return (unsigned)e < RS_OIIO_ERR_COUNT ? text[e] : "unknown OpenImageIO error";
}
