/* DESIGN: who owns what
 *
 * Threads: the game thread (renders, reads back, fills slots) and one
 * writer thread (owns the sink and the hashes file once started).
 *
 * Slots: `nslots` buffers allocated once.  A slot is always in exactly one
 * place: the free stack (nobody uses it), the game thread's hands (between
 * acquire and submit), the ready ring (queued, FIFO), or the writer's hands
 * (being written).  Both lists are guarded by `mu`; the game thread waits
 * on `cv_free` when no slot is free, the writer on `cv_ready` when nothing
 * is queued.  No frame is ever dropped: acquire waits instead.
 *
 * Errors: the writer stores the first sink error in `err` and `failed`,
 * stops writing and wakes the game thread; acquire/submit then return
 * NULL/false and cap_writer_finish returns the message.
 *
 * Queue 0 runs without a thread: submit writes inline (the sequential
 * reference, and the benchmark's queue=0 case). */
#include "cap_writer.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_progress.h"

struct cap_writer {
    cap_sink *sink;
    FILE *hashes;
    size_t frame_bytes;
    int nslots;
    uint8_t *mem;
    uint8_t **free_stack;
    int nfree;
    uint8_t **ready; /* ring of nslots */
    int rhead, rcount;
    bool threaded, done, failed;
    pthread_t thread;
    pthread_mutex_t mu;
    pthread_cond_t cv_free, cv_ready;
    uint64_t next_index;
    cap_writer_stats st;
    rs_err err;
};

/* Writes one frame; called by the writer thread (or inline at queue 0). */
static bool write_one(cap_writer *w, const uint8_t *frame, uint64_t index, rs_err *err)
{
    double t0 = rs_now();
    if (w->hashes && fprintf(w->hashes, "%llu %016llx\n", (unsigned long long)(index + w->sink->index_base),
                             (unsigned long long)rs_fnv1a64(frame, w->frame_bytes)) < 0)
        return rs_fail(err, CAP_ERR_WRITE, "writing the frame hash list failed at frame %llu: %s",
                       (unsigned long long)(index + w->sink->index_base), strerror(errno));
    bool ok = w->sink->ops->write(w->sink, frame, index, err);
    if (!ok && err && err->code == CAP_ERR_PIPE_CLOSED) { /* where the reader stopped */
        size_t l = strlen(err->msg);
        snprintf(err->msg + l, sizeof err->msg - l, " at frame %llu", (unsigned long long)(index + w->sink->index_base));
    }
    w->st.write_ms += (rs_now() - t0) * 1e3;
    if (ok)
        w->st.frames++;
    return ok;
}

