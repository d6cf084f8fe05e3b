/* ringside replay info|verify|sound|events: look into a replay,
 * re-simulate it and check every checkpoint, write its soundtrack, or list
 * the sounds each tick starts.  No GL. */
#include <getopt.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "job_poster.h"
#include "../runtime/audio/au.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_progress.h"

static void help(void)
{
    printf("usage: ringside replay info FILE\n"
           "       ringside replay verify FILE [--hashes OUT] [-y|-n] [--progress tty|plain|off] [-q|-v]\n"
           "       ringside replay sound FILE -o OUT.wav [--ticks A:B] [--loudness LUFS|off] [--float] [-y|-n]\n"
           "       ringside replay events FILE [--ticks A:B]\n\n"
           "info    prints the header: stage, seed, duration, players, winner, sizes.\n"
           "verify  re-simulates every tick from the recorded inputs (no GL) and checks\n"
           "        every state-hash checkpoint and the final hash.  On a mismatch it\n"
           "        prints the first checkpoint tick that differs and exits 1; a replay\n"
           "        recorded by another version of the game is refused before that.\n"
           "sound   writes the replay's soundtrack as a WAV (48 kHz stereo), the same\n"
           "        samples a render puts in its video: the whole match is mixed and\n"
           "        brought to the loudness target, then ticks A..B-1 are cut out.\n"
           "events  prints one line per sound a tick starts: \"TICK SOUND PAN GAIN\",\n"
           "        then the game's events of that tick in brackets.\n\n"
           "  --hashes OUT  also write \"tick hash\" for every tick to OUT ('-' for stdout)\n"
           "  -y, -n        replace an existing OUT, or refuse it, naming it (the default)\n"
           "  --progress M  tty (a line redrawn in place), plain (a line every 5 s and the\n"
           "                last, for logs) or off; default tty on a terminal, else plain\n"
           CLI_LOG_HELP
           "  -o OUT.wav    the WAV to write ('-' for stdout)\n"
           "  --ticks A:B   only ticks A to B-1 (default: the whole replay)\n"
           "  --loudness L  integrated loudness target in LUFS, -70..0 (default -16; true\n"
           "                peak at most -1 dBTP), or off: the mixer's level as it is\n"
           "  --float       32-bit float samples (default 16-bit PCM)\n\n"
           "examples:\n"
           "  ringside replay verify demos/dojo.rsr\n"
           "                re-simulate the match and check every state hash\n"
           "  ringside replay sound demos/dojo.rsr -o dojo.wav\n"
           "                the soundtrack a render puts in the video, at -16 LUFS\n");
}

static void duration(uint64_t ticks, char *buf, size_t n)
{
    uint64_t cs = ticks * 100 / G_HZ;
    snprintf(buf, n, "%" PRIu64 ":%02" PRIu64 ".%02" PRIu64, cs / 6000, cs / 100 % 60, cs % 100);
}

static void winner_text(int winner, const int rounds[2], char *buf, size_t n)
{
    if (winner > 0)
        snprintf(buf, n, "P%d, rounds %d-%d", winner, rounds[0], rounds[1]);
    else if (winner == 0)
        snprintf(buf, n, "draw, rounds %d-%d", rounds[0], rounds[1]);
    else
        snprintf(buf, n, "none (match unfinished, rounds %d-%d)", rounds[0], rounds[1]);
}

