/* Join: verified segments -> one video, by stream copy through
 * libavformat (no decoding, no encoding), and their hash lists -> one
 * list.  cap_seg.h has the contract, cap_seg.c the verification.
 *
 * Both outputs are written under "<name>.part" and renamed at the end,
 * the hash list first, so a video in place always has its list.  The
 * .part files are created before any segment is read: a missing or
 * read-only output directory is the output's failure (exit 1 in join,
 * the service retries later), never blamed on a segment.
 *
 * Audio (cap_join_audio): segments carry none; the job's track, mixed
 * once for the joined ticks, is encoded here beside the copied video,
 * up to the end of each packet's tick as it is written (cap_audio.c), so
 * the sound has no seam where the segments meet; or, encoded ahead
 * (cap_join_audio_track), its packets written up to the same point. */
#include "cap_seg.h"

#include <errno.h>
#include <fcntl.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_hash.h"

#ifdef RS_HAVE_FFMPEG
#include <libavformat/avformat.h>

#include "cap_enc_local.h"

struct cap_join {
    cap_join_desc d;
    AVFormatContext *fmt;
    AVStream *st;
    AVPacket *pkt;
    FILE *hf;
    char part[1100], hpart[1100];
    bool header;
    cap_sink audio; /* audio.audio NULL: no sound */
    cap_aenc a;
    cap_atrack *track; /* the sound encoded ahead, instead of audio */
    AVStream *ast;     /* its stream */
};

static int fail_av(rs_err *err, int id, const char *path, const char *what, int code)
{
    char msg[AV_ERROR_MAX_STRING_SIZE] = "";
    av_strerror(code, msg, sizeof msg);
    return rs_fail(err, id, "%s: %s: %s", path, what, msg);
}

cap_join *cap_join_open(const cap_join_desc *d, rs_err *err)
{
    const char *fmt = cap_seg_format_of(d->out);
    if (!fmt) {
        rs_fail(err, CAP_ERR_OUTPUT, "%s: a join writes .mp4, .mkv or .webm", d->out);
        return NULL;
    }
    cap_join *j = calloc(1, sizeof *j);
    if (!j || !(j->pkt = av_packet_alloc())) {
        free(j);
        rs_fail(err, CAP_ERR_NOMEM, "out of memory");
        return NULL;
    }
    j->d = *d;
    cap_av_log_level();
    snprintf(j->part, sizeof j->part, "%s.part", d->out);
    int r = avformat_alloc_output_context2(&j->fmt, NULL, !strcmp(fmt, "mkv") ? "matroska" : fmt, j->part);
    if (r < 0) {
        fail_av(err, CAP_ERR_NOT_BUILT, d->out, "this FFmpeg cannot write it", r);
        goto fail;
    }
    if ((r = avio_open(&j->fmt->pb, j->part, AVIO_FLAG_WRITE)) < 0) {
        fail_av(err, CAP_ERR_CREATE, j->part, "cannot create", r);
        goto fail;
    }
    if (d->hashes && !strcmp(d->hashes, "-")) {
        j->hf = stdout; /* --hashes -: written as it goes, nothing to rename */
    } else if (d->hashes) {
        snprintf(j->hpart, sizeof j->hpart, "%s.part", d->hashes);
        if (!(j->hf = fopen(j->hpart, "w"))) {
            rs_fail(err, CAP_ERR_CREATE, "%s: cannot create (as %s): %s", d->hashes, j->hpart, strerror(errno));
            goto fail;
        }
    }
    return j;
fail:
    cap_join_close(j, false, NULL);
    return NULL;
}

/* The output stream, from the first segment's (all are equal: verified),
 * and the first segment's metadata (the keys the render writes). */
