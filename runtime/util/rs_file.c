#define _XOPEN_SOURCE 700 /* realpath */
#include "rs_file.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

char *rs_read_file(const char *path, size_t max_bytes, size_t *len, rs_err *err)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        rs_fail(err, RS_FILE_ERR_OPEN, "%s: cannot open: %s", path, strerror(errno));
        return NULL;
    }
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n + 4096 + 1 > cap) {
            cap = cap ? cap * 2 : 8192;
            char *nb = realloc(buf, cap);
            if (!nb) {
                rs_fail(err, RS_FILE_ERR_READ, "%s: out of memory", path);
                goto fail;
            }
            buf = nb;
        }
        size_t got = fread(buf + n, 1, cap - n - 1, f);
        n += got;
        if (n > max_bytes) {
            rs_fail(err, RS_FILE_ERR_TOO_BIG, "%s: larger than the limit of %zu bytes", path, max_bytes);
            goto fail;
        }
        if (got == 0) {
            if (ferror(f)) {
                rs_fail(err, RS_FILE_ERR_READ, "%s: read error: %s", path, strerror(errno));
                goto fail;
            }
            break;
        }
    }
    fclose(f);
    buf[n] = 0;
    if (len)
        *len = n;
    return buf;
fail:
    fclose(f);
    free(buf);
    return NULL;
}

static char data_root[PATH_MAX];

static bool has_shaders(const char *dir)
{
    char p[PATH_MAX + 16];
    struct stat st;
    snprintf(p, sizeof p, "%s/shaders", dir);
    return stat(p, &st) == 0 && S_ISDIR(st.st_mode);
}

const char *rs_data_dir(rs_err *err)
{
    if (data_root[0])
        return data_root;
    const char *env = getenv("RINGSIDE_DATA");
    if (env && *env) {
        if (!has_shaders(env)) {
            rs_fail(err, RS_FILE_ERR_NO_DATA, "RINGSIDE_DATA=%s: no shaders/ directory there", env);
            return NULL;
        }
        snprintf(data_root, sizeof data_root, "%s", env);
        return data_root;
    }
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) {
        rs_fail(err, RS_FILE_ERR_NO_DATA, "cannot find the data directory (no /proc/self/exe); set RINGSIDE_DATA");
        return NULL;
    }
    exe[n] = 0;
    char *slash = strrchr(exe, '/');
    if (slash)
        *slash = 0;
    static const char *const rel[] = {"..", "../share/ringside"};
    char tried[2 * PATH_MAX] = "";
    for (size_t i = 0; i < sizeof rel / sizeof rel[0]; i++) {
        char cand[PATH_MAX + 32], real[PATH_MAX];
        snprintf(cand, sizeof cand, "%s/%s", exe, rel[i]);
        if (has_shaders(cand) && realpath(cand, real)) {
            snprintf(data_root, sizeof data_root, "%s", real);
            return data_root;
        }
        size_t tl = strlen(tried);
        snprintf(tried + tl, sizeof tried - tl, "%s%s/shaders", tl ? ", " : "", cand);
    }
    rs_fail(err, RS_FILE_ERR_NO_DATA, "cannot find the shaders directory (tried %s); set RINGSIDE_DATA", tried);
    return NULL;
}

void rs_data_reset(void)
{
    data_root[0] = 0;
}

void rs_data_path(const char *root, const char *rel, char *out, size_t n)
{
    char cwd[PATH_MAX];
    if (getcwd(cwd, sizeof cwd) && strcmp(cwd, root) == 0)
        snprintf(out, n, "%s", rel);
    else
        snprintf(out, n, "%s/%s", root, rel);
}

void rs_part_path(const char *path, char *out, size_t n)
{
    snprintf(out, n, "%s.part", path);
}

bool rs_write_part(const char *path, const void *data, size_t n, rs_err *err)
{
    char part[PATH_MAX + 8];
    rs_part_path(path, part, sizeof part);
    FILE *f = fopen(part, "wb");
    if (!f)
        return rs_fail(err, RS_FILE_ERR_WRITE, "%s: cannot create (as %s): %s", path, part, strerror(errno));
    errno = 0;
    bool ok = fwrite(data, 1, n, f) == n;
    int saved = errno;
    ok = fflush(f) == 0 && ok;
    if (!saved)
        saved = errno;
    ok = fsync(fileno(f)) == 0 && ok;
    ok = fclose(f) == 0 && ok;
    if (!ok) {
        if (!saved)
            saved = errno;
        unlink(part);
        return rs_fail(err, RS_FILE_ERR_WRITE, "%s: write failed: %s", path, strerror(saved));
    }
    return true;
}

bool rs_commit_file(const char *path, rs_err *err)
{
    char part[PATH_MAX + 8];
    rs_part_path(path, part, sizeof part);
    if (rename(part, path) != 0) {
        rs_fail(err, RS_FILE_ERR_WRITE, "%s: cannot rename %s into place: %s", path, part, strerror(errno));
        unlink(part);
        return false;
    }
    return true;
}

bool rs_mkdirs_for(const char *path, rs_err *err)
{
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (!slash || slash == dir)
        return true;
    *slash = 0;
    for (char *p = dir + 1;; p++) {
        bool last = *p == 0;
        if (*p == '/' || last) {
            char c = *p;
            *p = 0;
            if (mkdir(dir, 0777) != 0 && errno != EEXIST)
                return rs_fail(err, RS_FILE_ERR_WRITE, "%s: cannot create directory %s: %s", path, dir, strerror(errno));
            *p = c;
        }
        if (last)
            break;
    }
    return true;
}
