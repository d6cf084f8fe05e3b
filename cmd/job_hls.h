/* job_hls: a render's output cut into HLS pieces (render --hls-dir DIR),
 * for a job that is watched while it renders (capture/cap_hls.h has the
 * folder's layout).
 *
 *   job_hls h;
 *   job_hls_start(&h, &desc, err)   before the first frame: DIR made, and
 *                                   a process started that makes the
 *                                   match's sound (DIR/track.K.ts, 10 s a
 *                                   part) unless it is whole; makers take
 *                                   turns under a lock file, and the
 *                                   second finds the parts made
 *   ... render; the video (and a segment's manifest) in place ...
 *   job_hls_finish(&h, ok, err)     ok: checks the video (a segment as
 *                                   the join checks it: manifest, key,
 *                                   ticks, hash list), cuts it at its
 *                                   keyframes (each piece waits for the
 *                                   track's parts of its time while a
 *                                   maker is at work), the unit's index
 *                                   last.  A segment then leaves the rest
 *                                   of the track to its maker, which ends
 *                                   when the track is whole: the next
 *                                   units need it, and the service lists
 *                                   this unit's pieces when the render
 *                                   exits.  Anything else waits for the
 *                                   whole track and gets DIR/stream.m3u8.
 *                                   !ok: stops the maker.
 *
 * The track costs the match's loudness (two passes over the whole match:
 * au_norm_plan) and its encoding (AAC, about 1/60 of real time on one
 * core); a unit's pieces wait only for the first and the parts of their
 * own time, and drawing the unit's frames meanwhile hides most of it. */
#ifndef JOB_HLS_H
#define JOB_HLS_H

#include <stdbool.h>
#include <stdint.h>
#include <sys/types.h>

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
    pid_t maker;                /* this render's track maker while it runs; 0: none */
    int maker_status;           /* its wait status once it ended (0: none was needed) */
    double wait_s;              /* what the cut waited for the track's parts */
} job_hls;

bool job_hls_start(job_hls *h, const job_hls_desc *d, rs_err *err);
/* False with err set (CAP_ERR_*: CAP_ERR_SEG_* when the video is to blame). */
bool job_hls_finish(job_hls *h, bool ok, rs_err *err);

#endif