static bool write_header(cap_join *j, const AVFormatContext *ic, const AVStream *in, rs_err *err)
{
    if (!(j->st = avformat_new_stream(j->fmt, NULL)))
        return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", j->d.out);
    int r = avcodec_parameters_copy(j->st->codecpar, in->codecpar);
    if (r < 0)
        return fail_av(err, CAP_ERR_NOMEM, j->d.out, "codec parameters", r);
    bool mp4 = !strcmp(cap_seg_format_of(j->d.out), "mp4");
    /* the output container's own tag; HEVC in MP4 as hvc1, as the render writes it (cap_sink_ffmpeg.c) */
    j->st->codecpar->codec_tag = mp4 && in->codecpar->codec_id == AV_CODEC_ID_HEVC ? MKTAG('h', 'v', 'c', '1') : 0;
    for (int i = 0; cap_meta_keys[i]; i++) {
        const AVDictionaryEntry *e = av_dict_get(ic->metadata, cap_meta_keys[i], NULL, 0); /* any case: MKV's are upper */
        if (e)
            av_dict_set(&j->fmt->metadata, cap_meta_keys[i], e->value, 0);
    }
    j->st->time_base = (AVRational){1, 60};
    j->st->avg_frame_rate = j->st->r_frame_rate = (AVRational){60, 1};
    if (j->audio.audio && !cap_aenc_open(&j->a, &j->audio, j->fmt, err))
        return false;
    if (j->track) {
        if (!(j->ast = avformat_new_stream(j->fmt, NULL)))
            return rs_fail(err, CAP_ERR_NOMEM, "%s: out of memory", j->d.out);
        if ((r = avcodec_parameters_copy(j->ast->codecpar, j->track->par)) < 0)
            return fail_av(err, CAP_ERR_NOMEM, j->d.out, "codec parameters", r);
        j->ast->time_base = j->track->tb;
    }
    AVDictionary *opts = NULL;
    if (mp4) /* the index before the frames: plays while it downloads; every metadata key kept */
        av_dict_set(&opts, "movflags", "+faststart+use_metadata_tags", 0);
    r = avformat_write_header(j->fmt, &opts);
    av_dict_free(&opts);
    if (r < 0)
        return fail_av(err, CAP_ERR_WRITE, j->d.out, "cannot write the header", r);
    j->header = true;
    return true;
}

/* The track's packets encoded ahead up to sample frame upto, as the
 * encoder fed to there would have given them (cap_aenc_feed: whole
 * encoder frames; its priming delay holds back what it holds back, and
 * the muxer interleaves by time either way); all of them when upto is
 * past the end. */
static bool write_track(cap_join *j, size_t upto, rs_err *err)
{
    cap_atrack *t = j->track;
    int64_t end = av_rescale_q((int64_t)upto, (AVRational){1, 48000}, t->tb);
    while (t->next < t->n && t->pkt[t->next]->pts < end) {
        AVPacket *p = t->pkt[t->next++];
        av_packet_rescale_ts(p, t->tb, j->ast->time_base);
        p->stream_index = j->ast->index;
        int r = av_interleaved_write_frame(j->fmt, p); /* takes the packet's reference */
        if (r < 0)
            return fail_av(err, CAP_ERR_WRITE, j->d.out, "write failed", r);
    }
    return true;
}

/* Appends the segment's hash list, checked again: it is what was verified. */
static bool append_hashes(cap_join *j, const cap_seg *s, rs_err *err)
{
    char path[1100];
    size_t len;
    rs_err e = {0};
    cap_seg_hashes_path(s->path, path, sizeof path);
    char *text = rs_read_file(path, (size_t)1 << 30, &len, &e);
    if (!text)
        return rs_fail(err, CAP_ERR_SEG_HASHES, "%s", e.msg);
    bool changed = rs_fnv1a64(text, len) != s->m.hashes_fnv;
    errno = 0;
    bool wrote = changed || fwrite(text, 1, len, j->hf) == len;
    free(text);
    if (changed)
        return rs_fail(err, CAP_ERR_SEG_HASHES, "%s: changed since it was verified", path);
    if (!wrote)
        return rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", j->d.hashes, strerror(errno ? errno : EIO));
    return true;
}

