/* au_out: live audio output, one tick of stereo float in per call, to
 * OpenAL Soft, a WAV file or nowhere (the contract is au_out.h).
 *
 * One caller thread owns an au_out; OpenAL Soft's mixer thread reads the
 * buffers we queue on its source, and the only things crossing between the
 * two are OpenAL's own calls (queue, unqueue processed, query offset).
 *
 * DESIGN
 * - Backends are a table of two functions (write, close); adding one is
 *   a row, its functions and a case in au_out_open.  Volume is applied
 *   here, before any backend sees the samples, so the WAV of a run is what
 *   the speaker got.
 * - openal: one streaming source fed AL_BUF_FRAMES-frame buffers (a
 *   quarter tick, 4.2 ms).  At most latency_ms of audio is queued on the
 *   source (the number of buffers), so a sound never waits longer than
 *   that behind older audio; only a device period too long for that
 *   raises it, to the least that plays without gaps.  Playback starts
 *   (and restarts after running dry) with all but a tick of that queued:
 *   the free tick takes a late tick's catch-up, and what is queued beyond
 *   a tick and the device's period (which it takes at once) is how late a
 *   tick may come (al_open has the sums).  The device adds its own buffer
 *   (OpenAL Soft's period_size x periods, from alsoft.conf);
 *   AL_SOFT_source_latency reports it and the stats count it, so
 *   latency_ms in the stats is event to speaker, not just our queue.
 * - Audio handed to OpenAL cannot be taken back (only played buffers can be
 *   unqueued), so when every buffer is queued the oldest audio still in our
 *   hands (the staged quarter tick) is dropped: the game never waits for
 *   the speaker.  A source that stopped while we were still feeding it ran
 *   dry (the loop stalled): counted as an underrun; it restarts as above.
 * - write_ms reads the monotonic clock; it measures, it never changes what
 *   is played, so the audio stays a pure function of the caller's samples. */
#include "au_out.h"

#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#ifdef RS_HAVE_OPENAL
#include <AL/al.h>
#include <AL/alc.h>
#include <AL/alext.h>
#endif

typedef struct au_out_ops {
    bool (*write)(au_out *o, const float *pcm, int frames, rs_err *err);
    bool (*close)(au_out *o, bool ok, rs_err *err);
} au_out_ops;

#ifdef RS_HAVE_OPENAL
#define AL_BUF_FRAMES 200
#define AL_MAX_BUFS 512
#define AL_SLACK_FRAMES 480 /* 10 ms: how late a tick may come, at least */
typedef struct al_out {
    ALCdevice *dev;
    ALCcontext *ctx;
    ALuint src;
    ALuint bufs[AL_MAX_BUFS];
    ALuint idle[AL_MAX_BUFS];
    int nbufs, nidle;
    int start; /* buffers queued before playback (re)starts */
    ALenum format;
    bool float32, playing;
    LPALGETSOURCEDVSOFT get_sourcedv; /* AL_SOFT_source_latency, or NULL */
    float stage[AL_BUF_FRAMES * AU_CHANNELS]; /* the quarter tick being filled */
    int staged;
    int16_t conv[AL_BUF_FRAMES * AU_CHANNELS]; /* without AL_EXT_FLOAT32 */
} al_out;
#endif

struct au_out {
    const au_out_ops *ops;
    char name[320];
    float volume;
    float *scaled; /* the caller's block times volume */
    int scaled_cap;
    au_out_stats st;
    au_wav *wav;
#ifdef RS_HAVE_OPENAL
    al_out *al;
#endif
};

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

/* ---- null ---- */

static bool null_write(au_out *o, const float *pcm, int frames, rs_err *err)
{
    (void)pcm;
    (void)err;
    o->st.played += (uint64_t)frames;
    return true;
}

static bool null_close(au_out *o, bool ok, rs_err *err)
{
    (void)o;
    (void)ok;
    (void)err;
    return true;
}

static const au_out_ops null_ops = {null_write, null_close};

/* ---- wav ---- */

static bool wav_write(au_out *o, const float *pcm, int frames, rs_err *err)
{
    if (!au_wav_append(o->wav, pcm, (size_t)frames, err))
        return false;
    o->st.played += (uint64_t)frames;
    return true;
}

