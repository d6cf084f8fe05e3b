/* Segments: one video rendered in pieces, anywhere, and joined by stream
 * copy (docs/segments.md).
 *
 * A segment is the video of ticks A..B-1 (`render --ticks A:B --segment
 * KEY -o SEG.mp4`): its own file, first frame a keyframe, closed GOP,
 * pts = tick in 1/60 (the sink does that: cap_sink.segment), the same
 * encoder settings as every other segment.  Beside it:
 *   SEG.mp4.seg    its manifest (cap_seg_info), written last and
 *                  atomically: a manifest means the segment is complete;
 *   SEG.hashes     its --hashes list, when it has one (the segment's name
 *                  with the extension replaced: cap_seg_hashes_path).
 * The manifest records what the file must be when read back through
 * libavformat (packet count, CRC-32 of the packet payloads), so a join
 * can tell a whole segment from a truncated, stale or foreign one before
 * it writes anything.
 *
 *   render: cap_seg_seal(seg, key, A, B, hashes)       after the files are in place
 *   join:   j = cap_join_open(&desc)                    output directory writable?
 *           cap_seg_verify(segs, n, &want, bad, ctx)    every segment, and all together
 *           cap_join_audio(j, sink)                     optional: the whole job's track,
 *        or cap_join_audio_track(j, cap_atrack_encode(sink, out))  the same, encoded ahead
 *           cap_join_copy(j, segs, n, &bad)             stream copy
 *           cap_join_close(j, ok)                       faststart, rename into place
 *
 * Failures carry CAP_ERR_SEG_* ids when a segment is at fault (join exits
 * 3 and the segment is rendered again), other CAP_ERR_* ids when the
 * output is (exit 1). */
#ifndef CAP_SEG_H
#define CAP_SEG_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cap_sink.h"

#define CAP_SEG_KEY_MAX 64

/* The manifest, SEG.seg, one "name value" line each:
 *   ringside-segment 1
 *   key job42-a3
 *   format mp4
 *   size 640x360
 *   ticks 600 1200
 *   frames 600
 *   bytes 1234567
 *   crc32 89abcdef
 *   hashes 0123456789abcdef      ("hashes none" without a list)
 *   replay 0123456789abcdef      optional: FNV-1a 64 of the replay file's
 *                                bytes, so join --replay can tell the
 *                                segments' replay from another */
typedef struct cap_seg_info {
    char key[CAP_SEG_KEY_MAX + 1];
    char format[8];        /* mp4, mkv or webm: the segment file's extension */
    int w, h;
    uint64_t first, end;   /* ticks first..end-1 */
    uint64_t frames;       /* end - first */
    uint64_t bytes;        /* the segment file's size */
    uint32_t crc;          /* CRC-32 of every packet's payload, in the order libavformat reads them */
    bool has_hashes;
    uint64_t hashes_fnv;   /* FNV-1a 64 of the hash list's text */
    bool has_replay;       /* manifests before sound have no replay line */
    uint64_t replay_fnv;   /* FNV-1a 64 of the replay file */
} cap_seg_info;

/* The manifest's text (snprintf rules: returns the length it needs). */
int cap_seg_manifest_format(const cap_seg_info *m, char *out, size_t n);
/* A manifest's text, NUL-terminated (path names it in messages): false
 * (CAP_ERR_SEG_MANIFEST) saying which line is wrong; *out is filled only
 * when all of it is good, and formats back to a text that parses to it. */
bool cap_seg_manifest_parse(const char *text, const char *path, cap_seg_info *out, rs_err *err);
/* A hash list's len bytes, with text[len] == 0 (as rs_read_file gives
 * it): "N HHHHHHHHHHHHHHHH\n" for N = first..end-1 and nothing else.
 * *fnv gets the FNV-1a 64 of the text; false (CAP_ERR_SEG_HASHES) names
 * the first bad line or the count. */
bool cap_seg_hashes_parse(const char *text, size_t len, const char *path, uint64_t first, uint64_t end, uint64_t *fnv,
                          rs_err *err);

/* One segment as join sees it. */
typedef struct cap_seg {
    const char *path;      /* the segment file */
    cap_seg_info m;        /* its manifest (filled by cap_seg_verify) */
    uint32_t codec_sig;    /* CRC of the codec id, size and extradata: equal across a video */
    int reorder;           /* B-frame delay: the most any packet's pts lags its decode position */
} cap_seg;

