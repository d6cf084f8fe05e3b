/* The writer: a pthread that takes finished frames from a bounded queue and
 * hands them to the sink, so encoding and disk never stall the game thread
 * until the queue is full. */
#ifndef CAP_WRITER_H
#define CAP_WRITER_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "cap_sink.h"

typedef struct cap_writer cap_writer;

typedef struct cap_writer_stats {
    uint64_t frames;
    int high_water;         /* most frames ever queued at once */
    uint64_t full_waits;    /* times the game thread waited for a free slot */
    double wait_ms;         /* game thread time spent waiting */
    double write_ms;        /* writer time in the sink (encode + write) */
} cap_writer_stats;

/* queue_cap 0: no thread, frames are written inline by submit (the
 * sequential reference).  Otherwise queue_cap slots of frame_bytes each are
 * allocated once; peak memory is queue_cap * frame_bytes.
 * hashes: optional FILE for "index hash" lines (written by the writer, in
 * order); the sink must be opened already. */
cap_writer *cap_writer_start(cap_sink *sink, size_t frame_bytes, int queue_cap, FILE *hashes, rs_err *err);

/* A slot to fill.  Waits (on a condition variable) while the queue is
 * full.  NULL when the writer has failed: cap_writer_finish says why. */
uint8_t *cap_writer_acquire(cap_writer *w);
/* Hands the filled slot to the writer; false when the writer has failed. */
bool cap_writer_submit(cap_writer *w, uint8_t *slot);
/* Gives an acquired slot back unwritten (the frame could not be filled). */
void cap_writer_cancel(cap_writer *w, uint8_t *slot);
/* Waits for every queued frame, joins the thread, frees the slots.  Returns
 * the first error of the writer (disk full, encoder failure). */
bool cap_writer_finish(cap_writer *w, cap_writer_stats *stats, rs_err *err);

#endif