static bool wav_close(au_out *o, bool ok, rs_err *err)
{
    bool r = au_wav_close(o->wav, ok, err);
    o->wav = NULL;
    return r;
}

static const au_out_ops wav_ops = {wav_write, wav_close};

/* ---- openal ---- */

#ifdef RS_HAVE_OPENAL
static const char *al_error_name(ALenum e)
{
    switch (e) {
    case AL_INVALID_NAME: return "invalid name";
    case AL_INVALID_ENUM: return "invalid enum";
    case AL_INVALID_VALUE: return "invalid value";
    case AL_INVALID_OPERATION: return "invalid operation";
    case AL_OUT_OF_MEMORY: return "out of memory";
    default: return "unknown error";
    }
}

/* Takes back the buffers the device has played. */
static void al_reclaim(au_out *o)
{
    al_out *a = o->al;
    ALint n = 0;
    alGetSourcei(a->src, AL_BUFFERS_PROCESSED, &n);
    if (n <= 0)
        return;
    alSourceUnqueueBuffers(a->src, n, a->idle + a->nidle);
    a->nidle += n;
    o->st.played += (uint64_t)n * AL_BUF_FRAMES;
}

static bool al_queue_stage(au_out *o, rs_err *err)
{
    al_out *a = o->al;
    a->staged = 0;
    if (!a->nidle) {
        o->st.dropped += AL_BUF_FRAMES;
        return true;
    }
    ALuint b = a->idle[--a->nidle];
    if (a->float32) {
        alBufferData(b, a->format, a->stage, (ALsizei)sizeof a->stage, AU_RATE);
    } else {
        for (int i = 0; i < AL_BUF_FRAMES * AU_CHANNELS; i++) {
            float v = a->stage[i] < -1.0f ? -1.0f : a->stage[i] > 1.0f ? 1.0f : a->stage[i];
            a->conv[i] = (int16_t)lrintf(v * 32767.0f);
        }
        alBufferData(b, a->format, a->conv, (ALsizei)sizeof a->conv, AU_RATE);
    }
    alSourceQueueBuffers(a->src, 1, &b);
    ALenum e = alGetError();
    if (e != AL_NO_ERROR)
        return rs_fail(err, AU_ERR_DEVICE, "%s: queueing audio failed (%s)", o->name, al_error_name(e));
    return true;
}

/* Audio queued ahead of the speaker, in ms: the source's unplayed buffers,
 * what we still stage, and the device's own latency when it tells us. */
static double al_latency(au_out *o)
{
    al_out *a = o->al;
    ALint queued = 0;
    alGetSourcei(a->src, AL_BUFFERS_QUEUED, &queued);
    double ahead = (double)queued * AL_BUF_FRAMES / AU_RATE, dev = 0;
    if (a->get_sourcedv) {
        ALdouble v[2] = {0, 0};
        a->get_sourcedv(a->src, AL_SEC_OFFSET_LATENCY_SOFT, v);
        ahead -= v[0];
        dev = v[1];
    } else {
        ALint off = 0;
        alGetSourcei(a->src, AL_SAMPLE_OFFSET, &off);
        ahead -= (double)off / AU_RATE;
    }
    if (ahead < 0)
        ahead = 0;
    return (ahead + dev + (double)a->staged / AU_RATE) * 1e3;
}

