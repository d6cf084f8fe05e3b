/* The decode thread (see mv_dec.h): one mutex, two condition variables. */
#include "mv_dec.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { SLOT_FREE, SLOT_FILLING, SLOT_QUEUED, SLOT_HELD };

struct mv_dec {
    mv_src *src;
    uint8_t *slots[MV_DEC_MAX_SLOTS];
    int nslots;
    int state[MV_DEC_MAX_SLOTS];
    int64_t index[MV_DEC_MAX_SLOTS];
    int queue[MV_DEC_MAX_SLOTS]; /* slot numbers, oldest first */
    int head, count;
    bool end, failed, stop;
    rs_err err;
    double ms;
    int64_t frames;
    pthread_mutex_t mu;
    pthread_cond_t has_frame, has_free;
    pthread_t thread;
};

static double now_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static void *run(void *arg)
{
    mv_dec *d = arg;
    for (;;) {
        pthread_mutex_lock(&d->mu);
        int slot = -1;
        while (!d->stop) {
            for (int i = 0; i < d->nslots && slot < 0; i++)
                if (d->state[i] == SLOT_FREE)
                    slot = i;
            if (slot >= 0)
                break;
            pthread_cond_wait(&d->has_free, &d->mu);
        }
        if (d->stop) {
            pthread_mutex_unlock(&d->mu);
            return NULL;
        }
        d->state[slot] = SLOT_FILLING;
        pthread_mutex_unlock(&d->mu);

        rs_err err = {0};
        double t0 = now_ms();
        int64_t index = d->src->index;
        int r = d->src->read(d->src, d->slots[slot], &err);
        double dt = now_ms() - t0;

        pthread_mutex_lock(&d->mu);
        d->ms += dt;
        if (r == 1) {
            d->frames++;
            d->state[slot] = SLOT_QUEUED;
            d->index[slot] = index;
            d->queue[(d->head + d->count) % MV_DEC_MAX_SLOTS] = slot;
            d->count++;
        } else {
            d->state[slot] = SLOT_FREE;
            if (r == 0)
                d->end = true;
            else {
                d->failed = true;
                d->err = err;
            }
        }
        pthread_cond_broadcast(&d->has_frame);
        bool done = r != 1;
        pthread_mutex_unlock(&d->mu);
        if (done)
            return NULL;
    }
}

mv_dec *mv_dec_start(mv_src *src, uint8_t *const *slots, int nslots, rs_err *err)
{
    if (nslots < 1 || nslots > MV_DEC_MAX_SLOTS) {
        rs_fail(err, MV_ERR_ARG, "decoder: %d slots (1..%d)", nslots, MV_DEC_MAX_SLOTS);
        return NULL;
    }
    mv_dec *d = calloc(1, sizeof *d);
    if (!d) {
        rs_fail(err, MV_ERR_NOMEM, "decoder: out of memory");
        return NULL;
    }
    d->src = src;
    d->nslots = nslots;
    memcpy(d->slots, slots, sizeof *slots * (size_t)nslots);
    pthread_mutex_init(&d->mu, NULL);
    pthread_cond_init(&d->has_frame, NULL);
    pthread_cond_init(&d->has_free, NULL);
    int e = pthread_create(&d->thread, NULL, run, d);
    if (e) {
        rs_fail(err, MV_ERR_NOMEM, "decoder: cannot start its thread: %s", strerror(e));
        pthread_cond_destroy(&d->has_free);
        pthread_cond_destroy(&d->has_frame);
        pthread_mutex_destroy(&d->mu);
        free(d);
        return NULL;
    }
    return d;
}

int mv_dec_peek(mv_dec *d, int wait_ms, int *slot, int64_t *index)
{
    pthread_mutex_lock(&d->mu);
    if (!d->count && !d->end && !d->failed && wait_ms) {
        if (wait_ms < 0) {
            while (!d->count && !d->end && !d->failed)
                pthread_cond_wait(&d->has_frame, &d->mu);
        } else {
            struct timespec t;
            clock_gettime(CLOCK_REALTIME, &t);
            t.tv_sec += wait_ms / 1000;
            t.tv_nsec += (long)(wait_ms % 1000) * 1000000L;
            if (t.tv_nsec >= 1000000000L) {
                t.tv_sec++;
                t.tv_nsec -= 1000000000L;
            }
            while (!d->count && !d->end && !d->failed)
                if (pthread_cond_timedwait(&d->has_frame, &d->mu, &t) == ETIMEDOUT)
                    break;
        }
    }
    int r;
    if (d->count) {
        *slot = d->queue[d->head];
        *index = d->index[*slot];
        r = MV_DEC_FRAME;
    } else {
        r = d->failed ? MV_DEC_ERROR : d->end ? MV_DEC_END : MV_DEC_NONE;
    }
    pthread_mutex_unlock(&d->mu);
    return r;
}

void mv_dec_pop(mv_dec *d)
{
    pthread_mutex_lock(&d->mu);
    if (d->count) {
        d->state[d->queue[d->head]] = SLOT_HELD;
        d->head = (d->head + 1) % MV_DEC_MAX_SLOTS;
        d->count--;
    }
    pthread_mutex_unlock(&d->mu);
}

void mv_dec_release(mv_dec *d, int slot)
{
    pthread_mutex_lock(&d->mu);
    if (slot >= 0 && slot < d->nslots && d->state[slot] == SLOT_HELD) {
        d->state[slot] = SLOT_FREE;
        pthread_cond_signal(&d->has_free);
    }
    pthread_mutex_unlock(&d->mu);
}

const rs_err *mv_dec_error(mv_dec *d)
{
    return &d->err; /* written before `failed` is set, under the lock */
}

int mv_dec_held(mv_dec *d)
{
    pthread_mutex_lock(&d->mu);
    int n = 0;
    for (int i = 0; i < d->nslots; i++)
        n += d->state[i] == SLOT_HELD;
    pthread_mutex_unlock(&d->mu);
    return n;
}

void mv_dec_stats(mv_dec *d, double *ms, int64_t *frames)
{
    pthread_mutex_lock(&d->mu);
    *ms = d->ms;
    *frames = d->frames;
    pthread_mutex_unlock(&d->mu);
}

void mv_dec_stop(mv_dec *d)
{
    if (!d)
        return;
    pthread_mutex_lock(&d->mu);
    d->stop = true;
    pthread_cond_broadcast(&d->has_free);
    pthread_mutex_unlock(&d->mu);
    pthread_join(d->thread, NULL);
    pthread_cond_destroy(&d->has_free);
    pthread_cond_destroy(&d->has_frame);
    pthread_mutex_destroy(&d->mu);
    free(d);
}
