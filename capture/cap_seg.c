/* Segments: the manifest, reading a segment back, and join's verification
 * (cap_seg.h has the contract; the stream copy is cap_join.c).
 *
 * A segment is checked in this order, and the first failure is its reason:
 *   manifest there (SEG_MISSING) and well formed (SEG_MANIFEST); its key
 *   (SEG_KEY); its format, the file's extension and the output's
 *   (SEG_FORMAT); the file there (SEG_MISSING) with the manifest's byte
 *   size (SEG_SIZE); its hash list (SEG_HASHES); the file read back
 *   through libavformat: one video stream of the manifest's size, as many
 *   packets as frames, the first a keyframe, pts exactly first..end-1 in
 *   presentation order, the packet CRC (SEG_MEDIA).
 * then all of them together: ticks that continue from the segment before
 * (SEG_TICKS), one frame size (SEG_FORMAT) and one set of codec
 * parameters (SEG_CODEC), the majority's. */
#include "cap_seg.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_hash.h"

#ifdef RS_HAVE_FFMPEG
#include <libavformat/avformat.h>
#endif

#define MANIFEST_MAGIC "ringside-segment 1"
#define MANIFEST_MAX 4096
#define HASHES_MAX ((size_t)1 << 30) /* 40 million lines: a week of ticks */

