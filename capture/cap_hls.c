/* HLS pieces (cap_hls.h): the index and playlist text here, the cutting
 * through libavformat below.
 *
 * DESIGN
 * - Pieces are cut at the keyframes the encoder already places (every
 *   120 frames, and a segment's first frame), by stream copy into MPEG-TS:
 *   every piece starts with a keyframe and its parameter sets (the muxer's
 *   own Annex B filter puts them there), so each plays alone.
 * - The sound is one AAC stream for the whole match, encoded once, and a
 *   piece takes the track's packets that start in its time: cut by copy
 *   too, so there is no encoder restart, no priming and no click where
 *   pieces or units meet.  A unit's own encoding of its stretch would
 *   restart the AAC encoder at every unit.  The track is written in parts
 *   of 10 s (track.K.ts), each put in place when complete, so the first
 *   unit's pieces wait for the match's loudness and their own 10 s, not
 *   for the whole match's encoding (10 s of one core for 10 minutes).
 * - Timestamps come from ticks, not from the input's: pts = tick +
 *   CAP_HLS_OFFSET_TICKS, dts = position - CAP_HLS_REORDER, so two pieces
 *   cut by different processes continue each other exactly, as the join's
 *   do (cap_join.c).
 * - A unit is written as temporaries of this process, checked whole (the
 *   segment's CRC against its manifest), renamed, then indexed: an index
 *   on disk means the pieces it names are complete. */
#include "cap_hls.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <time.h>
#include <unistd.h>

#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_progress.h"

#define INDEX_MAGIC "ringside-hls 1"

void cap_hls_index_free(cap_hls_index *ix)
{
    free(ix->p);
    *ix = (cap_hls_index){0};
}

static void index_path(const char *dir, uint64_t first, char *out, size_t n)
{
    snprintf(out, n, "%s/u%" PRIu64 ".idx", dir, first);
}

static void piece_path(const char *dir, uint64_t tick, char *out, size_t n)
{
    snprintf(out, n, "%s/t%" PRIu64 ".ts", dir, tick);
}

#define PART_SAMPLES ((int64_t)CAP_HLS_TRACK_PART_TICKS * 800) /* 800 sample frames a tick */

int cap_hls_track_parts(uint64_t total)
{
    uint64_t n = (total + CAP_HLS_TRACK_PART_TICKS - 1) / CAP_HLS_TRACK_PART_TICKS;
    return n < 1 ? 1 : n > INT32_MAX ? INT32_MAX : (int)n;
}

void cap_hls_track_path(const char *dir, int k, char *out, size_t n)
{
    snprintf(out, n, "%s/track.%d.ts", dir, k);
}

bool cap_hls_track_whole(const char *dir, uint64_t total)
{
    char path[1100];
    cap_hls_track_path(dir, cap_hls_track_parts(total) - 1, path, sizeof path);
    return access(path, F_OK) == 0;
}

int cap_hls_index_format(const cap_hls_index *ix, char *out, size_t n)
{
    size_t at = 0;
    int k = snprintf(out, n, INDEX_MAGIC "\nunit %" PRIu64 " %" PRIu64 "\n", ix->first, ix->end);
    if (k < 0)
        return k;
    at += (size_t)k;
    for (int i = 0; i < ix->n; i++) {
        const cap_hls_piece *p = &ix->p[i];
        k = snprintf(at < n ? out + at : NULL, at < n ? n - at : 0, "piece %" PRIu64 " %" PRIu64 " %" PRIu64 " %016" PRIx64 "\n",
                     p->tick, p->frames, p->bytes, p->fnv);
        if (k < 0)
            return k;
        at += (size_t)k;
    }
    return (int)at;
}

/* A decimal without sign or leading zero (but "0"), then one separator. */
static bool num(const char **s, uint64_t *v, char sep)
{
    const char *p = *s;
    if (*p < '0' || *p > '9' || (*p == '0' && p[1] >= '0' && p[1] <= '9'))
        return false;
    uint64_t x = 0;
    for (; *p >= '0' && *p <= '9'; p++) {
        if (x > (UINT64_MAX - 9) / 10)
            return false;
        x = x * 10 + (uint64_t)(*p - '0');
    }
    if (*p != sep)
        return false;
    *v = x;
    *s = p + 1;
    return true;
}

