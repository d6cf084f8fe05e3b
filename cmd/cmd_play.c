/* ringside play: the game in a window (or headless), live or from a replay.
 *
 * One thread: the loop (loop.c) owns the GL context, the game state and
 * the recorder; input devices are polled on the same thread between ticks.
 * Sound is made on that thread too: each tick's cues are mixed and handed
 * to au_out (runtime/audio/au_out.h), which never blocks for longer than a
 * tick; OpenAL Soft's own thread plays what was queued. */
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "snd_out.h"
#include "../runtime/audio/au_out.h"
#include "../runtime/game/g_ai.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/input.h"
#include "../runtime/loop.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_quality.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_img.h"
#include "../runtime/util/rs_out.h"
#include "../runtime/util/rs_progress.h"
#include "job_err.h"

static void help(void)
{
    printf("usage: ringside play [--p1 human|cpu] [--p2 human|cpu] [--stage NAME] [--seed S] [--level L]\n"
           "                     [--record FILE] [--replay FILE] [--seconds N] [--screenshot FILE]\n"
           "                     [--size WxH] [--fullscreen] [--no-vsync] [--headless] [-q|-v]\n"
           "                     [--stage-file FILE] [--passes[=summary|frames]]\n"
           "                     [--hdr-format rgba16f|r11g11b10f] [--quality draft|standard|high|reference]\n"
           "                     [--audio-out FILE.wav] [--mute] [--volume V] [--audio-device D]\n\n"
           "Plays the game at a fixed 60 Hz in a window (GLFW; needs X, or xvfb-run -a).\n"
           "Keys: player 1 W A S D, J punch, K kick, L guard; player 2 arrows, numpad\n"
           "1 2 3 (or , . /); gamepads 1 and 2 too.  The 2-3-6 motion + punch is the\n"
           "special move.  Escape quits.  Matches follow one another until you quit.\n"
           "Sound plays through OpenAL Soft; with no audio device, one warning and the\n"
           "game runs silent.\n\n"
           "  --p1 / --p2 K    who plays each side (default: human vs cpu)\n"
           "  --stage NAME     dojo, harbor, temple, shallows, snowfield, mistvale, plaza or quarry\n"
           "                   (default dojo)\n"
           "  --seed S         random seed (default: the clock); stored in recordings\n"
           "  --level L        CPU skill 0..3 (default 2)\n"
           "  --record FILE    write what was played as a replay when the game ends\n"
           "  --replay FILE    watch a replay instead of playing; ends with it\n"
           "  --seconds N      stop after N seconds of game time\n"
           "  --screenshot F   save the last frame as .png or .ppm\n"
           "  --size WxH       window or frame size (default 1280x720)\n"
           "  --quality Q      draft, standard (default), high or reference: pixels drawn\n"
           "                   per window pixel and the renderer's knobs (render --help,\n"
           "                   docs/accuracy.md); a larger drawing is averaged down to the\n"
           "                   window\n"
           "  --fullscreen     primary monitor, its current mode\n"
           "  --no-vsync       do not wait for the display\n"
           "  --headless       no window: EGL/OSMesa, one tick per frame, as fast as possible\n"
           CLI_LOG_HELP
           "  --stage-file F   the look to use instead of stages/<stage>.stage (docs/stages.md)\n"
           "  --passes[=MODE]  time every render pass: a table at the end, or one line per frame\n"
           "  --hdr-format F   the HDR buffer: rgba16f (default) or r11g11b10f\n"
           "  --audio-out F    write the sound to F (.wav, 16-bit) instead of the audio device;\n"
           "                   headless, without it, the game is silent\n"
           "  --mute           no sound (the mixer does not run; --audio-out gets silence)\n"
           "  --volume V       output volume, 0..1 (linear; default 1; 0 is --mute)\n"
           "  --audio-device D  the OpenAL device to play on (default: the system's)\n");
}