/* One segment's packets.  False with *seg_fault set when the segment is to blame. */
static bool copy_one(cap_join *j, const cap_seg *s, int64_t origin, int reorder, uint64_t *done, uint64_t total,
                     bool *seg_fault, rs_err *err)
{
    AVFormatContext *ic = NULL;
    int r = avformat_open_input(&ic, s->path, NULL, NULL);
    bool ok = false;
    *seg_fault = true;
    if (r < 0 || ic->nb_streams != 1) {
        if (r < 0)
            fail_av(err, CAP_ERR_SEG_MEDIA, s->path, "libavformat cannot open it any more", r);
        else
            rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: changed since it was verified", s->path);
        goto done;
    }
    if (!j->header && !write_header(j, ic, ic->streams[0], err)) {
        *seg_fault = false;
        goto done;
    }
    AVRational in_tb = ic->streams[0]->time_base, tick = {1, 60};
    uint32_t crc = 0;
    uint64_t k = 0;
    while ((r = av_read_frame(ic, j->pkt)) >= 0) {
        if (j->d.stop && *j->d.stop) {
            av_packet_unref(j->pkt);
            *seg_fault = false;
            rs_fail(err, CAP_ERR_FAILED, "%s: interrupted at frame %" PRIu64 " of %" PRIu64 "; the partial output was removed",
                    j->d.out, *done, total);
            goto done;
        }
        if (k == s->m.frames) {
            av_packet_unref(j->pkt);
            break; /* more than verified: the CRC check below says so */
        }
        crc = rs_crc32(crc, j->pkt->data, (size_t)j->pkt->size);
        /* in ticks from the video's start, then in the muxer's time base */
        int64_t pts = av_rescale_q(j->pkt->pts, in_tb, tick) - origin;
        int64_t dts = (int64_t)(s->m.first + k) - origin - reorder;
        j->pkt->pts = av_rescale_q(pts, tick, j->st->time_base);
        j->pkt->dts = av_rescale_q(dts, tick, j->st->time_base);
        j->pkt->duration = av_rescale_q(1, tick, j->st->time_base);
        j->pkt->stream_index = j->st->index;
        j->pkt->pos = -1;
        if ((r = av_interleaved_write_frame(j->fmt, j->pkt)) < 0) { /* takes the packet's reference */
            *seg_fault = false;
            fail_av(err, CAP_ERR_WRITE, j->d.out, "write failed", r);
            goto done;
        }
        k++;
        (*done)++;
        /* the sound up to the end of this packet's tick */
        size_t upto = (size_t)(s->m.first + k - (uint64_t)origin) * 800;
        if ((j->a.ctx && !cap_aenc_feed(&j->a, &j->audio, j->fmt, upto, err)) || (j->track && !write_track(j, upto, err))) {
            *seg_fault = false;
            goto done;
        }
        if (j->d.progress)
            j->d.progress(j->d.ctx, *done, total);
    }
    if (r < 0 && r != AVERROR_EOF)
        fail_av(err, CAP_ERR_SEG_MEDIA, s->path, "read error", r);
    else if (k != s->m.frames || crc != s->m.crc)
        rs_fail(err, CAP_ERR_SEG_MEDIA, "%s: changed since it was verified (%" PRIu64 " packets, CRC-32 %08" PRIx32 ")",
                s->path, k, crc);
    else
        ok = !j->hf || append_hashes(j, s, err);
    if (!ok && err && err->code == CAP_ERR_WRITE)
        *seg_fault = false;
done:
    avformat_close_input(&ic);
    return ok;
}

bool cap_join_copy(cap_join *j, const cap_seg *segs, int n, int *bad_index, rs_err *err)
{
    *bad_index = -1;
    if (n < 1)
        return rs_fail(err, CAP_ERR_ARG, "%s: no segments to join", j->d.out);
    uint64_t total = 0, done = 0;
    int reorder = 0;
    for (int i = 0; i < n; i++) {
        total += segs[i].m.frames;
        if (segs[i].reorder > reorder)
            reorder = segs[i].reorder;
    }
    for (int i = 0; i < n; i++) {
        bool seg_fault;
        if (!copy_one(j, &segs[i], (int64_t)segs[0].m.first, reorder, &done, total, &seg_fault, err)) {
            if (seg_fault)
                *bad_index = i;
            return false;
        }
    }
    return true;
}