bool cap_hls_index_parse(const char *text, const char *path, cap_hls_index *ix, rs_err *err)
{
    *ix = (cap_hls_index){0};
    const char *s = text;
    size_t ml = strlen(INDEX_MAGIC);
    if (strncmp(s, INDEX_MAGIC "\n", ml + 1) != 0)
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s: not a piece index (line 1)", path);
    s += ml + 1;
    uint64_t first, end;
    if (strncmp(s, "unit ", 5) != 0 || (s += 5, !num(&s, &first, ' ')) || !num(&s, &end, '\n') || end <= first)
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s: line 2: expected 'unit FIRST END' with FIRST < END", path);
    cap_hls_index out = {.first = first, .end = end};
    uint64_t next = first;
    for (int line = 3; *s; line++) {
        cap_hls_piece p;
        char *hex_end;
        bool ok = strncmp(s, "piece ", 6) == 0 && (s += 6, num(&s, &p.tick, ' ')) && num(&s, &p.frames, ' ') &&
                  num(&s, &p.bytes, ' ');
        if (ok) {
            errno = 0;
            p.fnv = strtoull(s, &hex_end, 16);
            ok = !errno && hex_end == s + 16 && *hex_end == '\n';
            for (int k = 0; ok && k < 16; k++)
                ok = (s[k] >= '0' && s[k] <= '9') || (s[k] >= 'a' && s[k] <= 'f');
        }
        if (!ok || p.tick != next || p.frames == 0 || p.frames > end - next || p.bytes == 0) {
            free(out.p);
            return rs_fail(err, CAP_ERR_SEG_MANIFEST,
                           "%s: line %d: expected 'piece TICK FRAMES BYTES FNV' continuing at tick %" PRIu64
                           " within the unit's ticks", path, line, next);
        }
        s = hex_end + 1;
        if (out.n % 64 == 0) {
            cap_hls_piece *q = realloc(out.p, ((size_t)out.n + 64) * sizeof *q);
            if (!q) {
                free(out.p);
                return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", path);
            }
            out.p = q;
        }
        out.p[out.n++] = p;
        next = p.tick + p.frames;
    }
    if (next != end) {
        free(out.p);
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s: the pieces end at tick %" PRIu64 ", the unit at %" PRIu64, path,
                       next, end);
    }
    *ix = out;
    return true;
}

int cap_hls_index_read(const char *dir, uint64_t first, cap_hls_index *ix, rs_err *err)
{
    char path[1100];
    size_t len;
    rs_err e = {0};
    index_path(dir, first, path, sizeof path);
    *ix = (cap_hls_index){0};
    if (access(path, F_OK) != 0 && errno == ENOENT)
        return 0;
    char *text = rs_read_file(path, (size_t)4 << 20, &len, &e);
    if (!text)
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s", e.msg), -1;
    bool ok = strlen(text) == len && cap_hls_index_parse(text, path, ix, err);
    if (!ok && strlen(text) != len)
        rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s: not a piece index (a NUL byte)", path);
    free(text);
    if (ok && ix->first != first) {
        cap_hls_index_free(ix);
        return rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s: names another unit", path), -1;
    }
    return ok ? 1 : -1;
}

bool cap_hls_piece_check(const char *dir, const cap_hls_piece *p, uint8_t **data, rs_err *err)
{
    char path[1100];
    size_t len;
    rs_err e = {0};
    piece_path(dir, p->tick, path, sizeof path);
    char *bytes = rs_read_file(path, (size_t)p->bytes + 1, &len, &e);
    if (!bytes)
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s", e.msg);
    if (len != p->bytes || rs_fnv1a64(bytes, len) != p->fnv) {
        free(bytes);
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: %s its index (%" PRIu64 " bytes, FNV-1a %016" PRIx64 ")", path,
                       len != p->bytes ? "not the size of" : "not the bytes of", p->bytes, p->fnv);
    }
    if (data)
        *data = (uint8_t *)bytes;
    else
        free(bytes);
    return true;
}

bool cap_hls_unit_check(const char *dir, uint64_t first, uint64_t end, rs_err *err)
{
    cap_hls_index ix;
    int r = cap_hls_index_read(dir, first, &ix, err);
    if (r == 0)
        return rs_fail(err, CAP_ERR_SEG_MISSING, "%s/u%" PRIu64 ".idx: no index", dir, first);
    bool ok = r == 1 && (ix.end == end || rs_fail(err, CAP_ERR_SEG_MANIFEST, "%s/u%" PRIu64 ".idx: ends at tick %" PRIu64
                                                  ", not %" PRIu64, dir, first, ix.end, end));
    for (int i = 0; ok && i < ix.n; i++)
        ok = cap_hls_piece_check(dir, &ix.p[i], NULL, err);
    cap_hls_index_free(&ix);
    return ok;
}

