/* ringside join: segments (render --segment) -> one video, by stream copy.
 * The work is capture/cap_seg.c (verification) and capture/cap_join.c
 * (the copy); this file is the command: options, messages, exit status. */
#include <getopt.h>
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../capture/cap_seg.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_progress.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "job_audio.h"
#include "job_out.h"

static void help(void)
{
    printf("usage: ringside join --segment KEY -o OUT [-y|-n] [--hashes FILE] [--first T]\n"
           "                     [--progress-fd N] [--progress tty|plain|off] [-q|-v]\n"
           "                     [--replay R [--audio-bitrate RATE] [--loudness LUFS]] SEG...\n\n"
           "Joins segments written by 'ringside render --ticks A:B --segment KEY' into one\n"
           "video by stream copy (no re-encoding): .mp4 (index at the front), .mkv or .webm,\n"
           "as OUT's extension says, with the segments' own format.  SEG... in tick order.\n\n"
           "Every segment is checked against its manifest (SEG.seg) before anything is\n"
           "written: the key, format and size, ticks that continue from the segment before,\n"
           "the file's byte size, its packets (count, first one a keyframe, timestamps, CRC)\n"
           "and codec parameters, and its hash list (SEG with .hashes for its extension).\n"
           "OUT and its hash list appear only when complete.\n\n"
           "  --segment KEY     the job's key: segments with another key are never joined\n"
           "  -o OUT            the video (its directory must exist)\n"
           "  -y, --overwrite   replace OUT and the --hashes file if they exist\n"
           "  -n, --no-overwrite  refuse them, naming the file (the default; never asks)\n"
           "  --hashes FILE     also write the segments' --hashes lists, concatenated\n"
           "                    (one line per frame, as 'render --hashes' of the whole video;\n"
           "                    '-' for standard output)\n"
           "  --first T         the first segment starts at tick T (default 0)\n"
           "  --replay R        the segments' replay: its soundtrack for the joined ticks is\n"
           "                    mixed once and encoded beside the copied video (AAC in .mp4\n"
           "                    and .mkv, Opus in .webm); without it the video is silent\n"
           "  --audio-bitrate R, --loudness LUFS\n"
           "                    as in 'ringside render' (defaults 192k AAC, 128k Opus; -16)\n"
           "  --progress-fd N   report on file descriptor N, for programs (ringside serve):\n"
           "                    'bad INDEX REASON MESSAGE' for each bad segment (INDEX: its\n"
           "                    position in SEG..., from 0), then 'frames DONE TOTAL' lines\n"
           "  --progress MODE   tty (a line redrawn in place), plain (a line every 5 s and\n"
           "                    the last, for logs) or off; default tty on a terminal, else plain\n"
           CLI_LOG_HELP
           "exit status: 0 joined; 1 the output failed (directory gone, disk full), nothing\n"
           "left; 2 bad usage; 3 one or more segments are bad (each named on stderr and in a\n"
           "'bad' line), nothing written.  REASON is one of missing, manifest, key, format,\n"
           "ticks, size, media, codec, hashes (docs/segments.md).\n");
}

static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

typedef struct join_report {
    int fd;             /* --progress-fd, or -1 */
    rs_progress prog;
    double last;
} join_report;

/* "bad INDEX REASON MESSAGE": REASON is the id's name (CAP_ERR_SEG_KEY -> key). */
static void report_bad(void *ctx, int index, const rs_err *e)
{
    join_report *r = ctx;
    char reason[32];
    const char *name = cap_error_name(e->code);
    if (!strncmp(name, "SEG_", 4))
        name += 4;
    size_t i = 0;
    for (; name[i] && i + 1 < sizeof reason; i++)
        reason[i] = (char)(name[i] >= 'A' && name[i] <= 'Z' ? name[i] - 'A' + 'a' : name[i]);
    reason[i] = 0;
    cli_error("join", "segment %d: %s", index, e->msg);
    if (r->fd >= 0)
        dprintf(r->fd, "bad %d %s %s\n", index, reason, e->msg);
}

static void report_frames(void *ctx, uint64_t done, uint64_t total)
{
    join_report *r = ctx;
    rs_progress_update(&r->prog, done);
    cli_progress_fd(r->fd, done, total, &r->last);
}

