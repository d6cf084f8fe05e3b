/* Capture sinks: where finished frames go.  One file per sink kind
 * (cap_sink_y4m.c, cap_sink_ffmpeg.c, ...), all behind cap_sink_ops.
 *
 * A sink writes under a temporary name and makes the output appear only
 * in close(ok = true): a failed render never leaves a file that looks
 * finished.  Sinks are driven by one thread at a time (the writer). */
#ifndef CAP_SINK_H
#define CAP_SINK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"
#include "cap_enc.h"

/* Error ids (rs_err.h) of the whole capture pipeline: sizes, sinks,
 * outputs, the writer and the GL readback. */
#define CAP_ERRORS(X)                                                                                  \
    X(SIZE, "bad sizes: not positive, odd for 4:2:0, or not a downscale of at most 8x")               \
    X(ARG, "a bad capture setting (PBO ring size) or a sink used before it was opened")               \
    X(OUTPUT, "unknown output type, or an image-sequence name without a frame number")                \
    X(NOT_BUILT, "this build (or its FFmpeg) cannot write that kind of output")                        \
    X(CREATE, "cannot create the output (not a regular file, no directory, no permission)")           \
    X(WRITE, "writing the output or the frame hash list failed (disk full, I/O error, rename)")       \
    X(ENCODER, "the encoder or the container refused the frames")                                     \
    X(GL, "the GL side of capture failed (target incomplete, fence or mapping)")                      \
    X(NOMEM, "out of memory, or no writer thread")                                                     \
    X(FAILED, "the capture was closed as failed with no more precise reason")                          \
    /* segments (cap_seg.h): why a segment cannot be joined */                                       \
    X(SEG_MISSING, "a segment file or its manifest (.seg) is missing")                                 \
    X(SEG_MANIFEST, "a segment's manifest is unreadable or malformed")                                 \
    X(SEG_KEY, "a segment belongs to another job or attempt (its key differs)")                        \
    X(SEG_FORMAT, "a segment's container or frame size differs from the others or from the output")   \
    X(SEG_TICKS, "a segment's ticks do not continue from the segment before")                          \
    X(SEG_SIZE, "a segment file's byte size differs from its manifest (truncated or grown)")           \
    X(SEG_MEDIA, "a segment file does not open, or its packets differ from its manifest")             \
    X(SEG_CODEC, "a segment's codec parameters differ from the others (no stream copy possible)")      \
    X(SEG_HASHES, "a segment's frame hash list is missing, malformed or differs from its manifest")  \
    /* encoder settings (cap_enc.h) */                                                               \
    X(ENC_SETTING, "an encoder setting that the container or the encoder does not take")              \
    X(ENC_HW, "the hardware encoder asked for (--hw nvenc|vaapi) has no device or does not open")    \
    /* a stream output (-o -, a pipe) */                                                            \
    X(PIPE_CLOSED, "the program reading the output pipe closed it before the end")

typedef enum cap_error {
    CAP_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_CAP),
#define X(id, text) CAP_ERR_##id,
    CAP_ERRORS(X)
#undef X
        CAP_ERR_END
} cap_error;

const char *cap_error_text(int code);
/* The id's own name, "SEG_KEY" for CAP_ERR_SEG_KEY ("?" outside the list):
 * join's `bad INDEX REASON` lines carry it, lower case, without "SEG_". */
const char *cap_error_name(int code);

/* Frame layouts a sink can take. */
typedef enum cap_pixfmt {
    CAP_I420, /* planar Y, then Cb, then Cr at half size: BT.709 limited range, chroma sited at the centre */
    CAP_RGBA, /* 8-bit RGBA, rows top-down */
} cap_pixfmt;

size_t cap_frame_bytes(cap_pixfmt fmt, int w, int h);

/* Container metadata (title, stage, ...): FFmpeg sinks write it, join
 * copies it.  Keys are the ones in cap_meta_keys, in that order. */
#define CAP_META_MAX 8
typedef struct cap_meta {
    char key[24];
    char value[160];
} cap_meta;
extern const char *const cap_meta_keys[]; /* NULL-terminated */

/* Reads the next `frames` sample frames of a soundtrack (48 kHz stereo
 * float, interleaved) into dst, in order from its first; false with err
 * filled when it cannot. */
