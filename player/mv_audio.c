/* A movie's soundtrack on the tick (mv_audio.h): its own demuxer and
 * decode thread, libswresample to 48 kHz stereo float, a bounded ring.
 *
 * DESIGN
 * Own demuxer.  The audio opens the file a second time instead of sharing
 * the picture's demuxer: the picture's decoder sleeps whenever its few
 * frame slots are full, and a shared demuxer would then stop feeding the
 * audio, or would have to queue packets without bound for a file whose
 * tracks are interleaved a second or more apart.  Demuxing twice costs a
 * read of the file, not a decode.
 *
 * Threads.  The decode thread owns the demuxer, the decoder, the
 * resampler and the write position `wr`; the reader (the 60 Hz loop) owns
 * the read position `rd`.  Both positions, the ring's samples between them
 * and the counters are guarded by `mu`.  The ring holds frames [rd, wr) of
 * the timeline at ring[pos % MV_AUDIO_AHEAD]; the thread sleeps on
 * `has_room` while wr - rd is the whole ring, and the reader sleeps on
 * `has_data` only in wait mode.  A reader that moved past frames not yet
 * decoded (a late read) sets rd beyond wr; the thread then drops what it
 * decodes below rd, so the two meet again at the reader's position.
 *
 * Placement.  Positions are counted in the stream's own samples
 * (`in_next`, 0 = the video's first presentation time) so a frame is put
 * where its timestamp says: a gap is fed to the resampler as silence (so
 * its filter state runs on unbroken), an overlap is cut from the frame's
 * start.  Timestamps that jump by more than MAX_JUMP_S are taken as a
 * broken clock, not as silence to play: the track just continues. */
#include "mv_audio.h"

#include <errno.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#define MAX_JUMP_S 10

struct mv_audio {
    mv_audio_info info;
    /* the reader's and the thread's meeting point, under mu */
    pthread_mutex_t mu;
    pthread_cond_t has_data, has_room;
    float *ring; /* MV_AUDIO_AHEAD stereo frames */
    int64_t rd, wr;
    bool ended, stop;
    mv_audio_stats st;
    pthread_t thread;
    bool running;
    /* the decode thread's own */
    void *dec; /* ff_audio, below */
};

bool mv_audio_read(mv_audio *a, int64_t pos, float *out, int frames, bool wait)
{
    if (frames <= 0)
        return true;
    memset(out, 0, (size_t)frames * 2 * sizeof *out);
    if (frames > MV_AUDIO_AHEAD)
        wait = false; /* more than the ring holds can never all be there at once */
    pthread_mutex_lock(&a->mu);
    int64_t end = pos + frames;
    if (pos > a->rd) {
        a->rd = pos; /* skipped frames: the thread drops them */
        pthread_cond_broadcast(&a->has_room);
    }
    while (wait && a->wr < end && !a->ended)
        pthread_cond_wait(&a->has_data, &a->mu);
    int64_t from = pos > a->rd ? pos : a->rd, to = a->wr < end ? a->wr : end;
    for (int64_t p = from; p < to;) {
        int64_t at = p % MV_AUDIO_AHEAD, k = to - p;
        if (k > MV_AUDIO_AHEAD - at)
            k = MV_AUDIO_AHEAD - at;
        memcpy(out + 2 * (p - pos), a->ring + 2 * at, (size_t)k * 2 * sizeof *out);
        p += k;
    }
    bool on_time = a->wr >= end || a->ended;
    a->st.reads++;
    a->st.late += !on_time;
    if (end > a->rd) {
        a->rd = end;
        pthread_cond_broadcast(&a->has_room);
    }
    pthread_mutex_unlock(&a->mu);
    return on_time;
}

void mv_audio_prime(mv_audio *a, int frames, int timeout_ms)
{
    struct timespec t;
    clock_gettime(CLOCK_REALTIME, &t);
    t.tv_sec += timeout_ms / 1000;
    t.tv_nsec += (long)(timeout_ms % 1000) * 1000000L;
    if (t.tv_nsec >= 1000000000L) {
        t.tv_sec++;
        t.tv_nsec -= 1000000000L;
    }
    pthread_mutex_lock(&a->mu);
    while (a->wr < a->rd + frames && !a->ended)
        if (pthread_cond_timedwait(&a->has_data, &a->mu, &t) == ETIMEDOUT)
            break;
    pthread_mutex_unlock(&a->mu);
}