/* Grows *b by the printf; false once out of memory (then *b is NULL). */
static bool put(char **b, size_t *len, size_t *cap, const char *fmt, ...) __attribute__((format(printf, 4, 5)));
static bool put(char **b, size_t *len, size_t *cap, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = *b ? vsnprintf(*b + *len, *cap - *len, fmt, ap) : -1;
        va_end(ap);
        if (k < 0)
            return false;
        if ((size_t)k < *cap - *len) {
            *len += (size_t)k;
            return true;
        }
        char *nb = realloc(*b, *cap * 2 + (size_t)k);
        if (!nb) {
            free(*b);
            *b = NULL;
            return false;
        }
        *b = nb;
        *cap = *cap * 2 + (size_t)k;
    }
}

char *cap_hls_playlist(const cap_hls_index *units, int n, bool ended, const char *prefix, size_t *len)
{
    size_t cap = 4096, at = 0;
    char *b = malloc(cap);
    int target = CAP_HLS_TARGET_SECONDS;
    for (int u = 0; u < n; u++)
        for (int i = 0; i < units[u].n; i++) {
            int s = (int)((units[u].p[i].frames + 30) / 60); /* rounded, as the rule reads */
            if (s > target)
                target = s;
        }
    bool ok = put(&b, &at, &cap,
                  "#EXTM3U\n#EXT-X-VERSION:7\n#EXT-X-TARGETDURATION:%d\n#EXT-X-MEDIA-SEQUENCE:0\n"
                  "#EXT-X-PLAYLIST-TYPE:EVENT\n#EXT-X-INDEPENDENT-SEGMENTS\n",
                  target);
    for (int u = 0; ok && u < n; u++)
        for (int i = 0; ok && i < units[u].n; i++) {
            const cap_hls_piece *p = &units[u].p[i];
            ok = put(&b, &at, &cap, "#EXTINF:%" PRIu64 ".%06" PRIu64 ",\n%s%" PRIu64 ".ts\n", p->frames / 60,
                     p->frames % 60 * 1000000 / 60, prefix, p->tick);
        }
    if (ok && ended)
        ok = put(&b, &at, &cap, "#EXT-X-ENDLIST\n");
    if (!ok)
        return NULL;
    *len = at;
    return b;
}

#ifdef RS_HAVE_FFMPEG
#include <libavformat/avformat.h>

#include "cap_enc_local.h"

static bool fail_av(rs_err *err, int id, const char *path, const char *what, int code)
{
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, msg, sizeof msg);
    return rs_fail(err, id, "%s: %s: %s", path, what, msg);
}

static bool sync_close(const char *path, rs_err *err)
{
    int fd = open(path, O_RDONLY);
    bool ok = fd >= 0 && fsync(fd) == 0;
    if (fd >= 0)
        close(fd);
    return ok || rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", path, strerror(errno));
}

/* An MPEG-TS output at path; the caller adds streams. */
static AVFormatContext *ts_open(const char *path, rs_err *err)
{
    AVFormatContext *fmt = NULL;
    int r = avformat_alloc_output_context2(&fmt, NULL, "mpegts", path);
    if (r < 0) {
        fail_av(err, CAP_ERR_NOT_BUILT, path, "this FFmpeg cannot write MPEG-TS", r);
        return NULL;
    }
    if ((r = avio_open(&fmt->pb, path, AVIO_FLAG_WRITE)) < 0) {
        fail_av(err, CAP_ERR_CREATE, path, "cannot create", r);
        avformat_free_context(fmt);
        return NULL;
    }
    return fmt;
}

/* Trailer, close, fsync.  Frees fmt. */
static bool ts_close(AVFormatContext *fmt, const char *path, bool ok, rs_err *err)
{
    int r;
    if (ok && (r = av_write_trailer(fmt)) < 0)
        ok = fail_av(err, CAP_ERR_WRITE, path, "write failed", r);
    if (fmt->pb) {
        int perr = fmt->pb->error;
        if (avio_closep(&fmt->pb) < 0 && ok)
            ok = rs_fail(err, CAP_ERR_WRITE, "%s: write failed", path);
        if (ok && perr < 0)
            ok = fail_av(err, CAP_ERR_WRITE, path, "write failed", perr);
    }
    avformat_free_context(fmt);
    return ok && sync_close(path, err);
}

