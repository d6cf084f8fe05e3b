/* Output rules (rs_out.h): overwrite and missing-folder checks. */
#include "rs_out.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

bool rs_out_is_stream(const char *path)
{
    struct stat st; /* stat follows links: /dev/stdout is whatever fd 1 is */
    return !strcmp(path, "-") ||
           (stat(path, &st) == 0 && (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode) || S_ISSOCK(st.st_mode)));
}

bool rs_out_check(const char *path, bool overwrite, rs_err *err)
{
    if (rs_out_is_stream(path))
        return true;
    struct stat st;
    if (stat(path, &st) == 0) {
        if (!S_ISREG(st.st_mode))
            return rs_fail(err, RS_OUT_ERR_NOT_FILE, "%s: exists and is not a regular file", path);
        if (!overwrite)
            return rs_fail(err, RS_OUT_ERR_EXISTS, "%s: exists (use -y to overwrite)", path);
        return true;
    }
    /* DESIGN: refuse, as ffmpeg does, rather than create: a mistyped folder
     * would otherwise become a new tree of outputs nobody looks for */
    char dir[PATH_MAX];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (!slash)
        return true; /* the current folder */
    if (slash == dir)
        slash[1] = 0; /* "/x": the root */
    else
        *slash = 0;
    if (stat(dir, &st) != 0)
        return errno == ENOENT ? rs_fail(err, RS_OUT_ERR_NO_FOLDER, "%s: folder %s does not exist", path, dir)
                               : rs_fail(err, RS_OUT_ERR_NO_FOLDER, "%s: folder %s: %s", path, dir, strerror(errno));
    if (!S_ISDIR(st.st_mode))
        return rs_fail(err, RS_OUT_ERR_NO_FOLDER, "%s: %s is not a folder", path, dir);
    return true;
}
