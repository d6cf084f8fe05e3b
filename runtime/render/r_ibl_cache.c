/* The IBL cache: its key (r_ibl_hash), the file format, reading with
 * every field checked, atomic writing, and where the cache lives. */
#include "r_ibl_local.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../util/rs_file.h"
#include "../util/rs_log.h"

/* ---------- the cache key ---------- */

static void fnv(uint64_t *h, const void *data, size_t n)
{
    const uint8_t *p = data;
    for (size_t k = 0; k < n; k++) {
        *h ^= p[k];
        *h *= 0x100000001b3ull;
    }
}

#define FNV_START 0xcbf29ce484222325ull

static void fnv_u32(uint64_t *h, uint32_t v)
{
    uint8_t b[4] = {(uint8_t)v, (uint8_t)(v >> 8), (uint8_t)(v >> 16), (uint8_t)(v >> 24)};
    fnv(h, b, 4);
}

static void fnv_f32(uint64_t *h, const float *v, int n)
{
    for (int k = 0; k < n; k++) {
        uint32_t u;
        memcpy(&u, &v[k], 4);
        fnv_u32(h, u);
    }
}

static void fnv_light(uint64_t *h, const r_paint_light *l)
{
    fnv_f32(h, l->dir, 3);
    fnv_f32(h, l->color, 3);
    fnv_f32(h, &l->intensity, 1);
    fnv_f32(h, &l->size_deg, 1);
}

static bool fnv_file(uint64_t *h, const char *path, rs_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return rs_fail(err, R_IBL_ERR_FILE, "%s: cannot open: %s", path, strerror(errno));
    uint8_t buf[65536];
    size_t got, total = 0;
    while ((got = fread(buf, 1, sizeof buf, f)) > 0) {
        fnv(h, buf, got);
        total += got;
    }
    bool ok = !ferror(f);
    int saved = errno;
    fclose(f);
    if (!ok)
        return rs_fail(err, R_IBL_ERR_FILE, "%s: read error: %s", path, strerror(saved));
    fnv_u32(h, (uint32_t)total);
    fnv_u32(h, (uint32_t)((uint64_t)total >> 32));
    return true;
}

bool r_ibl_hash(const r_stage *st, const r_ibl_params *pin, uint64_t *hash, rs_err *err)
{
    r_ibl_params p;
    if (!r_ibl_resolve_params(pin, &p, err))
        return false;
    uint64_t h = FNV_START;
    fnv_u32(&h, R_IBL_FORMAT_VERSION);
    fnv_u32(&h, (uint32_t)p.src_size); /* not threads: the maps do not depend on it */
    for (int m = 0; m < R_IBL_MAPS; m++)
        fnv_u32(&h, (uint32_t)p.out_size[m]);
    if (st->env_path[0]) {
        fnv_u32(&h, 1);
        if (!fnv_file(&h, st->env_path, err))
            return false;
        fnv_f32(&h, &st->env_rotate_deg, 1);
        fnv_f32(&h, &st->env_scale, 1);
    } else {
        fnv_u32(&h, 0);
        fnv_f32(&h, st->sky_zenith, 3);
        fnv_f32(&h, st->sky_horizon, 3);
        fnv_f32(&h, st->ground, 3);
        fnv_light(&h, &st->key);
        fnv_light(&h, &st->counter);
    }
    fnv_u32(&h, st->sun);
    fnv_f32(&h, st->sun_dir, 3);
    fnv_f32(&h, st->sun_color, 3);
    fnv_f32(&h, &st->sun_intensity, 1);
    fnv_f32(&h, &st->key_area_deg, 1);
    *hash = h;
    return true;
}

/* ---------- the cache file ----------
 * "RSIBL\0\0\0", u32 format version, u64 hash, u32 src_size, u32 out_size[3],
 * f32 key_dir[3], then every map as RGB f32 in the order [map][key][face]
 * (key off first), rows top-down, then u64 FNV-1a of all bytes before it.
 * Little-endian throughout. */

#define CACHE_MAGIC "RSIBL\0\0\0"
#define CACHE_HEAD (8 + 4 + 8 + 4 * 4 + 3 * 4)

