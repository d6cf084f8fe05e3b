/* ringside attract: the cabinet's attract loop.
 *
 * Loops the movies and demo replays given (in command-line order) until a
 * player presses a button; then a match, that player against the CPU.
 * When the match is over, or nobody has touched the controls for --idle
 * seconds, back to the loop, with the item after the one interrupted.  A movie or replay that
 * cannot be opened or breaks mid-way is logged once and skipped from then
 * on; with nothing playable left the loop shows CPU-vs-CPU matches.  The
 * loop never stops on a bad file: only Escape (or --ticks) ends it.
 *
 * Everything runs on the 60 Hz loop (loop.c); movies decode on their own
 * thread (player/).  --headless with --script drives the same state
 * machine from a file of timed button presses, for tests.
 *
 * Sound: one mixer (runtime/audio) makes each tick's 800 frames after the
 * tick is stepped: a movie's soundtrack as the mixer's external input, a
 * demo's or a match's game sounds (au_game_cues) and stage music.  The
 * mixer is reset whenever an item or a match starts, so a demo sounds
 * exactly like `ringside replay sound` of its replay (delayed by the tick
 * that loads it) and a button press that starts a match cuts the movie's
 * sound at once.  The operator's --attract-sound off silences the loop
 * (movies and demos) but never a match being played. */
#include <ctype.h>
#include <stdarg.h>
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "../player/mv_player.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "snd_out.h"
#include "../runtime/game/g_ai.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/input.h"
#include "../runtime/loop.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_img.h"
#include "job_err.h"

static void help(void)
{
    printf("usage: ringside attract [MOVIE ...] [--demo REPLAY ...] [--idle SECONDS] [--fullscreen]\n"
           "                        [--size WxH] [--upload MODE] [--headless --script FILE --ticks N]\n"
           "                        [--screenshot FILE] [-q|-v] [--attract-sound on|off] [--mute]\n"
           "                        [--volume V] [--audio-out FILE.wav] [--audio-device NAME] [-y]\n\n"
           "The cabinet's attract loop: plays the movies and demo replays in the order given,\n"
           "over and over, until a player presses any button; then a match against the CPU.\n"
           "After the match, or after --idle seconds without input, back to the loop.  A file\n"
           "that cannot be played is logged once and skipped; with nothing playable the loop\n"
           "shows CPU-vs-CPU matches.  Escape quits.  Needs X for the window (xvfb-run -a).\n\n"
           "  MOVIE           Y4M, MP4, MKV, WebM ... (ringside movie --help)\n"
           "  --demo F        a replay, rendered live by the game (repeatable)\n"
           "  --idle S        seconds without input that end a match (default 30)\n"
           "  --fullscreen    primary monitor, its current mode\n"
           "  --size WxH      window or frame size (default 1280x720)\n"
           "  --upload MODE   movie upload path: pbo (default), direct or persistent\n"
           "  --headless      no window (EGL/OSMesa); needs --ticks; input from --script\n"
           "  --script F      timed input: lines 'TICK p1|p2 KEYS', KEYS '-' or names joined\n"
           "                  by '+': up down left right punch kick guard start\n"
           "  --ticks N       stop after N ticks\n"
           "  --screenshot F  save the last frame (.png or .ppm)\n"
           CLI_LOG_HELP
           "  --attract-sound on|off\n"
           "                  the operator's attract-sound setting: off silences the loop (movies'\n"
           "                  soundtracks, demos' game sound and music); a match always has sound\n"
           "                  (default on)\n"
           "  --mute          no sound at all (with --audio-out: a silent WAV)\n"
           "  --volume V      sound level, linear 0..1 (default 1; 0 is --mute)\n"
           "  --audio-out F   write the sound to F.wav (16-bit, 48 kHz stereo) instead of the device:\n"
           "                  800 frames per tick, headless or not\n"
           "  --audio-device N\n"
           "                  the OpenAL device (default: the system's); without one: one\n"
           "                  warning line, and the loop runs silent\n"
           "  -y, --overwrite replace an existing --audio-out file\n");
}

enum { ITEM_MOVIE, ITEM_DEMO };
enum { MODE_LOOP, MODE_MATCH };
enum { SOUND_NONE, SOUND_GAME, SOUND_MOVIE }; /* what the tick just stepped sounds like */

typedef struct item {
    int kind;
    const char *path;
    bool bad;
} item;

