/* ringside movie: one movie on the 60 Hz tick, in a window or headless.
 *
 * Headless (--dump, --hashes or --headless) plays every tick as fast as
 * possible and waits for the decoder, so the output is exact: the frames
 * the display would have shown, tick by tick.  That is what the colour and
 * pacing tests read.  The soundtrack goes out tick by tick too, 800 frames
 * after each picture (player/mv_audio.h): to the audio device, or with
 * --audio-out to a WAV that holds exactly the played ticks' audio. */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "../player/mv_csp.h"
#include "../player/mv_player.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "snd_out.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/input.h"
#include "../runtime/loop.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_target.h"
#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_img.h"
#include "../runtime/util/rs_out.h"
#include "job_err.h"

static void help(void)
{
    printf("usage: ringside movie FILE [--dump DIR] [--hashes FILE] [-y|-n] [--headless] [--ticks N]\n"
           "                      [--upload pbo|direct|persistent] [--matrix bt601|bt709]\n"
           "                      [--range limited|full] [--size WxH] [--fullscreen] [--loop] [-q|-v]\n"
           "                      [--mute] [--volume V] [--audio-out FILE.wav] [--audio-device NAME]\n\n"
           "Plays a movie on the 60 Hz tick: Y4M (8-bit 4:2:0, 4:2:2, 4:4:4, mono) or anything\n"
           "FFmpeg decodes (H.264, VP9, AV1, ...).  Frames are decoded on their own thread,\n"
           "streamed into Y, Cb, Cr textures and converted with the stream's matrix and range.\n"
           "A 24 fps movie shows its frames for 2 and 3 ticks in turn; 30 fps for 2 (docs/player.md).\n"
           "The movie's sound (its best audio stream: any rate, format and layout, downmixed to\n"
           "stereo 48 kHz) plays in step with the picture through OpenAL.\n"
           "In a window (GLFW; needs X, or xvfb-run -a) Escape quits.\n\n"
           "  --dump DIR      headless: write each displayed frame as DIR/frameNNNNNN.ppm (NNNNNN is\n"
           "                  the movie frame number)\n"
           "  --hashes FILE   headless: one line per tick: TICK FRAME HASH (FNV-1a of the RGB image);\n"
           "                  '-' for standard output\n"
           "  -y, --overwrite\n"
           "                  replace an existing --hashes file or dumped frame\n"
           "  -n, --no-overwrite\n"
           "                  refuse them, naming the file (the default; never asks).  The\n"
           "                  folder of --hashes, and the one above --dump DIR, must exist\n"
           "  --headless      no window: EGL/OSMesa, every tick as fast as possible\n"
           "  --ticks N       stop after N ticks (default: the end of the movie)\n"
           "  --upload MODE   pbo (two unpack buffers in ping-pong; default), direct (glTexSubImage2D\n"
           "                  from memory) or persistent (a mapped ring the decoder writes into)\n"
           "  --matrix M      override the stream's YCbCr matrix: bt601 or bt709\n"
           "  --range R       override the stream's range: limited or full\n"
           "  --size WxH      output size (default: the movie's display size)\n"
           "  --fullscreen    window: primary monitor\n"
           "  --loop          window: start again at the end (Escape quits)\n"
           CLI_LOG_HELP
           "  --mute          no sound (with --audio-out: a silent WAV of the same length)\n"
           "  --volume V      sound level, linear 0..1 (default 1; 0 is --mute)\n"
           "  --audio-out F   write the sound to F.wav (16-bit, 48 kHz stereo) instead of the device,\n"
           "                  one tick of audio per tick played; headless or not (-y replaces F)\n"
           "  --audio-device N\n"
           "                  the OpenAL device to play on (default: the system's).  Without a\n"
           "                  device: one warning line, and the movie plays silent\n");
}

typedef struct mv_cmd {
    const char *path;
    mv_player_opts po;
    mv_player *mp;
    plat *p;
    r_target target;
    int w, h;
    bool headless, loop, failed, quit, overwrite;
    int64_t limit, ticks, last_dumped;
    const char *dump;
    FILE *hashes;
    uint8_t *px;
    au_out *out; /* NULL: silent */
    float pcm[AU_TICK_FRAMES * 2];
    int ended; /* tick returned 0 */
    rs_err err;
} mv_cmd;

static void on_input(void *user, g_input in[2])
{
    (void)user;
    in[0] = in[1] = 0;
}

/* The sound of the tick just played, after its picture. */
static void play_audio(mv_cmd *s)
{
    if (!s->out)
        return;
    mv_player_audio(s->mp, s->pcm, AU_TICK_FRAMES);
    if (!au_out_write(s->out, s->pcm, AU_TICK_FRAMES, &s->err))
        s->failed = true;
}

