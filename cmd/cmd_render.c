/* ringside render: a replay to a video, headless, one frame per tick. */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <signal.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../capture/cap.h"
#include "../capture/cap_seg.h"
#include "cli.h"
#include "job_audio.h"
#include "job_poster.h"
#include "job_render.h"
#include "job_split.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_quality.h"
#include "../runtime/render/r_stage.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "../runtime/util/rs_version.h"
#include "job_err.h"

static void help(void)
{
    printf("usage: ringside render REPLAY -o OUT [--size WxH] [--render-size WxH]\n"
           "                       [--quality draft|standard|high|reference]\n"
           "                       [--capture async|sequential] [--downscale gpu|cpu]\n"
           "                       [--filter box|bilinear|nearest|lanczos3] [--pbo N] [--queue N]\n"
           "                       [--hashes FILE] [--backend egl|osmesa] [--quiet]\n"
           "                       [-y|-n] [--format y4m|nut|mkv|mp4|webm] [--progress tty|plain|off]\n"
           "                       [--stage-file FILE] [--passes[=summary|frames]] [--mask] [--no-hud]\n"
           "                       [--hdr-format rgba16f|r11g11b10f]\n"
           "                       [--ticks A:B] [--segment KEY] [--progress-fd N] [--poster FILE.png]\n"
           "                       [--codec C] [--crf N | --bitrate RATE] [--preset P]\n"
           "                       [--pix-fmt yuv420p|yuv444p] [--hw auto|off|nvenc|vaapi]\n"
           "                       [--audio on|off] [--audio-bitrate RATE] [--loudness LUFS] [--wav FILE]\n"
           "                       [--jobs N|auto]\n\n"
           "Renders every tick of a replay headless and writes one video frame per tick\n"
           "(60 frames a second, exact).  The output type comes from the extension (any\n"
           "case) or --format: %s.\n"
           "The output appears only when complete; a failed render leaves nothing.\n\n"
           "  -o OUT             output file ('/dev/null' and other devices are streamed), an\n"
           "                     image sequence pattern such as frames/f%%06d.png, or '-': a\n"
           "                     stream on standard output (Y4M unless --format says nut or mkv)\n"
           "  --format F         the container when the name does not say it: y4m, nut, mkv,\n"
           "                     mp4 (not to a pipe: its index goes last) or webm\n"
           "  -y, --overwrite    replace outputs that exist (video, images, --hashes, --poster,\n"
           "                     manifest)\n"
           "  -n, --no-overwrite\n"
           "                     never replace them: an existing output is refused, naming it,\n"
           "                     and nothing is written.  The default: ringside never asks,\n"
           "                     on a terminal or off it.  The output's folder must exist\n"
           "  --size WxH         output size, %d..%d a side, even numbers for video\n"
           "                     (default 640x360)\n"
           "  --quality Q        draft, standard (default), high or reference: how many\n"
           "                     pixels are drawn per output pixel and the renderer's\n"
           "                     knobs, chosen by measured error (docs/accuracy.md):\n"
           "%s"
           "  --render-size WxH  draw at this size instead of the quality's (at least the\n"
           "                     output size, at most %d times it)\n"
           "  --capture MODE     async (default): GPU downscale, PBO ring, writer thread;\n"
           "                     sequential: the original, everything on the game thread\n"
           "  --downscale WHERE  gpu (async default) or cpu (sequential default)\n"
           "  --filter F         GPU downscale: box (default), bilinear, nearest, lanczos3\n"
           "                     (docs/capture.md compares them)\n"
           "  --pbo N            pixel-buffer ring size, 1..%d (default %d)\n"
           "  --queue N          writer queue cap in frames, 0..1000 (default %d; 0: no thread)\n"
           "  --hashes FILE      write \"frame hash\" (64-bit FNV-1a of the frame bytes) per frame\n"
           "                     ('-' for standard output, unless -o - is there)\n"
           "  --poster FILE.png  also write one frame worth showing, at the output size: the\n"
           "                     last knock-out or ring-out (%d ticks on), else the match end,\n"
           "                     else the middle; chosen by simulating the replay first.  With\n"
           "                     --ticks, written only by the render whose range holds it\n"
           "  --backend B        GL backend (default egl, falling back to osmesa)\n"
           "  --stage-file FILE  the look to use instead of stages/<replay's stage>.stage\n"
           "                     (docs/stages.md)\n"
           "  --passes[=MODE]    time every render pass: a summary table at the end (default)\n"
           "                     or one line per frame (frames); skipped passes are listed\n"
           "  --mask             alpha = the fighters' mask, no HUD: RGBA cut-outs for artwork;\n"
           "                     needs an image pattern output (.png)\n"
           "  --no-hud           leave out bars, timer and announcements\n"
           "  --hdr-format F     the HDR buffer: rgba16f (default) or r11g11b10f (no alpha)\n"
           "  --ticks A:B        write only ticks A to B-1, bit for bit the frames a full render\n"
           "                     writes there: the game runs from tick 0 and the effects that\n"
           "                     carry history (water, snow, mist, LSPSM) are warmed up first;\n"
           "                     image names and --hashes lines are numbered A..B-1\n"
           "  --segment KEY      write a segment that 'ringside join' can put together with the\n"
           "                     others (.mp4, .mkv or .webm): first frame a keyframe, closed GOP,\n"
           "                     timestamps from tick A; beside it OUT.seg, its manifest (KEY,\n"
           "                     ticks, sizes, checksums), written last.  KEY ([A-Za-z0-9._:-],\n"
           "                     at most 64) names the job and attempt; --hashes, if given, must\n"
           "                     be OUT with its extension replaced by .hashes (docs/segments.md)\n"
           "  --progress-fd N    also report progress on file descriptor N, for programs\n"
           "                     (ringside serve): 'frames DONE TOTAL' lines, and 'desync TICK'\n"
           "                     if the replay's state hashes stop matching\n"
           "  --codec C          h264, hevc, vp9 or av1 (.mp4: h264, hevc, av1; .webm: vp9, av1;\n"
           "                     .mkv: all); default h264, vp9 for .webm\n"
           "  --crf N            constant quality, lower is better (x264/x265 1..51, default\n"
           "                     20 both; vp9/av1 1..63, default 32/35)\n"
           "  --bitrate RATE     an average rate instead, such as 4M or 800k\n"
           "  --preset P         the encoder's own speed names: x264/x265 ultrafast..placebo\n"
           "                     (default veryfast/superfast), vp9 cpu-used -8..8 (default 8),\n"
           "                     SVT-AV1 -1..13 (default 10), NVENC p1..p7 (default p4)\n"
           "  --pix-fmt F        yuv420p (default) or yuv444p (full-resolution colour)\n"
           "  --hw H             auto (default): NVENC or VAAPI when a device exists and the\n"
           "                     encoder opens, else software, with a note; off: software;\n"
           "                     nvenc, vaapi: that one or fail (docs/capture.md, Encoders)\n"
           "  --audio on|off     the replay's soundtrack as an audio stream: AAC in .mp4, .mkv\n"
           "                     and .nut, Opus in .webm (default on for those, off for Y4M,\n"
           "                     image sequences and segments, which carry none)\n"
           "  --audio-bitrate R  AAC 32k..512k (default 192k), Opus 16k..510k (default 128k)\n"
           "  --loudness LUFS    the whole match's integrated loudness, EBU R128, %.0f..%.0f\n"
           "                     (default %.0f; true peak at most -1 dBTP); --ticks A:B gets\n"
           "                     exactly those samples of the whole match's track\n"
           "  --wav FILE         also write the track of the rendered ticks as a 16-bit WAV,\n"
           "                     beside any output (Y4M, images); obeys -y/-n\n"
           "  --jobs N|auto      draw the video as N segments at once, each in a process\n"
           "                     of its own, and join them: .mp4, .mkv or .webm files,\n"
           "                     not with --segment, --passes, --wav or --format.  auto\n"
           "                     (default): one a CPU, each of %d frames or more, when\n"
           "                     the GL renderer is software (llvmpipe), else 1.  The\n"
           "                     frames are the same (docs/capture.md)\n"
           "  --progress MODE    tty: one line redrawn in place; plain: a line every 5 s and\n"
           "                     the last, for logs; off.  Default: tty when stderr is a\n"
           "                     terminal, else plain\n"
           "  --quiet            no progress line (--progress off) and no summary\n"
           "\nThe replay's state-hash checkpoints are checked as the game runs: a replay that\n"
           "desyncs (inputs that no longer produce the recorded game) fails with the first\n"
           "tick that differs, and nothing is written.\n",
           cap_sink_formats(), CLI_SIZE_MIN, R_RENDER_MAX, cli_quality_help(), CAP_MAX_SCALE, CAP_MAX_PBO, CAP_DEFAULT_PBO, CAP_DEFAULT_QUEUE, JOB_POSTER_AFTER_KO, JOB_AUDIO_LUFS_MIN,
           JOB_AUDIO_LUFS_MAX, JOB_AUDIO_LUFS_DEFAULT, JOB_SPLIT_MIN_FRAMES);
}