static int info(const char *path)
{
    rp_replay rp;
    rs_err err = {0};
    if (!rp_read(path, &rp, &err)) {
        cli_error("replay", "%s", err.msg);
        return RS_EXIT_FAIL;
    }
    struct stat sb;
    long long n = stat(path, &sb) == 0 ? (long long)sb.st_size : -1;
    char dur[32], win[64];
    duration(rp.ticks, dur, sizeof dur);
    winner_text(rp.winner, rp.rounds, win, sizeof win);
    printf("file         %s (%lld bytes, inputs %zu bytes)\n", path, n, rp.input_bytes);
    printf("format       version %d\n", rp.version);
    if (rp.game_version)
        printf("game         version %lu (this build: %d%s)\n", (unsigned long)rp.game_version, G_GAME_VERSION,
               rp.game_version == G_GAME_VERSION ? "" : "; verify refuses it");
    else
        printf("game         none recorded (format 1: taken as this build's, %d)\n", G_GAME_VERSION);
    printf("stage        %d (%s)\n", rp.stage, g_stages[rp.stage].name);
    printf("seed         %" PRIu64 "\n", rp.seed);
    printf("duration     %" PRIu64 " ticks, %s\n", rp.ticks, dur);
    printf("players      P1 %s, P2 %s\n", rp.kind[0] ? "cpu" : "human", rp.kind[1] ? "cpu" : "human");
    printf("winner       %s\n", win);
    uint64_t active[2] = {0, 0};
    for (uint64_t t = 0; t < rp.ticks; t++)
        for (int i = 0; i < 2; i++)
            active[i] += rp.inputs[2 * t + (uint64_t)i] != 0;
    printf("input ticks  P1 %" PRIu64 ", P2 %" PRIu64 " (ticks with a button or direction held)\n", active[0], active[1]);
    printf("checkpoints  %zu, every %d ticks\n", rp.ncheck, rp.interval);
    printf("final hash   %016" PRIx64 "\n", rp.final_hash);
    if (rp.ticks > 0) { /* the frame render --poster writes (simulates the match: about 1 ms a minute of it) */
        int why;
        uint64_t t = job_poster_tick(&rp, &why);
        printf("poster       frame %" PRIu64 " (%s)\n", t, job_poster_why_name(why));
    }
    rp_free(&rp);
    return RS_EXIT_OK;
}

static void on_progress(uint64_t done, uint64_t total, void *user)
{
    (void)total;
    rs_progress_update(user, done);
}

static int verify(const char *path, const char *hashes_path, bool overwrite, rs_progress_mode pmode)
{
    rp_replay rp;
    rs_err err = {0};
    if (!rp_read(path, &rp, &err)) {
        cli_error("replay", "%s", err.msg);
        return RS_EXIT_FAIL;
    }
    FILE *hf = NULL;
    if (hashes_path) {
        hf = cli_text_open("replay", hashes_path, overwrite);
        if (!hf) {
            rp_free(&rp);
            return RS_EXIT_FAIL;
        }
    }
    rs_progress prog;
    rs_progress_start(&prog, "verify", "ticks", rp.ticks, pmode);
    rp_verify_result res;
    bool ran = rp_verify(&rp, hf, on_progress, &prog, &res, &err);
    if (ran)
        rs_progress_update(&prog, rp.ticks); /* rp_verify reports now and then; the last line says all */
    double secs = rs_progress_end(&prog);
    if (hf && cli_fclose(hf) != 0 && ran)
        ran = rs_fail(&err, RP_ERR_WRITE, "%s: write failed", hashes_path);
    int status = RS_EXIT_FAIL;
    if (!ran) {
        cli_error("replay", "%s: %s", path, err.msg);
    } else if (res.header_mismatch) {
        if (rs_log_on(RS_LOG_ERROR))
            fprintf(stderr,
                "ringside replay: %s: the header says winner %d, rounds %d-%d, but the simulation gives winner %d, "
                "rounds %d-%d (byte 32; the inputs themselves verify)\n",
                path, rp.winner, rp.rounds[0], rp.rounds[1], res.winner, res.rounds[0], res.rounds[1]);
    } else if (!res.ok) {
        char what[400];
        rp_desync_text(&res, what, sizeof what);
        cli_error("replay", "%s: %s", path, what);
    } else {
        char win[64];
        winner_text(res.winner, res.rounds, win, sizeof win);
        cli_info("replay", "%s: ok: %" PRIu64 " ticks, %zu checkpoints and the final hash match; winner %s (%.0f ticks/s)",
                 path, rp.ticks, rp.ncheck, win, secs > 0 ? rp.ticks / secs : 0.0);
        status = RS_EXIT_OK;
    }
    rp_free(&rp);
    return status;
}

/* "A:B" into first, end (end > first); prints a usage error. */
static bool ticks_arg(const char *arg, uint64_t *first, uint64_t *end)
{
    const char *colon = strchr(arg, ':');
    char a[32];
    long f, e;
    if (!colon || (size_t)(colon - arg) >= sizeof a) {
        cli_error("replay", "--ticks '%s': expected A:B, such as 600:660", arg);
        return false;
    }
    memcpy(a, arg, (size_t)(colon - arg));
    a[colon - arg] = 0;
    if (!cli_int("--ticks start", a, 0, 100000000, &f) || !cli_int("--ticks end", colon + 1, 1, 100000000, &e))
        return false;
    if (e <= f) {
        cli_error("replay", "--ticks '%s': the end must be after the start", arg);
        return false;
    }
    *first = (uint64_t)f;
    *end = (uint64_t)e;
    return true;
}

