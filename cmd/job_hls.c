/* job_hls: render --hls-dir (job_hls.h). */
#include "job_hls.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <time.h>
#include <unistd.h>

#include "../capture/cap_hls.h"
#include "../runtime/audio/au.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "job_audio.h"

typedef struct track_src {
    au_replay_stream *s;
    job_hls *h;
} track_src;

static bool read_track(void *u, float *dst, size_t frames, rs_err *err)
{
    track_src *t = u;
    if (atomic_load(&t->h->stop))
        return rs_fail(err, CAP_ERR_FAILED, "%s/track.ts: stopped (the render failed)", t->h->d.dir);
    return au_replay_read(t->s, dst, frames, err);
}

/* DIR/track.ts from the whole match: under DIR/.track.lock, so renders
 * starting together make it once (the lock goes with a maker that dies) */
static bool make_track(job_hls *h, rs_err *err)
{
    const job_hls_desc *d = &h->d;
    char path[1100], lock[1100];
    snprintf(path, sizeof path, "%s/track.ts", d->dir);
    snprintf(lock, sizeof lock, "%s/.track.lock", d->dir);
    if (access(path, F_OK) == 0)
        return true;
    int fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
        return rs_fail(err, CAP_ERR_CREATE, "%s: %s", lock, strerror(errno));
    while (flock(fd, LOCK_EX | LOCK_NB) != 0) {
        int e = errno;
        if (atomic_load(&h->stop) || (e != EWOULDBLOCK && e != EINTR)) {
            close(fd);
            return rs_fail(err, CAP_ERR_FAILED, "%s: %s", lock, atomic_load(&h->stop) ? "stopped" : strerror(e));
        }
        nanosleep(&(struct timespec){0, 50000000}, NULL);
    }
    bool ok = true;
    if (access(path, F_OK) != 0) { /* not made while this one waited */
        double t0 = rs_now();
        au_replay_opts o = {.target_lufs = d->lufs ? d->lufs : JOB_AUDIO_LUFS_DEFAULT, .no_check = true};
        track_src src = {.h = h, .s = au_replay_open(d->rp, d->name, 0, d->rp->ticks, &o, err)};
        ok = src.s != NULL;
        if (ok) {
            cap_sink sink = {.audio = read_track, .audio_u = &src, .audio_frames = au_replay_info(src.s)->frames,
                             .audio_bitrate = d->bitrate};
            ok = cap_hls_track(d->dir, &sink, err);
            au_replay_close(src.s);
        }
        h->track_s = rs_now() - t0;
    }
    close(fd); /* and the lock with it */
    return ok;
}

static void *track_thread(void *u)
{
    job_hls *h = u;
    h->track_ok = make_track(h, &h->track_err);
    return NULL;
}

bool job_hls_start(job_hls *h, const job_hls_desc *d, rs_err *err)
{
    *h = (job_hls){.d = *d, .track_ok = true};
    char probe[1100];
    snprintf(probe, sizeof probe, "%s/.", d->dir);
    if (!rs_mkdirs_for(probe, err))
        return false;
    if (d->silent)
        return true; /* no track to make */
    if (pthread_create(&h->thread, NULL, track_thread, h) != 0)
        return rs_fail(err, CAP_ERR_NOMEM, "%s: cannot start a thread for the track", d->dir);
    h->running = true;
    return true;
}

static void first_bad(void *ctx, int index, const rs_err *e)
{
    (void)index;
    rs_err *err = ctx;
    if (!err->code)
        *err = *e;
}

/* A whole render's playlist beside the pieces: a finished stream */
static bool whole_playlist(const job_hls_desc *d, rs_err *err)
{
    cap_hls_index ix;
    if (cap_hls_index_read(d->dir, d->first, &ix, err) != 1)
        return false;
    size_t len;
    char *text = cap_hls_playlist(&ix, 1, true, "t", &len), path[1100];
    cap_hls_index_free(&ix);
    snprintf(path, sizeof path, "%s/stream.m3u8", d->dir);
    bool ok = text ? rs_write_part(path, text, len, err) && rs_commit_file(path, err)
                   : rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", path);
    free(text);
    return ok;
}

bool job_hls_finish(job_hls *h, bool ok, rs_err *err)
{
    if (!ok)
        atomic_store(&h->stop, 1);
    double t0 = rs_now();
    if (h->running)
        pthread_join(h->thread, NULL);
    h->wait_s = rs_now() - t0;
    h->running = false;
    if (!ok || !h->d.dir)
        return false;
    if (!h->track_ok) {
        *err = h->track_err;
        return false;
    }
    const job_hls_desc *d = &h->d;
    cap_seg seg = {.path = d->video};
    if (d->segment) {
        rs_err bad = {0};
        cap_seg_want want = {.key = d->segment, .format = cap_seg_format_of(d->video), .first = d->first, .hashes = d->hashes};
        if (cap_seg_verify(&seg, 1, &want, first_bad, &bad) > 0) {
            *err = bad;
            return false;
        }
    }
    if (!cap_hls_cut(&(cap_hls_cut_desc){.dir = d->dir, .video = d->video, .seg = d->segment ? &seg : NULL,
                                         .first = d->first, .end = d->end, .total = d->rp->ticks,
                                         .silent = d->silent},
                     err))
        return false;
    return d->segment || whole_playlist(d, err); /* a segment's: the service lists the units it knows are done */
}