typedef struct ev {
    int64_t tick;
    int player;
    g_input keys;
} ev;

typedef struct attract {
    item *items;
    int nitems, cur;
    int mode;
    bool on; /* an item is playing */
    /* movie */
    mv_player *mp;
    mv_player_opts po;
    /* demo replay or match */
    rp_replay demo;
    bool demo_loaded, cpu_demo;
    uint64_t demo_tick;
    g_state prev, st;
    g_ai ai[2];
    int human;    /* MATCH: 0 or 1 */
    int32_t matches0;
    int64_t last_input;
    int64_t idle_ticks;
    /* input */
    g_input held[2], last[2];
    ev *script;
    size_t nscript, next_ev;
    /* output */
    plat *p;
    r_game *r;
    r_target target;
    int w, h;
    int prepared; /* stage the renderer holds, -1 none */
    int64_t tick, limit;
    bool quiet, quit, failed, headless;
    uint64_t seed;
    rs_err err;
    /* sound */
    snd_opts snd;
    bool attract_sound, overwrite;
    au_out *out;  /* NULL: silent */
    au_mixer *mix;
    int sound;    /* SOUND_*, set by this tick's step */
    float pcm[AU_TICK_FRAMES * 2], ext[AU_TICK_FRAMES * 2];
} attract;

