#include "cap_out.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../runtime/util/rs_file.h"
#include "cap_sink.h" /* CAP_ERRORS */

bool cap_out_is_stream(const char *path)
{
    struct stat st; /* stat follows links: /dev/stdout is whatever fd 1 is */
    return stat(path, &st) == 0 && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode));
}

bool cap_out_open(cap_out *o, const char *path, rs_err *err)
{
    memset(o, 0, sizeof *o);
    snprintf(o->path, sizeof o->path, "%s", path);
    o->device = cap_out_is_stream(path);
    struct stat st;
    if (!o->device && stat(path, &st) == 0 && !S_ISREG(st.st_mode))
        return rs_fail(err, CAP_ERR_CREATE, "%s: exists and is not a regular file (nor a device or pipe to stream to)", path);
    snprintf(o->tmp, sizeof o->tmp, o->device ? "%s" : "%s.part", path);
    if (!o->device && !rs_mkdirs_for(path, err)) {
        if (err)
            err->code = CAP_ERR_CREATE; /* rs_file's failure, as one of ours */
        return false;
    }
    o->f = fopen(o->tmp, "wb");
    if (!o->f)
        return rs_fail(err, CAP_ERR_CREATE, "%s: cannot create: %s", o->tmp, strerror(errno));
    setvbuf(o->f, NULL, _IOFBF, 1 << 20);
    return true;
}

bool cap_out_write(cap_out *o, const void *data, size_t n, rs_err *err)
{
    errno = 0;
    if (fwrite(data, 1, n, o->f) != n)
        return rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", o->path, strerror(errno ? errno : EIO));
    return true;
}

bool cap_out_close(cap_out *o, bool ok, rs_err *err)
{
    if (!o->f)
        return !ok;
    if (ok) {
        errno = 0;
        bool good = fflush(o->f) == 0;
        int e = errno;
        if (good && !o->device && fsync(fileno(o->f)) != 0) {
            good = false;
            e = errno;
        }
        if (fclose(o->f) != 0 && good) {
            good = false;
            e = errno;
        }
        o->f = NULL;
        if (!good) {
            if (!o->device)
                unlink(o->tmp);
            return rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", o->path, strerror(e ? e : EIO));
        }
        if (!o->device && rename(o->tmp, o->path) != 0) {
            e = errno;
            unlink(o->tmp);
            return rs_fail(err, CAP_ERR_WRITE, "%s: cannot rename %s into place: %s", o->path, o->tmp, strerror(e));
        }
        return true;
    }
    fclose(o->f);
    o->f = NULL;
    if (!o->device)
        unlink(o->tmp);
    return true;
}