typedef struct play {
    g_state prev, cur;
    g_ai ai[2];
    int kind[2]; /* RP_HUMAN / RP_CPU */
    rp_replay *watch;
    rp_recorder *rec;
    plat *p;
    r_game *r;
    r_target target; /* headless */
    int w, h;
    const r_preset *quality;
    /* the quality's larger drawing and the halvings that bring it to the window (ss_fit) */
    r_target ss[4];
    int nss, ss_w, ss_h;
    uint64_t limit;
    bool quit, failed;
    rs_err err;
    /* sound: NULL mixer when muted or silent */
    au_mixer *mix;
    au_out *out;
    float pcm[AU_TICK_FRAMES * AU_CHANNELS];
    double audio_ms; /* mixing and output, summed over the ticks */
} play;

static void on_input(void *user, g_input in[2])
{
    play *s = user;
    for (int i = 0; i < 2; i++) {
        if (s->watch)
            in[i] = s->watch->inputs[2 * s->cur.tick + (uint64_t)i];
        else if (s->kind[i] == RP_CPU)
            in[i] = g_ai_input(&s->ai[i], &s->cur);
        else
            in[i] = plat_window(s->p) ? in_read(plat_window(s->p), i) : 0;
    }
}

/* The tick's sound: the cues of the step that took prev to cur, mixed as
 * au_replay_track mixes them, so a headless --audio-out run of a replay
 * is that replay's unnormalized soundtrack, sample for sample. */
static void play_sound(play *s, const g_events *ev)
{
    double t0 = rs_now();
    au_cue cues[AU_MAX_CUES];
    int n = au_game_cues(&s->prev, &s->cur, ev, cues, AU_MAX_CUES);
    for (int i = 0; i < n; i++)
        au_mixer_cue(s->mix, &cues[i]);
    au_mixer_music(s->mix, s->cur.stage);
    au_mixer_mix(s->mix, s->pcm, AU_TICK_FRAMES, NULL, 0);
    if (!au_out_write(s->out, s->pcm, AU_TICK_FRAMES, &s->err))
        s->failed = true;
    s->audio_ms += (rs_now() - t0) * 1e3;
}

static void on_step(void *user, const g_input in[2])
{
    play *s = user;
    g_events ev;
    s->prev = s->cur;
    g_step(&s->cur, in, &ev);
    if (s->rec && !rp_rec_tick(s->rec, in, &s->cur, &s->err))
        s->failed = true;
    if (s->mix)
        play_sound(s, &ev);
    else if (s->out && !au_out_write(s->out, s->pcm, AU_TICK_FRAMES, &s->err)) /* muted: s->pcm stays zero */
        s->failed = true;
}

static void ss_free(play *s)
{
    for (int i = 0; i < s->nss; i++)
        r_target_destroy(&s->ss[i]);
    s->nss = 0;
}

/* The drawing targets for a w x h frame under the quality: none when it
 * draws 1:1; else the scaled size, then halvings down to at most twice
 * the frame, so that each linear blit averages whole 2x2 blocks. */
static bool ss_fit(play *s, int w, int h)
{
    int rw, rh;
    r_preset_render_size(s->quality, w, h, R_RENDER_MAX, &rw, &rh);
    if (s->ss_w == w && s->ss_h == h && (s->nss || (rw == w && rh == h)))
        return true;
    ss_free(s);
    s->ss_w = w, s->ss_h = h;
    while (rw > w || rh > h) {
        if (s->nss == 4 || !r_target_create(&s->ss[s->nss], rw, rh, &s->err))
            return s->nss == 4 ? rs_fail(&s->err, JOB_ERR_LIMIT, "%dx%d: too many halvings", rw, rh) : false;
        s->nss++;
        if (rw <= 2 * w && rh <= 2 * h)
            break;
        rw = rw / 2 > w ? rw / 2 : w, rh = rh / 2 > h ? rh / 2 : h;
    }
    return true;
}