/* long-only options (no letter): the encoder's */
enum { OPT_CODEC = 0x200, OPT_CRF, OPT_BITRATE, OPT_PRESET, OPT_PIXFMT, OPT_HW, OPT_JOBS };

/* What a segment of a parallel render (--jobs) is given of the user's
 * options: the ones that decide the pictures and the encoding.  The rest
 * (outputs, ticks, progress, sound) the parent handles (job_split.h). */
static bool for_segments(int c)
{
    switch (c) {
    case 's': case 'r': case 'L': case 'c': case 'd': case 'p': case 'Q': case 'F': case 'T': case 'U': case 'X':
    case 'b': case OPT_CODEC: case OPT_CRF: case OPT_BITRATE: case OPT_PRESET: case OPT_PIXFMT: case OPT_HW:
        return true;
    default:
        return false;
    }
}

/* A software GL renderer: the one --jobs auto splits for. */
static bool software_gl(void)
{
    const char *r = glcaps.renderer ? glcaps.renderer : "";
    return strstr(r, "llvmpipe") || strstr(r, "softpipe") || strstr(r, "Software Rasterizer");
}

/* The metadata every video carries (cap_meta_keys): from the replay's header. */
static void render_meta(cap_sink *s, const char *replay, const rp_replay *rp)
{
    static const char *const kind[] = {"human", "cpu"};
    const char *base = strrchr(replay, '/');
    char text[160];
    const char *p1 = kind[rp->kind[0] != 0], *p2 = kind[rp->kind[1] != 0];
    const char *stage = rp->stage >= 0 && rp->stage < G_STAGES ? g_stages[rp->stage].name : "?";
    snprintf(text, sizeof text, "%s: P1 (%s) vs P2 (%s), %s", base ? base + 1 : replay, p1, p2, stage);
    cap_sink_meta(s, "title", text);
    cap_sink_meta(s, "stage", stage);
    snprintf(text, sizeof text, "P1 %s, P2 %s", p1, p2);
    cap_sink_meta(s, "players", text);
    if (rp->winner > 0)
        snprintf(text, sizeof text, "P%d, rounds %d-%d", rp->winner, rp->rounds[0], rp->rounds[1]);
    else if (rp->winner == 0)
        snprintf(text, sizeof text, "draw, rounds %d-%d", rp->rounds[0], rp->rounds[1]);
    else /* the words of `replay info` */
        snprintf(text, sizeof text, "none (match unfinished, rounds %d-%d)", rp->rounds[0], rp->rounds[1]);
    cap_sink_meta(s, "winner", text);
    cap_sink_meta(s, "ringside_version", RS_VERSION);
}