static void logf_(attract *a, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void logf_(attract *a, const char *fmt, ...)
{
    if (a->quiet)
        return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "attract: tick %" PRId64 ": ", a->tick);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* --- the script --- */

static bool parse_keys(const char *s, g_input *out)
{
    static const struct { const char *name; g_input bit; } names[] = {
        {"up", G_IN_UP}, {"down", G_IN_DOWN}, {"left", G_IN_LEFT}, {"right", G_IN_RIGHT},
        {"punch", G_IN_PUNCH}, {"kick", G_IN_KICK}, {"guard", G_IN_GUARD}, {"start", G_IN_START}};
    *out = 0;
    if (!strcmp(s, "-"))
        return true;
    while (*s) {
        size_t n = strcspn(s, "+");
        bool found = false;
        for (size_t k = 0; k < sizeof names / sizeof names[0]; k++)
            if (strlen(names[k].name) == n && !strncmp(s, names[k].name, n)) {
                *out |= names[k].bit;
                found = true;
            }
        if (!found || n == 0)
            return false;
        s += n;
        if (*s == '+')
            s++;
    }
    return true;
}

static bool load_script(attract *a, const char *path)
{
    FILE *f = fopen(path, "r");
    if (!f)
        return rs_fail(&a->err, JOB_ERR_SCRIPT, "%s: %s", path, strerror(errno));
    char line[256];
    int ln = 0;
    int64_t prev = 0;
    size_t cap = 0;
    while (fgets(line, sizeof line, f)) {
        ln++;
        char *hash = strchr(line, '#');
        if (hash)
            *hash = 0;
        char who[16], keys[128];
        long long t;
        char extra;
        int n = sscanf(line, "%lld %15s %127s %c", &t, who, keys, &extra);
        if (n <= 0) {
            bool blank = true;
            for (char *c = line; *c; c++)
                blank &= isspace((unsigned char)*c) != 0;
            if (blank)
                continue;
        }
        ev e = {0};
        if (n != 3 || t < 0 || t < prev || (strcmp(who, "p1") && strcmp(who, "p2")) || !parse_keys(keys, &e.keys)) {
            fclose(f);
            return rs_fail(&a->err, JOB_ERR_SCRIPT,
                           "%s:%d: expected 'TICK p1|p2 KEYS' with TICK >= %" PRId64
                           " and KEYS '-' or up+down+left+right+punch+kick+guard+start",
                           path, ln, prev);
        }
        e.tick = prev = t;
        e.player = who[1] - '1';
        if (a->nscript == cap) {
            cap = cap ? cap * 2 : 16;
            ev *g = realloc(a->script, cap * sizeof *g);
            if (!g) {
                fclose(f);
                return rs_fail(&a->err, JOB_ERR_NOMEM, "%s: out of memory", path);
            }
            a->script = g;
        }
        a->script[a->nscript++] = e;
    }
    fclose(f);
    return true;
}

/* --- items --- */

static void stop_item(attract *a)
{
    mv_player_close(a->mp);
    a->mp = NULL;
    if (a->demo_loaded)
        rp_free(&a->demo);
    a->demo_loaded = false;
    a->cpu_demo = false;
    a->on = false;
    if (a->mix) { /* whatever was sounding stops with its item */
        au_mixer_reset(a->mix);
        au_mixer_music(a->mix, -1); /* a game's steps set it again */
    }
}

static bool prepare_stage(attract *a, int stage)
{
    if (a->prepared == stage)
        return true;
    if (!r_game_prepare(a->r, stage, &a->err))
        return false;
    a->prepared = stage;
    return true;
}

/* Starts the next playable item after a->cur; false when none is left. */
static bool start_next(attract *a)
{
    for (int tries = 0; tries < a->nitems; tries++) {
        a->cur = (a->cur + 1) % a->nitems;
        item *it = &a->items[a->cur];
        if (it->bad)
            continue;
        rs_err e = {0};
        if (it->kind == ITEM_MOVIE) {
            a->mp = mv_player_open(it->path, &a->po, &e);
            if (a->mp) {
                const mv_info *i = mv_player_info(a->mp);
                logf_(a, "movie %s (%s %dx%d, %d/%d fps)", it->path, i->codec, i->w, i->h, i->fps_num, i->fps_den);
                if (mv_player_audio_why(a->mp)[0])
                    logf_(a, "%s: playing it silent", mv_player_audio_why(a->mp));
                a->on = true;
                return true;
            }
        } else if (rp_read(it->path, &a->demo, &e)) {
            a->demo_loaded = true;
            if (prepare_stage(a, a->demo.stage)) {
                g_init(&a->st, a->demo.stage, a->demo.seed);
                a->prev = a->st;
                a->demo_tick = 0;
                logf_(a, "demo %s (%s, %" PRIu64 " ticks)", it->path, g_stages[a->demo.stage].name, a->demo.ticks);
                a->on = true;
                return true;
            }
            e = a->err;
            rp_free(&a->demo);
            a->demo_loaded = false;
        }
        logf_(a, "skipping %s from now on: %s", it->path, e.msg);
        it->bad = true;
    }
    return false;
}

static bool start_cpu_demo(attract *a)
{
    int stage = (int)(a->seed % G_STAGES);
    if (!prepare_stage(a, stage))
        return false;
    g_init(&a->st, stage, a->seed);
    a->prev = a->st;
    g_ai_init(&a->ai[0], 0, 2, a->seed);
    g_ai_init(&a->ai[1], 1, 2, a->seed + 1);
    a->matches0 = a->st.matches;
    a->cpu_demo = true;
    a->on = true;
    a->seed = a->seed * 6364136223846793005ull + 1442695040888963407ull;
    logf_(a, "nothing playable: a CPU-vs-CPU match on %s", g_stages[stage].name);
    return true;
}

static bool loop_next(attract *a)
{
    stop_item(a);
    if (a->nitems && start_next(a))
        return true;
    return start_cpu_demo(a);
}

static bool start_match(attract *a, int human)
{
    stop_item(a);
    int stage = (int)(a->seed % G_STAGES);
    if (!prepare_stage(a, stage))
        return false;
    a->mode = MODE_MATCH;
    a->human = human;
    g_init(&a->st, stage, a->seed);
    a->prev = a->st;
    g_ai_init(&a->ai[1 - human], 1 - human, 2, a->seed + 7);
    a->matches0 = a->st.matches;
    a->last_input = a->tick;
    a->seed = a->seed * 6364136223846793005ull + 1442695040888963407ull;
    logf_(a, "player %d pressed a button: match on %s, player %d against the CPU", human + 1, g_stages[stage].name,
          human + 1);
    return true;
}

static void back_to_loop(attract *a, const char *why)
{
    logf_(a, "%s: back to the attract loop", why);
    a->mode = MODE_LOOP;
    if (!loop_next(a))
        a->failed = true;
}

/* --- sound --- */

static bool audible(const attract *a)
{
    return a->out && !a->snd.mute && (a->mode == MODE_MATCH || a->attract_sound);
}

/* One tick of the game, its sounds cued. */
static void game_step(attract *a, const g_input in[2])
{
    g_events events;
    a->prev = a->st;
    g_step(&a->st, in, &events);
    if (!audible(a))
        return;
    au_cue cues[AU_MAX_CUES];
    int n = au_game_cues(&a->prev, &a->st, &events, cues, AU_MAX_CUES);
    for (int i = 0; i < n; i++)
        au_mixer_cue(a->mix, &cues[i]);
    au_mixer_music(a->mix, a->st.stage);
    a->sound = SOUND_GAME;
}

/* The tick's audio, after its step: silence on a tick that started
 * something (nothing was stepped yet) or when the loop is silenced. */
static void emit_sound(attract *a)
{
    if (!a->out)
        return;
    int what = audible(a) ? a->sound : SOUND_NONE;
    a->sound = SOUND_NONE;
    if (what == SOUND_NONE) {
        memset(a->pcm, 0, sizeof a->pcm);
    } else if (what == SOUND_MOVIE) {
        mv_player_audio(a->mp, a->ext, AU_TICK_FRAMES);
        au_mixer_mix(a->mix, a->pcm, AU_TICK_FRAMES, a->ext, 1.0f);
    } else {
        au_mixer_mix(a->mix, a->pcm, AU_TICK_FRAMES, NULL, 0);
    }
    if (!au_out_write(a->out, a->pcm, AU_TICK_FRAMES, &a->err))
        a->failed = true;
}

/* --- the loop's callbacks --- */

static void on_input(void *user, g_input in[2])
{
    attract *a = user;
    if (a->headless) {
        while (a->next_ev < a->nscript && a->script[a->next_ev].tick <= a->tick) {
            const ev *e = &a->script[a->next_ev++];
            a->held[e->player] = e->keys;
        }
        in[0] = a->held[0];
        in[1] = a->held[1];
    } else {
        in[0] = in_read(plat_window(a->p), 0);
        in[1] = in_read(plat_window(a->p), 1);
    }
}

/* Plays the loop item's tick.  False when it is over or broken: it is
 * stopped, and the caller starts the next. */
static bool play_item(attract *a)
{
    if (a->mp) {
        rs_err e = {0};
        int r = mv_player_tick(a->mp, &e);
        if (r == 1) {
            a->sound = SOUND_MOVIE;
            return true;
        }
        if (r < 0) {
            logf_(a, "skipping %s from now on: %s", a->items[a->cur].path, e.msg);
            a->items[a->cur].bad = true;
        } else if (mv_player_frame(a->mp) < 0) {
            logf_(a, "skipping %s from now on: it has no frames", a->items[a->cur].path);
            a->items[a->cur].bad = true;
        }
        stop_item(a);
        return false;
    }
    if (a->cpu_demo) {
        g_input ai[2] = {g_ai_input(&a->ai[0], &a->st), g_ai_input(&a->ai[1], &a->st)};
        game_step(a, ai);
        if (a->st.matches > a->matches0 && a->st.phase != G_PHASE_MATCH_END)
            a->on = false; /* its last picture and sound stay this tick; the next item starts on the next */
        return true;
    }
    if (a->demo_tick >= a->demo.ticks) {
        stop_item(a);
        return false;
    }
    game_step(a, &a->demo.inputs[2 * a->demo_tick]);
    a->demo_tick++;
    return true;
}

static void on_step(void *user, const g_input in[2])
{
    attract *a = user;
    bool pressed[2];
    for (int k = 0; k < 2; k++) {
        pressed[k] = in[k] && !a->last[k]; /* a new press, not a held button */
        a->last[k] = in[k];
    }
    if (a->mode == MODE_LOOP) {
        if (pressed[0] || pressed[1]) {
            if (!start_match(a, pressed[0] ? 0 : 1))
                a->failed = true;
        } else {
            /* an item that ends hands its tick to the next one: no dead
             * tick (a black frame, a gap in the sound) between items */
            for (int k = 0; k <= a->nitems + 1 && !a->failed; k++) {
                if (!a->on && !loop_next(a))
                    a->failed = true;
                else if (play_item(a))
                    break;
            }
        }
    } else {
        int h = a->human;
        g_input gi[2];
        gi[h] = in[h];
        gi[1 - h] = g_ai_input(&a->ai[1 - h], &a->st);
        if (in[0] || in[1])
            a->last_input = a->tick;
        game_step(a, gi);
        if (a->st.matches > a->matches0 && a->st.phase != G_PHASE_MATCH_END) {
            char why[64];
            snprintf(why, sizeof why, "match over (winner: %s)",
                     a->st.match_winner == 0 ? "draw" : a->st.match_winner == h + 1 ? "the player" : "the CPU");
            back_to_loop(a, why);
        } else if (a->tick - a->last_input >= a->idle_ticks) {
            char why[64];
            snprintf(why, sizeof why, "no input for %" PRId64 " s", a->idle_ticks / G_HZ);
            back_to_loop(a, why);
        }
    }
    emit_sound(a);
    a->tick++;
}

static void draw(attract *a, float alpha, int w, int h)
{
    if (w <= 0 || h <= 0) /* a minimised window: nothing to draw */
        return;
    if (a->mode == MODE_LOOP && a->mp) {
        mv_player_draw(a->mp, w, h);
    } else if (a->mode == MODE_MATCH || a->demo_loaded || a->cpu_demo) {
        if (!r_game_draw(a->r, &a->prev, &a->st, alpha, w, h, &a->err))
            a->failed = true;
    } else {
        gl.Viewport(0, 0, w, h);
        gl.ClearColor(0, 0, 0, 1);
        gl.Clear(GL_COLOR_BUFFER_BIT);
    }
}

static void on_render(void *user, float alpha)
{
    attract *a = user;
    int w = a->w, h = a->h;
    if (plat_window(a->p))
        plat_size(a->p, &w, &h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, a->target.fbo);
    if (w > 0 && h > 0)
        draw(a, alpha, w, h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    plat_present(a->p);
}

static bool on_running(void *user)
{
    attract *a = user;
    if (a->failed || a->quit)
        return false;
    if (plat_window(a->p) && (!plat_poll(a->p) || in_quit(plat_window(a->p)))) {
        a->quit = true;
        return false;
    }
    return !a->limit || a->tick < a->limit;
}

static bool screenshot(attract *a, const char *path)
{
    int w = a->w, h = a->h;
    if (plat_window(a->p))
        plat_size(a->p, &w, &h);
    uint8_t *px = malloc((size_t)w * h * 3);
    if (!px)
        return rs_fail(&a->err, JOB_ERR_NOMEM, "out of memory for a %dx%d screenshot", w, h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, a->target.fbo);
    draw(a, 1.0f, w, h);
    r_read_pixels(a->target.fbo, w, h, 3, px);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    bool ok = rs_mkdirs_for(path, &a->err) && rs_image_write(path, w, h, 3, px, &a->err);
    free(px);
    return ok;
}

int cmd_attract(int argc, char **argv)
{
    static const struct option opts[] = {
        {"demo", required_argument, 0, 'd'},   {"idle", required_argument, 0, 'i'},
        {"fullscreen", no_argument, 0, 'f'},   {"size", required_argument, 0, 'z'},
        {"upload", required_argument, 0, 'u'}, {"headless", no_argument, 0, 'H'},
        {"script", required_argument, 0, 's'}, {"ticks", required_argument, 0, 'n'},
        {"screenshot", required_argument, 0, 'o'}, {"help", no_argument, 0, 'h'},         {"attract-sound", required_argument, 0, 'S'},
        {"mute", no_argument, 0, 'M'},         {"volume", required_argument, 0, 'V'},
        {"audio-out", required_argument, 0, 'A'}, {"audio-device", required_argument, 0, 'D'},
        {"overwrite", no_argument, 0, 'y'},    {0}};
    attract *a = calloc(1, sizeof *a);
    item *items = calloc((size_t)argc + 1, sizeof *items);
    if (!a || !items) {
        free(a);
        free(items);
        return RS_EXIT_FAIL;
    }
    a->items = items;
    a->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    a->cur = -1;
    a->prepared = -1;
    a->w = 1280;
    a->h = 720;
    a->idle_ticks = 30 * G_HZ;
    a->seed = (uint64_t)time(NULL);
    a->attract_sound = true;
    int c, status = RS_EXIT_USAGE;
    long n;
    const char *script = NULL, *shot = NULL;
    plat_desc pd = {.title = "ringside"};
    optind = 1;
    opterr = 0;
    /* "-" first: movies and --demo keep their command-line order */
    while ((c = getopt_long(argc, argv, "-hy", opts, NULL)) != -1) {
        switch (c) {
        case 1: items[a->nitems++] = (item){ITEM_MOVIE, optarg, false}; break;
        case 'd': items[a->nitems++] = (item){ITEM_DEMO, optarg, false}; break;
        case 'i':
            if (!cli_int("--idle", optarg, 1, 24 * 3600, &n))
                goto done;
            a->idle_ticks = n * G_HZ;
            break;
        case 'f': pd.fullscreen = true; break;
        case 'z': if (!cli_size("--size", optarg, 8192, &a->w, &a->h)) goto done; break;
        case 'u':
            if ((a->po.upload = mv_up_parse(optarg)) < 0) {
                cli_error("attract", "--upload '%s': expected pbo, direct or persistent", optarg);
                goto done;
            }
            break;
        case 'H': a->headless = true; break;
        case 's': script = optarg; break;
        case 'n':
            if (!cli_int("--ticks", optarg, 1, 1L << 40, &n))
                goto done;
            a->limit = n;
            break;
        case 'o': shot = optarg; break;
        case 'S':
            if (strcmp(optarg, "on") && strcmp(optarg, "off")) {
                cli_error("attract", "--attract-sound '%s': expected on or off", optarg);
                goto done;
            }
            a->attract_sound = !strcmp(optarg, "on");
            break;
        case 'M': a->snd.mute = true; break;
        case 'V': if (!snd_volume_arg("attract", optarg, &a->snd)) goto done; break;
        case 'A': a->snd.wav = optarg; break;
        case 'D': a->snd.device = optarg; break;
        case 'y': a->overwrite = true; break;
        case 'h': help(); status = RS_EXIT_OK; goto done;
        default:
            status = cli_bad_option("attract", argv);
            goto done;
        }
    }
    if (a->headless && !a->limit) {
        cli_error("attract", "--headless needs --ticks N (nobody can press Escape in a headless loop)");
        goto done;
    }
    if (script && !a->headless) {
        cli_error("attract", "--script drives the headless loop: add --headless --ticks N");
        goto done;
    }
    if (shot) {
        const char *dot = strrchr(shot, '.');
        if (!dot || (strcmp(dot, ".png") && strcmp(dot, ".ppm"))) {
            cli_error("attract", "%s: unknown image extension (expected .png or .ppm)", shot);
            goto done;
        }
    }
    status = RS_EXIT_FAIL;
    if (script && !load_script(a, script))
        goto done;
    if (a->headless)
        a->seed = 1; /* the same run every time */
    a->po.wait = a->headless;
    bool fatal;
    if (!(a->out = snd_open("attract", &a->snd, a->headless, a->overwrite, &fatal)) && fatal)
        goto done;
    if (a->out && !(a->mix = au_mixer_new(NULL, &a->err)))
        goto done;
    a->po.mute = !a->out || a->snd.mute || !a->attract_sound; /* movies play only in the loop */
    pd.backend = a->headless ? NULL : "glfw";
    pd.width = a->w;
    pd.height = a->h;
    if (!(a->p = plat_create(&pd, &a->err))) {
        status = cli_plat_status(&a->err);
        goto done;
    }
    if (!(a->r = r_game_create_opts(&(r_game_opts){.quiet = true}, &a->err)))
        goto done;
    if (a->headless && !r_target_create(&a->target, a->w, a->h, &a->err))
        goto done;
    if (!a->nitems)
        logf_(a, "no movies or demos given");
    lp_game g = {a, on_input, on_step, on_render, on_running};
    lp_stats ls;
    lp_run(&(lp_desc){.headless = a->headless}, &g, &ls);
    if (a->failed)
        goto done;
    if (shot && !screenshot(a, shot))
        goto done;
    logf_(a, "stopped (%s) after %.1f s", a->quit ? "quit" : "--ticks", ls.seconds);
    if (!a->quiet)
        snd_summary("attract", a->out, a->snd.mute ? "muted" : a->attract_sound ? "mixer" : "mixer (attract sound off)");
    bool aok = snd_close("attract", a->out, true);
    a->out = NULL;
    if (!aok)
        goto done;
    status = RS_EXIT_OK;
done:
    if (status == RS_EXIT_FAIL && a->err.msg[0])
        cli_error("attract", "%s", a->err.msg);
    stop_item(a);
    snd_close("attract", a->out, false);
    au_mixer_free(a->mix);
    if (a->p) {
        r_target_destroy(&a->target);
        r_game_destroy(a->r);
        plat_destroy(a->p);
    }
    free(a->script);
    free(items);
    free(a);
    return status;
}