static const struct option opts[] = {
    {"output", required_argument, 0, 'o'},     {"segment", required_argument, 0, 'S'},
    {"hashes", required_argument, 0, 'H'},     {"first", required_argument, 0, 'f'},
    {"progress-fd", required_argument, 0, 'G'}, {"help", no_argument, 0, 'h'},
    {"overwrite", no_argument, 0, 'y'},        {"no-overwrite", no_argument, 0, 'n'},
    {"progress", required_argument, 0, 'g'},   {"replay", required_argument, 0, 'R'},
    {"audio-bitrate", required_argument, 0, JOB_AUDIO_OPT_BITRATE},
    {"loudness", required_argument, 0, JOB_AUDIO_OPT_LOUDNESS}, {0}};

/* What the command line asks for. */
typedef struct join_opts {
    const char *out, *key, *hashes, *replay;
    job_audio audio;
    uint64_t first;
    long progress_fd;
    bool quiet, overwrite;
    int progress;
    int n;              /* the segments: paths[0..n-1] */
    char *const *paths;
} join_opts;

/* One option; -1 to go on, else the exit status (--help: RS_EXIT_OK). */
static int join_option(join_opts *o, int c, const char *arg, char **argv)
{
    switch (c) {
    case 'o': o->out = arg; return -1;
    case 'S': o->key = arg; return -1;
    case 'H': o->hashes = arg; return -1;
    case 'f': return cli_u64("--first", arg, &o->first) ? -1 : RS_EXIT_USAGE;
    case 'G': return cli_int("--progress-fd", arg, 3, 1023, &o->progress_fd) ? -1 : RS_EXIT_USAGE;
    case 'h': help(); return RS_EXIT_OK;
    case 'y': o->overwrite = true; return -1;
    case 'n': o->overwrite = false; return -1;
    case 'g': return cli_progress_mode("join", arg, &o->progress) ? -1 : RS_EXIT_USAGE;
    case 'R': o->replay = arg; return -1;
    case JOB_AUDIO_OPT_BITRATE: case JOB_AUDIO_OPT_LOUDNESS:
        return job_audio_option(&o->audio, "join", c, arg) ? -1 : RS_EXIT_USAGE;
    default: return cli_bad_option("join", argv);
    }
}

/* The command line into o, checked; -1 to go on, else the exit status. */
static int parse_options(int argc, char **argv, join_opts *o)
{
    *o = (join_opts){.progress_fd = -1, .progress = RS_PROGRESS_AUTO};
    o->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    int c, status;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:hyn", opts, NULL)) != -1)
        if ((status = join_option(o, c, optarg, argv)) >= 0)
            return status;
    if (!o->key || !cap_seg_key_ok(o->key)) {
        cli_error("join", o->key ? "--segment '%s': expected a key of 1 to 64 characters from A-Z a-z 0-9 . _ : -"
                                 : "--segment KEY is required%s",
                  o->key ? o->key : "");
        return RS_EXIT_USAGE;
    }
    if (!o->out || !cap_seg_format_of(o->out)) {
        cli_error("join", o->out ? "-o %s: expected .mp4, .mkv or .webm" : "-o OUT is required%s", o->out ? o->out : "");
        return RS_EXIT_USAGE;
    }
    if (optind >= argc) {
        cli_error("join", "no segments given");
        return cli_usage_error("join");
    }
    o->n = argc - optind;
    o->paths = argv + optind;
    job_out outs = {.cmd = "join", .overwrite = o->overwrite, .video = o->out, .hashes = o->hashes};
    if (!job_out_check(&outs))
        return RS_EXIT_FAIL;
    if (!o->replay && (o->audio.bitrate || o->audio.lufs)) {
        cli_error("join", "--audio-bitrate and --loudness need --replay R (the sound comes from the replay)");
        return RS_EXIT_USAGE;
    }
    return -1;
}

/* A join under way. */
typedef struct join_run {
    join_opts *o;
    rs_err err;
    cap_sink asink;     /* the output as a render's sink: which codec, which bitrate */
    rp_replay rp;
    cap_seg *segs;
    uint64_t total;     /* frames in all segments */
    join_report rep;
} join_run;

/* --replay: the segments' replay, and the sound of their ticks given to
 * the join; -1 to go on, else the exit status. */