static AVDictionary *ts_opts(void)
{
    AVDictionary *o = NULL;
    av_dict_set(&o, "mpegts_copyts", "1", 0); /* our timestamps as they are: no shift of the muxer's */
    /* each piece's continuity counters start again: say so in its first
     * packets, or a player reading pieces back to back (FFmpeg's HLS
     * demuxer) flags the piece before as corrupt */
    av_dict_set(&o, "mpegts_flags", "+initial_discontinuity", 0);
    return o;
}

/* The track's packets into their parts, as the encoder gives them */
typedef struct part_writer {
    const char *dir;
    int nparts;
    int k;                    /* the part being written (or skipped); -1: none yet */
    bool skip;                /* part k was there: its packets are dropped */
    int64_t first_pts;        /* the first packet's (sample 0); AV_NOPTS_VALUE: none yet */
    AVRational tb;            /* the packets' time base */
    const AVCodecParameters *par;
    int frame_size;
    AVFormatContext *out;
    char path[1100], tmp[1200];
} part_writer;

static bool part_open(part_writer *w, int k, rs_err *err)
{
    w->k = k;
    cap_hls_track_path(w->dir, k, w->path, sizeof w->path);
    w->skip = access(w->path, F_OK) == 0;
    if (w->skip)
        return true;
    snprintf(w->tmp, sizeof w->tmp, "%s/.track.%d.ts.%d.part", w->dir, k, (int)getpid());
    if (!(w->out = ts_open(w->tmp, err)))
        return false;
    AVStream *st = avformat_new_stream(w->out, NULL);
    if (!st)
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", w->tmp);
    int r = avcodec_parameters_copy(st->codecpar, w->par);
    if (r < 0)
        return fail_av(err, CAP_ERR_NOMEM, w->tmp, "codec parameters", r);
    st->codecpar->frame_size = w->frame_size;
    st->time_base = w->tb;
    AVDictionary *o = ts_opts();
    r = avformat_write_header(w->out, &o);
    av_dict_free(&o);
    return r >= 0 || fail_av(err, CAP_ERR_WRITE, w->tmp, "cannot write the header", r);
}

/* The part being written: closed, synced, linked into place (a part a
 * racing maker put there first stays). */
static bool part_close(part_writer *w, bool ok, rs_err *err)
{
    if (w->skip || !w->out)
        return ok;
    ok = ts_close(w->out, w->tmp, ok, err);
    w->out = NULL;
    if (ok && link(w->tmp, w->path) != 0 && errno != EEXIST)
        ok = rs_fail(err, CAP_ERR_WRITE, "%s: cannot link %s into place: %s", w->path, w->tmp, strerror(errno));
    unlink(w->tmp);
    return ok;
}

static bool part_put(void *u, AVPacket *pkt, rs_err *err)
{
    part_writer *w = u;
    if (w->first_pts == AV_NOPTS_VALUE)
        w->first_pts = pkt->pts;
    int64_t sample = av_rescale_q(pkt->pts - w->first_pts, w->tb, (AVRational){1, 48000});
    int64_t k = sample / PART_SAMPLES;
    if (k >= w->nparts) /* the encoder's last packets: the last part's */
        k = w->nparts - 1;
    while (w->k < k) {
        if (!part_close(w, true, err) || !part_open(w, w->k + 1, err))
            return false;
    }
    if (w->skip)
        return true;
    AVStream *st = w->out->streams[0];
    av_packet_rescale_ts(pkt, w->tb, st->time_base);
    pkt->stream_index = 0;
    int r = av_interleaved_write_frame(w->out, pkt); /* takes the reference */
    return r >= 0 || fail_av(err, CAP_ERR_WRITE, w->tmp, "write failed", r);
}

bool cap_hls_track(const char *dir, const cap_sink *audio, uint64_t total, rs_err *err)
{
    if (cap_hls_track_whole(dir, total))
        return true;
    cap_av_log_level();
    /* the encoder's stream lives in a container without a file: the
     * packets go to the parts */
    AVFormatContext *fmt = NULL;
    int r = avformat_alloc_output_context2(&fmt, NULL, "mpegts", NULL);
    if (r < 0)
        return fail_av(err, CAP_ERR_NOT_BUILT, dir, "this FFmpeg cannot write MPEG-TS", r);
    cap_sink s = *audio;
    if (!s.audio_bitrate)
        s.audio_bitrate = 192000; /* the default of .mp4 renders (cap_audio.c) */
    snprintf(s.audio_codec, sizeof s.audio_codec, "aac"); /* what every HLS player plays */
    s.audio_fast = true; /* a 3-minute match in 2.3 s instead of 9.5 */
    snprintf(s.path, sizeof s.path, "%s/track.K.ts", dir); /* for messages: the parts */
    part_writer w = {.dir = dir, .nparts = cap_hls_track_parts(total), .k = -1, .first_pts = AV_NOPTS_VALUE};
    cap_aenc a = {0};
    bool ok = cap_aenc_open(&a, &s, fmt, err);
    if (ok) {
        w.tb = a.st->time_base;
        w.par = a.st->codecpar;
        w.frame_size = a.ctx->frame_size;
        a.put = part_put, a.put_u = &w;
        ok = part_open(&w, 0, err) && cap_aenc_finish(&a, &s, fmt, err);
    }
    /* the parts no packet started in (a last part shorter than a packet) */
    while (ok && w.k < w.nparts - 1)
        ok = part_close(&w, true, err) && part_open(&w, w.k + 1, err);
    ok = part_close(&w, ok, err);
    cap_aenc_close(&a);
    avformat_free_context(fmt);
    return ok;
}