static size_t cache_len(const r_ibl_params *p)
{
    size_t floats = 0;
    for (int m = 0; m < R_IBL_MAPS; m++)
        floats += (size_t)2 * 6 * p->out_size[m] * p->out_size[m] * 3;
    return CACHE_HEAD + floats * 4 + 8;
}

static uint8_t *put_u32(uint8_t *b, uint32_t v)
{
    for (int k = 0; k < 4; k++)
        b[k] = (uint8_t)(v >> (8 * k));
    return b + 4;
}

static uint8_t *put_u64(uint8_t *b, uint64_t v)
{
    for (int k = 0; k < 8; k++)
        b[k] = (uint8_t)(v >> (8 * k));
    return b + 8;
}

static uint8_t *put_f32(uint8_t *b, float f)
{
    uint32_t u;
    memcpy(&u, &f, 4);
    return put_u32(b, u);
}

static uint32_t get_u32(const uint8_t *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

static uint64_t get_u64(const uint8_t *b)
{
    return (uint64_t)get_u32(b) | (uint64_t)get_u32(b + 4) << 32;
}

static float get_f32(const uint8_t *b)
{
    uint32_t u = get_u32(b);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

/* Writes the file under a temporary name of its own (mkstemp in the same
 * directory) and renames it into place: two processes that miss the same
 * entry at once each write their own file, and the last rename wins with
 * a complete one. */
static bool write_unique(const char *path, const void *data, size_t n, rs_err *err)
{
    char tmp[PATH_MAX + 16];
    snprintf(tmp, sizeof tmp, "%s.XXXXXX", path);
    int fd = mkstemp(tmp);
    if (fd < 0)
        return rs_fail(err, R_IBL_ERR_FILE, "%s: cannot create: %s", tmp, strerror(errno));
    const char *p = data;
    size_t left = n;
    int saved = 0;
    while (left > 0) {
        ssize_t w = write(fd, p, left);
        if (w < 0 && errno == EINTR)
            continue;
        if (w <= 0) {
            saved = w < 0 ? errno : EIO;
            break;
        }
        p += w, left -= (size_t)w;
    }
    if (!saved && fsync(fd) != 0)
        saved = errno;
    if (close(fd) != 0 && !saved)
        saved = errno;
    if (!saved && rename(tmp, path) != 0)
        saved = errno;
    if (saved) {
        unlink(tmp);
        return rs_fail(err, R_IBL_ERR_FILE, "%s: write failed: %s", path, strerror(saved));
    }
    return true;
}

void r_ibl_cache_write(const char *path, const r_ibl_params *p, const r_ibl *ibl)
{
    size_t len = cache_len(p);
    uint8_t *buf = malloc(len), *b = buf;
    rs_err e = {0};
    if (!buf) {
        rs_fail(&e, R_IBL_ERR_MEMORY, "%s: out of memory", path);
    } else {
        memcpy(b, CACHE_MAGIC, 8);
        b = put_u32(b + 8, R_IBL_FORMAT_VERSION);
        b = put_u64(b, ibl->hash);
        b = put_u32(b, (uint32_t)p->src_size);
        for (int m = 0; m < R_IBL_MAPS; m++)
            b = put_u32(b, (uint32_t)p->out_size[m]);
        for (int k = 0; k < 3; k++)
            b = put_f32(b, ibl->key_dir[k]);
        for (int m = 0; m < R_IBL_MAPS; m++)
            for (int k = 0; k < 2; k++)
                for (int f = 0; f < 6; f++)
                    for (size_t i = 0; i < (size_t)ibl->size[m] * ibl->size[m] * 3; i++)
                        b = put_f32(b, ibl->map[m][k][f][i]);
        uint64_t h = FNV_START;
        fnv(&h, buf, (size_t)(b - buf));
        put_u64(b, h);
    }
    if ((!buf || !rs_mkdirs_for(path, &e) || !write_unique(path, buf, len, &e)) && rs_log_on(RS_LOG_WARNING))
        fprintf(stderr, "ringside: warning: %s (IBL cache not saved; going on without it)\n", e.msg);
    free(buf);
}

static const char *whyf(char *why, size_t n, const char *fmt, ...) RS_PRINTF(3, 4);
static const char *whyf(char *why, size_t n, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, n, fmt, ap);
    va_end(ap);
    return why;
}

/* Why the bytes are not a cache file for this request, or NULL. */
static const char *cache_check(const uint8_t *b, size_t len, size_t want, const r_ibl_params *p, uint64_t hash,
                               char *why, size_t n)
{
    if (len < CACHE_HEAD + 8)
        return whyf(why, n, "%zu bytes, shorter than its header", len);
    if (memcmp(b, CACHE_MAGIC, 8))
        return "not an IBL cache file (bad magic)";
    if (get_u32(b + 8) != R_IBL_FORMAT_VERSION)
        return whyf(why, n, "format version %u, expected %d", get_u32(b + 8), R_IBL_FORMAT_VERSION);
    if (len != want)
        return whyf(why, n, "%zu bytes, expected %zu", len, want);
    uint64_t h = FNV_START;
    fnv(&h, b, len - 8);
    if (h != get_u64(b + len - 8))
        return "checksum mismatch";
    if (get_u64(b + 12) != hash)
        return whyf(why, n, "hash %016llx, expected %016llx", (unsigned long long)get_u64(b + 12),
                    (unsigned long long)hash);
    if (get_u32(b + 20) != (uint32_t)p->src_size)
        return "source size differs";
    for (int m = 0; m < R_IBL_MAPS; m++)
        if (get_u32(b + 24 + 4 * m) != (uint32_t)p->out_size[m])
            return "map sizes differ";
    double l2 = 0;
    for (int k = 0; k < 3; k++) {
        float v = get_f32(b + 36 + 4 * k);
        if (!isfinite(v))
            return "key direction not finite";
        l2 += (double)v * v;
    }
    if (fabs(l2 - 1) > 1e-3)
        return "key direction not of unit length";
    for (size_t o = CACHE_HEAD; o < len - 8; o += 4) {
        float v = get_f32(b + o);
        if (!(v >= 0 && v <= R_HALF_MAX))
            return whyf(why, n, "value out of range at byte %zu", o);
    }
    return NULL;
}

bool r_ibl_cache_read(const char *path, const r_ibl_params *p, uint64_t hash, r_ibl *out)
{
    struct stat sb;
    if (stat(path, &sb) != 0 && errno == ENOENT)
        return false; /* a plain miss */
    size_t want = cache_len(p), len = 0;
    rs_err e = {0};
    uint8_t *b = (uint8_t *)rs_read_file(path, want, &len, &e);
    char whyb[160];
    const char *why = NULL;
    if (!b && e.code == RS_FILE_ERR_TOO_BIG)
        why = whyf(whyb, sizeof whyb, "longer than %zu bytes", want);
    else if (!b)
        why = whyf(whyb, sizeof whyb, "unreadable: %s", e.msg);
    else
        why = cache_check(b, len, want, p, hash, whyb, sizeof whyb);
    if (why) {
        if (rs_log_on(RS_LOG_WARNING))
            fprintf(stderr, "ringside: %s: corrupt IBL cache (%s); rebuilding\n", path, why);
        free(b);
        return false;
    }
    bool ok = r_ibl_alloc_maps(out, &e);
    if (ok) {
        for (int k = 0; k < 3; k++)
            out->key_dir[k] = get_f32(b + 36 + 4 * k);
        const uint8_t *q = b + CACHE_HEAD;
        for (int m = 0; m < R_IBL_MAPS; m++)
            for (int k = 0; k < 2; k++)
                for (int f = 0; f < 6; f++)
                    for (size_t i = 0; i < (size_t)out->size[m] * out->size[m] * 3; i++, q += 4)
                        out->map[m][k][f][i] = get_f32(q);
    }
    free(b);
    return ok;
}

const char *r_ibl_cache_dir(void)
{
    static char dir[PATH_MAX];
    const char *v = getenv("RINGSIDE_CACHE");
    if (v && *v) {
        if (!strcmp(v, "off"))
            return NULL;
        snprintf(dir, sizeof dir, "%s", v);
        return dir;
    }
    if ((v = getenv("XDG_CACHE_HOME")) && *v)
        snprintf(dir, sizeof dir, "%s/ringside", v);
    else if ((v = getenv("HOME")) && *v)
        snprintf(dir, sizeof dir, "%s/.cache/ringside", v);
    else
        return NULL;
    return dir;
}