static void on_step(void *user, const g_input in[2])
{
    (void)in;
    mv_cmd *s = user;
    int r = mv_player_tick(s->mp, &s->err);
    if (r < 0) {
        s->failed = true;
        return;
    }
    if (r == 0) {
        if (s->loop && !s->headless && mv_player_frame(s->mp) >= 0) {
            mv_player_close(s->mp);
            if (!(s->mp = mv_player_open(s->path, &s->po, &s->err))) {
                s->failed = true;
                return;
            }
            if (mv_player_tick(s->mp, &s->err) < 0)
                s->failed = true;
            else
                play_audio(s);
            return;
        }
        s->ended = 1;
        return;
    }
    play_audio(s);
    s->ticks++;
}

static bool write_outputs(mv_cmd *s)
{
    int64_t tick = s->ticks - 1, frame = mv_player_frame(s->mp);
    r_read_pixels(s->target.fbo, s->w, s->h, 3, s->px);
    if (s->hashes)
        fprintf(s->hashes, "%" PRId64 " %" PRId64 " %016" PRIx64 "\n", tick, frame,
                rs_fnv1a64(s->px, (size_t)s->w * s->h * 3));
    if (s->dump && frame >= 0 && frame != s->last_dumped) {
        char path[1100];
        snprintf(path, sizeof path, "%s/frame%06" PRId64 ".ppm", s->dump, frame);
        if (!rs_out_check(path, s->overwrite, &s->err) || !rs_image_write(path, s->w, s->h, 3, s->px, &s->err))
            return false;
        s->last_dumped = frame;
    }
    return true;
}

static void on_render(void *user, float alpha)
{
    (void)alpha;
    mv_cmd *s = user;
    if (s->failed || s->ended)
        return;
    int w = s->w, h = s->h;
    if (plat_window(s->p))
        plat_size(s->p, &w, &h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, s->target.fbo);
    if (w > 0 && h > 0)
        mv_player_draw(s->mp, w, h);
    if (s->headless && s->ticks > 0 && (s->dump || s->hashes) && !write_outputs(s))
        s->failed = true;
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    plat_present(s->p);
}

static bool on_running(void *user)
{
    mv_cmd *s = user;
    if (s->failed || s->ended || s->quit)
        return false;
    if (plat_window(s->p) && (!plat_poll(s->p) || in_quit(plat_window(s->p)))) {
        s->quit = true;
        return false;
    }
    return !s->limit || s->ticks < s->limit;
}

static const char *siting_name(int loc)
{
    return loc == MV_CHROMA_CENTER ? "centre" : loc == MV_CHROMA_LEFT ? "left" : "top-left";
}

static void summary(mv_cmd *s, const lp_stats *ls)
{
    const mv_info *i = mv_player_info(s->mp);
    mv_stats st;
    mv_player_stats(s->mp, &st);
    char frames[32] = "?";
    if (i->frames >= 0)
        snprintf(frames, sizeof frames, "%" PRId64, i->frames);
    fprintf(stderr,
            "ringside movie: %s: %s %s %dx%d, %s%s %s range, chroma %s, %d/%d fps, %s frames\n"
            "ringside movie: %" PRId64 " ticks in %.1f s: %" PRId64 " frames shown, %" PRId64
            " repeated (cadence), %" PRId64 " late, %" PRId64 " dropped\n"
            "ringside movie: upload %s: %.3f ms copy + %.3f ms GL per frame (%" PRId64
            " staged a tick ahead); decode %.2f ms per frame\n",
            s->path, i->codec, i->pixfmt, i->w, i->h, mv_matrix_name(i->matrix), i->matrix_guessed ? " (guessed)" : "",
            i->full_range ? "full" : "limited", i->mono ? "none" : siting_name(i->chroma_loc), i->fps_num, i->fps_den,
            frames, st.ticks, ls->seconds, st.shown, st.repeats, st.late, st.dropped, mv_up_name(mv_player_upload(s->mp)),
            st.up.uploads ? st.up.copy_ms / (double)st.up.uploads : 0.0,
            st.up.uploads ? st.up.upload_ms / (double)st.up.uploads : 0.0, st.up.staged,
            st.decoded ? st.decode_ms / (double)st.decoded : 0.0);
    const mv_audio_info *ai = mv_player_audio_info(s->mp);
    char src[160];
    if (ai) {
        snprintf(src, sizeof src, "%s %d Hz %s %s", ai->codec, ai->rate, ai->layout, ai->format);
        fprintf(stderr,
                "ringside movie: sound: %s: %" PRId64 " ticks, %" PRId64 " late (silent), %" PRId64
                " damaged packets skipped; decode+resample %.4f ms CPU per tick\n",
                src, st.audio.reads, st.audio.late, st.audio.bad_packets,
                st.audio.reads ? st.audio.cpu_ms / (double)st.audio.reads : 0.0);
    } else if (!s->po.mute) {
        const char *why = mv_player_audio_why(s->mp);
        snprintf(src, sizeof src, "%s", why[0] ? "unplayable" : "none");
        fprintf(stderr, "ringside movie: sound: %s\n", why[0] ? why : "none (no audio stream)");
    } else {
        snprintf(src, sizeof src, "muted");
    }
    snd_summary("movie", s->out, src);
}