typedef struct cutter {
    const cap_hls_cut_desc *d;
    AVFormatContext *vin, *ain; /* ain: the track's part being read, or NULL */
    int vi;                   /* the video stream of vin */
    AVPacket *pkt, *apkt;     /* apkt: the track's next packet, read ahead (empty: none left) */
    AVCodecParameters *apar;  /* the track's stream (NULL: silent pieces) */
    AVRational atb;           /* its time base */
    int apart, nparts;        /* the track's next part to read (ain: the one being read), of */
    int64_t a0;               /* the track's first pts: sample 0 */
    bool a_eof;
    AVFormatContext *out;     /* the piece being written */
    AVStream *ost, *oast;
    cap_hls_index ix;         /* what is written so far */
    char part[1200];
} cutter;

static void part_path(const cutter *c, uint64_t tick, char *out, size_t n)
{
    snprintf(out, n, "%s/.t%" PRIu64 ".ts.%d.part", c->d->dir, tick, (int)getpid());
}

static bool piece_open(cutter *c, uint64_t tick, rs_err *err)
{
    if (c->ix.n % 64 == 0) {
        cap_hls_piece *q = realloc(c->ix.p, ((size_t)c->ix.n + 64) * sizeof *q);
        if (!q)
            return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", c->d->dir);
        c->ix.p = q;
    }
    c->ix.p[c->ix.n++] = (cap_hls_piece){.tick = tick}; /* first: remove_parts finds its temporary */
    part_path(c, tick, c->part, sizeof c->part);
    if (!(c->out = ts_open(c->part, err)))
        return false;
    AVStream *in = c->vin->streams[c->vi];
    if (!(c->ost = avformat_new_stream(c->out, NULL)) || (c->apar && !(c->oast = avformat_new_stream(c->out, NULL))))
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", c->part);
    int r;
    if ((r = avcodec_parameters_copy(c->ost->codecpar, in->codecpar)) < 0 ||
        (c->apar && (r = avcodec_parameters_copy(c->oast->codecpar, c->apar)) < 0))
        return fail_av(err, CAP_ERR_NOMEM, c->part, "codec parameters", r);
    c->ost->codecpar->codec_tag = 0;
    c->ost->time_base = (AVRational){1, 90000};
    if (c->oast) {
        c->oast->codecpar->codec_tag = 0;
        if (!c->oast->codecpar->frame_size)
            c->oast->codecpar->frame_size = 1024; /* AAC's; MPEG-TS does not keep it */
        c->oast->time_base = (AVRational){1, 90000};
    }
    AVDictionary *o = ts_opts();
    r = avformat_write_header(c->out, &o);
    av_dict_free(&o);
    if (r < 0)
        return fail_av(err, CAP_ERR_WRITE, c->part, "cannot write the header", r);
    return true;
}

/* Part k of the track open in c->ain: waited for while a maker is at
 * work (cap_hls_cut_desc.track_alive), checked to be one AAC stream. */
static bool part_read_open(cutter *c, int k, rs_err *err)
{
    const cap_hls_cut_desc *d = c->d;
    char path[1100];
    cap_hls_track_path(d->dir, k, path, sizeof path);
    double t0 = rs_now();
    for (int gone = 0; access(path, F_OK) != 0;) {
        /* no maker twice in a row, 100 ms apart: one maker may be handing
         * the lock to another that waited for it */
        if (d->track_alive && d->track_alive(d->track_u))
            gone = 0;
        else if (++gone == 2)
            return rs_fail(err, CAP_ERR_SEG_MISSING, "%s: missing, and no process is making the match's sound", path);
        nanosleep(&(struct timespec){0, gone ? 100000000 : 20000000}, NULL);
    }
    if (d->waited)
        *d->waited += rs_now() - t0;
    int r = avformat_open_input(&c->ain, path, NULL, NULL);
    if (r < 0)
        return fail_av(err, CAP_ERR_SEG_MISSING, path, "cannot open the match's sound", r);
    if (c->ain->nb_streams != 1 || c->ain->streams[0]->codecpar->codec_id != AV_CODEC_ID_AAC)
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: not one AAC stream", path);
    c->atb = c->ain->streams[0]->time_base;
    return true;
}