bool cap_seg_key_ok(const char *key)
{
    size_t n = strlen(key);
    if (n < 1 || n > CAP_SEG_KEY_MAX)
        return false;
    for (size_t i = 0; i < n; i++) {
        char c = key[i];
        if (!((c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
              c == ':' || c == '-'))
            return false;
    }
    return true;
}

void cap_seg_manifest_path(const char *seg, char *out, size_t n)
{
    snprintf(out, n, "%s.seg", seg);
}

static const char *ext_of(const char *path)
{
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : NULL;
}

void cap_seg_hashes_path(const char *seg, char *out, size_t n)
{
    const char *dot = ext_of(seg);
    int base = dot ? (int)(dot - seg) : (int)strlen(seg);
    snprintf(out, n, "%.*s.hashes", base, seg);
}

const char *cap_seg_format_of(const char *path)
{
    const char *e = ext_of(path);
    if (!e)
        return NULL;
    return !strcmp(e, ".mp4") ? "mp4" : !strcmp(e, ".mkv") ? "mkv" : !strcmp(e, ".webm") ? "webm" : NULL;
}

/* --- the hash list ------------------------------------------------------ */

bool cap_seg_hashes_parse(const char *text, size_t len, const char *path, uint64_t first, uint64_t end, uint64_t *fnv,
                          rs_err *err)
{
    const char *p = text, *stop = text + len;
    uint64_t want = first;
    bool ok = true;
    for (; p < stop && ok; want++) {
        char *q;
        errno = 0;
        unsigned long long n = strtoull(p, &q, 10);
        /* N as the render writes it (%llu): digits only, no leading zero */
        ok = q > p && *p >= '0' && *p <= '9' && (*p != '0' || q == p + 1) && !errno && n == want && *q == ' ';
        for (int i = 1; ok && i <= 16; i++)
            ok = q + i < stop && ((q[i] >= '0' && q[i] <= '9') || (q[i] >= 'a' && q[i] <= 'f'));
        ok = ok && q + 17 < stop && q[17] == '\n';
        if (ok)
            p = q + 18;
    }
    if (!ok)
        return rs_fail(err, CAP_ERR_SEG_HASHES, "%s: line %" PRIu64 " is not \"%" PRIu64 " <16 hex digits>\"", path,
                       want - first, want - 1);
    if (want != end)
        return rs_fail(err, CAP_ERR_SEG_HASHES, "%s: %" PRIu64 " lines, expected %" PRIu64 " (ticks %" PRIu64 "..%" PRIu64 ")",
                       path, want - first, end - first, first, end - 1);
    *fnv = rs_fnv1a64(text, len);
    return true;
}

/* The hash list at path: its text checked by cap_seg_hashes_parse. */
static bool hashes_check(const char *path, uint64_t first, uint64_t end, uint64_t *fnv, rs_err *err)
{
    size_t len;
    rs_err e = {0};
    char *text = rs_read_file(path, HASHES_MAX, &len, &e);
    if (!text)
        return rs_fail(err, CAP_ERR_SEG_HASHES, "%s", e.msg);
    bool ok = cap_seg_hashes_parse(text, len, path, first, end, fnv, err);
    free(text);
    return ok;
}

/* --- the manifest ------------------------------------------------------- */

int cap_seg_manifest_format(const cap_seg_info *m, char *out, size_t n)
{
    char hashes[24] = "none", replay[32] = "";
    if (m->has_hashes)
        snprintf(hashes, sizeof hashes, "%016" PRIx64, m->hashes_fnv);
    if (m->has_replay)
        snprintf(replay, sizeof replay, "replay %016" PRIx64 "\n", m->replay_fnv);
    return snprintf(out, n,
                    MANIFEST_MAGIC "\nkey %s\nformat %s\nsize %dx%d\nticks %" PRIu64 " %" PRIu64 "\nframes %" PRIu64
                                   "\nbytes %" PRIu64 "\ncrc32 %08" PRIx32 "\nhashes %s\n%s",
                    m->key, m->format, m->w, m->h, m->first, m->end, m->frames, m->bytes, m->crc, hashes, replay);
}

static bool manifest_write(const char *seg, const cap_seg_info *m, rs_err *err)
{
    char path[1100], text[MANIFEST_MAX];
    cap_seg_manifest_path(seg, path, sizeof path);
    int n = cap_seg_manifest_format(m, text, sizeof text);
    rs_err e = {0};
    if (!rs_write_part(path, text, (size_t)n, &e) || !rs_commit_file(path, &e))
        return rs_fail(err, CAP_ERR_WRITE, "%s", e.msg); /* rs_file's failure, as one of ours */
    return true;
}

/* One "name value" line; value points into the line. */
static bool manifest_line(const char **p, const char *name, char *value, size_t n)
{
    size_t len = strlen(name);
    const char *nl = strchr(*p, '\n');
    if (!nl || strncmp(*p, name, len) != 0 || (*p)[len] != ' ' || (size_t)(nl - *p - (ptrdiff_t)len - 1) >= n)
        return false;
    memcpy(value, *p + len + 1, (size_t)(nl - *p) - len - 1);
    value[nl - *p - (ptrdiff_t)len - 1] = 0;
    *p = nl + 1;
    return true;
}

bool cap_seg_manifest_parse(const char *text, const char *path, cap_seg_info *out, rs_err *err)
{
    cap_seg_info got = {0}, *m = &got; /* the caller's is filled only when all of it is good */
    const char *p = text;
    char v[5][128];
    const char *bad = NULL;
    char tail;
    if (strncmp(p, MANIFEST_MAGIC "\n", sizeof MANIFEST_MAGIC) != 0)
        bad = "does not start with '" MANIFEST_MAGIC "'";
    else if (p += sizeof MANIFEST_MAGIC, !manifest_line(&p, "key", m->key, sizeof m->key) || !cap_seg_key_ok(m->key))
        bad = "no valid 'key' line";
    else if (!manifest_line(&p, "format", m->format, sizeof m->format))
        bad = "no 'format' line";
    else if (!manifest_line(&p, "size", v[0], sizeof v[0]) || sscanf(v[0], "%dx%d%c", &m->w, &m->h, &tail) != 2 ||
             m->w <= 0 || m->h <= 0)
        bad = "no valid 'size WxH' line";
    else if (!manifest_line(&p, "ticks", v[1], sizeof v[1]) ||
             sscanf(v[1], "%" SCNu64 " %" SCNu64 "%c", &m->first, &m->end, &tail) != 2 || m->end <= m->first)
        bad = "no valid 'ticks FIRST END' line";
    else if (!manifest_line(&p, "frames", v[2], sizeof v[2]) || sscanf(v[2], "%" SCNu64 "%c", &m->frames, &tail) != 1 ||
             m->frames != m->end - m->first)
        bad = "no 'frames' line equal to END - FIRST";
    else if (!manifest_line(&p, "bytes", v[3], sizeof v[3]) || sscanf(v[3], "%" SCNu64 "%c", &m->bytes, &tail) != 1 ||
             m->bytes < m->frames) /* every packet has a byte at least: bounds what reading it back allocates */
        bad = "no valid 'bytes' line (at least one a frame)";
    else if (!manifest_line(&p, "crc32", v[4], sizeof v[4]) || strlen(v[4]) != 8 ||
             sscanf(v[4], "%" SCNx32 "%c", &m->crc, &tail) != 1)
        bad = "no valid 'crc32' line";
    else if (!manifest_line(&p, "hashes", v[0], sizeof v[0]) ||
             (strcmp(v[0], "none") && (strlen(v[0]) != 16 || sscanf(v[0], "%" SCNx64 "%c", &m->hashes_fnv, &tail) != 1)))
        bad = "no valid 'hashes' line";
    else if (*p && !(m->has_replay = manifest_line(&p, "replay", v[1], sizeof v[1]) && strlen(v[1]) == 16 &&
                                     sscanf(v[1], "%" SCNx64 "%c", &m->replay_fnv, &tail) == 1))
        bad = "no valid 'replay' line after the 'hashes' line";
    else if (*p)
        bad = "has text after the 'replay' line";
    m->has_hashes = !bad && strcmp(v[0], "none") != 0;
    if (bad)
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s: %s (not a ringside segment manifest, or a damaged one)", path, bad);
    *out = got;
    return true;
}

static bool manifest_read(const char *seg, cap_seg_info *out, rs_err *err)
{
    char path[1100];
    cap_seg_manifest_path(seg, path, sizeof path);
    struct stat st;
    if (stat(path, &st) != 0)
        return rs_fail(err, CAP_ERR_SEG_MISSING, "%s: no manifest %s (the segment is unfinished or was never rendered)",
                       seg, path);
    size_t len;
    rs_err e = {0};
    char *text = rs_read_file(path, MANIFEST_MAX, &len, &e);
    if (!text)
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s", e.msg);
    bool ok = cap_seg_manifest_parse(text, path, out, err);
    free(text);
    return ok;
}

/* --- reading a segment back --------------------------------------------- */

#ifdef RS_HAVE_FFMPEG
static int cmp_i64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

/* Opens seg through libavformat and checks its packets are ticks
 * m->first..m->end-1 (m->w == 0: takes the size from the file); fills the
 * packet CRC, the codec signature and the B-frame delay. */
static bool probe(const char *seg, cap_seg_info *m, uint32_t *crc, cap_seg *out, rs_err *err)
{
    AVFormatContext *ic = NULL;
    AVPacket *pkt = av_packet_alloc();
    int64_t *pts = malloc((size_t)m->frames * sizeof *pts);
    bool ok = false;
    uint64_t n = 0;
    int r;
    if (!pkt || !pts) {
        rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory for %" PRIu64 " timestamps", seg, m->frames);
        goto done;
    }
    if ((r = avformat_open_input(&ic, seg, NULL, NULL)) < 0) {
        char why[AV_ERROR_MAX_STRING_SIZE];
        av_strerror(r, why, sizeof why);
        rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: libavformat cannot open it: %s", seg, why);
        goto done;
    }
    const AVCodecParameters *par = ic->nb_streams == 1 ? ic->streams[0]->codecpar : NULL;
    if (!par || par->codec_type != AVMEDIA_TYPE_VIDEO) {
        rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: %u streams, expected one video stream", seg, ic->nb_streams);
        goto done;
    }
    if (!m->w) {
        m->w = par->width;
        m->h = par->height;
    }
    if (par->width != m->w || par->height != m->h) {
        rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: frames of %dx%d, the manifest says %dx%d", seg, par->width, par->height,
                m->w, m->h);
        goto done;
    }
    uint32_t sig = rs_crc32(0, &par->codec_id, sizeof par->codec_id);
    sig = rs_crc32(sig, &par->width, sizeof par->width);
    sig = rs_crc32(sig, &par->height, sizeof par->height);
    out->codec_sig = par->extradata ? rs_crc32(sig, par->extradata, (size_t)par->extradata_size) : sig;
    AVRational tb = ic->streams[0]->time_base;
    *crc = 0;
    while ((r = av_read_frame(ic, pkt)) >= 0) {
        const char *bad = n == m->frames ? "more packets than the manifest's frames"
                          : n == 0 && !(pkt->flags & AV_PKT_FLAG_KEY) ? "the first packet is not a keyframe"
                          : pkt->pts == AV_NOPTS_VALUE ? "a packet without a timestamp"
                                                       : NULL;
        if (bad) {
            av_packet_unref(pkt);
            rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: packet %" PRIu64 ": %s", seg, n, bad);
            goto done;
        }
        pts[n] = av_rescale_q(pkt->pts, tb, (AVRational){1, 60});
        int64_t lag = (int64_t)(m->first + n) - pts[n];
        if (lag > out->reorder)
            out->reorder = (int)lag;
        *crc = rs_crc32(*crc, pkt->data, (size_t)pkt->size);
        n++;
        av_packet_unref(pkt);
    }
    if (r != AVERROR_EOF) {
        char why[AV_ERROR_MAX_STRING_SIZE];
        av_strerror(r, why, sizeof why);
        rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: read error after %" PRIu64 " packets: %s", seg, n, why);
        goto done;
    }
    if (n != m->frames) {
        rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: %" PRIu64 " packets, expected %" PRIu64 " frames (ticks %" PRIu64 "..%" PRIu64 ")",
                seg, n, m->frames, m->first, m->end - 1);
        goto done;
    }
    qsort(pts, (size_t)n, sizeof *pts, cmp_i64);
    for (uint64_t k = 0; k < n; k++)
        if (pts[k] != (int64_t)(m->first + k)) {
            rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: timestamps are not ticks %" PRIu64 "..%" PRIu64 " at 1/60 s: frame %" PRIu64
                    " is at %" PRId64, seg, m->first, m->end - 1, k, pts[k]);
            goto done;
        }
    ok = true;
