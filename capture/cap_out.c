#include "cap_out.h"

#include <errno.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../runtime/util/rs_out.h"
#include "cap_sink.h" /* CAP_ERRORS */

bool cap_out_is_stream(const char *path)
{
    return rs_out_is_stream(path);
}

const char *cap_out_name(const char *path)
{
    return strcmp(path, "-") ? path : "standard output";
}

bool cap_out_open(cap_out *o, const char *path, rs_err *err)
{
    memset(o, 0, sizeof *o);
    snprintf(o->path, sizeof o->path, "%s", path);
    o->device = cap_out_is_stream(path);
    /* the folder must exist (named in the message, never the .part name);
     * whether an existing output may be replaced is the command's check */
    if (!o->device && !rs_out_check(path, true, err)) {
        if (err)
            err->code = CAP_ERR_CREATE; /* rs_out's failure, as one of ours */
        return false;
    }
    snprintf(o->tmp, sizeof o->tmp, o->device ? "%s" : "%s.part", path);
    if (!strcmp(path, "-")) { /* standard output: a copy of fd 1, so closing it leaves stdout alone */
        int fd = dup(1);
        o->f = fd >= 0 ? fdopen(fd, "wb") : NULL;
        if (!o->f && fd >= 0)
            close(fd);
    } else {
        o->f = fopen(o->tmp, "wb");
    }
    if (!o->f)
        return rs_fail(err, CAP_ERR_CREATE, "%s: cannot create (as %s): %s", cap_out_name(o->path), o->tmp, strerror(errno));
    setvbuf(o->f, NULL, _IOFBF, 1 << 20);
    return true;
}

bool cap_out_write(cap_out *o, const void *data, size_t n, rs_err *err)
{
    errno = 0;
    if (fwrite(data, 1, n, o->f) != n) {
        if (errno == EPIPE)
            return rs_fail(err, CAP_ERR_PIPE_CLOSED, "%s: the reader closed the pipe", cap_out_name(o->path));
        return rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", cap_out_name(o->path), strerror(errno ? errno : EIO));
    }
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
            if (e == EPIPE)
                return rs_fail(err, CAP_ERR_PIPE_CLOSED, "%s: the reader closed the pipe before the end", cap_out_name(o->path));
            return rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", cap_out_name(o->path), strerror(e ? e : EIO));
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
