/* Output rules every command follows, ffmpeg's: an existing output is
 * refused unless the user said -y; a missing folder is refused, named,
 * never created; "-", devices and pipes are streams, never "existing".
 * The checks run before any work, so a refused run touches nothing. */
#ifndef RS_OUT_H
#define RS_OUT_H

#include <stdbool.h>

#include "rs_err.h"

/* Block-0 codes (rs_err.h): they mean something only next to these calls. */
enum { RS_OUT_ERR_EXISTS = 1, RS_OUT_ERR_NO_FOLDER, RS_OUT_ERR_NOT_FILE };

/* "-" (standard output), or an existing character device, pipe or socket:
 * written in place, never renamed, never refused as existing. */
bool rs_out_is_stream(const char *path);

/* May path be written?  Streams: yes.  Otherwise the folder it names must
 * exist ("x/y.mp4: folder x does not exist"), and an existing entry is
 * refused unless overwrite ("y.mp4: exists (use -y to overwrite)"); an
 * existing directory or other non-file is refused either way. */
bool rs_out_check(const char *path, bool overwrite, rs_err *err);

#endif