done:
    avformat_close_input(&ic);
    av_packet_free(&pkt);
    free(pts);
    return ok;
}
#else
static bool probe(const char *seg, cap_seg_info *m, uint32_t *crc, cap_seg *out, rs_err *err)
{
    (void)m, (void)crc, (void)out;
    return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no segments", seg);
}
#endif

bool cap_seg_seal(const char *seg, const char *key, uint64_t first, uint64_t end, const char *hashes,
                  const uint64_t *replay_fnv, rs_err *err)
{
    cap_seg_info m = {.first = first, .end = end, .frames = end - first};
    if (replay_fnv)
        m.has_replay = true, m.replay_fnv = *replay_fnv;
    cap_seg s = {.path = seg};
    const char *fmt = cap_seg_format_of(seg);
    struct stat st;
    if (!cap_seg_key_ok(key) || !fmt)
        return rs_fail(err, CAP_ERR_ARG, "%s: a segment needs a key of [A-Za-z0-9._:-]{1,64} and .mp4, .mkv or .webm", seg);
    snprintf(m.key, sizeof m.key, "%s", key);
    snprintf(m.format, sizeof m.format, "%s", fmt);
    if (stat(seg, &st) != 0)
        return rs_fail(err, CAP_ERR_SEG_MISSING, "%s: gone before its manifest was written: %s", seg, strerror(errno));
    m.bytes = (uint64_t)st.st_size;
    /* read back what was just written, as join will (Chocolate Doom's demo writer does the same) */
    if (!probe(seg, &m, &m.crc, &s, err)) {
        rs_err_prefix(err, "read back");
        return false;
    }
    if (hashes) {
        m.has_hashes = true;
        if (!hashes_check(hashes, first, end, &m.hashes_fnv, err))
            return false;
    }
    return manifest_write(seg, &m, err);
}