static bool read_for_sound(const char *path, uint64_t end, rp_replay *rp)
{
    rs_err err = {0};
    if (!rp_read(path, rp, &err)) {
        cli_error("replay", "%s", err.msg);
        return false;
    }
    if (end > rp->ticks) {
        cli_error("replay", "%s: --ticks ends at %" PRIu64 ", past the replay's end (%" PRIu64 " ticks)", path, end,
                  rp->ticks);
        rp_free(rp);
        return false;
    }
    return true;
}

static int sound(const char *path, const char *out, uint64_t first, uint64_t end, double lufs, bool float32,
                 bool overwrite)
{
    if (!cli_out_ok("replay", out, overwrite))
        return RS_EXIT_FAIL;
    rp_replay rp;
    if (!read_for_sound(path, end, &rp))
        return RS_EXIT_FAIL;
    rs_err err = {0};
    au_replay_opts o = {.target_lufs = lufs, .before_peak = true}; /* its message reports it */
    int status = RS_EXIT_FAIL;
    /* streamed: the match mixed again as the WAV is written, never held whole */
    au_replay_stream *st = au_replay_open(&rp, path, first, end, &o, &err);
    au_wav *w = st ? au_wav_open_known(out, float32, au_replay_info(st)->frames, &err) : NULL;
    enum { PIECE = AU_TICK_FRAMES * 60 };
    float *buf = w ? malloc(PIECE * 2 * sizeof *buf) : NULL;
    bool ok = buf != NULL;
    if (w && !buf)
        rs_fail(&err, AU_ERR_NOMEM, "%s: out of memory", out);
    const au_track_info *t = st ? au_replay_info(st) : NULL;
    for (size_t at = 0; ok && at < t->frames;) {
        size_t n = t->frames - at < PIECE ? t->frames - at : PIECE;
        ok = au_replay_read(st, buf, n, &err) && au_wav_append(w, buf, n, &err);
        at += n;
    }
    if (w)
        ok = au_wav_close(w, ok, ok ? &err : &(rs_err){0}) && ok;
    if (!ok) {
        cli_error("replay", "%s", err.msg);
    } else {
        if (rs_log_on(RS_LOG_INFO)) {
            if (isnan(lufs))
                fprintf(stderr, "ringside replay: %s: ticks %" PRIu64 ":%" PRIu64 ", %zu frames, not normalized\n", out,
                        t->first, t->end, t->frames);
            else
                fprintf(stderr,
                        "ringside replay: %s: ticks %" PRIu64 ":%" PRIu64 ", %zu frames; match %.1f LUFS %.1f dBTP -> "
                        "%.1f LUFS %.1f dBTP (gain %+.1f dB)\n",
                        out, t->first, t->end, t->frames, t->lufs_before, t->peak_before, t->lufs_after, t->peak_after,
                        t->gain_db);
        }
        status = RS_EXIT_OK;
    }
    free(buf);
    au_replay_close(st);
    rp_free(&rp);
    return status;
}

static int events(const char *path, uint64_t first, uint64_t end)
{
    rp_replay rp;
    if (!read_for_sound(path, end, &rp))
        return RS_EXIT_FAIL;
    if (!end)
        end = rp.ticks;
    g_state st, prev;
    g_init(&st, rp.stage, rp.seed);
    size_t next = 0;
    rs_err err = {0};
    int status = RS_EXIT_OK;
    for (uint64_t k = 0; k < end; k++) {
        g_events ev;
        prev = st;
        g_step(&st, &rp.inputs[2 * k], &ev);
        if (!rp_check_tick(&rp, &st, k + 1, &next, path, &err)) {
            cli_error("replay", "%s", err.msg);
            status = RS_EXIT_FAIL;
            break;
        }
        if (k < first)
            continue;
        au_cue c[AU_MAX_CUES];
        int n = au_game_cues(&prev, &st, &ev, c, AU_MAX_CUES);
        char names[256] = "";
        size_t at = 0;
        for (int i = 0; i < ev.n && at < sizeof names; i++)
            at += (size_t)snprintf(names + at, sizeof names - at, "%s%s", i ? " " : "", g_event_name(ev.ev[i].type));
        for (int i = 0; i < n; i++)
            printf("%" PRIu64 " %s %+.2f %.2f%s%s%s\n", k, au_bank_get(c[i].sound)->name, c[i].pan, c[i].gain,
                   ev.n ? " [" : "", names, ev.n ? "]" : "");
    }
    if (fflush(stdout) != 0)
        status = RS_EXIT_FAIL;
    rp_free(&rp);
    return status;
}

