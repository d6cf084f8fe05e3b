/* Files and the data directory (where shaders/ and other run-time data live). */
#ifndef RS_FILE_H
#define RS_FILE_H

#include <stdbool.h>
#include <stddef.h>

#include "rs_err.h"

enum { RS_FILE_ERR_OPEN = 1, RS_FILE_ERR_READ, RS_FILE_ERR_TOO_BIG, RS_FILE_ERR_WRITE, RS_FILE_ERR_NO_DATA };

/* Reads a whole file, NUL-terminated; refuses files over max_bytes so user
 * data can never make us allocate without bound.  Free with free(). */
char *rs_read_file(const char *path, size_t max_bytes, size_t *len, rs_err *err);

/* The data root: a directory holding shaders/.  Search order:
 *   $RINGSIDE_DATA, then <dir of the executable>/.. (the source tree:
 *   build/ringside), then <dir of the executable>/../share/ringside
 *   (after `make install`).
 * The result is cached; rs_data_reset() forgets it (tests). */
const char *rs_data_dir(rs_err *err);
void rs_data_reset(void);

/* Writes "<root>/<rel>" into out; the root is shown relative to the
 * current directory when it is the current directory, so messages read
 * "shaders/x.frag" from the source tree. */
void rs_data_path(const char *root, const char *rel, char *out, size_t n);

/* Creates the directories above path (mkdir -p of its parent). */
bool rs_mkdirs_for(const char *path, rs_err *err);

/* Atomic output: write to "<path>.part", then rs_commit_file renames it.
 * A failed run never leaves a file that looks finished. */
void rs_part_path(const char *path, char *out, size_t n);
/* Writes n bytes to "<path>.part" and fsyncs it; on failure the part file is
 * removed and the message names the file and the system's reason. */
bool rs_write_part(const char *path, const void *data, size_t n, rs_err *err);
bool rs_commit_file(const char *path, rs_err *err);

#endif