const mv_audio_info *mv_audio_info_get(const mv_audio *a)
{
    return &a->info;
}

void mv_audio_stats_get(mv_audio *a, mv_audio_stats *st)
{
    pthread_mutex_lock(&a->mu);
    *st = a->st;
    pthread_mutex_unlock(&a->mu);
}

#ifndef RS_HAVE_FFMPEG

mv_audio *mv_audio_open(const char *path, rs_err *err)
{
    (void)path;
    rs_err_clear(err); /* no decoder in this build: the movie plays silent */
    return NULL;
}

void mv_audio_close(mv_audio *a)
{
    (void)a; /* mv_audio_open never made one */
}

#else

#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/channel_layout.h>
#include <libavutil/samplefmt.h>
#include <libswresample/swresample.h>

static double thread_cpu_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

/* The thread's output: n frames at position wr.  False when told to stop. */
static bool push(mv_audio *a, const float *pcm, int64_t n)
{
    pthread_mutex_lock(&a->mu);
    a->st.frames += n;
    while (n > 0 && !a->stop) {
        if (a->wr < a->rd) { /* the reader has passed these: drop */
            int64_t d = a->rd - a->wr < n ? a->rd - a->wr : n;
            a->st.discarded += d;
            a->wr += d;
            pcm += 2 * d;
            n -= d;
            continue;
        }
        int64_t room = a->rd + MV_AUDIO_AHEAD - a->wr;
        if (room <= 0) {
            pthread_cond_wait(&a->has_room, &a->mu);
            continue;
        }
        int64_t k = room < n ? room : n, at = a->wr % MV_AUDIO_AHEAD;
        if (k > MV_AUDIO_AHEAD - at)
            k = MV_AUDIO_AHEAD - at; /* the rest after the wrap, next time round */
        memcpy(a->ring + 2 * at, pcm, (size_t)k * 2 * sizeof *pcm);
        a->wr += k;
        pcm += 2 * k;
        n -= k;
        pthread_cond_broadcast(&a->has_data);
    }
    bool ok = !a->stop;
    pthread_mutex_unlock(&a->mu);
    return ok;
}

typedef struct ff_audio {
    AVFormatContext *fmt;
    AVCodecContext *dec;
    AVPacket *pkt;
    AVFrame *frame;
    int stream;
    AVRational tb;      /* the audio stream's time base */
    int64_t start;      /* the video's first presentation time, in tb (audio only: the first frame's) */
    SwrContext *swr;
    int in_rate, in_fmt; /* what swr was set up for */
    AVChannelLayout in_layout; /* the frames' layout, as they say it */
    int in_channels;
    bool placed;        /* the first frame has been put on the timeline */
    int64_t in_next;    /* the next input sample's timeline position, at in_rate */
    int last_nb;        /* the last frame's samples */
    float *out;         /* resampler output */
    int out_cap;        /* in frames */
} ff_audio;

static const char *av_msg(int e, char *buf, size_t n)
{
    av_strerror(e, buf, n);
    return buf;
}

/* n input samples (NULL, 0: flush) through the resampler into the ring. */
static bool feed(mv_audio *a, ff_audio *f, const uint8_t **in, int n)
{
    int cap = swr_get_out_samples(f->swr, n);
    if (cap <= 0)
        return true;
    if (cap > f->out_cap) {
        float *g = realloc(f->out, (size_t)cap * 2 * sizeof *g);
        if (!g)
            return false;
        f->out = g;
        f->out_cap = cap;
    }
    uint8_t *o = (uint8_t *)f->out;
    int got = swr_convert(f->swr, &o, cap, in, n);
    return got <= 0 || push(a, f->out, got);
}

static bool feed_silence(mv_audio *a, ff_audio *f, int64_t n)
{
    uint8_t **z = NULL;
    int chunk = 4096, ch = f->in_channels;
    if (av_samples_alloc_array_and_samples(&z, NULL, ch, chunk, f->in_fmt, 0) < 0)
        return false;
    av_samples_set_silence(z, 0, chunk, ch, f->in_fmt);
    bool ok = true;
    for (int64_t left = n; left > 0 && ok; left -= chunk)
        ok = feed(a, f, (const uint8_t **)z, left < chunk ? (int)left : chunk);
    av_freep(&z[0]);
    av_freep(&z);
    return ok;
}