/* Ctrl-C / SIGTERM: the handler only sets a flag; the loop stops, and
 * cap_close removes the partial output. */
static volatile sig_atomic_t stop_requested;

static void on_signal(int sig)
{
    (void)sig;
    stop_requested = 1;
}

int cmd_render(int argc, char **argv)
{
    static const struct option opts[] = {
        {"output", required_argument, 0, 'o'},     {"size", required_argument, 0, 's'},
        {"render-size", required_argument, 0, 'r'}, {"capture", required_argument, 0, 'c'},
        {"downscale", required_argument, 0, 'd'},  {"pbo", required_argument, 0, 'p'},
        {"queue", required_argument, 0, 'Q'},      {"hashes", required_argument, 0, 'H'},
        {"backend", required_argument, 0, 'b'},    {"quiet", no_argument, 0, 'q'},
        {"filter", required_argument, 0, 'F'},    {"stage-file", required_argument, 0, 'T'},
        {"passes", optional_argument, 0, 'P'},     {"mask", no_argument, 0, 'M'},
        {"no-hud", no_argument, 0, 'U'},           {"hdr-format", required_argument, 0, 'X'},
        {"ticks", required_argument, 0, 'K'},      {"progress-fd", required_argument, 0, 'G'},
        {"segment", required_argument, 0, 'S'},    {"help", no_argument, 0, 'h'},
        {"overwrite", no_argument, 0, 'y'},        {"no-overwrite", no_argument, 0, 'n'},
        {"format", required_argument, 0, 'f'},     {"progress", required_argument, 0, 'g'},
        {"codec", required_argument, 0, OPT_CODEC}, {"crf", required_argument, 0, OPT_CRF},
        {"bitrate", required_argument, 0, OPT_BITRATE}, {"preset", required_argument, 0, OPT_PRESET},
        {"pix-fmt", required_argument, 0, OPT_PIXFMT}, {"hw", required_argument, 0, OPT_HW},
        {"poster", required_argument, 0, 'O'},     {"quality", required_argument, 0, 'L'},
        {"audio", required_argument, 0, JOB_AUDIO_OPT_AUDIO}, {"audio-bitrate", required_argument, 0, JOB_AUDIO_OPT_BITRATE},
        {"loudness", required_argument, 0, JOB_AUDIO_OPT_LOUDNESS}, {"wav", required_argument, 0, JOB_AUDIO_OPT_WAV},
        {"jobs", required_argument, 0, OPT_JOBS}, {0}};
    cap_enc enc = {0};
    job_audio audio = {0};
    const char *out = NULL, *hashes = NULL, *backend = NULL, *segment = NULL, *format = NULL, *poster_path = NULL;
    bool overwrite = false;
    int progress = RS_PROGRESS_AUTO;
    cap_desc cd = {.w = 640, .h = 360};
    const r_preset *quality = &r_presets[R_PRESET_DEFAULT];
    bool quiet = false;
    r_game_opts go = {0};
    int passes = 0; /* 1 summary, 2 per frame */
    long first = 0, end = -1; /* --ticks; end -1: the whole replay */
    long progress_fd = -1;
    long v;
    int c, jobs = 0; /* 0: auto */
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:qhyn", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 's': if (!cli_out_size("--size", optarg, &cd.w, &cd.h)) return RS_EXIT_USAGE; break;
        case 'r': if (!cli_size("--render-size", optarg, R_RENDER_MAX, &cd.src_w, &cd.src_h)) return RS_EXIT_USAGE; break;
        case 'L': if (!(quality = cli_quality("render", optarg))) return RS_EXIT_USAGE; break;
        case 'c':
            if (!strcmp(optarg, "async"))
                cd.mode = CAP_ASYNC;
            else if (!strcmp(optarg, "sequential"))
                cd.mode = CAP_SEQUENTIAL;
            else {
                cli_error("render", "--capture '%s': expected async or sequential", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case 'd':
            if (!strcmp(optarg, "gpu"))
                cd.downscale = CAP_DS_GPU;
            else if (!strcmp(optarg, "cpu"))
                cd.downscale = CAP_DS_CPU;
            else {
                cli_error("render", "--downscale '%s': expected gpu or cpu", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case 'p': if (!cli_int("--pbo", optarg, 1, CAP_MAX_PBO, &v)) return RS_EXIT_USAGE; cd.pbo = (int)v; break;
        case 'Q':
            if (!cli_int("--queue", optarg, 0, 1000, &v))
                return RS_EXIT_USAGE;
            cd.queue = (int)v;
            cd.no_writer = v == 0;
            break;
        case 'F':
            if (!cap_filter_parse(optarg, &cd.filter)) {
                cli_error("render", "--filter '%s': expected box, bilinear, nearest or lanczos3", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case 'T': go.stage_file = optarg; break;
        case 'P':
            if (!cli_passes("render", optarg, &passes))
                return RS_EXIT_USAGE;
            break;
        case 'M': go.mask = true; break;
        case 'U': go.no_hud = true; break;
        case 'X': {
            int fmt;
            if (!cli_hdr_format(optarg, &fmt))
                return RS_EXIT_USAGE;
            go.hdr_format = r_game_hdr_of(fmt);
            break;
        }
        case 'K': {
            char *colon = strchr(optarg, ':'), a[32];
            if (!colon || (size_t)(colon - optarg) >= sizeof a) {
                cli_error("render", "--ticks '%s': expected A:B, such as 600:660", optarg);
                return RS_EXIT_USAGE;
            }
            memcpy(a, optarg, (size_t)(colon - optarg));
            a[colon - optarg] = 0;
            if (!cli_int("--ticks start", a, 0, 100000000, &first) ||
                !cli_int("--ticks end", colon + 1, 1, 100000000, &end))
                return RS_EXIT_USAGE;
            if (end <= first) {
                cli_error("render", "--ticks '%s': the end must be after the start", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        }
        case 'H': hashes = optarg; break;
        case 'S':
            if (!cap_seg_key_ok(optarg)) {
                cli_error("render", "--segment '%s': expected a key of 1 to %d characters from A-Z a-z 0-9 . _ : -", optarg,
                          CAP_SEG_KEY_MAX);
                return RS_EXIT_USAGE;
            }
            segment = optarg;
            break;
        case 'b': backend = optarg; break;
        case 'q': quiet = true; break;
        case 'G': if (!cli_int("--progress-fd", optarg, 3, 1023, &progress_fd)) return RS_EXIT_USAGE; break;
        case 'h': help(); return RS_EXIT_OK;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'f': format = optarg; break;
        case 'g': if (!cli_progress_mode("render", optarg, &progress)) return RS_EXIT_USAGE; break;
        case OPT_CODEC:
            if (!cap_codec_parse(optarg, &enc.codec)) {
                cli_error("render", "--codec '%s': expected h264, hevc, vp9 or av1", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case OPT_CRF: if (!cli_int("--crf", optarg, 1, 255, &v)) return RS_EXIT_USAGE; enc.crf = (int)v; break;
        case OPT_BITRATE:
            if (!cap_bitrate_parse(optarg, &enc.bitrate)) {
                cli_error("render", "--bitrate '%s': expected bits a second such as 4M, 800k or 2500000 (10k..1000M)", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case OPT_PRESET: snprintf(enc.preset, sizeof enc.preset, "%s", optarg); break;
        case OPT_PIXFMT:
            if (!cap_chroma_parse(optarg, &enc.chroma)) {
                cli_error("render", "--pix-fmt '%s': expected yuv420p or yuv444p", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case OPT_HW:
            if (!cap_hw_parse(optarg, &enc.hw)) {
                cli_error("render", "--hw '%s': expected auto, off, nvenc or vaapi", optarg);
                return RS_EXIT_USAGE;
            }
            break;
        case 'O': poster_path = optarg; break;
        case OPT_JOBS:
            if (!strcmp(optarg, "auto"))
                jobs = 0;
            else if (!cli_int("--jobs", optarg, 1, JOB_SPLIT_MAX, &v))
                return RS_EXIT_USAGE;
            else
                jobs = (int)v;
            break;
        case JOB_AUDIO_OPT_AUDIO: case JOB_AUDIO_OPT_BITRATE: case JOB_AUDIO_OPT_LOUDNESS: case JOB_AUDIO_OPT_WAV:
            if (!job_audio_option(&audio, "render", c, optarg))
                return RS_EXIT_USAGE;
            break;
        default: return cli_bad_option("render", argv);
        }
    }
    if (optind + 1 != argc) {
        cli_error("render", optind >= argc ? "a REPLAY file is required" : "unexpected argument '%s'",
                  argv[argc - 1]);
        return cli_usage_error("render");
    }
    if (!out) {
        cli_error("render", "-o OUT is required");
        return RS_EXIT_USAGE;
    }
    const char *replay = argv[optind];
    rs_err err = {0};
    if (!strcmp(out, "-") && hashes && !strcmp(hashes, "-")) {
        cli_error("render", "-o - and --hashes - both write to standard output: give --hashes a file");
        return RS_EXIT_USAGE;
    }
    if (!strcmp(out, "-") && isatty(1)) {
        cli_error("render", "-o -: standard output is a terminal; pipe it into a program or a file");
        return RS_EXIT_USAGE;
    }
    cap_pixfmt fmt = strchr(out, '%') ? CAP_RGBA : CAP_I420;
    if (go.mask && fmt != CAP_RGBA) {
        cli_error("render", "--mask writes RGBA images: give -o an image pattern such as cut/f%%04d.png, not %s", out);
        return RS_EXIT_USAGE;
    }
    char seg_hashes[1100], seg_manifest[1100];
    if (segment) {
        /* join finds a segment's list by name, so there is one name for it */
        cap_seg_hashes_path(out, seg_hashes, sizeof seg_hashes);
        cap_seg_manifest_path(out, seg_manifest, sizeof seg_manifest);
        if (!cap_seg_format_of(out)) {
            cli_error("render", "--segment writes .mp4, .mkv or .webm, not %s", out);
            return RS_EXIT_USAGE;
        }
        if (hashes && strcmp(hashes, seg_hashes) != 0) {
            cli_error("render", "--segment: --hashes must be %s (where join looks for it), not %s", seg_hashes, hashes);
            return RS_EXIT_USAGE;
        }
    }
    go.quiet = quiet;
    go.q = quality->q;
    if (!cd.src_w) /* the quality's scale, unless --render-size said */
        r_preset_render_size(quality, cd.w, cd.h, R_RENDER_MAX, &cd.src_w, &cd.src_h);
    if (!cap_check_sizes_for(fmt, cd.src_w, cd.src_h, cd.w, cd.h, &err)) {
        cli_error("render", "%s", err.msg);
        return RS_EXIT_USAGE;
    }

    int status = RS_EXIT_FAIL;
    rp_replay rp = {0};
    cap_sink sink;
    plat *p = NULL;
    r_game *r = NULL;
    r_target t = {0};
    FILE *hf = NULL;
    char hpart[1100] = "";
    job_poster poster = {0};
    /* Ctrl-C and SIGTERM from here on end the render cleanly (nothing
     * partial left), also during start-up: the GL context, shaders and the
     * IBL prefilter can take seconds, and outputs are created before the
     * first frame.  (A background job of a script starts with SIGINT
     * ignored; the handler replaces that too.) */
    stop_requested = 0;
    struct sigaction sa = {0}, old_int, old_term;
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    /* everything that can be checked without rendering, first */
    if (!rp_read(replay, &rp, &err))
        goto done;
    if (end > (long)rp.ticks) {
        rs_fail(&err, JOB_ERR_TICKS, "%s: --ticks %ld:%ld is past the replay's end (%" PRIu64 " ticks)", replay, first, end,
                rp.ticks);
        status = RS_EXIT_USAGE;
        goto done;
    }
    uint64_t t_first = (uint64_t)first, t_end = end < 0 ? rp.ticks : (uint64_t)end;
    if (!job_poster_plan(&poster, poster_path, &rp, t_first, t_end, &err))
        goto done;
    if (!cap_sink_for_format(out, format, cd.w, cd.h, &sink, &err))
        goto done;
    /* every output this render writes, checked before anything is touched */
    if (!(sink.fmt == CAP_RGBA ? cli_pattern_ok("render", out, t_first, t_end, overwrite)
                               : cli_out_ok("render", out, overwrite)) ||
        (hashes && strcmp(hashes, "-") && !cli_out_ok("render", hashes, overwrite)) ||
        (segment && !cli_out_ok("render", seg_manifest, overwrite)) ||
        (poster.due && !cli_out_ok("render", poster.path, overwrite))) {
        err.msg[0] = 0; /* said */
        goto done;
    }
    sink.index_base = t_first; /* frame numbers are ticks: f%04d.png of --ticks 600:660 is f0600..f0659 */
    sink.segment = segment != NULL;
    audio.overwrite = overwrite;
    bool usage;
    if (!job_audio_check(&audio, "render", &sink, &usage, &err)) {
        status = usage ? RS_EXIT_USAGE : RS_EXIT_FAIL;
        goto done;
    }
    render_meta(&sink, replay, &rp);
    if (!cap_sink_encoder(&sink, &enc, &err)) {
        status = err.code == CAP_ERR_ENC_SETTING ? RS_EXIT_USAGE : RS_EXIT_FAIL;
        goto done;
    }
    if (sink.enc_note[0])
        fprintf(stderr, "ringside render: %s\n", sink.enc_note); /* once: the choice is made here, for the whole run */
    /* --jobs: segments drawn at once by processes of their own, then joined
     * (job_split.h), where the output can be joined */
    bool splittable = fmt == CAP_I420 && !format && !segment && !passes && !audio.wav && cap_seg_format_of(out);
    if (jobs > 1 && !splittable) {
        cli_error("render", "--jobs %d: only a .mp4, .mkv or .webm file is rendered in segments at once (not %s%s)", jobs,
                  segment ? "with --segment" : passes ? "with --passes" : audio.wav ? "with --wav" : format ? "with --format" : out,
                  "");
        status = RS_EXIT_USAGE;
        goto done;
    }
    int split = 1;
    if (splittable && jobs != 1) {
        uint64_t frames = t_end - t_first;
        split = jobs ? (frames < (uint64_t)jobs ? (int)frames : jobs) : job_split_auto(frames);
        if (jobs == 0 && split > 1) {
            /* auto: a software rasteriser gains, a GPU does not need it; the
             * context this render would draw with says which (and is kept if so) */
            if (!(p = plat_create(&(plat_desc){.backend = backend, .hidden = true}, &err))) {
                status = cli_plat_status(&err);
                goto done;
            }
            if (!software_gl())
                split = 1;
            else
                plat_destroy(p), p = NULL;
        }
    }
    if (split > 1) {
        /* what every segment would refuse, refused once here: the look */
        r_stage look;
        if (go.stage_file ? !r_stage_load(&look, go.stage_file, &err) : !r_stage_for_game(&look, rp.stage, &err))
            goto done;
        /* the user's options that decide the pictures and the encoding, for every segment */
        const char *pass[96];
        int np = 0;
        optind = 1;
        while ((c = getopt_long(argc, argv, "o:qhyn", opts, NULL)) != -1 && np < 94) {
            if (!for_segments(c))
                continue;
            for (const struct option *o = opts; o->name; o++)
                if (o->val == c) {
                    static char name[96][40];
                    snprintf(name[np], sizeof name[np], "--%s", o->name);
                    pass[np] = name[np];
                    np++;
                    if (o->has_arg == required_argument)
                        pass[np++] = optarg;
                    break;
                }
        }
        pass[np] = NULL;
        char exe[1100], what[160];
        ssize_t ne = readlink("/proc/self/exe", exe, sizeof exe - 1);
        if (ne <= 0) {
            rs_fail(&err, JOB_ERR_PROCESS, "cannot find this program (/proc/self/exe): %s", strerror(errno));
            goto done;
        }
        exe[ne] = 0;
        snprintf(what, sizeof what, "%dx%d (drawn at %dx%d, quality %s)", cd.w, cd.h, cd.src_w, cd.src_h, quality->name);
        job_split_desc jd = {.exe = exe, .replay = replay, .out = out, .first = t_first, .end = t_end, .jobs = split,
                             .pass = pass, .rp = &rp, .sink = &sink, .audio = &audio, .hashes = hashes,
                             .poster = poster.due ? poster_path : NULL, .overwrite = overwrite,
                             .progress = quiet ? RS_PROGRESS_OFF : (rs_progress_mode)progress, .progress_fd = (int)progress_fd,
                             .quiet = quiet, .what = what, .said = sink.enc_note, .stop = &stop_requested};
        status = job_split_run(&jd, &err);
        goto done;
    }
    /* a manifest says "complete": an older one must not vouch for the files this render replaces */
    if (segment && unlink(seg_manifest) != 0 && errno != ENOENT) {
        rs_fail(&err, JOB_ERR_WRITE, "%s: cannot remove the old manifest: %s", seg_manifest, strerror(errno));
        goto done;
    }
    if (hashes && !strcmp(hashes, "-")) {
        cd.hashes = stdout;
    } else if (hashes) {
        snprintf(hpart, sizeof hpart, "%s.part", hashes);
        if (!(hf = fopen(hpart, "w"))) {
            rs_fail(&err, JOB_ERR_CREATE, "%s: cannot create: %s", hpart, strerror(errno));
            goto done;
        }
        cd.hashes = hf;
    }
    if (!job_audio_plan(&audio, &sink, &rp, replay, t_first, t_end, &err))
        goto done;
    if (!p && !(p = plat_create(&(plat_desc){.backend = backend, .hidden = true}, &err))) {
        status = cli_plat_status(&err);
        goto done;
    }
    if (!(r = r_game_create_opts(&go, &err)) || !r_game_prepare(r, rp.stage, &err) ||
        !r_target_create(&t, cd.src_w, cd.src_h, &err))
        goto done;
    if (passes)
        r_game_passes(r, passes == 2, stderr);
    cap *cp = cap_open(&cd, &sink, &err);
    if (!cp)
        goto done;

    rs_progress prog;
    rs_progress_start(&prog, "render", "frames", t_end - t_first, quiet ? RS_PROGRESS_OFF : (rs_progress_mode)progress);
    double last_report = 0;
    cli_progress_fd((int)progress_fd, 0, t_end - t_first, &last_report);
    job_render j;
    bool ok = job_render_begin(
        &j, &(job_render_desc){.rp = &rp, .game = r, .target = &t, .cap = cp, .name = replay, .first = t_first, .end = t_end},
        &err);
    while (ok && j.tick < t_end) {
        uint64_t tick = j.tick; /* every tick is a frame */
        if (stop_requested) {
            ok = false;
            rs_fail(&err, JOB_ERR_INTERRUPTED, "%s: interrupted at frame %" PRIu64 " of %" PRIu64 "; the partial output was removed",
                    out, tick, t_end);
            break;
        }
        ok = job_render_next(&j, &err) > 0 && job_poster_frame(&poster, tick, &t, cd.w, cd.h, &err);
        if (j.desync)
            break;
        rs_progress_update(&prog, tick + 1 - t_first);
        cli_progress_fd((int)progress_fd, tick + 1 - t_first, t_end - t_first, &last_report);
    }
    if (j.desync) {
        /* the render's own words: the replay's message, and that no output is left */
        ok = false;
        size_t n = strlen(err.msg);
        snprintf(err.msg + n, sizeof err.msg - n, "; nothing written");
        if (progress_fd >= 0)
            dprintf((int)progress_fd, "desync %" PRIu64 "\n", j.desync);
    }
    double secs = rs_progress_end(&prog);
    if (passes)
        r_game_report(r, stderr);
    cap_stats st;
    if (!cap_close(cp, ok, &st, &err))
        goto done;
    if (cd.hashes == stdout && fflush(stdout) != 0) {
        rs_fail(&err, JOB_ERR_WRITE, "--hashes -: write failed");
        goto done;
    }
    if (hf) {
        bool hok = fclose(hf) == 0;
        hf = NULL;
        if (!hok || rename(hpart, hashes) != 0) {
            /* the video and its hash list go together: without the list, no video */
            struct stat vst;
            if (stat(out, &vst) == 0 && S_ISREG(vst.st_mode))
                unlink(out);
            rs_fail(&err, JOB_ERR_WRITE, "%s: write failed; %s removed with it", hashes, out);
            goto done;
        }
        hpart[0] = 0;
    }
    if (!job_audio_commit(&audio, &err)) {
        /* the video and its WAV go together, as with the hash list */
        struct stat vst;
        if (stat(out, &vst) == 0 && S_ISREG(vst.st_mode))
            unlink(out);
        goto done;
    }
    if (!job_poster_commit(&poster, &err))
        goto done;
    uint64_t replay_fnv = 0; /* the manifest names the replay: join --replay checks it is the segments' */
    if (segment && (!cap_seg_replay_fnv(replay, &replay_fnv, &err) ||
                    !cap_seg_seal(out, segment, t_first, t_end, hashes, &replay_fnv, &err))) {
        /* no manifest, no segment: the files go too */
        unlink(out);
        if (hashes)
            unlink(hashes);
        if (poster.due)
            unlink(poster.path);
        if (audio.wav)
            unlink(audio.wav);
        goto done;
    }
    char said[300];
    job_audio_describe(&audio, &sink, said, sizeof said);
    if (!quiet)
        fprintf(stderr,
                "ringside render: wrote %s: %" PRIu64 " frames %dx%d (drawn at %dx%d, quality %s) in %.1f s, %.1f fps; %s capture, "
                "%s downscale, pbo %d, queue %d, high-water %d, %" PRIu64 " fence waits%s%s%s\n", /* the encoder last */
                out, st.frames, cd.w, cd.h, cd.src_w, cd.src_h, quality->name, secs, secs > 0 ? st.frames / secs : 0.0,
                cd.mode == CAP_SEQUENTIAL ? "sequential" : "async",
                (cd.downscale ? cd.downscale : (cd.mode == CAP_SEQUENTIAL ? CAP_DS_CPU : CAP_DS_GPU)) == CAP_DS_GPU ? "gpu" : "cpu",
                cd.pbo ? cd.pbo : CAP_DEFAULT_PBO, cd.no_writer || cd.mode == CAP_SEQUENTIAL ? 0 : cd.queue ? cd.queue : CAP_DEFAULT_QUEUE,
                st.high_water, st.fence_waits, said, sink.enc_name[0] ? "; encoder " : "", sink.enc_name);
    if (!quiet && poster.due)
        fprintf(stderr, "ringside render: poster %s: frame %" PRIu64 " (%s)\n", poster.path, poster.tick,
                job_poster_why_name(poster.why));
    if (!quiet && t_first > 0)
        fprintf(stderr,
                "ringside render: warm-up for tick %" PRIu64 ": the effects' history from tick %" PRIu64 " (%" PRIu64
                " ticks advanced, %" PRIu64 " of them drawn) in %.2f s; the frames took %.2f s (docs/effects.md, History)\n",
                t_first, j.warm_from, t_first - j.warm_from, j.warm_drawn, j.ms_warm / 1e3, j.ms_draw / 1e3);
    status = RS_EXIT_OK;
done:
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    if (status != RS_EXIT_OK && err.msg[0])
        cli_error("render", "%s", err.msg);
    if (hf)
        fclose(hf);
    if (hpart[0])
        unlink(hpart);
    job_poster_abandon(&poster);
    job_audio_free(&audio);
    if (p) {
        r_target_destroy(&t);
        r_game_destroy(r);
        plat_destroy(p);
    }
    rp_free(&rp);
    return status;
}