/* Draws the frame into fbo (w x h), through the quality's larger drawing. */
static bool draw_frame(play *s, GLuint fbo, float alpha, int w, int h)
{
    if (!ss_fit(s, w, h))
        return false;
    const r_target *top = s->nss ? &s->ss[0] : NULL;
    gl.BindFramebuffer(GL_FRAMEBUFFER, top ? top->fbo : fbo);
    if (!r_game_draw(s->r, &s->prev, &s->cur, alpha, top ? top->w : w, top ? top->h : h, &s->err))
        return false;
    for (int i = 0; i < s->nss; i++) {
        const r_target *src = &s->ss[i];
        int dw = i + 1 < s->nss ? s->ss[i + 1].w : w, dh = i + 1 < s->nss ? s->ss[i + 1].h : h;
        gl.BindFramebuffer(GL_READ_FRAMEBUFFER, src->fbo);
        gl.BindFramebuffer(GL_DRAW_FRAMEBUFFER, i + 1 < s->nss ? s->ss[i + 1].fbo : fbo);
        gl.BlitFramebuffer(0, 0, src->w, src->h, 0, 0, dw, dh, GL_COLOR_BUFFER_BIT, GL_LINEAR);
    }
    gl.BindFramebuffer(GL_FRAMEBUFFER, fbo);
    return true;
}

static void on_render(void *user, float alpha)
{
    play *s = user;
    int w = s->w, h = s->h;
    if (plat_window(s->p))
        plat_size(s->p, &w, &h);
    if (w > 0 && h > 0 && !draw_frame(s, s->target.fbo, alpha, w, h))
        s->failed = true;
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    plat_present(s->p);
}

static bool on_running(void *user)
{
    play *s = user;
    if (s->failed || s->quit)
        return false;
    if (plat_window(s->p)) {
        if (!plat_poll(s->p) || in_quit(plat_window(s->p))) {
            s->quit = true;
            return false;
        }
    }
    if (s->watch && s->cur.tick >= s->watch->ticks)
        return false;
    return !s->limit || s->cur.tick < s->limit;
}

/* Renders the final state once more and saves it. */
static bool screenshot(play *s, const char *path, rs_err *err)
{
    int w = s->w, h = s->h;
    if (plat_window(s->p))
        plat_size(s->p, &w, &h);
    uint8_t *px = malloc((size_t)w * h * 4);
    if (!px)
        return rs_fail(err, JOB_ERR_NOMEM, "out of memory for a %dx%d screenshot", w, h);
    if (!draw_frame(s, s->target.fbo, 1.0f, w, h)) {
        free(px);
        return false;
    }
    r_read_pixels(s->target.fbo, w, h, 4, px);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    bool ok = rs_mkdirs_for(path, err) && rs_image_write(path, w, h, 4, px, err);
    free(px);
    return ok;
}

/* The output the options ask for.  --audio-out is opened before anything
 * else, so a bad path stops the run at once; the device after the window,
 * so a run that cannot open a window says only that.  A device that
 * cannot be opened is one warning: the game runs silent.  false: a fatal
 * error, in s->err. */
static bool audio_open(play *s, const char *wav, bool mute, float volume, const char *device, bool headless,
                       int stage)
{
    bool silent = mute || volume == 0;
    if ((silent && !wav) || (headless && !wav))
        return true;
    if (wav && !rs_out_check(wav, true, &s->err))
        return false;
    rs_err err = {0};
    s->out = au_out_open(&(au_out_opts){.wav_path = wav, .device = device, .volume = silent ? 1 : volume}, &err);
    if (!s->out) {
        if (wav || err.code != AU_ERR_DEVICE) {
            s->err = err;
            return false;
        }
        cli_warn("play", "%s; the game runs silent", err.msg);
        return true;
    }
    if (silent) /* --audio-out records what was played: silence, tick for tick */
        return true;
    s->mix = au_mixer_new(NULL, &s->err);
    if (!s->mix)
        return false;
    /* the bank and the stage's music are built on first use: here, not in
     * the first tick, where it would be a hitch (the same music the tick
     * would choose, so the samples do not change) */
    au_bank_get(0);
    au_mixer_music(s->mix, stage);
    return true;
}