static void *writer_main(void *arg)
{
    cap_writer *w = arg;
    pthread_mutex_lock(&w->mu);
    for (;;) {
        while (w->rcount == 0 && !w->done)
            pthread_cond_wait(&w->cv_ready, &w->mu);
        if (w->rcount == 0 && w->done)
            break;
        uint8_t *slot = w->ready[w->rhead];
        w->rhead = (w->rhead + 1) % w->nslots;
        w->rcount--;
        uint64_t index = w->next_index++;
        bool failed = w->failed;
        pthread_mutex_unlock(&w->mu);

        rs_err e = {0};
        bool ok = failed || write_one(w, slot, index, &e); /* after a failure, only drain */

        pthread_mutex_lock(&w->mu);
        if (!ok && !w->failed) {
            w->failed = true;
            w->err = e;
        }
        w->free_stack[w->nfree++] = slot;
        pthread_cond_signal(&w->cv_free);
    }
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

cap_writer *cap_writer_start(cap_sink *sink, size_t frame_bytes, int queue_cap, FILE *hashes, rs_err *err)
{
    cap_writer *w = calloc(1, sizeof *w);
    if (!w) {
        rs_fail(err, CAP_ERR_NOMEM, "out of memory");
        return NULL;
    }
    w->sink = sink;
    w->hashes = hashes;
    w->frame_bytes = frame_bytes;
    w->threaded = queue_cap > 0;
    w->nslots = queue_cap > 0 ? queue_cap : 1;
    w->mem = malloc(frame_bytes * (size_t)w->nslots);
    w->free_stack = malloc(sizeof(uint8_t *) * (size_t)w->nslots);
    w->ready = malloc(sizeof(uint8_t *) * (size_t)w->nslots);
    if (!w->mem || !w->free_stack || !w->ready) {
        rs_fail(err, CAP_ERR_NOMEM, "out of memory for %d frame slots of %zu bytes", w->nslots, frame_bytes);
        goto fail;
    }
    for (int i = 0; i < w->nslots; i++)
        w->free_stack[w->nfree++] = w->mem + frame_bytes * (size_t)i;
    pthread_mutex_init(&w->mu, NULL);
    pthread_cond_init(&w->cv_free, NULL);
    pthread_cond_init(&w->cv_ready, NULL);
    if (w->threaded && pthread_create(&w->thread, NULL, writer_main, w) != 0) {
        rs_fail(err, CAP_ERR_NOMEM, "cannot start the writer thread");
        pthread_mutex_destroy(&w->mu);
        pthread_cond_destroy(&w->cv_free);
        pthread_cond_destroy(&w->cv_ready);
        goto fail;
    }
    return w;
fail:
    free(w->mem);
    free(w->free_stack);
    free(w->ready);
    free(w);
    return NULL;
}

uint8_t *cap_writer_acquire(cap_writer *w)
{
    pthread_mutex_lock(&w->mu);
    if (w->nfree == 0 && !w->failed) {
        /* the queue is full: the game thread blocks here until the writer
         * frees a slot (the documented back-pressure, never a drop) */
        double t0 = rs_now();
        w->st.full_waits++;
        while (w->nfree == 0 && !w->failed)
            pthread_cond_wait(&w->cv_free, &w->mu);
        w->st.wait_ms += (rs_now() - t0) * 1e3;
    }
    uint8_t *slot = w->failed ? NULL : w->free_stack[--w->nfree];
    pthread_mutex_unlock(&w->mu);
    return slot;
}

bool cap_writer_submit(cap_writer *w, uint8_t *slot)
{
    if (!w->threaded) {
        rs_err e = {0};
        bool ok = !w->failed && write_one(w, slot, w->next_index++, &e);
        if (!ok && !w->failed) {
            w->failed = true;
            w->err = e;
        }
        w->free_stack[w->nfree++] = slot;
        return ok;
    }
    pthread_mutex_lock(&w->mu);
    bool ok = !w->failed;
    w->ready[(w->rhead + w->rcount) % w->nslots] = slot;
    w->rcount++;
    if (w->rcount > w->st.high_water)
        w->st.high_water = w->rcount;
    pthread_cond_signal(&w->cv_ready);
    pthread_mutex_unlock(&w->mu);
    return ok;
}

void cap_writer_cancel(cap_writer *w, uint8_t *slot)
{
    pthread_mutex_lock(&w->mu);
    w->free_stack[w->nfree++] = slot;
    pthread_cond_signal(&w->cv_free);
    pthread_mutex_unlock(&w->mu);
}

bool cap_writer_finish(cap_writer *w, cap_writer_stats *stats, rs_err *err)
{
    if (w->threaded) {
        pthread_mutex_lock(&w->mu);
        w->done = true;
        pthread_cond_signal(&w->cv_ready);
        pthread_mutex_unlock(&w->mu);
        pthread_join(w->thread, NULL);
    }
    bool ok = !w->failed;
    if (!ok && err)
        *err = w->err;
    if (stats)
        *stats = w->st;
    pthread_mutex_destroy(&w->mu);
    pthread_cond_destroy(&w->cv_free);
    pthread_cond_destroy(&w->cv_ready);
    free(w->mem);
    free(w->free_stack);
    free(w->ready);
    free(w);
    return ok;
}
