/* The output file of a sink: "<path>.part" until commit renames it, or the
 * path itself when it is a stream ("-" for standard output, /dev/null,
 * /dev/full, a pipe such as /dev/stdout): nothing to rename. */
#ifndef CAP_OUT_H
#define CAP_OUT_H

#include <stdbool.h>
#include <stdio.h>

#include "../runtime/util/rs_err.h"

typedef struct cap_out {
    FILE *f;
    char path[1024], tmp[1040];
    bool device;
} cap_out;

bool cap_out_open(cap_out *o, const char *path, rs_err *err);
/* path as messages name it: "-" is "standard output" */
const char *cap_out_name(const char *path);
/* "-", or an existing character device, pipe or socket: written in place, never renamed. */
bool cap_out_is_stream(const char *path);
bool cap_out_write(cap_out *o, const void *data, size_t n, rs_err *err);
/* ok: flush, fsync, rename into place; !ok: close and remove. */
bool cap_out_close(cap_out *o, bool ok, rs_err *err);

#endif