bool cap_seg_replay_fnv(const char *replay, uint64_t *out, rs_err *err)
{
    size_t len;
    char *bytes = rs_read_file(replay, (size_t)1 << 30, &len, err);
    if (!bytes)
        return false;
    *out = rs_fnv1a64(bytes, len);
    free(bytes);
    return true;
}

/* --- verification ------------------------------------------------------- */

static bool verify_one(cap_seg *s, const cap_seg_want *want, rs_err *err)
{
    cap_seg_info *m = &s->m;
    if (!manifest_read(s->path, m, err))
        return false;
    if (strcmp(m->key, want->key) != 0)
        return rs_fail(err, CAP_ERR_SEG_KEY, "%s: segment of '%s', not of '%s' (another job, or an earlier attempt)", s->path,
                       m->key, want->key);
    const char *fmt = cap_seg_format_of(s->path);
    if (!fmt || strcmp(fmt, m->format) != 0)
        return rs_fail(err, CAP_ERR_SEG_FORMAT, "%s: its manifest says %s, its name does not", s->path, m->format);
    if (strcmp(m->format, want->format) != 0)
        return rs_fail(err, CAP_ERR_SEG_FORMAT, "%s: a %s segment, and the output is %s", s->path, m->format, want->format);
    struct stat st;
    if (stat(s->path, &st) != 0)
        return rs_fail(err, CAP_ERR_SEG_MISSING, "%s: the segment file is missing: %s", s->path, strerror(errno));
    if (!S_ISREG(st.st_mode) || (uint64_t)st.st_size != m->bytes)
        return rs_fail(err, CAP_ERR_SEG_SIZE, "%s: %lld bytes, the manifest says %" PRIu64 " (truncated or overwritten)",
                       s->path, (long long)st.st_size, m->bytes);
    if (m->has_hashes || want->hashes) {
        char hpath[1100];
        uint64_t fnv;
        cap_seg_hashes_path(s->path, hpath, sizeof hpath);
        if (!m->has_hashes)
            return rs_fail(err, CAP_ERR_SEG_HASHES, "%s: rendered without --hashes, and the join wants them", s->path);
        if (!hashes_check(hpath, m->first, m->end, &fnv, err))
            return false;
        if (fnv != m->hashes_fnv)
            return rs_fail(err, CAP_ERR_SEG_HASHES, "%s: its FNV-1a is %016" PRIx64 ", the manifest says %016" PRIx64 " (edited?)",
                           hpath, fnv, m->hashes_fnv);
    }
    uint32_t crc;
    if (!probe(s->path, m, &crc, s, err))
        return false;
    if (crc != m->crc)
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: packet CRC-32 %08" PRIx32 ", the manifest says %08" PRIx32 " (damaged)",
                       s->path, crc, m->crc);
    return true;
}

