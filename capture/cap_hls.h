/* HLS pieces: a rendered video cut into short MPEG-TS files that any HLS
 * player can play while the rest of the job still renders
 * (docs/service.md, "Watching while it renders").
 *
 * One folder per job holds:
 *   track.K.ts    the whole match's sound, AAC in MPEG-TS, in parts of
 *                 CAP_HLS_TRACK_PART_TICKS (10 s): part K has the packets
 *                 that start in its time (the last part the rest).  One
 *                 encoding of the whole match (cap_hls_track), by whichever
 *                 render needs it first, a part linked into place as soon
 *                 as it is complete, so a piece waits only for the parts of
 *                 its own time; the track is deterministic, so two makers
 *                 make the same parts;
 *   tTICK.ts      a piece: the video from its keyframe at TICK up to the
 *                 next keyframe (or the unit's end), stream-copied (nothing
 *                 decoded or encoded again), and the track's packets of the
 *                 same time;
 *   uFIRST.idx    a unit's index, written last and atomically: the pieces
 *                 of ticks FIRST..END-1, each with its size and FNV-1a.
 * An index means its pieces are complete, and they never change after:
 * a later cut of the same unit keeps an index whose pieces still match
 * it, and writes the unit again only when they do not.
 *
 * Timestamps are the ticks' times plus CAP_HLS_OFFSET_TICKS, in every
 * piece, so pieces cut by different processes (and machines) play as one
 * stream; decode times trail the frames' positions by CAP_HLS_REORDER.
 *
 *   render:  cap_hls_track(dir, sink, total)  the sound, the parts not there
 *            cap_hls_cut(&cut)             pieces, then the index
 *   serve:   cap_hls_index_read(dir, first, &ix)
 *            cap_hls_playlist(units, n, ended, prefix)
 *            cap_hls_piece_check(dir, &piece)  before sending one */
#ifndef CAP_HLS_H
#define CAP_HLS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cap_seg.h"
#include "cap_sink.h"

/* 1 s: the first frame's pts.  B-frames' decode times sit before it. */
#define CAP_HLS_OFFSET_TICKS 60
/* The most a frame's pts may trail its decode position (x264 and x265
 * as capture runs them: 2).  A video with more is refused. */
#define CAP_HLS_REORDER 8
/* A piece's length the playlist promises (EXT-X-TARGETDURATION): the
 * encoder's keyframe interval, 120 frames. */
#define CAP_HLS_TARGET_SECONDS 2

typedef struct cap_hls_piece {
    uint64_t tick;   /* its first frame's tick: the file is tTICK.ts */
    uint64_t frames; /* frames in it */
    uint64_t bytes;  /* the file's size */
    uint64_t fnv;    /* FNV-1a 64 of the file */
} cap_hls_piece;

/* A unit's index: ticks first..end-1 in n pieces (malloc'd). */
typedef struct cap_hls_index {
    uint64_t first, end;
    int n;
    cap_hls_piece *p;
} cap_hls_index;

void cap_hls_index_free(cap_hls_index *ix);

#define CAP_HLS_TRACK_PART_TICKS 600

/* The track's parts for a match of total ticks, and part k's path. */
int cap_hls_track_parts(uint64_t total);
void cap_hls_track_path(const char *dir, int k, char *out, size_t n);
/* Every part of the track is in DIR (the last is written last). */
bool cap_hls_track_whole(const char *dir, uint64_t total);

/* Makes DIR/track.K.ts from audio's track (cap_sink_audio filled its
 * audio, audio_u, audio_frames and bitrate; the track starts at tick 0 and
 * is total ticks long), encoding the whole match once and writing each
 * part that is not there yet.  A part is written as a temporary of this
 * process and linked into place: a racing maker's part is kept, never
 * half-replaced. */
bool cap_hls_track(const char *dir, const cap_sink *audio, uint64_t total, rs_err *err);

typedef struct cap_hls_cut_desc {
    const char *dir;     /* the job's folder; must exist; its track's parts are read as they come */
    const char *video;   /* a segment (pts = tick), or a render's output (pts from 0 at tick first) */
    const cap_seg *seg;  /* the segment as cap_seg_verify filled it, or NULL (a whole render):
                            its packets must match its manifest (count, CRC-32), as the join checks */
    uint64_t first, end; /* the video's ticks, first..end-1 */
    uint64_t total;      /* the match's last tick + 1: the last piece takes the track's rest */
    bool silent;         /* pieces without sound (a job asked for none): no track needed */
    bool *kept;          /* optional: set when a good index was there already */
    /* a part of the track not there yet is waited for while track_alive
     * says a maker is at work (NULL: it must be there); the seconds spent
     * waiting are added to *waited (optional) */
    bool (*track_alive)(void *u);
    void *track_u;
    double *waited;
} cap_hls_cut_desc;

/* Cuts the video at its keyframes into pieces and writes the unit's
 * index last, all under DIR/.uFIRST.lock (flock): two renders of the same
 * unit (a lease lost while the old one still ran) cut one after the
 * other, and the second keeps the first's pieces.  A video that is not H.264 or HEVC is refused
 * (CAP_ERR_ENC_SETTING: MPEG-TS carries neither VP9 nor AV1); a segment
 * whose packets differ from its manifest gets CAP_ERR_SEG_MEDIA and
 * leaves nothing; a write failure CAP_ERR_WRITE. */
bool cap_hls_cut(const cap_hls_cut_desc *d, rs_err *err);

/* Reads DIR/uFIRST.idx.  0: there is none (nothing cut yet); 1: *ix
 * filled; -1: unreadable or malformed (err names the file and line). */
int cap_hls_index_read(const char *dir, uint64_t first, cap_hls_index *ix, rs_err *err);

/* DIR/uFIRST.idx is there, for ticks first..end-1, and every piece is
 * the bytes it names.  False with err saying what is not ("no index"). */
bool cap_hls_unit_check(const char *dir, uint64_t first, uint64_t end, rs_err *err);

/* An index's text (parse and format agree; snprintf rules). */
int cap_hls_index_format(const cap_hls_index *ix, char *out, size_t n);
bool cap_hls_index_parse(const char *text, const char *path, cap_hls_index *ix, rs_err *err);

/* DIR/tTICK.ts is p's size and FNV-1a: false (CAP_ERR_SEG_MEDIA) says
 * how it differs.  data: optional, gets the file's bytes (malloc'd). */
bool cap_hls_piece_check(const char *dir, const cap_hls_piece *p, uint8_t **data, rs_err *err);

/* The playlist of units' pieces in order (HLS version 7, EVENT; "#EXT-X-
 * ENDLIST" when ended): each piece's URI is prefix, its tick, ".ts".
 * Returns malloc'd text (NULL: out of memory), its length in *len. */
char *cap_hls_playlist(const cap_hls_index *units, int n, bool ended, const char *prefix, size_t *len);

#endif
