/* job_hls: render --hls-dir (job_hls.h). */
#define _GNU_SOURCE /* close_range */
#include "job_hls.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "../capture/cap_hls.h"
#include "../runtime/audio/au.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "job_audio.h"

static bool read_track(void *u, float *dst, size_t frames, rs_err *err)
{
    return au_replay_read(u, dst, frames, err);
}

/* DIR/.track.lock: held by the maker at work */
static void lock_path(const char *dir, char *out, size_t n)
{
    snprintf(out, n, "%s/.track.lock", dir);
}

/* In the maker's process: DIR/track.K.ts from the whole match, under
 * DIR/.track.lock (flock, waited for), so renders starting together make
 * it once: a maker that finds the track whole does nothing, and one that
 * takes over from a maker that died writes only the parts it left.  The
 * lock goes with a maker that dies. */
static bool make_track(const job_hls_desc *d, rs_err *err)
{
    char lock[1100];
    lock_path(d->dir, lock, sizeof lock);
    int fd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
        return rs_fail(err, CAP_ERR_CREATE, "%s: %s", lock, strerror(errno));
    while (flock(fd, LOCK_EX) != 0)
        if (errno != EINTR) {
            int e = errno;
            close(fd);
            return rs_fail(err, CAP_ERR_FAILED, "%s: %s", lock, strerror(e));
        }
    bool ok = true;
    if (!cap_hls_track_whole(d->dir, d->rp->ticks)) {
        au_replay_opts o = {.target_lufs = d->lufs ? d->lufs : JOB_AUDIO_LUFS_DEFAULT, .no_check = true};
        au_replay_stream *s = au_replay_open(d->rp, d->name, 0, d->rp->ticks, &o, err);
        ok = s != NULL;
        if (ok) {
            cap_sink sink = {.audio = read_track, .audio_u = s, .audio_frames = au_replay_info(s)->frames,
                             .audio_bitrate = d->bitrate};
            ok = cap_hls_track(d->dir, &sink, d->rp->ticks, err);
            au_replay_close(s);
        }
    }
    close(fd); /* and the lock with it */
    return ok;
}

bool job_hls_start(job_hls *h, const job_hls_desc *d, rs_err *err)
{
    *h = (job_hls){.d = *d};
    char probe[1100];
    snprintf(probe, sizeof probe, "%s/.", d->dir);
    if (!rs_mkdirs_for(probe, err))
        return false;
    if (d->silent || cap_hls_track_whole(d->dir, d->rp->ticks))
        return true; /* no track to make */
    /* a process of its own, so a unit of a split job can be done (and
     * listed) when its pieces are, while the rest of the track is made
     * for the units after it; it needs nothing of the render's but the
     * replay (its copy), and none of its descriptors */
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0)
        return rs_fail(err, CAP_ERR_NOMEM, "%s: cannot start a process for the match's sound: %s", d->dir, strerror(errno));
    if (pid == 0) {
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL); /* the render's handler only sets its flag */
        close_range(3, ~0U, 0);   /* --progress-fd: the render's alone */
        rs_err e = {0};
        bool ok = make_track(d, &e);
        if (!ok)
            fprintf(stderr, "ringside render: %s\n", e.msg);
        _exit(ok ? 0 : 1); /* nothing of the render's to clean up: that is the render's */
    }
    h->maker = pid;
    return true;
}

/* The cut's question: is anyone making the track?  This render's own
 * maker, still running (it may be waiting for another's lock), or any
 * process holding DIR/.track.lock. */
static bool track_alive(void *u)
{
    job_hls *h = u;
    if (h->maker > 0) {
        int st;
        pid_t r = waitpid(h->maker, &st, WNOHANG);
        if (r == 0)
            return true;
        if (r == h->maker)
            h->maker_status = st;
        h->maker = 0;
    }
    char lock[1100];
    lock_path(h->d.dir, lock, sizeof lock);
    int fd = open(lock, O_RDONLY | O_CLOEXEC);
    if (fd < 0)
        return false;
    bool held = flock(fd, LOCK_SH | LOCK_NB) != 0 && errno == EWOULDBLOCK;
    close(fd); /* our shared lock, if we got it, with it */
    return held;
}

/* This render's maker: stopped (!wait), or waited for; its status */
static int end_maker(job_hls *h, bool wait)
{
    if (h->maker > 0) {
        if (!wait)
            kill(h->maker, SIGTERM);
        int st;
        while (waitpid(h->maker, &st, 0) < 0 && errno == EINTR)
            ;
        h->maker_status = st;
        h->maker = 0;
    }
    return h->maker_status;
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
    if (!ok || !h->d.dir) {
        end_maker(h, false);
        return false;
    }
    const job_hls_desc *d = &h->d;
    cap_seg seg = {.path = d->video};
    if (d->segment) {
        rs_err bad = {0};
        cap_seg_want want = {.key = d->segment, .format = cap_seg_format_of(d->video), .first = d->first, .hashes = d->hashes};
        if (cap_seg_verify(&seg, 1, &want, first_bad, &bad) > 0) {
            *err = bad;
            end_maker(h, false);
            return false;
        }
    }
    if (!cap_hls_cut(&(cap_hls_cut_desc){.dir = d->dir, .video = d->video, .seg = d->segment ? &seg : NULL,
                                         .first = d->first, .end = d->end, .total = d->rp->ticks,
                                         .silent = d->silent, .track_alive = track_alive, .track_u = h,
                                         .waited = &h->wait_s},
                     err)) {
        end_maker(h, false);
        return false;
    }
    /* a segment leaves the rest of the track to its maker (the next units
     * need it, not this one); anything else waits for the whole track */
    if (!d->segment) {
        int st = end_maker(h, true);
        if (!WIFEXITED(st) || WEXITSTATUS(st) != 0)
            return rs_fail(err, CAP_ERR_FAILED, "%s: the match's sound could not be made (%s above)", d->dir,
                           WIFEXITED(st) ? "its error" : "its process was killed");
    }
    return d->segment || whole_playlist(d, err); /* a segment's: the service lists the units it knows are done */
}