/* [A-Za-z0-9._:-]{1,64} */
bool cap_seg_key_ok(const char *key);
/* "dir/s1.mp4" -> "dir/s1.mp4.seg" */
void cap_seg_manifest_path(const char *seg, char *out, size_t n);
/* "dir/s1.mp4" -> "dir/s1.hashes" */
void cap_seg_hashes_path(const char *seg, char *out, size_t n);
/* "mp4", "mkv", "webm", or NULL when path is none of them. */
const char *cap_seg_format_of(const char *path);

/* After a segment's render, with the file (and its hash list) in place:
 * reads it back through libavformat, checks it is ticks first..end-1
 * (count, keyframe, pts), and writes SEG.seg atomically.  hashes: its
 * list, or NULL; replay_fnv: the replay file's FNV-1a 64 (rs_fnv1a64 of
 * its bytes), or NULL.  False (CAP_ERR_SEG_* or CAP_ERR_WRITE) leaves no
 * manifest; the caller removes the files. */
bool cap_seg_seal(const char *seg, const char *key, uint64_t first, uint64_t end, const char *hashes,
                  const uint64_t *replay_fnv, rs_err *err);

/* The FNV-1a 64 of a replay file's bytes, as manifests record it. */
bool cap_seg_replay_fnv(const char *replay, uint64_t *out, rs_err *err);

/* What join wants of every segment. */
typedef struct cap_seg_want {
    const char *key;       /* required: segments of another job or attempt are bad */
    const char *format;    /* required: the output's container (cap_seg_format_of) */
    uint64_t first;        /* the first segment's first tick; 0 default */
    bool hashes;           /* every segment must have its hash list (join --hashes) */
} cap_seg_want;

/* Checks each segment against its manifest (CAP_ERR_SEG_*, in the order
 * the header of cap_seg.c lists) and all of them together: contiguous
 * ticks from want->first, one size, one set of codec parameters (the
 * majority's; the others are bad).  Calls bad(ctx, index, err) once for
 * each bad segment, in order; returns how many were bad. */
int cap_seg_verify(cap_seg *segs, int n, const cap_seg_want *want,
                   void (*bad)(void *ctx, int index, const rs_err *err), void *ctx);

typedef struct cap_join cap_join;

typedef struct cap_join_desc {
    const char *out;       /* required: .mp4 (faststart), .mkv or .webm; its directory must exist */
    const char *hashes;    /* optional: the segments' hash lists, concatenated */
    void (*progress)(void *ctx, uint64_t done, uint64_t total); /* optional: after every packet */
    void *ctx;
    const volatile sig_atomic_t *stop; /* optional: set (by a signal) to give up */
} cap_join_desc;

/* Creates OUT.part (and HASHES.part): fails with CAP_ERR_CREATE when the
 * output directory is gone or not writable, before any segment is read. */
cap_join *cap_join_open(const cap_join_desc *d, rs_err *err);
/* Optional, before cap_join_copy: an audio stream, the track, codec and
 * bitrate of `audio` (a sink of the output given them by cap_sink_audio:
 * the track covers the joined ticks, 800 sample frames each), encoded as
 * the video is copied, so the sound is one piece across segment joins. */
void cap_join_audio(cap_join *j, const cap_sink *audio);
/* The same track encoded ahead, while there is nothing else to do (a
 * split render encodes it while its segments draw, job_split.c): every
 * packet in memory (192 kb/s: 1.4 MiB a minute), for a join into a file
 * named like `out` (its container decides the stream's header and the
 * encoder's priming, as in cap_join_audio).  The packets are the ones
 * cap_join_audio would encode, so the joined file is the same.  NULL
 * with err filled (the track's read failed, or the encoder). */
typedef struct cap_atrack cap_atrack;
cap_atrack *cap_atrack_encode(const cap_sink *audio, const char *out, rs_err *err);
/* Seconds the encoding took. */
double cap_atrack_secs(const cap_atrack *t);
void cap_atrack_free(cap_atrack *t);
/* cap_join_audio from a track encoded ahead; t is borrowed until close. */
void cap_join_audio_track(cap_join *j, cap_atrack *t);
/* Stream-copies the verified segments in order: pts continue from one
 * segment to the next (the video starts at pts 0, as any render does),
 * dts = position - the largest B-frame delay, so they rise by one a
 * packet across the joins.  A segment that changed since cap_seg_verify
 * fails with a CAP_ERR_SEG_* id and *bad_index set to its index (-1 for
 * the other failures, which are the output's). */
bool cap_join_copy(cap_join *j, const cap_seg *segs, int n, int *bad_index, rs_err *err);
/* ok: trailer (MP4: index moved to the front), fsync, hash list then
 * video renamed into place; !ok or any failure: both temporaries
 * removed, nothing left.  Always frees j. */
bool cap_join_close(cap_join *j, bool ok, rs_err *err);

#endif