/* fsync by name: avio has no fsync, and a renamed file must be on disk first. */
static bool sync_file(const char *path)
{
    int fd = open(path, O_RDONLY);
    bool ok = fd >= 0 && fsync(fd) == 0;
    if (fd >= 0)
        close(fd);
    return ok;
}

bool cap_join_close(cap_join *j, bool ok, rs_err *err)
{
    if (!j)
        return !ok;
    bool good = ok && j->header;
    int r;
    if (ok && !j->header)
        rs_fail(err, CAP_ERR_ARG, "%s: closed before any segment was copied", j->d.out);
    if (good && j->a.ctx)
        good = cap_aenc_finish(&j->a, &j->audio, j->fmt, err);
    if (good && j->track)
        good = write_track(j, SIZE_MAX, err);
    if (good && (r = av_write_trailer(j->fmt)) < 0) /* MP4: moves the index to the front, rewriting the file */
        good = fail_av(err, CAP_ERR_WRITE, j->d.out, "write failed", r);
    if (j->fmt && j->fmt->pb) {
        int perr = j->fmt->pb->error;
        if (avio_closep(&j->fmt->pb) < 0 && good)
            good = rs_fail(err, CAP_ERR_WRITE, "%s: write failed", j->d.out);
        if (good && perr < 0)
            good = fail_av(err, CAP_ERR_WRITE, j->d.out, "write failed", perr);
    }
    if (good && !sync_file(j->part))
        good = rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", j->d.out, strerror(errno));
    if (j->hf == stdout) {
        j->hf = NULL;
        if (fflush(stdout) != 0 && good)
            good = rs_fail(err, CAP_ERR_WRITE, "--hashes -: write failed: %s", strerror(errno));
    } else if (j->hf) {
        errno = 0;
        bool hok = fflush(j->hf) == 0 && fsync(fileno(j->hf)) == 0;
        int e = errno;
        hok = fclose(j->hf) == 0 && hok;
        j->hf = NULL;
        if (good && !hok)
            good = rs_fail(err, CAP_ERR_WRITE, "%s: write failed: %s", j->d.hashes, strerror(e ? e : EIO));
        if (good && rename(j->hpart, j->d.hashes) != 0)
            good = rs_fail(err, CAP_ERR_WRITE, "%s: cannot rename %s into place: %s", j->d.hashes, j->hpart, strerror(errno));
        else if (good)
            j->hpart[0] = 0; /* in place */
    }
    if (good && rename(j->part, j->d.out) != 0) {
        good = rs_fail(err, CAP_ERR_WRITE, "%s: cannot rename %s into place: %s", j->d.out, j->part, strerror(errno));
        if (j->d.hashes && strcmp(j->d.hashes, "-"))
            unlink(j->d.hashes); /* no list without its video */
    }
    if (!good) {
        unlink(j->part);
        if (j->hpart[0])
            unlink(j->hpart);
    }
    av_packet_free(&j->pkt);
    cap_aenc_close(&j->a);
    avformat_free_context(j->fmt);
    free(j);
    return good;
}

void cap_join_audio(cap_join *j, const cap_sink *audio)
{
    j->audio = *audio;
}

void cap_join_audio_track(cap_join *j, cap_atrack *t)
{
    j->track = t;
}

#else /* no FFmpeg: nothing to join with */
struct cap_join {
    int unused;
};

cap_join *cap_join_open(const cap_join_desc *d, rs_err *err)
{
    rs_fail(err, CAP_ERR_NOT_BUILT, "%s: this build has no FFmpeg libraries, so no joins", d->out);
    return NULL;
}

bool cap_join_copy(cap_join *j, const cap_seg *segs, int n, int *bad_index, rs_err *err)
{
    (void)j, (void)segs, (void)n, (void)err;
    *bad_index = -1;
    return false;
}

bool cap_join_close(cap_join *j, bool ok, rs_err *err)
{
    (void)j, (void)err;
    return !ok;
}

void cap_join_audio(cap_join *j, const cap_sink *audio)
{
    (void)j, (void)audio;
}

void cap_join_audio_track(cap_join *j, cap_atrack *t)
{
    (void)j, (void)t;
}
#endif