static const struct option opts[] = {
    {"dump", required_argument, 0, 'd'},    {"hashes", required_argument, 0, 'x'},
    {"headless", no_argument, 0, 'H'},      {"ticks", required_argument, 0, 't'},
    {"upload", required_argument, 0, 'u'},  {"matrix", required_argument, 0, 'm'},
    {"range", required_argument, 0, 'r'},   {"size", required_argument, 0, 'z'},
    {"fullscreen", no_argument, 0, 'f'},    {"loop", no_argument, 0, 'L'},
    {"help", no_argument, 0, 'h'},
    {"overwrite", no_argument, 0, 'y'},     {"no-overwrite", no_argument, 0, 'n'},
    {"mute", no_argument, 0, 'M'},          {"volume", required_argument, 0, 'V'},
    {"audio-out", required_argument, 0, 'A'}, {"audio-device", required_argument, 0, 'D'},
    {0}};

/* What the command line asks for, beyond what goes straight into mv_cmd. */
typedef struct movie_opts {
    bool quiet;
    const char *hashes;
    snd_opts snd;
    plat_desc pd;
} movie_opts;

/* --upload, --matrix, --range: how the pictures are decoded and uploaded. */
static bool picture_option(mv_cmd *s, int c, const char *arg)
{
    if (c == 'u') {
        if ((s->po.upload = mv_up_parse(arg)) >= 0)
            return true;
        cli_error("movie", "--upload '%s': expected pbo, direct or persistent", arg);
    } else if (c == 'm') {
        if (!strcmp(arg, "bt601") || !strcmp(arg, "601"))
            s->po.matrix = MV_OVERRIDE_601;
        else if (!strcmp(arg, "bt709") || !strcmp(arg, "709"))
            s->po.matrix = MV_OVERRIDE_709;
        else {
            cli_error("movie", "--matrix '%s': expected bt601 or bt709", arg);
            return false;
        }
        return true;
    } else {
        if (!strcmp(arg, "limited") || !strcmp(arg, "tv"))
            s->po.range = MV_OVERRIDE_LIMITED;
        else if (!strcmp(arg, "full") || !strcmp(arg, "pc"))
            s->po.range = MV_OVERRIDE_FULL;
        else {
            cli_error("movie", "--range '%s': expected limited or full", arg);
            return false;
        }
        return true;
    }
    return false;
}

/* One option; -1 to go on, else the exit status (--help: RS_EXIT_OK). */
static int movie_option(mv_cmd *s, movie_opts *o, int c, const char *arg, char **argv)
{
    long n;
    switch (c) {
    case 'd': s->dump = arg; s->headless = true; return -1;
    case 'x': o->hashes = arg; s->headless = true; return -1;
    case 'H': s->headless = true; return -1;
    case 't':
        if (!cli_int("--ticks", arg, 1, 1L << 40, &n))
            return RS_EXIT_USAGE;
        s->limit = n;
        return -1;
    case 'u': case 'm': case 'r': return picture_option(s, c, arg) ? -1 : RS_EXIT_USAGE;
    case 'z': return cli_size("--size", arg, 8192, &s->w, &s->h) ? -1 : RS_EXIT_USAGE;
    case 'f': o->pd.fullscreen = true; return -1;
    case 'L': s->loop = true; return -1;
    case 'y': s->overwrite = true; return -1;
    case 'n': s->overwrite = false; return -1;
    case 'M': o->snd.mute = true; return -1;
    case 'V': return snd_volume_arg("movie", arg, &o->snd) ? -1 : RS_EXIT_USAGE;
    case 'A': o->snd.wav = arg; return -1;
    case 'D': o->snd.device = arg; return -1;
    case 'h': help(); return RS_EXIT_OK;
    default: return cli_bad_option("movie", argv);
    }
}