/* (Re)creates the resampler for frame's rate, format and layout, flushing
 * the old one into the ring first. */
static bool setup_swr(mv_audio *a, ff_audio *f, const AVFrame *fr)
{
    if (f->swr && !feed(a, f, NULL, 0))
        return false;
    swr_free(&f->swr);
    AVChannelLayout in = {0}, out = (AVChannelLayout)AV_CHANNEL_LAYOUT_STEREO;
    if (fr->ch_layout.order == AV_CHANNEL_ORDER_UNSPEC)
        av_channel_layout_default(&in, fr->ch_layout.nb_channels); /* as ffmpeg guesses */
    else if (av_channel_layout_copy(&in, &fr->ch_layout) < 0)
        return false;
    int r = swr_alloc_set_opts2(&f->swr, &out, AV_SAMPLE_FMT_FLT, AU_RATE, &in, fr->format, fr->sample_rate, 0, NULL);
    if (r < 0 || swr_init(f->swr) < 0) {
        av_channel_layout_uninit(&in);
        swr_free(&f->swr);
        return false;
    }
    if (f->placed && f->in_rate != fr->sample_rate)
        f->in_next = av_rescale(f->in_next, fr->sample_rate, f->in_rate);
    av_channel_layout_uninit(&in);
    av_channel_layout_uninit(&f->in_layout);
    if (av_channel_layout_copy(&f->in_layout, &fr->ch_layout) < 0) {
        swr_free(&f->swr);
        return false;
    }
    f->in_channels = fr->ch_layout.nb_channels;
    f->in_rate = fr->sample_rate;
    f->in_fmt = fr->format;
    return true;
}

/* One decoded frame onto the timeline.  False: stop (told to, or out of
 * memory). */
static bool put_frame(mv_audio *a, ff_audio *f, AVFrame *fr)
{
    if (fr->sample_rate <= 0 || fr->nb_samples <= 0 || fr->ch_layout.nb_channels <= 0)
        return true;
    if (!f->swr || fr->sample_rate != f->in_rate || fr->format != f->in_fmt ||
        av_channel_layout_compare(&fr->ch_layout, &f->in_layout)) {
        if (!setup_swr(a, f, fr)) { /* a layout the resampler refuses: that frame is lost */
            pthread_mutex_lock(&a->mu);
            a->st.bad_packets++;
            bool go = !a->stop;
            pthread_mutex_unlock(&a->mu);
            return go;
        }
    }
    int64_t ts = fr->best_effort_timestamp, skip = 0;
    AVRational in_tb = {1, fr->sample_rate};
    if (ts != AV_NOPTS_VALUE && f->start == AV_NOPTS_VALUE)
        f->start = ts;
    if (ts != AV_NOPTS_VALUE) {
        int64_t at = av_rescale_q(ts - f->start, f->tb, in_tb);
        int64_t jump = (int64_t)MAX_JUMP_S * fr->sample_rate, tol = f->placed ? fr->sample_rate / 50 : 0;
        int64_t gap = at - f->in_next;
        if (gap > jump || gap < -jump) {
            if (!f->placed && gap > 0) /* audio starting far later than the picture: as ffmpeg would, keep it */
                gap = 0;
        } else if (gap > tol) {
            /* Lost frames: a container's rounded timestamps (Matroska's are
             * whole milliseconds) make a gap of k frames look a few samples
             * off; take it as k frames when it is within a millisecond. */
            int64_t fs = f->last_nb, k = fs > 0 ? (gap + fs / 2) / fs : 0;
            if (k >= 1 && llabs(gap - k * fs) <= fr->sample_rate / 1000)
                gap = k * fs;
            pthread_mutex_lock(&a->mu);
            a->st.filled += av_rescale(gap, AU_RATE, fr->sample_rate);
            pthread_mutex_unlock(&a->mu);
            if (!feed_silence(a, f, gap))
                return false;
            f->in_next += gap;
        } else if (gap < -tol) {
            skip = -gap < fr->nb_samples ? -gap : fr->nb_samples;
        }
    }
    f->placed = true;
    f->last_nb = fr->nb_samples;
    int n = fr->nb_samples - (int)skip;
    if (n <= 0)
        return true;
    const uint8_t *in[AV_NUM_DATA_POINTERS * 8];
    int planes = av_sample_fmt_is_planar(fr->format) ? fr->ch_layout.nb_channels : 1;
    if (planes > (int)(sizeof in / sizeof in[0]))
        return true;
    int step = av_get_bytes_per_sample(fr->format) * (planes == 1 ? fr->ch_layout.nb_channels : 1);
    for (int p = 0; p < planes; p++)
        in[p] = fr->extended_data[p] + skip * step;
    f->in_next += n;
    return feed(a, f, in, n);
}

