/* job_hls: a render's output cut into HLS pieces (render --hls-dir DIR),
 * for a job that is watched while it renders (capture/cap_hls.h has the
 * folder's layout).
 *
 *   job_hls h;
 *   job_hls_start(&h, &desc, err)   before the first frame: DIR made, and
 *                                   the match's sound (DIR/track.ts) made
 *                                   on a thread of its own unless another
 *                                   render made it or is making it (a lock
 *                                   file: one maker at a time)
 *   ... render; the video (and a segment's manifest) in place ...
 *   job_hls_finish(&h, ok, err)     ok: waits for the track, checks the
 *                                   video (a segment as the join checks
 *                                   it: manifest, key, ticks, hash list),
 *                                   cuts it at its keyframes, the unit's
 *                                   index last; a whole render also gets
 *                                   DIR/stream.m3u8.  !ok: stops the track.
 *
 * The track takes about 2.3 s of one core for a 3-minute match; drawing
 * the first unit's frames meanwhile is what keeps it off the time to the
 * first piece. */
#ifndef JOB_HLS_H
#define JOB_HLS_H

#include <pthread.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>

#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_err.h"

typedef struct job_hls_desc {
    const char *dir;      /* created if missing */
    const char *video;    /* the render's output: .mp4 or .mkv, H.264 or HEVC */
    const char *segment;  /* its --segment KEY, or NULL */
    bool hashes;          /* a segment with a hash list: checked too */
    const rp_replay *rp;  /* the replay: its whole match is the track; lives until finish */
    const char *name;     /* the replay's name, for messages */
    double lufs;          /* the track's loudness target; 0: the default */
    int64_t bitrate;      /* the track's AAC bits/s; 0: the default, 192k */
    bool silent;          /* no sound in the pieces (--audio off): no track */
    uint64_t first, end;  /* the video's ticks */
} job_hls_desc;

typedef struct job_hls {
    job_hls_desc d;
    pthread_t thread;
    bool running;
    atomic_int stop;            /* set (by the render's thread): the track maker gives up */
    bool track_ok;
    rs_err track_err;
    double track_s;             /* what making the track took (0: it was there) */
    double wait_s;              /* what job_hls_finish waited for it after the frames */
} job_hls;

bool job_hls_start(job_hls *h, const job_hls_desc *d, rs_err *err);
/* False with err set (CAP_ERR_*: CAP_ERR_SEG_* when the video is to blame). */
bool job_hls_finish(job_hls *h, bool ok, rs_err *err);

#endif