static int join_sound(join_run *run, cap_join *j)
{
    join_opts *o = run->o;
    const char *replay = o->replay;
    uint64_t replay_fnv = 0;
    if (!cap_seg_replay_fnv(replay, &replay_fnv, &run->err))
        return RS_EXIT_FAIL;
    for (int i = 0; i < o->n; i++)
        if (run->segs[i].m.has_replay && run->segs[i].m.replay_fnv != replay_fnv) {
            cli_error("join", "--replay %s: not the replay segment %d (%s) was rendered from (FNV-1a %016" PRIx64
                              ", the manifest says %016" PRIx64 ")", replay, i, run->segs[i].path, replay_fnv, run->segs[i].m.replay_fnv);
            return RS_EXIT_USAGE;
        }
    /* the whole job's sound, once: ticks first..end of the manifests */
    uint64_t t0 = run->segs[0].m.first, t1 = t0 + run->total;
    if (t1 > run->rp.ticks) {
        cli_error("join", "--replay %s: %" PRIu64 " ticks, but the segments run to tick %" PRIu64 "; not their replay", replay,
                  run->rp.ticks, t1);
        return RS_EXIT_USAGE;
    }
    if (!job_audio_plan(&o->audio, &run->asink, &run->rp, replay, t0, t1, &run->err))
        return RS_EXIT_FAIL;
    cap_join_audio(j, &run->asink);
    return -1;
}

/* The output first (a directory that is gone is the output's failure, not
 * the segments'), then the segments checked, then the copy. */
static int join_segments(join_run *run)
{
    join_opts *o = run->o;
    cap_join *j = cap_join_open(&(cap_join_desc){.out = o->out, .hashes = o->hashes, .progress = report_frames, .ctx = &run->rep,
                                                 .stop = &stop_requested},
                                &run->err);
    if (!j)
        return RS_EXIT_FAIL;
    cap_seg_want want = {.key = o->key, .format = cap_seg_format_of(o->out), .first = o->first, .hashes = o->hashes != NULL};
    if (cap_seg_verify(run->segs, o->n, &want, report_bad, &run->rep) > 0) {
        cap_join_close(j, false, NULL);
        cli_error("join", "%s not written: bad segments", o->out);
        return RS_EXIT_SEGMENT;
    }
    for (int i = 0; i < o->n; i++)
        run->total += run->segs[i].m.frames;
    int status = o->replay ? join_sound(run, j) : -1;
    if (status >= 0) {
        cap_join_close(j, false, NULL);
        return status;
    }
    rs_progress_start(&run->rep.prog, "join", "frames", run->total, o->quiet ? RS_PROGRESS_OFF : (rs_progress_mode)o->progress);
    cli_progress_fd(run->rep.fd, 0, run->total, &run->rep.last);
    int bad = -1;
    bool ok = cap_join_copy(j, run->segs, o->n, &bad, &run->err);
    double secs = rs_progress_end(&run->rep.prog);
    if (!ok && bad >= 0) {
        report_bad(&run->rep, bad, &run->err);
        cap_join_close(j, false, NULL);
        cli_error("join", "%s not written: bad segments", o->out);
        return RS_EXIT_SEGMENT;
    }
    if (!cap_join_close(j, ok, &run->err))
        return RS_EXIT_FAIL;
    char said[300];
    job_audio_describe(&o->audio, &run->asink, said, sizeof said);
    if (!o->quiet)
        fprintf(stderr, "ringside join: wrote %s: %" PRIu64 " frames (ticks %" PRIu64 "..%" PRIu64 ") from %d segments in %.2f s%s\n",
                o->out, run->total, run->segs[0].m.first, run->segs[0].m.first + run->total - 1, o->n, secs, said);
    return RS_EXIT_OK;
}

int cmd_join(int argc, char **argv)
{
    join_opts o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0)
        return status;
    join_run run = {.o = &o, .rep = {.fd = (int)o.progress_fd}};
    bool usage;
    o.audio.mode = o.replay ? JOB_AUDIO_ON : JOB_AUDIO_OFF;
    if (o.replay && (!cap_sink_for(o.out, 16, 16, &run.asink, &run.err) ||
                     !job_audio_check(&o.audio, "join", &run.asink, &usage, &run.err))) {
        if (run.err.msg[0])
            cli_error("join", "%s", run.err.msg);
        return RS_EXIT_USAGE;
    }
    if (o.replay && !rp_read(o.replay, &run.rp, &run.err)) {
        cli_error("join", "%s", run.err.msg);
        return RS_EXIT_USAGE;
    }
    if (!(run.segs = calloc((size_t)o.n, sizeof *run.segs))) {
        cli_error("join", "out of memory for %d segments", o.n);
        return RS_EXIT_FAIL;
    }
    for (int i = 0; i < o.n; i++)
        run.segs[i].path = o.paths[i];
    stop_requested = 0;
    struct sigaction sa = {0}, old_int, old_term;
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    status = join_segments(&run);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    if (status == RS_EXIT_FAIL)
        cli_error("join", "%s", run.err.msg);
    free(run.segs);
    job_audio_free(&o.audio);
    rp_free(&run.rp);
    return status;
}