/* Every frame the decoder has ready.  False: stop. */
static bool drain(mv_audio *a, ff_audio *f)
{
    for (;;) {
        int r = avcodec_receive_frame(f->dec, f->frame);
        if (r == AVERROR(EAGAIN) || r == AVERROR_EOF)
            return true;
        if (r < 0) { /* a broken packet: skipped, the next one decodes */
            pthread_mutex_lock(&a->mu);
            a->st.bad_packets++;
            pthread_mutex_unlock(&a->mu);
            return true;
        }
        bool ok = put_frame(a, f, f->frame);
        av_frame_unref(f->frame);
        if (!ok)
            return false;
    }
}

static void *run(void *arg)
{
    mv_audio *a = arg;
    ff_audio *f = a->dec;
    double cpu0 = thread_cpu_ms();
    int read_errors = 0;
    bool go = true;
    while (go) {
        int r = av_read_frame(f->fmt, f->pkt);
        if (r == AVERROR_EOF || (r < 0 && ((f->fmt->pb && avio_feof(f->fmt->pb)) || ++read_errors > 100)))
            break; /* the end, or a demuxer that cannot get past damage */
        if (r < 0)
            continue;
        read_errors = 0;
        if (f->pkt->stream_index != f->stream) {
            av_packet_unref(f->pkt);
            continue;
        }
        r = avcodec_send_packet(f->dec, f->pkt);
        av_packet_unref(f->pkt);
        if (r < 0 && r != AVERROR(EAGAIN)) { /* refused: the rest of the stream decodes on */
            pthread_mutex_lock(&a->mu);
            a->st.bad_packets++;
            pthread_mutex_unlock(&a->mu);
        }
        go = drain(a, f);
        pthread_mutex_lock(&a->mu);
        a->st.cpu_ms = thread_cpu_ms() - cpu0;
        pthread_mutex_unlock(&a->mu);
    }
    if (go) {
        avcodec_send_packet(f->dec, NULL);
        if (drain(a, f) && f->swr)
            feed(a, f, NULL, 0);
    }
    pthread_mutex_lock(&a->mu);
    a->ended = true;
    a->st.cpu_ms = thread_cpu_ms() - cpu0;
    pthread_cond_broadcast(&a->has_data);
    pthread_mutex_unlock(&a->mu);
    return NULL;
}

static void ff_free(ff_audio *f)
{
    if (!f)
        return;
    swr_free(&f->swr);
    av_channel_layout_uninit(&f->in_layout);
    av_frame_free(&f->frame);
    av_packet_free(&f->pkt);
    avcodec_free_context(&f->dec);
    avformat_close_input(&f->fmt);
    free(f->out);
    free(f);
}

void mv_audio_close(mv_audio *a)
{
    if (!a)
        return;
    if (a->running) {
        pthread_mutex_lock(&a->mu);
        a->stop = true;
        pthread_cond_broadcast(&a->has_room);
        pthread_mutex_unlock(&a->mu);
        pthread_join(a->thread, NULL);
    }
    ff_free(a->dec);
    pthread_cond_destroy(&a->has_room);
    pthread_cond_destroy(&a->has_data);
    pthread_mutex_destroy(&a->mu);
    free(a->ring);
    free(a);
}