/* "; audio: BACKEND, ..." for the summary line. */
static void audio_summary(const play *s, uint64_t ticks, char *buf, size_t size)
{
    if (!s->out) {
        snprintf(buf, size, "; audio: off");
        return;
    }
    au_out_stats st;
    au_out_stats_get(s->out, &st);
    int n = snprintf(buf, size, "; audio: %s, %.3f ms a tick (mix and output)", au_out_backend_name(s->out),
                     ticks ? s->audio_ms / (double)ticks : 0.0);
    if (strncmp(au_out_backend_name(s->out), "openal", 6) == 0 && n > 0 && (size_t)n < size)
        snprintf(buf + n, size - (size_t)n, ", latency max %.1f ms, %" PRIu64 " underruns, %" PRIu64 " frames dropped",
                 st.max_latency_ms, st.underruns, st.dropped);
}

static bool parse_kind(const char *opt, const char *arg, int *kind)
{
    if (!strcmp(arg, "human"))
        *kind = RP_HUMAN;
    else if (!strcmp(arg, "cpu") || !strcmp(arg, "ai"))
        *kind = RP_CPU;
    else {
        cli_error("play", "%s '%s': expected human or cpu", opt, arg);
        return false;
    }
    return true;
}

static const struct option opts[] = {
    {"p1", required_argument, 0, '1'},     {"p2", required_argument, 0, '2'},
    {"stage", required_argument, 0, 't'},  {"seed", required_argument, 0, 'S'},
    {"level", required_argument, 0, 'l'},  {"record", required_argument, 0, 'r'},
    {"replay", required_argument, 0, 'R'}, {"seconds", required_argument, 0, 's'},
    {"screenshot", required_argument, 0, 'o'}, {"size", required_argument, 0, 'z'},
    {"fullscreen", no_argument, 0, 'f'},   {"no-vsync", no_argument, 0, 'v'},
    {"headless", no_argument, 0, 'H'},     {"stage-file", required_argument, 0, 'T'}, {"passes", optional_argument, 0, 'P'},
    {"hdr-format", required_argument, 0, 'X'},
    {"audio-out", required_argument, 0, 'A'}, {"mute", no_argument, 0, 'M'},
    {"volume", required_argument, 0, 'V'}, {"audio-device", required_argument, 0, 'D'},
    {"quality", required_argument, 0, 'Q'}, {"help", no_argument, 0, 'h'}, {0}};

/* What the command line asks for, beyond what goes straight into play. */
typedef struct play_opts {
    int stage;
    long level, seconds;
    uint64_t seed;
    const char *record, *replay, *shot;
    const char *audio_out, *audio_device;
    bool headless, quiet, mute;
    float volume;
    r_game_opts go;
    int passes;
    plat_desc pd;
} play_opts;