/* The track's next packet into c->apkt, from the parts in turn: 1; 0
 * when there is none for a piece ending at tick upto (the part it would
 * come from starts there or later: not waited for yet) or none at all
 * (a_eof); -1 with err. */
static int track_next(cutter *c, uint64_t upto, rs_err *err)
{
    for (;;) {
        if (!c->ain) {
            if (c->apart >= c->nparts) {
                c->a_eof = true;
                return 0;
            }
            if (upto < c->d->total && (int64_t)c->apart * PART_SAMPLES >= (int64_t)upto * 800)
                return 0;
            if (!part_read_open(c, c->apart, err))
                return -1;
        }
        int r = av_read_frame(c->ain, c->apkt);
        if (r == AVERROR_EOF) {
            avformat_close_input(&c->ain);
            c->apart++;
            continue;
        }
        if (r < 0) {
            char path[1100];
            cap_hls_track_path(c->d->dir, c->apart, path, sizeof path);
            fail_av(err, CAP_ERR_SEG_MEDIA, path, "read error", r);
            return -1;
        }
        if (c->a0 == AV_NOPTS_VALUE)
            c->a0 = c->apkt->pts;
        return 1;
    }
}

/* The track's packets that start before tick `upto` (all of them when
 * upto is the match's end), then the piece is closed. */
static bool piece_close(cutter *c, uint64_t upto, rs_err *err)
{
    bool ok = true;
    int r;
    uint64_t from = c->ix.p[c->ix.n - 1].tick;
    while (ok && c->apar && !c->a_eof) {
        if (!c->apkt->data) {
            r = track_next(c, upto, err);
            if (r < 0)
                return false;
            if (r == 0)
                break;
        }
        /* its first sample, in 1/48000 from the match's start; 800 a tick */
        int64_t sample = av_rescale_q(c->apkt->pts - c->a0, c->atb, (AVRational){1, 48000});
        if (upto < c->d->total && sample >= (int64_t)upto * 800)
            break;
        if (sample < (int64_t)from * 800) { /* before this unit: another piece's */
            av_packet_unref(c->apkt);
            continue;
        }
        int64_t ts = av_rescale_q(c->apkt->pts - c->a0, c->atb, c->oast->time_base) +
                     (int64_t)CAP_HLS_OFFSET_TICKS * 1500;
        c->apkt->pts = c->apkt->dts = ts;
        c->apkt->stream_index = c->oast->index;
        c->apkt->pos = -1;
        if ((r = av_interleaved_write_frame(c->out, c->apkt)) < 0) /* takes the reference: apkt is empty again */
            ok = fail_av(err, CAP_ERR_WRITE, c->part, "write failed", r);
    }
    ok = ts_close(c->out, c->part, ok, err);
    c->out = NULL;
    cap_hls_piece *p = &c->ix.p[c->ix.n - 1];
    p->frames = upto - p->tick;
    if (ok) {
        size_t len;
        rs_err e = {0};
        char *bytes = rs_read_file(c->part, (size_t)1 << 30, &len, &e);
        if (!bytes)
            ok = rs_fail(err, CAP_ERR_WRITE, "%s", e.msg);
        else {
            p->bytes = len;
            p->fnv = rs_fnv1a64(bytes, len);
        }
        free(bytes);
    }
    return ok;
}

static void remove_parts(cutter *c)
{
    char path[1200];
    for (int i = 0; i < c->ix.n; i++) {
        part_path(c, c->ix.p[i].tick, path, sizeof path);
        unlink(path);
    }
}

