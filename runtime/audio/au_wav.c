/* RIFF WAVE files: the whole-buffer writer, the streaming writer (live
 * output's wave backend) and a reader of PCM 8/16/24/32-bit and 32-bit
 * float of any channel count and rate.
 *
 * Writing goes to "<path>.part", renamed into place when complete
 * (rs_file.h), so a failed or interrupted run never leaves a WAV that
 * looks finished; errors name the file as given.  "-" and other streams
 * (rs_out_is_stream) are written in place by au_wav_write and
 * au_wav_open_known, whose sizes are known up front.
 *
 * DESIGN: 16-bit output is plain rounding with clipping, no dither: dither
 * would need noise, and the soundtrack must be a pure function of the
 * replay; at -16 LUFS the rounding error sits ~80 dB under the programme. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "au_local.h"
#include "../util/rs_file.h"
#include "../util/rs_out.h"

#define WAV_MAX_FILE (2u << 30) /* 2 GiB: what the reader accepts */
#define FMT_PCM 1
#define FMT_FLOAT 3
#define FMT_EXTENSIBLE 0xFFFE

const char *au_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        AU_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_AU, text, (int)(sizeof text / sizeof text[0]));
}

static void put16(uint8_t *p, unsigned v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}
static void put32(uint8_t *p, uint32_t v)
{
    for (int i = 0; i < 4; i++)
        p[i] = (uint8_t)(v >> (8 * i));
}
static unsigned get16(const uint8_t *p)
{
    return (unsigned)p[0] | (unsigned)p[1] << 8;
}
static uint32_t get32(const uint8_t *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* The header of a stereo AU_RATE file with `data_bytes` of samples: 44
 * bytes for PCM; float adds cbSize and a fact chunk (58 bytes), as the
 * format asks of non-PCM data. */
static size_t header(uint8_t *h, bool float32, uint32_t data_bytes)
{
    unsigned bits = float32 ? 32 : 16, block = AU_CHANNELS * bits / 8;
    size_t fmt_len = float32 ? 18 : 16, n = 0;
    memcpy(h, "RIFF", 4);
    memcpy(h + 8, "WAVEfmt ", 8);
    put32(h + 16, (uint32_t)fmt_len);
    put16(h + 20, float32 ? FMT_FLOAT : FMT_PCM);
    put16(h + 22, AU_CHANNELS);
    put32(h + 24, AU_RATE);
    put32(h + 28, AU_RATE * block);
    put16(h + 32, block);
    put16(h + 34, bits);
    n = 36;
    if (float32) {
        put16(h + 36, 0);
        memcpy(h + 38, "fact", 4);
        put32(h + 42, 4);
        put32(h + 46, data_bytes / block);
        n = 50;
    }
    memcpy(h + n, "data", 4);
    put32(h + n + 4, data_bytes);
    n += 8;
    put32(h + 4, (uint32_t)(n - 8 + data_bytes));
    return n;
}

/* x 32768, clipped at 32767: the inverse of the reader's / 32768, so a
 * 16-bit file read and written again keeps every sample */
static int16_t to16(float v)
{
    double s = (double)v * 32768.0;
    if (!(s > -32768.0)) /* NaN goes to the floor, then clipped like any sample */
        s = s != s ? 0.0 : -32768.0;
    if (s > 32767.0)
        s = 32767.0;
    return (int16_t)lrint(s);
}

/* Encodes frames into little-endian bytes at out (frames * block bytes). */
static void encode(uint8_t *out, const float *pcm, size_t frames, bool float32)
{
    size_t n = frames * AU_CHANNELS;
    if (float32) {
        for (size_t i = 0; i < n; i++) {
            uint32_t u;
            memcpy(&u, &pcm[i], 4);
            put32(out + 4 * i, u);
        }
    } else {
        for (size_t i = 0; i < n; i++)
            put16(out + 2 * i, (uint16_t)to16(pcm[i]));
    }
}

static bool too_long(const char *path, size_t frames, bool float32, uint32_t *bytes, rs_err *err)
{
    uint64_t b = (uint64_t)frames * AU_CHANNELS * (float32 ? 4 : 2);
    *bytes = 0;
    if (b > UINT32_MAX - 64)
        return !rs_fail(err, AU_ERR_ARG, "%s: %zu frames do not fit in a WAV file (4 GiB)", path, frames);
    *bytes = (uint32_t)b;
    return false;
}

bool au_wav_write(const char *path, const float *pcm, size_t frames, bool float32, rs_err *err)
{
    uint32_t bytes;
    if (too_long(path, frames, float32, &bytes, err))
        return false;
    uint8_t h[64];
    size_t hn = header(h, float32, bytes);
    uint8_t *buf = malloc(hn + bytes);
    if (!buf)
        return rs_fail(err, AU_ERR_NOMEM, "%s: out of memory for %u bytes of WAV", path, bytes);
    memcpy(buf, h, hn);
    encode(buf + hn, pcm, frames, float32);
    bool ok;
    if (rs_out_is_stream(path)) {
        FILE *f = strcmp(path, "-") ? fopen(path, "wb") : stdout;
        ok = f && fwrite(buf, 1, hn + bytes, f) == hn + bytes;
        ok = f && fflush(f) == 0 && ok;
        if (f && f != stdout)
            ok = fclose(f) == 0 && ok;
        if (!ok)
            rs_fail(err, AU_ERR_WAV_OPEN, "%s: write failed: %s", path, strerror(errno));
    } else {
        ok = rs_write_part(path, buf, hn + bytes, err) && rs_commit_file(path, err);
        if (!ok && err)
            err->code = AU_ERR_WAV_OPEN;
    }
    free(buf);
    return ok;
}

/* ---- streaming writer ---- */

struct au_wav {
    FILE *f;
    bool float32;
    bool stream;     /* "-" or a pipe: written in place, its size known up front */
    uint64_t frames, known;
    char path[PATH_MAX];
    char part[PATH_MAX + 8];
};

/* known: the frames that will be appended (the header says so from the
 * start, so "-" and pipes can take it), or 0 with a file: written at close */
static au_wav *wav_open(const char *path, bool float32, size_t known, rs_err *err)
{
    au_wav *w = calloc(1, sizeof *w);
    if (!w) {
        rs_fail(err, AU_ERR_NOMEM, "%s: out of memory", path);
        return NULL;
    }
    uint32_t bytes = 0;
    if (known && too_long(path, known, float32, &bytes, err)) {
        free(w);
        return NULL;
    }
    w->float32 = float32;
    w->known = known;
    w->stream = known && rs_out_is_stream(path);
    snprintf(w->path, sizeof w->path, "%s", path);
    rs_part_path(path, w->part, sizeof w->part);
    w->f = !w->stream ? fopen(w->part, "wb") : strcmp(path, "-") ? fopen(path, "wb") : stdout;
    uint8_t h[64];
    size_t hn = header(h, float32, bytes);
    if (!w->f || fwrite(h, 1, hn, w->f) != hn) {
        if (w->stream)
            rs_fail(err, AU_ERR_WAV_OPEN, "%s: cannot write: %s", w->path, strerror(errno));
        else
            rs_fail(err, AU_ERR_WAV_OPEN, "%s: cannot create (as %s): %s", w->path, w->part, strerror(errno));
        if (w->f && w->f != stdout)
            fclose(w->f);
        if (w->f && !w->stream)
            unlink(w->part);
        free(w);
        return NULL;
    }
    return w;
}

au_wav *au_wav_open(const char *path, bool float32, rs_err *err)
{
    return wav_open(path, float32, 0, err);
}

au_wav *au_wav_open_known(const char *path, bool float32, size_t frames, rs_err *err)
{
    return wav_open(path, float32, frames, err);
}

bool au_wav_append(au_wav *w, const float *pcm, size_t frames, rs_err *err)
{
    uint8_t buf[4096 * AU_CHANNELS * 4];
    size_t block = AU_CHANNELS * (w->float32 ? 4 : 2);
    uint32_t bytes;
    if (too_long(w->path, (size_t)w->frames + frames, w->float32, &bytes, err))
        return false;
    while (frames) {
        size_t n = frames < 4096 ? frames : 4096;
        encode(buf, pcm, n, w->float32);
        if (fwrite(buf, 1, n * block, w->f) != n * block)
            return rs_fail(err, AU_ERR_WAV_OPEN, "%s: write failed: %s", w->path, strerror(errno));
        w->frames += n;
        pcm += n * AU_CHANNELS;
        frames -= n;
    }
    return true;
}

bool au_wav_close(au_wav *w, bool ok, rs_err *err)
{
    if (!w)
        return ok;
    if (ok && w->known && w->frames != w->known)
        ok = rs_fail(err, AU_ERR_WAV_OPEN, "%s: %llu frames written where its header says %llu", w->path,
                     (unsigned long long)w->frames, (unsigned long long)w->known);
    if (ok && w->stream) {
        ok = fflush(w->f) == 0;
        if (!ok)
            rs_fail(err, AU_ERR_WAV_OPEN, "%s: write failed: %s", w->path, strerror(errno));
    } else if (ok) {
        uint8_t h[64];
        size_t hn = header(h, w->float32, (uint32_t)(w->frames * AU_CHANNELS * (w->float32 ? 4 : 2)));
        ok = fflush(w->f) == 0 && fseek(w->f, 0, SEEK_SET) == 0 && fwrite(h, 1, hn, w->f) == hn &&
             fflush(w->f) == 0 && fsync(fileno(w->f)) == 0;
        if (!ok)
            rs_fail(err, AU_ERR_WAV_OPEN, "%s: write failed: %s", w->path, strerror(errno));
    }
    if (w->f != stdout && fclose(w->f) != 0 && ok)
        ok = rs_fail(err, AU_ERR_WAV_OPEN, "%s: write failed: %s", w->path, strerror(errno));
    if (w->stream) {
        /* a stream is the reader's: nothing to rename or remove */
    } else if (ok) {
        ok = rs_commit_file(w->path, err);
        if (!ok && err)
            err->code = AU_ERR_WAV_OPEN;
    } else {
        unlink(w->part);
    }
    free(w);
    return ok;
}

/* ---- reader ---- */

static bool bad(rs_err *err, const char *path, const char *what)
{
    return rs_fail(err, AU_ERR_WAV_FORMAT, "%s: %s", path, what);
}

bool au_wav_read(const char *path, float **pcm, size_t *frames, int *channels, int *rate, rs_err *err)
{
    *pcm = NULL;
    size_t len;
    rs_err ferr = {0};
    uint8_t *d = (uint8_t *)rs_read_file(path, WAV_MAX_FILE, &len, &ferr);
    if (!d)
        return rs_fail(err, AU_ERR_WAV_OPEN, "%s", ferr.msg);
    bool ok = au_wav_parse(d, len, path, pcm, frames, channels, rate, err);
    free(d);
    return ok;
}

bool au_wav_parse(const uint8_t *d, size_t len, const char *path, float **pcm, size_t *frames, int *channels,
                  int *rate, rs_err *err)
{
    *pcm = NULL;
    bool ok = false;
    unsigned fmt = 0, ch = 0, bits = 0;
    uint32_t hz = 0;
    const uint8_t *data = NULL;
    size_t data_len = 0;
    if (len < 12 || memcmp(d, "RIFF", 4) || memcmp(d + 8, "WAVE", 4)) {
        bad(err, path, len < 12 ? "truncated: shorter than a RIFF header (12 bytes)" : "not a RIFF WAVE file (no RIFF/WAVE magic)");
        goto done;
    }
    for (size_t at = 12; at + 8 <= len;) {
        uint32_t n = get32(d + at + 4);
        const uint8_t *body = d + at + 8;
        size_t room = len - at - 8;
        if (!memcmp(d + at, "fmt ", 4)) {
            if (n < 16 || room < 16) {
                bad(err, path, "truncated: the fmt chunk is shorter than 16 bytes");
                goto done;
            }
            fmt = get16(body);
            ch = get16(body + 2);
            hz = get32(body + 4);
            bits = get16(body + 14);
            if (fmt == FMT_EXTENSIBLE && n >= 40 && room >= 40)
                fmt = get16(body + 24); /* the sub-format GUID starts with the format tag */
        } else if (!memcmp(d + at, "data", 4)) {
            data = body;
            data_len = n;
            if (n > room) {
                /* a streamed writer's placeholder size means "to the end" */
                if (n != 0xFFFFFFFFu) {
                    char m[160];
                    snprintf(m, sizeof m, "truncated: the data chunk says %u bytes, the file holds %zu", n, room);
                    bad(err, path, m);
                    goto done;
                }
                data_len = room;
            }
            break;
        }
        if (n > room)
            break;
        at += 8 + (size_t)n + (n & 1);
    }
    if (!fmt) {
        bad(err, path, "no fmt chunk (truncated, or not a WAV file)");
        goto done;
    }
    if (!data) {
        bad(err, path, "no data chunk (truncated)");
        goto done;
    }
    if (ch == 0 || ch > 64) {
        char m[96];
        snprintf(m, sizeof m, "%u channels (expected 1..64)", ch);
        bad(err, path, m);
        goto done;
    }
    if (hz < 1000 || hz > 768000) {
        char m[96];
        snprintf(m, sizeof m, "sample rate %u Hz (expected 1000..768000)", hz);
        bad(err, path, m);
        goto done;
    }
    if (!((fmt == FMT_PCM && (bits == 8 || bits == 16 || bits == 24 || bits == 32)) || (fmt == FMT_FLOAT && bits == 32))) {
        char m[128];
        snprintf(m, sizeof m, "format %u with %u-bit samples (expected PCM 8/16/24/32 or float 32)", fmt, bits);
        bad(err, path, m);
        goto done;
    }
    size_t bps = bits / 8, n = data_len / (bps * ch);
    float *out = malloc((n ? n : 1) * ch * sizeof *out);
    if (!out) {
        rs_fail(err, AU_ERR_NOMEM, "%s: out of memory for %zu frames", path, n);
        goto done;
    }
    for (size_t i = 0; i < n * ch; i++) {
        const uint8_t *p = data + i * bps;
        float v;
        switch (bits) {
        case 8: v = (float)((int)p[0] - 128) / 128.0f; break;
        case 16: v = (float)(int16_t)get16(p) / 32768.0f; break;
        case 24: v = (float)((int32_t)((uint32_t)p[0] << 8 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 24) >> 8) / 8388608.0f; break;
        default:
            if (fmt == FMT_FLOAT) {
                uint32_t u = get32(p);
                memcpy(&v, &u, 4);
                if (!isfinite(v))
                    v = 0;
            } else {
                v = (float)((double)(int32_t)get32(p) / 2147483648.0);
            }
        }
        out[i] = v;
    }
    *pcm = out;
    *frames = n;
    *channels = (int)ch;
    *rate = (int)hz;
    ok = true;
done:
    return ok;
}
