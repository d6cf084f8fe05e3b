/* mv_up: frames onto three R8 textures (Y, Cb, Cr), and the shader that
 * converts them to RGB.
 *
 * Three ways to get a packed frame (mv.h) onto the textures:
 *   PBO         the default: two GL_PIXEL_UNPACK_BUFFERs in
 *               ping-pong.  mv_up_stage copies the next frame into one
 *               (map with invalidate, memcpy, unmap: the transfer can start)
 *               while the other, filled the tick before, defines the
 *               textures in mv_up_commit from offsets 0, nY, nY+nC.
 *   DIRECT      glTexSubImage2D from client memory: the driver copies (and
 *               may wait) inside the call.
 *   PERSISTENT  one buffer, persistently and coherently mapped
 *               (glBufferStorage, GL 4.4 / ARB_buffer_storage), cut into
 *               slots; the decoder writes frames straight into a slot (no
 *               second copy), the textures are defined from the slot's
 *               offset and a fence says when the GPU is done reading it.
 * Rows are packed (GL_UNPACK_ALIGNMENT 1), so odd widths need no padding. */
#ifndef MV_UP_H
#define MV_UP_H

#include <stdbool.h>
#include <stdint.h>

#include "mv.h"
#include "mv_csp.h"

enum { MV_UP_PBO = 0, MV_UP_DIRECT = 1, MV_UP_PERSISTENT = 2, MV_UP_COUNT };

typedef struct mv_up mv_up;

typedef struct mv_up_stats {
    int64_t uploads;  /* frames defined on the textures */
    int64_t staged;   /* PBO: frames copied a tick ahead */
    double copy_ms;   /* CPU copying into staging memory (PBO) */
    double upload_ms; /* CPU in the GL calls that define the textures (and map/unmap) */
} mv_up_stats;

const char *mv_up_name(int mode);
/* "pbo", "direct", "persistent" -> MV_UP_*; -1 when unknown. */
int mv_up_parse(const char *name);

/* Needs a current GL context.  nslots: how many frame slots the caller's
 * decoder uses; slot memory is malloc'd, or (PERSISTENT) mapped. */
mv_up *mv_up_create(const mv_info *info, int mode, int nslots, rs_err *err);
void mv_up_destroy(mv_up *u);
int mv_up_mode(const mv_up *u);
uint8_t *mv_up_slot(mv_up *u, int slot);

/* Colour conversion; mv_up_create sets the stream's. */
void mv_up_set_csp(mv_up *u, int matrix, bool full_range);

/* The frame in `slot` onto the textures now (PBO: through the buffer the
 * textures were not last defined from).  PERSISTENT: the slot stays busy
 * until the GPU has read it (mv_up_busy). */
void mv_up_upload(mv_up *u, int slot);
/* PBO only: copies the frame in `slot` into the idle buffer; the next
 * mv_up_commit defines the textures from it.  Other modes: false. */
bool mv_up_stage(mv_up *u, int slot);
void mv_up_commit(mv_up *u);
bool mv_up_has_staged(const mv_up *u);
/* PERSISTENT: true while the GPU may still read `slot`; wait: block (up to
 * a second) for it.  Other modes: always false. */
bool mv_up_busy(mv_up *u, int slot, bool wait);

/* Draws the textures, letterboxed to the picture's display aspect, into
 * the bound framebuffer of size vw x vh (black bars are cleared). */
void mv_up_draw(mv_up *u, int vw, int vh);
void mv_up_stats_get(const mv_up *u, mv_up_stats *st);

#endif