static bool open_inputs(cutter *c, rs_err *err)
{
    const cap_hls_cut_desc *d = c->d;
    int r = avformat_open_input(&c->vin, d->video, NULL, NULL);
    if (r < 0)
        return fail_av(err, d->seg ? CAP_ERR_SEG_MEDIA : CAP_ERR_ENCODER, d->video, "cannot open", r);
    if ((r = avformat_find_stream_info(c->vin, NULL)) < 0)
        return fail_av(err, CAP_ERR_SEG_MEDIA, d->video, "cannot read its streams", r);
    c->vi = av_find_best_stream(c->vin, AVMEDIA_TYPE_VIDEO, -1, -1, NULL, 0);
    if (c->vi < 0)
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: no video stream", d->video);
    enum AVCodecID id = c->vin->streams[c->vi]->codecpar->codec_id;
    if (id != AV_CODEC_ID_H264 && id != AV_CODEC_ID_HEVC)
        return rs_fail(err, CAP_ERR_ENC_SETTING, "%s: HLS pieces carry H.264 or HEVC, not %s (MPEG-TS has no place for it)",
                       d->video, avcodec_get_name(id));
    if (d->silent)
        return true;
    /* part 0 first, for the track's stream and its first pts (sample 0) */
    c->nparts = cap_hls_track_parts(d->total);
    if (!part_read_open(c, 0, err))
        return false;
    r = avformat_find_stream_info(c->ain, NULL);
    if (r < 0 || (r = av_read_frame(c->ain, c->apkt)) < 0)
        return fail_av(err, CAP_ERR_SEG_MEDIA, c->ain->url, "cannot read the match's sound", r);
    c->a0 = c->apkt->pts;
    av_packet_unref(c->apkt);
    if (!(c->apar = avcodec_parameters_alloc()) || avcodec_parameters_copy(c->apar, c->ain->streams[0]->codecpar) < 0)
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", d->video);
    avformat_close_input(&c->ain);
    /* then from the part of the unit's first sample */
    int64_t k = (int64_t)d->first * 800 / PART_SAMPLES;
    c->apart = k < c->nparts ? (int)k : c->nparts - 1;
    return true;
}

/* The video's packets into pieces; the CRC and count against the segment's manifest. */
static bool cut_all(cutter *c, rs_err *err)
{
    const cap_hls_cut_desc *d = c->d;
    AVRational in_tb = c->vin->streams[c->vi]->time_base, tick = {1, 60}, ts = {1, 90000};
    uint64_t k = 0;
    uint32_t crc = 0;
    int r;
    /* a segment's pts are its ticks; any other render's start at 0 */
    int64_t base = d->seg ? 0 : (int64_t)d->first;
    while ((r = av_read_frame(c->vin, c->pkt)) >= 0) {
        if (c->pkt->stream_index != c->vi) {
            av_packet_unref(c->pkt);
            continue;
        }
        crc = rs_crc32(crc, c->pkt->data, (size_t)c->pkt->size);
        int64_t t = av_rescale_q(c->pkt->pts, in_tb, tick) + base;
        uint64_t pos = d->first + k;
        if (k >= d->end - d->first || t < (int64_t)pos - CAP_HLS_REORDER || t < (int64_t)d->first || t >= (int64_t)d->end) {
            av_packet_unref(c->pkt);
            return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: frame %" PRIu64 " has pts tick %" PRId64
                           " (ticks %" PRIu64 "..%" PRIu64 ", a B-frame delay of at most %d)",
                           d->video, k, t, d->first, d->end - 1, CAP_HLS_REORDER);
        }
        bool key = c->pkt->flags & AV_PKT_FLAG_KEY;
        if (k == 0 && !key) {
            av_packet_unref(c->pkt);
            return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: does not start with a keyframe", d->video);
        }
        if (key && (k == 0 || t == (int64_t)pos)) { /* a keyframe in decode order: a new piece */
            if (c->out && !piece_close(c, pos, err))
                goto fail;
            if (!piece_open(c, pos, err))
                goto fail;
        }
        c->pkt->pts = av_rescale_q(t + CAP_HLS_OFFSET_TICKS, tick, ts);
        c->pkt->dts = av_rescale_q((int64_t)pos + CAP_HLS_OFFSET_TICKS - CAP_HLS_REORDER, tick, ts);
        c->pkt->duration = av_rescale_q(1, tick, ts);
        c->pkt->stream_index = c->ost->index;
        c->pkt->pos = -1;
        if ((r = av_interleaved_write_frame(c->out, c->pkt)) < 0) {
            fail_av(err, CAP_ERR_WRITE, c->part, "write failed", r);
            goto fail;
        }
        k++;
    }
    if (r != AVERROR_EOF)
        return fail_av(err, CAP_ERR_SEG_MEDIA, d->video, "read error", r);
    if (k != d->end - d->first)
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: %" PRIu64 " frames, not the %" PRIu64 " of ticks %" PRIu64 "..%" PRIu64,
                       d->video, k, d->end - d->first, d->first, d->end - 1);
    if (d->seg && crc != d->seg->m.crc)
        return rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: changed since it was verified (CRC-32 %08" PRIx32 ", its manifest %08"
                       PRIx32 ")", d->video, crc, d->seg->m.crc);
    return piece_close(c, d->end, err);