static bool al_write(au_out *o, const float *pcm, int frames, rs_err *err)
{
    al_out *a = o->al;
    if (alcGetCurrentContext() != a->ctx)
        alcMakeContextCurrent(a->ctx);
    al_reclaim(o);
    if (a->playing) {
        ALint state = AL_PLAYING;
        alGetSourcei(a->src, AL_SOURCE_STATE, &state);
        if (state != AL_PLAYING) {
            o->st.underruns++;
            a->playing = false;
        }
    }
    for (int done = 0; done < frames;) {
        int n = frames - done < AL_BUF_FRAMES - a->staged ? frames - done : AL_BUF_FRAMES - a->staged;
        memcpy(a->stage + (size_t)a->staged * AU_CHANNELS, pcm + (size_t)done * AU_CHANNELS,
               (size_t)n * AU_CHANNELS * sizeof *pcm);
        a->staged += n;
        done += n;
        if (a->staged == AL_BUF_FRAMES && !al_queue_stage(o, err))
            return false;
    }
    ALint queued = 0;
    alGetSourcei(a->src, AL_BUFFERS_QUEUED, &queued);
    if (!a->playing && queued >= a->start) {
        alSourcePlay(a->src);
        a->playing = true;
    }
    double lat = al_latency(o);
    o->st.latency_ms = lat;
    if (lat > o->st.max_latency_ms)
        o->st.max_latency_ms = lat;
    ALenum e = alGetError();
    if (e != AL_NO_ERROR)
        return rs_fail(err, AU_ERR_DEVICE, "%s: playback failed (%s)", o->name, al_error_name(e));
    return true;
}

static void al_free(al_out *a)
{
    if (a->ctx) {
        alcMakeContextCurrent(a->ctx);
        if (a->src) {
            alSourceStop(a->src);
            alSourcei(a->src, AL_BUFFER, 0);
            alDeleteSources(1, &a->src);
        }
        if (a->nbufs)
            alDeleteBuffers(a->nbufs, a->bufs);
        alcMakeContextCurrent(NULL);
        alcDestroyContext(a->ctx);
    }
    if (a->dev)
        alcCloseDevice(a->dev);
    free(a);
}

static bool al_close(au_out *o, bool ok, rs_err *err)
{
    (void)err;
    al_out *a = o->al;
    if (ok) {
        alcMakeContextCurrent(a->ctx);
        /* play out what is queued (at most latency_ms and a quarter tick),
         * so the last sound is not cut; the partial quarter tick is padded */
        if (a->staged) {
            memset(a->stage + (size_t)a->staged * AU_CHANNELS, 0,
                   (size_t)(AL_BUF_FRAMES - a->staged) * AU_CHANNELS * sizeof(float));
            a->staged = AL_BUF_FRAMES;
            al_reclaim(o);
            al_queue_stage(o, NULL);
        }
        ALint queued = 0, state = AL_STOPPED;
        alGetSourcei(a->src, AL_BUFFERS_QUEUED, &queued);
        alGetSourcei(a->src, AL_SOURCE_STATE, &state);
        if (queued && state != AL_PLAYING)
            alSourcePlay(a->src);
        double give_up = now_ms() + 1e3 * queued * AL_BUF_FRAMES / AU_RATE + 250;
        for (;;) {
            alGetSourcei(a->src, AL_SOURCE_STATE, &state);
            if (state != AL_PLAYING || now_ms() > give_up)
                break;
            nanosleep(&(struct timespec){0, 2000000}, NULL);
        }
        al_reclaim(o);
    }
    al_free(a);
    o->al = NULL;
    return true;
}

static const au_out_ops al_ops = {al_write, al_close};

/* OpenAL Soft and the libraries under it print their own lines while they
 * look for a device ("AL lib: (EE) ...", "ALSA lib pcm.c: Unknown PCM
 * default"); the caller says what failed once, from err.  So standard
 * error is /dev/null while the device opens, unless the user asked for
 * OpenAL Soft's log (ALSOFT_LOGLEVEL).  Returns the saved descriptor, or
 * -1 when nothing was changed. */
static int quiet_stderr(void)
{
    if (getenv("ALSOFT_LOGLEVEL"))
        return -1;
    fflush(stderr);
    int saved = dup(2), null = open("/dev/null", O_WRONLY);
    if (saved < 0 || null < 0 || dup2(null, 2) < 0) {
        if (saved >= 0)
            close(saved);
        saved = -1;
    }
    if (null >= 0)
        close(null);
    return saved;
}

static void restore_stderr(int saved)
{
    if (saved < 0)
        return;
    dup2(saved, 2);
    close(saved);
}

/* Whether an OpenAL Soft config file the user or the system keeps sets the
 * mixing period (period_size or periods, in any section). */
