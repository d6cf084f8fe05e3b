/* mv: movie sources for the attract loop.
 *
 * A source delivers 8-bit planar YCbCr frames, packed plane after plane with
 * no row padding: Y (w*h bytes), then Cb (cw*ch), then Cr (cw*ch).  Mono
 * sources have cw = ch = 0 and deliver Y only.  That layout is what the
 * upload paths copy into a pixel-unpack buffer (offsets 0, nY, nY+nC), so a
 * source may write a frame straight into mapped GPU memory.
 *
 * Two readers: Y4M (no dependencies; read directly) and anything FFmpeg's
 * libavformat/libavcodec decode (built when FFmpeg is found).  mv_open picks
 * by content: the "YUV4MPEG2 " magic means Y4M, anything else goes to FFmpeg. */
#ifndef MV_H
#define MV_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"

enum { MV_BT601 = 0, MV_BT709 = 1 };
/* Where chroma samples sit relative to luma (ITU-T H.273 terms):
 * CENTER  between luma columns and rows (JPEG, MPEG-1; Y4M 420jpeg)
 * LEFT    on even luma columns, between rows (MPEG-2, H.264 default; 420mpeg2)
 * TOPLEFT on even columns and even rows (DV PAL; Y4M 420paldv) */
enum { MV_CHROMA_CENTER = 0, MV_CHROMA_LEFT = 1, MV_CHROMA_TOPLEFT = 2 };

/* Error ids (rs_err.h) of every movie source, the decoder thread and the
 * uploader. */
#define MV_ERRORS(X)                                                                       \
    X(OPEN, "cannot open or read the file")                                                \
    X(FORMAT, "not a movie we understand: bad header, bad tag, bad size")                  \
    X(UNSUPPORTED, "a valid movie in a format we do not play (10-bit, alpha, interlaced)") \
    X(TRUNCATED, "the file ends inside a frame")                                           \
    X(DECODE, "the decoder failed mid-stream")                                             \
    X(NOMEM, "out of memory, or no thread to decode with")                                 \
    X(ARG, "a bad argument from the caller (slot count)")

typedef enum mv_error {
    MV_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_MV),
#define X(id, text) MV_ERR_##id,
    MV_ERRORS(X)
#undef X
        MV_ERR_END
} mv_error;

const char *mv_error_text(int code);

typedef struct mv_info {
    int w, h;             /* luma size, >= 1 */
    int cw, ch;           /* chroma plane size; 0x0 for mono */
    int sx, sy;           /* chroma subsampling as shifts: 4:2:0 is 1,1; 4:2:2 1,0; 4:4:4 0,0 */
    bool mono;
    int matrix;           /* MV_BT601 or MV_BT709 */
    bool full_range;      /* false: limited (16-235 / 16-240) */
    bool matrix_guessed;  /* the file did not say; chosen by size (HD -> 709) */
    int chroma_loc;       /* MV_CHROMA_* */
    int fps_num, fps_den; /* > 0 */
    int sar_num, sar_den; /* pixel aspect; 1:1 when unknown */
    int64_t frames;       /* -1 when unknown */
    char codec[32];       /* "y4m", "h264", "vp9", ... */
    char pixfmt[32];      /* "420jpeg", "yuv420p", ... as the file says */
} mv_info;

/* Bytes of one packed frame. */
static inline size_t mv_frame_bytes(const mv_info *i)
{
    return (size_t)i->w * (size_t)i->h + 2 * (size_t)i->cw * (size_t)i->ch;
}

/* Fills the derived fields (cw, ch from w, h, sx, sy, mono). */
void mv_info_planes(mv_info *i);
/* mpv's guess when the file has no matrix: BT.709 for HD sizes
 * (w >= 1280 or h > 576), else BT.601. */
int mv_guess_matrix(int w, int h);

typedef struct mv_src mv_src;
struct mv_src {
    mv_info info;
    char path[512];
    int64_t index; /* frames delivered so far */
    /* Writes the next frame into dst (mv_frame_bytes(&info) bytes).
     * 1: a frame; 0: clean end of stream; -1: error in err ("path: frame N: ..."). */
    int (*read)(mv_src *s, uint8_t *dst, rs_err *err);
    void (*close)(mv_src *s);
};

/* Opens by content (Y4M magic, else FFmpeg).  Errors name the path. */
mv_src *mv_open(const char *path, rs_err *err);
mv_src *mv_y4m_open(const char *path, rs_err *err);
mv_src *mv_ffmpeg_open(const char *path, rs_err *err); /* MV_ERR_UNSUPPORTED when built without FFmpeg */
void mv_close(mv_src *s);

/* The Y4M header parser alone (tests and fuzzing): the text after
 * "YUV4MPEG2 " up to (not including) the newline. */
bool mv_y4m_parse_header(const char *hdr, size_t len, mv_info *info, rs_err *err);

#endif