/* One option; -1 to go on, else the exit status (--help: RS_EXIT_OK). */
static int play_option(play *s, play_opts *o, int c, const char *arg, char **argv)
{
    int k;
    switch (c) {
    case '1': return parse_kind("--p1", arg, &s->kind[0]) ? -1 : RS_EXIT_USAGE;
    case '2': return parse_kind("--p2", arg, &s->kind[1]) ? -1 : RS_EXIT_USAGE;
    case 't': return cli_stage(arg, &o->stage) ? -1 : RS_EXIT_USAGE;
    case 'S': return cli_u64("--seed", arg, &o->seed) ? -1 : RS_EXIT_USAGE;
    case 'l': return cli_int("--level", arg, 0, 3, &o->level) ? -1 : RS_EXIT_USAGE;
    case 'r': o->record = arg; return -1;
    case 'R': o->replay = arg; return -1;
    case 's': return cli_int("--seconds", arg, 1, 7 * 24 * 3600, &o->seconds) ? -1 : RS_EXIT_USAGE;
    case 'o': o->shot = arg; return -1;
    case 'z': return cli_out_size("--size", arg, &s->w, &s->h) ? -1 : RS_EXIT_USAGE;
    case 'Q': return (s->quality = cli_quality("play", arg)) ? -1 : RS_EXIT_USAGE;
    case 'f': o->pd.fullscreen = true; return -1;
    case 'v': o->pd.no_vsync = true; return -1;
    case 'H': o->headless = true; return -1;
    case 'T': o->go.stage_file = arg; return -1;
    case 'P': return cli_passes("play", arg, &o->passes) ? -1 : RS_EXIT_USAGE;
    case 'X':
        if (!cli_hdr_format(arg, &k))
            return RS_EXIT_USAGE;
        o->go.hdr_format = r_game_hdr_of(k);
        return -1;
    case 'A': o->audio_out = arg; return -1;
    case 'M': o->mute = true; return -1;
    case 'V': {
        snd_opts so = {0}; /* the parsing movie and attract use */
        if (!snd_volume_arg("play", arg, &so))
            return RS_EXIT_USAGE;
        o->volume = so.volume;
        return -1;
    }
    case 'D': o->audio_device = arg; return -1;
    case 'h': help(); return RS_EXIT_OK;
    default: return cli_bad_option("play", argv);
    }
}

/* The command line into s and o, checked; -1 to go on, else the exit status. */
static int parse_options(int argc, char **argv, play *s, play_opts *o)
{
    s->kind[0] = RP_HUMAN;
    s->kind[1] = RP_CPU;
    s->w = 1280;
    s->h = 720;
    s->quality = &r_presets[R_PRESET_DEFAULT];
    *o = (play_opts){.level = 2, .seed = (uint64_t)time(NULL), .volume = 1, .pd = {.title = "ringside"}};
    o->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    int c, status;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1)
        if ((status = play_option(s, o, c, optarg, argv)) >= 0)
            return status;
    if (optind < argc) {
        cli_error("play", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("play");
    }
    const char *dot = o->shot ? strrchr(o->shot, '.') : NULL;
    if (o->shot && (!dot || (strcmp(dot, ".png") && strcmp(dot, ".ppm")))) {
        cli_error("play", "%s: unknown image extension (expected .png or .ppm)", o->shot);
        return RS_EXIT_USAGE;
    }
    if (o->headless && !o->replay && !o->seconds) {
        cli_error("play", "--headless needs --seconds N or --replay FILE (nobody can close a headless game)");
        return RS_EXIT_USAGE;
    }
    if (o->replay && o->record) {
        cli_error("play", "--replay and --record together: the replay is already recorded");
        return RS_EXIT_USAGE;
    }
    dot = o->audio_out ? strrchr(o->audio_out, '.') : NULL;
    if (o->audio_out && (!dot || strcmp(dot, ".wav"))) {
        cli_error("play", "--audio-out %s: expected a .wav file", o->audio_out);
        return RS_EXIT_USAGE;
    }
    return -1;
}

/* The replay watched, the sound, the window or context, the renderer and
 * the game; -1 to go on, else the exit status (the error in s->err). */
