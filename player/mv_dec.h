/* The decode thread: reads a movie source into a small ring of frame slots
 * so a slow frame never stalls the 60 Hz loop.
 *
 * The slots are memory the caller provides (malloc'd, or slices of a
 * persistently mapped GPU buffer), each mv_frame_bytes() long.  A slot is
 * in one of three hands: free (the decoder may fill it), queued (decoded,
 * in order, waiting for the display) or held by the display (popped, not
 * yet released: still being read by the GPU, say).  The decoder only writes
 * free slots; the queue is bounded by the slot count. */
#ifndef MV_DEC_H
#define MV_DEC_H

#include <stdbool.h>
#include <stdint.h>

#include "mv.h"

#define MV_DEC_MAX_SLOTS 16

enum { MV_DEC_FRAME = 0, MV_DEC_NONE = -1, MV_DEC_END = -2, MV_DEC_ERROR = -3 };

typedef struct mv_dec mv_dec;

/* Takes no ownership of src or slots; src must outlive the thread. */
mv_dec *mv_dec_start(mv_src *src, uint8_t *const *slots, int nslots, rs_err *err);

/* The oldest queued frame: MV_DEC_FRAME with *slot and *index set, or
 * MV_DEC_NONE (nothing decoded yet), MV_DEC_END (the movie is over and the
 * queue empty) or MV_DEC_ERROR (the decoder failed; mv_dec_error says why;
 * frames decoded before the failure are delivered first).
 * wait_ms > 0 waits up to that long for a frame; < 0 waits as long as it takes. */
int mv_dec_peek(mv_dec *d, int wait_ms, int *slot, int64_t *index);
/* Takes the oldest queued frame off the queue; the caller now holds its slot. */
void mv_dec_pop(mv_dec *d);
/* Hands a held slot back to the decoder. */
void mv_dec_release(mv_dec *d, int slot);
const rs_err *mv_dec_error(mv_dec *d);
/* Slots the display holds (popped, not released). */
int mv_dec_held(mv_dec *d);
/* Milliseconds the decoder spent reading frames, and how many. */
void mv_dec_stats(mv_dec *d, double *ms, int64_t *frames);

/* Stops and joins the thread (a read in progress finishes first). */
void mv_dec_stop(mv_dec *d);

#endif