static bool al_conf_sets_period(const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return false;
    char line[512];
    bool found = false;
    while (!found && fgets(line, sizeof line, f)) {
        const char *p = line + strspn(line, " \t");
        found = !strncmp(p, "period_size", 11) || !strncmp(p, "periods", 7);
    }
    fclose(f);
    return found;
}

/* OpenAL Soft 1.19 takes its mixing period from its config files, not from
 * the program (it ignores ALC_REFRESH), and Debian's default (1024 frames x
 * 3) alone adds about 64 ms at 48 kHz: over the 50 ms the game allows.  So
 * before OpenAL reads its config (once, at the first device call) we lay a
 * file of our own over the others through ALSOFT_CONF, which it reads last
 * and key by key: period_size 256, periods 2 (about 11 ms).  Not when the
 * user has set ALSOFT_CONF, nor when a config they or the system keep
 * (/etc/openal/alsoft.conf, $XDG_CONFIG_DIRS, ~/.alsoftrc,
 * $XDG_CONFIG_HOME/alsoft.conf) sets the period itself: theirs wins.  The
 * file is removed once read (al_conf_unlayer, after the first device
 * call).  path gets the file's name, or "" when none was laid. */
static void al_conf_layer(char *path, size_t size)
{
    static bool done;
    path[0] = 0;
    if (done)
        return;
    done = true;
    if (getenv("ALSOFT_CONF"))
        return;
    char conf[1024]; /* the user's and the system's files, only read */
    const char *home = getenv("HOME"), *xdg = getenv("XDG_CONFIG_HOME"), *dirs = getenv("XDG_CONFIG_DIRS");
    if (al_conf_sets_period("/etc/openal/alsoft.conf"))
        return;
    snprintf(conf, sizeof conf, "%s/alsoft.conf", dirs && *dirs && !strchr(dirs, ':') ? dirs : "/etc/xdg");
    if (al_conf_sets_period(conf))
        return;
    if (home) {
        snprintf(conf, sizeof conf, "%s/.alsoftrc", home);
        if (al_conf_sets_period(conf))
            return;
    }
    if (xdg && *xdg)
        snprintf(conf, sizeof conf, "%s/alsoft.conf", xdg);
    else if (home)
        snprintf(conf, sizeof conf, "%s/.config/alsoft.conf", home);
    if ((xdg && *xdg) || home) {
        if (al_conf_sets_period(conf))
            return;
    }
    const char *tmp = getenv("TMPDIR");
    snprintf(path, size, "%s/ringside-alsoft-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    int fd = mkstemp(path);
    if (fd < 0) {
        path[0] = 0;
        return; /* OpenAL's own periods: more latency, still sound */
    }
    static const char layer[] = "# ringside (au_out.c): OpenAL Soft's mixing period for 50 ms of latency\n"
                                "[general]\nperiod_size = 256\nperiods = 2\n";
    bool ok = write(fd, layer, sizeof layer - 1) == (ssize_t)(sizeof layer - 1);
    close(fd);
    if (!ok || setenv("ALSOFT_CONF", path, 1)) {
        unlink(path);
        path[0] = 0;
    }
}

/* After the first device call: OpenAL Soft has read its config. */
static void al_conf_unlayer(char *path)
{
    if (!path[0])
        return;
    unsetenv("ALSOFT_CONF");
    unlink(path);
    path[0] = 0;
}

static bool al_open(au_out *o, const au_out_opts *opts, int latency_ms, rs_err *err)
{
    al_out *a = calloc(1, sizeof *a);
    if (!a)
        return rs_fail(err, AU_ERR_NOMEM, "out of memory for the audio output");
    o->al = a;
    int saved = quiet_stderr();
    char layer[1024];
    al_conf_layer(layer, sizeof layer);
    a->dev = alcOpenDevice(opts->device);
    al_conf_unlayer(layer);
    restore_stderr(saved);
    if (!a->dev) {
        if (opts->device)
            return rs_fail(err, AU_ERR_DEVICE, "audio device '%s': OpenAL Soft cannot open it", opts->device);
        return rs_fail(err, AU_ERR_DEVICE, "the default audio device: OpenAL Soft cannot open it (none found?)");
    }
    const ALCchar *dname = alcGetString(a->dev, ALC_DEVICE_SPECIFIER);
    snprintf(o->name, sizeof o->name, "openal (%s)", dname ? dname : opts->device ? opts->device : "default");
    /* 48 kHz so the device does not resample; 5 ms periods asked for
     * (honoured by OpenAL Soft releases that read ALC_REFRESH) */
    const ALCint attrs[] = {ALC_FREQUENCY, AU_RATE, ALC_REFRESH, 200, 0};
    saved = quiet_stderr();
    a->ctx = alcCreateContext(a->dev, attrs);
    restore_stderr(saved);
    if (!a->ctx || !alcMakeContextCurrent(a->ctx))
        return rs_fail(err, AU_ERR_DEVICE, "%s: cannot create an OpenAL context", o->name);
    alGetError();
    a->float32 = alIsExtensionPresent("AL_EXT_FLOAT32");
    a->format = a->float32 ? alGetEnumValue("AL_FORMAT_STEREO_FLOAT32") : AL_FORMAT_STEREO16;
    if (!a->format) {
        a->float32 = false;
        a->format = AL_FORMAT_STEREO16;
    }
    if (alIsExtensionPresent("AL_SOFT_source_latency"))
        a->get_sourcedv = (LPALGETSOURCEDVSOFT)alGetProcAddress("alGetSourcedvSOFT");
    /* The sums.  The queue holds latency_ms (nbufs buffers).  Playback
     * starts with all but a tick of it queued (start), or all but a period
     * when a period is longer: the device takes whole periods, so the
     * queue swings by that much at a steady rate.  Just before the
     * next tick arrives the source holds start - 1 tick, and the device
     * takes a whole period at once, so what is left, start - tick -
     * period, is how late a tick may be without a gap: at 50 ms with
     * 256-frame periods, 1600 - 800 - 256 = 544 frames, 11 ms.  When the
     * period is too long to leave AL_SLACK_FRAMES so (OpenAL Soft 1.19
     * ignores ALC_REFRESH: the period is alsoft.conf's period_size, 1024
     * frames at 44.1 kHz unless set), start grows to a period, a tick and
     * that slack, and the queue to that and a tick: more latency, rather
     * than gaps whenever a frame of the game runs long. */
    ALCint refresh = 0, freq = 0;
    alcGetIntegerv(a->dev, ALC_REFRESH, 1, &refresh);
    alcGetIntegerv(a->dev, ALC_FREQUENCY, 1, &freq);
    long period = refresh > 0 && freq > 0 ? (long)AU_RATE / refresh : AU_TICK_FRAMES;
    long room = ((period > AU_TICK_FRAMES ? period : AU_TICK_FRAMES) + AL_BUF_FRAMES - 1) / AL_BUF_FRAMES;
    long least = (period + AU_TICK_FRAMES + AL_SLACK_FRAMES + AL_BUF_FRAMES - 1) / AL_BUF_FRAMES;
    long n = (long)latency_ms * AU_RATE / 1000 / AL_BUF_FRAMES;
    if (n < least + room)
        n = least + room;
    a->nbufs = n > AL_MAX_BUFS ? AL_MAX_BUFS : (int)n;
    a->start = a->nbufs - (int)room;
    alGenSources(1, &a->src);
    alGenBuffers(a->nbufs, a->bufs);
    ALenum e = alGetError();
    if (e != AL_NO_ERROR) {
        a->nbufs = 0;
        return rs_fail(err, AU_ERR_DEVICE, "%s: cannot make a source and its buffers (%s)", o->name, al_error_name(e));
    }
    memcpy(a->idle, a->bufs, sizeof a->bufs);
    a->nidle = a->nbufs;
    /* the source plays the mix as it is: no distance, no 3-D panning, and
     * (AL_SOFT_direct_channels) left and right straight to the front
     * speakers whatever the layout (5.1, HRTF) instead of as two virtual
     * speakers at +-30 degrees; on a stereo device 1.19 plays them bit for
     * bit either way (test_au_out's wave driver case) */
    if (alIsExtensionPresent("AL_SOFT_direct_channels"))
        alSourcei(a->src, AL_DIRECT_CHANNELS_SOFT, AL_TRUE);
    alSourcei(a->src, AL_SOURCE_RELATIVE, AL_TRUE);
    alSource3f(a->src, AL_POSITION, 0, 0, 0);
    alSourcef(a->src, AL_ROLLOFF_FACTOR, 0);
    o->ops = &al_ops;
    return true;
}
#endif

/* ---- the contract ---- */

static void out_free(au_out *o)
{
#ifdef RS_HAVE_OPENAL
    if (o->al)
        al_free(o->al);
#endif
    if (o->wav)
        au_wav_close(o->wav, false, NULL);
    free(o->scaled);
    free(o);
}

au_out *au_out_open(const au_out_opts *opts, rs_err *err)
{
    static const au_out_opts none = {0};
    if (!opts)
        opts = &none;
    float vol = opts->volume == 0 ? 1.0f : opts->volume;
    if (!(vol > 0 && vol <= 1)) {
        rs_fail(err, AU_ERR_ARG, "audio volume %g: expected 0..1 (linear)", (double)opts->volume);
        return NULL;
    }
    int latency = opts->latency_ms == 0 ? 50 : opts->latency_ms;
    if (latency < 10 || latency > 2000) {
        rs_fail(err, AU_ERR_ARG, "audio latency %d ms: expected 10..2000", opts->latency_ms);
        return NULL;
    }
    au_out_backend kind = opts->backend;
    if (kind == AU_OUT_AUTO)
        kind = opts->wav_path ? AU_OUT_WAV : AU_OUT_OPENAL;
    au_out *o = calloc(1, sizeof *o);
    if (!o) {
        rs_fail(err, AU_ERR_NOMEM, "out of memory for the audio output");
        return NULL;
    }
    o->volume = vol;
    switch (kind) {
    case AU_OUT_NULL:
        o->ops = &null_ops;
        snprintf(o->name, sizeof o->name, "null");
        break;
    case AU_OUT_WAV:
        if (!opts->wav_path || !*opts->wav_path) {
            rs_fail(err, AU_ERR_ARG, "the wav audio output needs a file name");
            goto fail;
        }
        o->wav = au_wav_open(opts->wav_path, opts->wav_float, err);
        if (!o->wav)
            goto fail;
        o->ops = &wav_ops;
        snprintf(o->name, sizeof o->name, "wav %s", opts->wav_path);
        break;
    case AU_OUT_OPENAL:
#ifdef RS_HAVE_OPENAL
        if (!al_open(o, opts, latency, err))
            goto fail;
#else
        rs_fail(err, AU_ERR_DEVICE, "audio device '%s': this build has no OpenAL (install libopenal-dev and rebuild)",
                opts->device ? opts->device : "default");
        goto fail;
#endif
        break;
    default:
        rs_fail(err, AU_ERR_ARG, "audio output backend %d: unknown", (int)kind);
        goto fail;
    }
    return o;
fail:
    out_free(o);
    return NULL;
}

const char *au_out_backend_name(const au_out *o)
{
    return o ? o->name : "none";
}

bool au_out_write(au_out *o, const float *pcm, int frames, rs_err *err)
{
    if (frames <= 0)
        return true;
    double t0 = now_ms();
    o->st.frames += (uint64_t)frames;
    if (o->volume != 1.0f) {
        if (frames > o->scaled_cap) {
            float *p = realloc(o->scaled, (size_t)frames * AU_CHANNELS * sizeof *p);
            if (!p)
                return rs_fail(err, AU_ERR_NOMEM, "out of memory for %d frames of audio", frames);
            o->scaled = p;
            o->scaled_cap = frames;
        }
        for (int i = 0; i < frames * AU_CHANNELS; i++)
            o->scaled[i] = pcm[i] * o->volume;
        pcm = o->scaled;
    }
    bool ok = o->ops->write(o, pcm, frames, err);
    o->st.write_ms += now_ms() - t0;
    return ok;
}

void au_out_stats_get(const au_out *o, au_out_stats *st)
{
    *st = o->st;
}

bool au_out_close(au_out *o, bool ok, rs_err *err)
{
    if (!o)
        return true;
    bool r = o->ops->close(o, ok, err);
    out_free(o);
    return r;
}