fail:
    av_packet_unref(c->pkt);
    return false;
}

static bool cut_locked(const cap_hls_cut_desc *d, rs_err *err);

/* The index through a temporary of this process, synced, then renamed */
static bool write_index(const char *dir, const char *idx, const char *text, size_t n, rs_err *err)
{
    char part[1200];
    snprintf(part, sizeof part, "%s/.%s.%d.part", dir, strrchr(idx, '/') + 1, (int)getpid());
    int fd = open(part, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    bool ok = fd >= 0 && write(fd, text, n) == (ssize_t)n && fsync(fd) == 0;
    int e = errno;
    if (fd >= 0 && close(fd) != 0 && ok)
        ok = false, e = errno;
    if (ok && rename(part, idx) != 0)
        ok = false, e = errno;
    if (!ok) {
        unlink(part);
        return rs_fail(err, CAP_ERR_WRITE, "%s: cannot write it: %s", idx, strerror(e ? e : EIO));
    }
    return true;
}

bool cap_hls_cut(const cap_hls_cut_desc *d, rs_err *err)
{
    if (d->kept)
        *d->kept = false;
    if (d->end <= d->first || d->end > d->total)
        return rs_fail(err, CAP_ERR_ARG, "%s: ticks %" PRIu64 "..%" PRIu64 " are not within the match's %" PRIu64, d->video,
                       d->first, d->end, d->total);
    char lock[1100];
    snprintf(lock, sizeof lock, "%s/.u%" PRIu64 ".lock", d->dir, d->first);
    int lfd = open(lock, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (lfd < 0 || flock(lfd, LOCK_EX) != 0) {
        int e = errno;
        if (lfd >= 0)
            close(lfd);
        return rs_fail(err, CAP_ERR_CREATE, "%s: %s", lock, strerror(e));
    }
    bool ok = cut_locked(d, err);
    close(lfd); /* and the lock with it */
    return ok;
}

static bool cut_locked(const cap_hls_cut_desc *d, rs_err *err)
{
    if (cap_hls_unit_check(d->dir, d->first, d->end, &(rs_err){0})) {
        if (d->kept)
            *d->kept = true;
        return true;
    }
    cap_av_log_level();
    cutter c = {.d = d, .a0 = AV_NOPTS_VALUE, .ix = {.first = d->first, .end = d->end}};
    bool ok = (c.pkt = av_packet_alloc()) && (c.apkt = av_packet_alloc());
    if (!ok)
        rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", d->video);
    ok = ok && open_inputs(&c, err) && cut_all(&c, err);
    if (c.out) /* a failure mid-piece */
        ts_close(c.out, c.part, false, &(rs_err){0});
    /* in place, then the index that vouches for them */
    char path[1200], idx[1100];
    for (int i = 0; ok && i < c.ix.n; i++) {
        part_path(&c, c.ix.p[i].tick, c.part, sizeof c.part);
        piece_path(d->dir, c.ix.p[i].tick, path, sizeof path);
        if (rename(c.part, path) != 0)
            ok = rs_fail(err, CAP_ERR_WRITE, "%s: cannot rename %s into place: %s", path, c.part, strerror(errno));
    }
    if (ok) {
        int n = cap_hls_index_format(&c.ix, NULL, 0);
        char *text = n > 0 ? malloc((size_t)n + 1) : NULL;
        index_path(d->dir, d->first, idx, sizeof idx);
        if (!text)
            ok = rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", idx);
        else {
            cap_hls_index_format(&c.ix, text, (size_t)n + 1);
            ok = write_index(d->dir, idx, text, (size_t)n, err);
        }
        free(text);
    }
    if (!ok)
        remove_parts(&c);
    av_packet_free(&c.pkt);
    av_packet_free(&c.apkt);
    avformat_close_input(&c.vin);
    avformat_close_input(&c.ain);
    avcodec_parameters_free(&c.apar);
    free(c.ix.p);
    return ok;
}

#else /* no FFmpeg: nothing to cut with */
bool cap_hls_track(const char *dir, const cap_sink *audio, uint64_t total, rs_err *err)
{
    (void)audio, (void)total;
    return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no HLS pieces", dir);
}

bool cap_hls_cut(const cap_hls_cut_desc *d, rs_err *err)
{
    return rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no HLS pieces", d->video);
}
#endif