static int play_setup(play *s, play_opts *o, rp_replay *watch, rp_recorder *rec)
{
    if (o->replay) {
        if (!rp_read(o->replay, watch, &s->err))
            return RS_EXIT_FAIL;
        s->watch = watch;
        o->stage = watch->stage;
        o->seed = watch->seed;
    }
    if (o->audio_out && !audio_open(s, o->audio_out, o->mute, o->volume, o->audio_device, o->headless, o->stage))
        return RS_EXIT_FAIL;
    o->pd.backend = o->headless ? NULL : "glfw";
    o->pd.width = s->w;
    o->pd.height = s->h;
    o->pd.hidden = false;
    if (!(s->p = plat_create(&o->pd, &s->err)))
        return cli_plat_status(&s->err);
    o->go.quiet = o->quiet;
    o->go.q = s->quality->q;
    s->r = r_game_create_opts(&o->go, &s->err);
    if (!s->r || !r_game_prepare(s->r, o->stage, &s->err) ||
        (o->headless && !r_target_create(&s->target, s->w, s->h, &s->err)))
        return RS_EXIT_FAIL;
    if (o->passes)
        r_game_passes(s->r, o->passes == 2, stderr);
    if (!o->audio_out && !audio_open(s, NULL, o->mute, o->volume, o->audio_device, o->headless, o->stage))
        return RS_EXIT_FAIL;
    g_init(&s->cur, o->stage, o->seed);
    s->prev = s->cur;
    g_ai_init(&s->ai[0], 0, (int)o->level, o->seed);
    g_ai_init(&s->ai[1], 1, (int)o->level, o->seed + 1);
    if (o->record) {
        rp_rec_init(rec, o->stage, o->seed, s->kind[0], s->kind[1]);
        s->rec = rec;
    }
    s->limit = o->seconds ? (uint64_t)o->seconds * G_HZ : 0;
    return -1;
}

/* The game until it ends, then its outputs: the screenshot, the pass
 * table, the recording, the summary and the WAV. */
static int play_run(play *s, const play_opts *o)
{
    if (!o->headless && !o->replay && s->kind[0] == RP_CPU && s->kind[1] == RP_CPU && !o->seconds && !o->quiet)
        cli_info("play", "CPU vs CPU; Escape quits");
    /* the first frame compiles shaders and fills caches (a tenth of a
     * second and more): drawn here, it does not hold up the first ticks,
     * which would then come in a burst that the audio queue cannot hold */
    if (!o->headless)
        on_render(s, 1.0f);
    lp_game g = {s, on_input, on_step, on_render, on_running};
    lp_stats st;
    lp_run(&(lp_desc){.headless = o->headless}, &g, &st);
    if (s->failed || (o->shot && !screenshot(s, o->shot, &s->err)))
        return RS_EXIT_FAIL;
    if (o->passes)
        r_game_report(s->r, stderr);
    if (s->rec && !rp_rec_save(s->rec, o->record, &s->err))
        return RS_EXIT_FAIL;
    if (!o->quiet) {
        char audio[512];
        audio_summary(s, st.ticks, audio, sizeof audio);
        fprintf(stderr,
                "ringside play: %" PRIu64 " ticks (%.1f s of game) in %.1f s, %" PRIu64 " frames, %" PRIu64
                " late ticks, %" PRIu64 " stalls; rounds %d-%d%s%s%s\n",
                st.ticks, st.ticks / (double)G_HZ, st.seconds, st.frames, st.late_ticks, st.stalls,
                s->cur.f[0].rounds_won, s->cur.f[1].rounds_won, o->record ? "; recorded " : "", o->record ? o->record : "",
                audio);
    }
    if (s->out) {
        au_out *out = s->out;
        s->out = NULL;
        if (!au_out_close(out, true, &s->err))
            return RS_EXIT_FAIL;
    }
    return RS_EXIT_OK;
}

int cmd_play(int argc, char **argv)
{
    play *s = calloc(1, sizeof *s);
    if (!s)
        return RS_EXIT_FAIL;
    play_opts o;
    rp_replay watch = {0};
    rp_recorder rec;
    int status = parse_options(argc, argv, s, &o);
    if (status < 0)
        status = play_setup(s, &o, &watch, &rec);
    if (status < 0)
        status = play_run(s, &o);
    if (status == RS_EXIT_FAIL || (status == RS_EXIT_USAGE && s->err.msg[0]))
        cli_error("play", "%s", s->err.msg);
    if (s->p) {
        ss_free(s);
        r_target_destroy(&s->target);
        r_game_destroy(s->r);
        plat_destroy(s->p);
    }
    if (s->out)
        au_out_close(s->out, false, NULL);
    if (s->mix)
        au_mixer_free(s->mix);
    if (s->rec)
        rp_free(&s->rec->rp);
    rp_free(&watch);
    free(s);
    return status;
}