int cmd_replay(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        help();
        return argc < 2 ? RS_EXIT_USAGE : RS_EXIT_OK;
    }
    const char *sub = argv[1];
    if (strcmp(sub, "info") && strcmp(sub, "verify") && strcmp(sub, "sound") && strcmp(sub, "events")) {
        cli_error("replay", "unknown subcommand '%s' (expected info, verify, sound or events)", sub);
        return RS_EXIT_USAGE;
    }
    static const struct option opts[] = {
        {"hashes", required_argument, 0, 'H'}, {"help", no_argument, 0, 'h'},
        {"overwrite", no_argument, 0, 'y'},   {"no-overwrite", no_argument, 0, 'n'},
        {"progress", required_argument, 0, 'g'}, {"output", required_argument, 0, 'o'},
        {"ticks", required_argument, 0, 'K'},     {"loudness", required_argument, 0, 'L'},
        {"float", no_argument, 0, 'F'},          {0}};
    const char *hashes = NULL;
    const char *out = NULL;
    bool quiet = !rs_log_on(RS_LOG_INFO), overwrite = false, float32 = false, any_sound_opt = false;
    uint64_t first = 0, end = 0;
    double lufs = 0;
    int progress = RS_PROGRESS_AUTO;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc - 1, argv + 1, "qhyno:", opts, NULL)) != -1) {
        switch (c) {
        case 'H': hashes = optarg; break;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'g': if (!cli_progress_mode("replay", optarg, &progress)) return RS_EXIT_USAGE; break;
        case 'h': help(); return RS_EXIT_OK;
        case 'o': out = optarg; any_sound_opt = true; break;
        case 'K': if (!ticks_arg(optarg, &first, &end)) return RS_EXIT_USAGE; break;
        case 'L': {
            char *e;
            lufs = strcmp(optarg, "off") ? strtod(optarg, &e) : NAN;
            if (!isnan(lufs) && (*e || e == optarg || !(lufs >= -70 && lufs <= 0))) {
                cli_error("replay", "--loudness '%s': expected LUFS from -70 to 0, or off", optarg);
                return RS_EXIT_USAGE;
            }
            any_sound_opt = true;
            break;
        }
        case 'F': float32 = any_sound_opt = true; break;
        default: return cli_bad_option("replay", argv + 1);
        }
    }
    if (optind + 1 != argc - 1) {
        cli_error("replay", "%s needs exactly one FILE", sub);
        return cli_usage_error("replay");
    }
    const char *file = argv[optind + 1];
    bool is_sound = !strcmp(sub, "sound"), is_events = !strcmp(sub, "events");
    if (!is_sound && (any_sound_opt || (end && !is_events))) {
        cli_error("replay", "-o, --ticks, --loudness and --float belong to 'replay sound' (--ticks also to 'replay events')");
        return RS_EXIT_USAGE;
    }
    if ((is_sound || is_events) && hashes) {
        cli_error("replay", "--hashes belongs to 'replay verify'");
        return RS_EXIT_USAGE;
    }
    if (is_sound) {
        if (!out) {
            cli_error("replay", "sound needs -o OUT.wav");
            return cli_usage_error("replay");
        }
        return sound(file, out, first, end, lufs, float32, overwrite);
    }
    if (is_events)
        return events(file, first, end);
    if (!strcmp(sub, "info")) {
        if (hashes) {
            cli_error("replay", "--hashes belongs to 'replay verify'");
            return RS_EXIT_USAGE;
        }
        return info(file);
    }
    return verify(file, hashes, overwrite, quiet ? RS_PROGRESS_OFF : (rs_progress_mode)progress);
}
