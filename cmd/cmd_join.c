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
#include "job_audio.h"

static void help(void)
{
    printf("usage: ringside join --segment KEY -o OUT [-y|-n] [--hashes FILE] [--first T]\n"
           "                     [--progress-fd N] [--progress tty|plain|off] [--quiet]\n"
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
           "  --quiet           no progress line\n\n"
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

int cmd_join(int argc, char **argv)
{
    static const struct option opts[] = {
        {"output", required_argument, 0, 'o'},     {"segment", required_argument, 0, 'S'},
        {"hashes", required_argument, 0, 'H'},     {"first", required_argument, 0, 'f'},
        {"progress-fd", required_argument, 0, 'G'}, {"quiet", no_argument, 0, 'q'},
        {"help", no_argument, 0, 'h'},
        {"overwrite", no_argument, 0, 'y'},        {"no-overwrite", no_argument, 0, 'n'},
        {"progress", required_argument, 0, 'g'},   {"replay", required_argument, 0, 'R'},
        {"audio-bitrate", required_argument, 0, JOB_AUDIO_OPT_BITRATE},
        {"loudness", required_argument, 0, JOB_AUDIO_OPT_LOUDNESS}, {0}};
    const char *out = NULL, *key = NULL, *hashes = NULL, *replay = NULL;
    job_audio audio = {0};
    uint64_t first = 0;
    long progress_fd = -1;
    bool quiet = false, overwrite = false;
    int progress = RS_PROGRESS_AUTO;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:qhyn", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 'S': key = optarg; break;
        case 'H': hashes = optarg; break;
        case 'f': if (!cli_u64("--first", optarg, &first)) return RS_EXIT_USAGE; break;
        case 'G': if (!cli_int("--progress-fd", optarg, 3, 1023, &progress_fd)) return RS_EXIT_USAGE; break;
        case 'q': quiet = true; break;
        case 'h': help(); return RS_EXIT_OK;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'g': if (!cli_progress_mode("join", optarg, &progress)) return RS_EXIT_USAGE; break;
        case 'R': replay = optarg; break;
        case JOB_AUDIO_OPT_BITRATE: case JOB_AUDIO_OPT_LOUDNESS:
            if (!job_audio_option(&audio, "join", c, optarg))
                return RS_EXIT_USAGE;
            break;
        default: return cli_bad_option("join", argv);
        }
    }
    if (!key || !cap_seg_key_ok(key)) {
        cli_error("join", key ? "--segment '%s': expected a key of 1 to 64 characters from A-Z a-z 0-9 . _ : -"
                              : "--segment KEY is required%s",
                  key ? key : "");
        return RS_EXIT_USAGE;
    }
    if (!out || !cap_seg_format_of(out)) {
        cli_error("join", out ? "-o %s: expected .mp4, .mkv or .webm" : "-o OUT is required%s", out ? out : "");
        return RS_EXIT_USAGE;
    }
    if (optind >= argc) {
        cli_error("join", "no segments given");
        return cli_usage_error("join");
    }
    if (!cli_out_ok("join", out, overwrite) || (hashes && strcmp(hashes, "-") && !cli_out_ok("join", hashes, overwrite)))
        return RS_EXIT_FAIL;
    if (!replay && (audio.bitrate || audio.lufs)) {
        cli_error("join", "--audio-bitrate and --loudness need --replay R (the sound comes from the replay)");
        return RS_EXIT_USAGE;
    }
    rs_err err = {0};
    cap_sink asink = {0}; /* the output as a render's sink: which codec, which bitrate */
    bool usage;
    audio.mode = replay ? JOB_AUDIO_ON : JOB_AUDIO_OFF;
    if (replay && (!cap_sink_for(out, 16, 16, &asink, &err) || !job_audio_check(&audio, "join", &asink, &usage, &err))) {
        if (err.msg[0])
            cli_error("join", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    rp_replay rp = {0};
    if (replay && !rp_read(replay, &rp, &err)) {
        cli_error("join", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    int n = argc - optind;
    char *const *paths = argv + optind;
    join_report rep = {.fd = (int)progress_fd};
    cap_seg *segs = calloc((size_t)n, sizeof *segs);
    if (!segs) {
        cli_error("join", "out of memory for %d segments", n);
        return RS_EXIT_FAIL;
    }
    for (int i = 0; i < n; i++)
        segs[i].path = paths[i];

    stop_requested = 0;
    struct sigaction sa = {0}, old_int, old_term;
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    int status = RS_EXIT_FAIL;
    /* the output first: a directory that is gone is the output's failure, not the segments' */
    cap_join *j = cap_join_open(&(cap_join_desc){.out = out, .hashes = hashes, .progress = report_frames, .ctx = &rep,
                                                 .stop = &stop_requested},
                                &err);
    if (!j)
        goto done;
    cap_seg_want want = {.key = key, .format = cap_seg_format_of(out), .first = first, .hashes = hashes != NULL};
    if (cap_seg_verify(segs, n, &want, report_bad, &rep) > 0) {
        cap_join_close(j, false, NULL);
        cli_error("join", "%s not written: bad segments", out);
        status = RS_EXIT_SEGMENT;
        goto done;
    }
    uint64_t total = 0;
    for (int i = 0; i < n; i++)
        total += segs[i].m.frames;
    uint64_t replay_fnv = 0;
    if (replay && !cap_seg_replay_fnv(replay, &replay_fnv, &err)) {
        cap_join_close(j, false, NULL);
        goto done;
    }
    for (int i = 0; replay && i < n; i++)
        if (segs[i].m.has_replay && segs[i].m.replay_fnv != replay_fnv) {
            cap_join_close(j, false, NULL);
            cli_error("join", "--replay %s: not the replay segment %d (%s) was rendered from (FNV-1a %016" PRIx64
                              ", the manifest says %016" PRIx64 ")", replay, i, segs[i].path, replay_fnv, segs[i].m.replay_fnv);
            status = RS_EXIT_USAGE;
            goto done;
        }
    if (replay) {
        /* the whole job's sound, once: ticks first..end of the manifests */
        uint64_t t0 = segs[0].m.first, t1 = t0 + total;
        if (t1 > rp.ticks) {
            cap_join_close(j, false, NULL);
            cli_error("join", "--replay %s: %" PRIu64 " ticks, but the segments run to tick %" PRIu64 "; not their replay", replay,
                      rp.ticks, t1);
            status = RS_EXIT_USAGE;
            goto done;
        }
        if (!job_audio_plan(&audio, &asink, &rp, replay, t0, t1, &err)) {
            cap_join_close(j, false, NULL);
            goto done;
        }
        cap_join_audio(j, &asink);
    }
    rs_progress_start(&rep.prog, "join", "frames", total, quiet ? RS_PROGRESS_OFF : (rs_progress_mode)progress);
    cli_progress_fd(rep.fd, 0, total, &rep.last);
    int bad = -1;
    bool ok = cap_join_copy(j, segs, n, &bad, &err);
    double secs = rs_progress_end(&rep.prog);
    if (!ok && bad >= 0) {
        report_bad(&rep, bad, &err);
        cap_join_close(j, false, NULL);
        cli_error("join", "%s not written: bad segments", out);
        status = RS_EXIT_SEGMENT;
        goto done;
    }
    if (!cap_join_close(j, ok, &err))
        goto done;
    char said[300];
    job_audio_describe(&audio, &asink, said, sizeof said);
    if (!quiet)
        fprintf(stderr, "ringside join: wrote %s: %" PRIu64 " frames (ticks %" PRIu64 "..%" PRIu64 ") from %d segments in %.2f s%s\n",
                out, total, segs[0].m.first, segs[0].m.first + total - 1, n, secs, said);
    status = RS_EXIT_OK;
done:
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    if (status == RS_EXIT_FAIL)
        cli_error("join", "%s", err.msg);
    free(segs);
    job_audio_free(&audio);
    rp_free(&rp);
    return status;
}