mv_audio *mv_audio_open(const char *path, rs_err *err)
{
    char m[128];
    rs_err_clear(err);
    mv_audio *a = calloc(1, sizeof *a);
    ff_audio *f = calloc(1, sizeof *f);
    if (!a || !f) {
        free(a);
        free(f);
        rs_fail(err, MV_ERR_NOMEM, "%s: out of memory for the audio", path);
        return NULL;
    }
    a->dec = f;
    pthread_mutex_init(&a->mu, NULL);
    pthread_cond_init(&a->has_data, NULL);
    pthread_cond_init(&a->has_room, NULL);
    av_log_set_level(AV_LOG_FATAL); /* damaged audio is counted (bad_packets), not printed */
    int r = avformat_open_input(&f->fmt, path, NULL, NULL);
    if (r < 0) {
        rs_fail(err, MV_ERR_OPEN, "%s: cannot open for its audio: %s", path, av_msg(r, m, sizeof m));
        goto fail;
    }
    if ((r = avformat_find_stream_info(f->fmt, NULL)) < 0) {
        rs_fail(err, MV_ERR_FORMAT, "%s: cannot read the stream layout: %s", path, av_msg(r, m, sizeof m));
        goto fail;
    }
    int video = av_find_best_stream(f->fmt, AVMEDIA_TYPE_VIDEO, -1, -1, NULL, 0);
    const AVCodec *codec = NULL;
    f->stream = av_find_best_stream(f->fmt, AVMEDIA_TYPE_AUDIO, -1, video >= 0 ? video : -1, &codec, 0);
    if (f->stream == AVERROR_STREAM_NOT_FOUND)
        goto fail; /* no audio: err stays clear */
    if (f->stream < 0 || !codec) {
        rs_fail(err, MV_ERR_UNSUPPORTED, "%s: no decoder for its audio codec", path);
        goto fail;
    }
    AVStream *st = f->fmt->streams[f->stream];
    f->tb = st->time_base;
    if (video >= 0 && f->fmt->streams[video]->start_time != AV_NOPTS_VALUE)
        f->start = av_rescale_q(f->fmt->streams[video]->start_time, f->fmt->streams[video]->time_base, f->tb);
    else
        f->start = AV_NOPTS_VALUE; /* no picture: the first decoded sample is the start */
    f->dec = avcodec_alloc_context3(codec);
    f->pkt = av_packet_alloc();
    f->frame = av_frame_alloc();
    a->ring = malloc((size_t)MV_AUDIO_AHEAD * 2 * sizeof *a->ring);
    if (!f->dec || !f->pkt || !f->frame || !a->ring) {
        rs_fail(err, MV_ERR_NOMEM, "%s: out of memory for the audio", path);
        goto fail;
    }
    f->dec->thread_count = 1;
    f->dec->pkt_timebase = st->time_base; /* so the decoder moves a frame's pts past the priming it drops */
    if ((r = avcodec_parameters_to_context(f->dec, st->codecpar)) < 0 || (r = avcodec_open2(f->dec, codec, NULL)) < 0) {
        rs_fail(err, MV_ERR_UNSUPPORTED, "%s: cannot open the %s audio decoder: %s", path, codec->name,
                av_msg(r, m, sizeof m));
        goto fail;
    }
    /* discard everything but the audio: the demuxer skips the picture's packets cheaply */
    for (unsigned k = 0; k < f->fmt->nb_streams; k++)
        if ((int)k != f->stream)
            f->fmt->streams[k]->discard = AVDISCARD_ALL;
    mv_audio_info *i = &a->info;
    snprintf(i->codec, sizeof i->codec, "%s", avcodec_get_name(st->codecpar->codec_id));
    const char *sf = av_get_sample_fmt_name(st->codecpar->format);
    snprintf(i->format, sizeof i->format, "%s", sf ? sf : "?");
    if (av_channel_layout_describe(&st->codecpar->ch_layout, i->layout, sizeof i->layout) < 0)
        snprintf(i->layout, sizeof i->layout, "%d channels", st->codecpar->ch_layout.nb_channels);
    i->rate = st->codecpar->sample_rate;
    i->channels = st->codecpar->ch_layout.nb_channels;
    if ((r = pthread_create(&a->thread, NULL, run, a)) != 0) {
        rs_fail(err, MV_ERR_NOMEM, "%s: cannot start the audio thread: %s", path, strerror(r));
        goto fail;
    }
    a->running = true;
    return a;
fail:
    mv_audio_close(a);
    return NULL;
}

#endif