typedef bool (*cap_audio_read_fn)(void *u, float *dst, size_t frames, rs_err *err);

typedef struct cap_sink cap_sink;

typedef struct cap_sink_ops {
    const char *name;
    bool (*open)(cap_sink *s, rs_err *err);
    bool (*write)(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *err);
    /* ok: commit the output; !ok: remove everything written */
    bool (*close)(cap_sink *s, bool ok, rs_err *err);
} cap_sink_ops;

struct cap_sink {
    const cap_sink_ops *ops;
    void *impl;
    char path[1024];
    int w, h;
    cap_pixfmt fmt;
    uint64_t frames;
    /* added to frame numbers where they are shown: image-sequence names
     * and the --hashes list (render --ticks A:B numbers frames from A);
     * video timestamps still start at 0, unless segment */
    uint64_t index_base;
    /* a segment (render --segment, cap_seg.h; FFmpeg sinks only): video
     * timestamps start at index_base too, the first frame is a keyframe
     * and no frame refers outside the file (closed GOP) */
    bool segment;
    /* a closed GOP without being a segment (render --hls-dir): every
     * keyframe is a place where a piece can start (cap_hls.h) */
    bool closed_gop;
    /* the container, lower case with its dot (".mp4", ".nut"), from the
     * name's extension or --format: sinks go by it, not by the name */
    char ext[8];
    /* FFmpeg sinks: the encoder settings and the encoder chosen
     * (cap_sink_encoder; zero: the defaults, chosen at open), and the
     * metadata to write (cap_sink_meta) */
    cap_enc enc;
    char enc_name[32];
    char enc_note[256];
    cap_meta meta[CAP_META_MAX];
    int n_meta;
    /* FFmpeg sinks: the soundtrack (cap_audio.c), set by cap_sink_audio
     * before open; audio NULL: no audio stream */
    cap_audio_read_fn audio; /* the track, read in order on the writer thread; NULL: none */
    void *audio_u;           /* its argument, borrowed until close */
    size_t audio_frames;     /* sample frames: 800 a video frame */
    int64_t audio_bitrate; /* bits/s, filled with the default when 0 */
    bool audio_fast;         /* AAC: FFmpeg's fast coder (4x faster, for a live stream's track) */
    char audio_codec[8];   /* "aac" or "opus" */
};

/* Adds one metadata entry (key from cap_meta_keys; empty values are skipped). */
void cap_sink_meta(cap_sink *s, const char *key, const char *value);

/* Picks the sink from the output's extension (.y4m, .mp4, .mkv, .webm,
 * name%06d.png|.exr|.tif, any case) and checks it can work (the encoder
 * exists) before anything is rendered.  Does not create the file yet: that
 * is open(). */
bool cap_sink_for(const char *path, int w, int h, cap_sink *s, rs_err *err);
/* The same, with the container named by format ("y4m", "nut", "mkv",
 * "mp4", "webm"; NULL: from the extension).  path "-" is standard output:
 * Y4M unless format says otherwise; MP4 is refused there (its index is
 * written last, by seeking back). */
bool cap_sink_for_format(const char *path, const char *format, int w, int h, cap_sink *s, rs_err *err);

/* The audio codec the sink's container carries: "aac" (.mp4, .mkv,
 * .nut), "opus" (.webm), or NULL: no audio there (Y4M, images, null:,
 * segments, or a build without FFmpeg). */
const char *cap_sink_audio_codec(const cap_sink *s);
/* Gives the sink its soundtrack: frames stereo 48 kHz float frames (800
 * for every video frame, the first at video frame 0), encoded at bitrate
 * bits/s (0: 192k AAC, 128k Opus) and interleaved with the video as it is
 * written.  CAP_ERR_ENC_SETTING when the container takes no audio or the
 * bitrate is outside the encoder's range (the message names both). */
bool cap_sink_audio(cap_sink *s, cap_audio_read_fn read, void *u, size_t frames, int64_t bitrate, rs_err *err);

/* Human-readable list of what this build can write. */
const char *cap_sink_formats(void);

extern const cap_sink_ops cap_sink_y4m;
extern const cap_sink_ops cap_sink_null; /* counts frames, writes nothing (benchmarks) */

#endif