/* The command line into s and o; -1 to go on, else the exit status. */
static int parse_options(int argc, char **argv, mv_cmd *s, movie_opts *o)
{
    *o = (movie_opts){.pd = {.title = "ringside movie"}};
    o->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    int c, status;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1)
        if ((status = movie_option(s, o, c, optarg, argv)) >= 0)
            return status;
    if (optind != argc - 1) {
        cli_error("movie", optind >= argc ? "no movie file given" : "unexpected argument '%s'",
                  optind < argc ? argv[optind + 1] : "");
        return cli_usage_error("movie");
    }
    s->path = argv[optind];
    s->po.wait = s->headless;
    return -1;
}

/* The outputs, the movie, the sound and the window or context; -1 to go
 * on, else the exit status (the error in s->err). */
static int movie_open(mv_cmd *s, movie_opts *o)
{
    struct stat dst;
    bool fatal;
    /* --dump DIR is created, as an output is, when the folder it is in exists */
    if (s->dump && stat(s->dump, &dst) != 0 && (!rs_out_check(s->dump, false, &s->err) || mkdir(s->dump, 0777) != 0)) {
        if (!s->err.msg[0])
            rs_fail(&s->err, JOB_ERR_CREATE, "%s: cannot create: %s", s->dump, strerror(errno));
        return RS_EXIT_FAIL;
    }
    if (o->hashes && !(s->hashes = cli_text_open("movie", o->hashes, s->overwrite)))
        return RS_EXIT_FAIL;
    /* A file we cannot play is reported as such, before any window opens. */
    mv_src *probe = mv_open(s->path, &s->err);
    if (!probe)
        return RS_EXIT_FAIL;
    mv_close(probe);
    /* a --audio-out that cannot be written stops us before anything plays */
    if (!(s->out = snd_open("movie", &o->snd, s->headless, s->overwrite, &fatal)) && fatal)
        return RS_EXIT_FAIL;
    s->po.mute = o->snd.mute || !s->out; /* nothing to play it on: do not decode it */
    o->pd.backend = s->headless ? NULL : "glfw";
    o->pd.width = s->w ? s->w : 1280;
    o->pd.height = s->h ? s->h : 720;
    if (!(s->p = plat_create(&o->pd, &s->err)))
        return cli_plat_status(&s->err);
    if (!(s->mp = mv_player_open(s->path, &s->po, &s->err)))
        return RS_EXIT_FAIL;
    if (!s->w) {
        const mv_info *i = mv_player_info(s->mp);
        s->w = (int)((double)i->w * i->sar_num / i->sar_den + 0.5);
        s->h = i->h;
        if (s->w < 1 || s->w > 16384)
            s->w = i->w;
    }
    if (s->headless) {
        if (!r_target_create(&s->target, s->w, s->h, &s->err))
            return RS_EXIT_FAIL;
        if (!(s->px = malloc((size_t)s->w * s->h * 3)))
            return rs_fail(&s->err, JOB_ERR_NOMEM, "out of memory for a %dx%d frame", s->w, s->h), RS_EXIT_FAIL;
    }
    return -1;
}

/* The movie played, then the sound and the hash list closed. */
static int movie_run(mv_cmd *s, const movie_opts *o)
{
    lp_game g = {s, on_input, on_step, on_render, on_running};
    lp_stats ls;
    lp_run(&(lp_desc){.headless = s->headless}, &g, &ls);
    if (!o->quiet && s->mp)
        summary(s, &ls);
    if (s->failed)
        return RS_EXIT_FAIL;
    bool aok = snd_close("movie", s->out, true);
    s->out = NULL;
    if (!aok)
        return RS_EXIT_FAIL;
    if (s->hashes) {
        bool hok = cli_text_close("movie", o->hashes, s->hashes);
        s->hashes = NULL;
        if (!hok)
            return RS_EXIT_FAIL;
    }
    return RS_EXIT_OK;
}

int cmd_movie(int argc, char **argv)
{
    mv_cmd *s = calloc(1, sizeof *s);
    if (!s)
        return RS_EXIT_FAIL;
    s->last_dumped = -1;
    movie_opts o;
    int status = parse_options(argc, argv, s, &o);
    if (status < 0)
        status = movie_open(s, &o);
    if (status < 0)
        status = movie_run(s, &o);
    if (status == RS_EXIT_FAIL && s->err.msg[0])
        cli_error("movie", "%s", s->err.msg);
    snd_close("movie", s->out, false);
    if (s->hashes && s->hashes != stdout)
        fclose(s->hashes);
    if (s->p) {
        mv_player_close(s->mp);
        r_target_destroy(&s->target);
        plat_destroy(s->p);
    }
    free(s->px);
    free(s);
    return status;
}