/* Index of the value most segments still good share (ties: the earliest). */
static int majority(const cap_seg *segs, const bool *bad, int n, uint64_t (*key)(const cap_seg *))
{
    int best = -1, best_count = 0;
    for (int i = 0; i < n; i++) {
        if (bad[i])
            continue;
        int c = 0;
        for (int j = 0; j < n; j++)
            c += !bad[j] && key(&segs[j]) == key(&segs[i]);
        if (c > best_count)
            best = i, best_count = c;
    }
    return best;
}

static uint64_t size_of(const cap_seg *s)
{
    return (uint64_t)s->m.w << 32 | (uint32_t)s->m.h;
}

static uint64_t codec_of(const cap_seg *s)
{
    return s->codec_sig;
}

int cap_seg_verify(cap_seg *segs, int n, const cap_seg_want *want, void (*bad)(void *ctx, int index, const rs_err *err),
                   void *ctx)
{
    bool *is_bad = calloc((size_t)n + 1, sizeof *is_bad);
    rs_err *why = calloc((size_t)n + 1, sizeof *why);
    bool *parsed = calloc((size_t)n + 1, sizeof *parsed);
    if (!is_bad || !why || !parsed) {
        for (int i = 0; i < n; i++) /* cannot even say which: all of them, so nothing is joined */
            bad(ctx, i, &(rs_err){CAP_ERR_NOMEM, "out of memory"});
        free(is_bad), free(why), free(parsed);
        return n;
    }
    for (int i = 0; i < n; i++) {
        segs[i].m = (cap_seg_info){0};
        segs[i].reorder = 0;
        is_bad[i] = !verify_one(&segs[i], want, &why[i]);
        parsed[i] = segs[i].m.end > 0; /* its ticks are known, even if it is bad for another reason */
    }
    /* ticks: each segment starts where the one before ended */
    for (int i = 0; i < n; i++) {
        if (is_bad[i] || (i > 0 && !parsed[i - 1]))
            continue;
        uint64_t from = i == 0 ? want->first : segs[i - 1].m.end;
        if (segs[i].m.first != from) {
            is_bad[i] = true;
            rs_fail(&why[i], CAP_ERR_SEG_TICKS, "%s: ticks %" PRIu64 "..%" PRIu64 ", expected to start at %" PRIu64 " (%s)",
                    segs[i].path, segs[i].m.first, segs[i].m.end - 1, from,
                    i == 0 ? "the video's first tick" : "where the segment before ends");
        }
    }
    int ref = majority(segs, is_bad, n, size_of);
    for (int i = 0; ref >= 0 && i < n; i++)
        if (!is_bad[i] && size_of(&segs[i]) != size_of(&segs[ref])) {
            is_bad[i] = true;
            rs_fail(&why[i], CAP_ERR_SEG_FORMAT, "%s: %dx%d frames, the other segments are %dx%d", segs[i].path, segs[i].m.w,
                    segs[i].m.h, segs[ref].m.w, segs[ref].m.h);
        }
    ref = majority(segs, is_bad, n, codec_of);
    for (int i = 0; ref >= 0 && i < n; i++)
        if (!is_bad[i] && segs[i].codec_sig != segs[ref].codec_sig) {
            is_bad[i] = true;
            rs_fail(&why[i], CAP_ERR_SEG_CODEC, "%s: codec parameters differ from %s's (another encoder or settings)",
                    segs[i].path, segs[ref].path);
        }
    int count = 0;
    for (int i = 0; i < n; i++)
        if (is_bad[i]) {
            bad(ctx, i, &why[i]);
            count++;
        }
    free(is_bad), free(why), free(parsed);
    return count;
}
