/* ringside render: a replay to a video, headless, one frame per tick. */
#include <errno.h>
#include <getopt.h>
#include <inttypes.h>
#include <limits.h>
#include <signal.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../capture/cap.h"
#include "../capture/cap_seg.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "job_audio.h"
#include "job_hls.h"
#include "../runtime/audio/au.h"
#include "job_poster.h"
#include "job_out.h"
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
           "                       [--hashes FILE] [--backend egl|osmesa] [-q|-v]\n"
           "                       [-y|-n] [--format y4m|nut|mkv|mp4|webm] [--progress tty|plain|off]\n"
           "                       [--stage-file FILE] [--passes[=summary|frames]] [--mask] [--no-hud]\n"
           "                       [--hdr-format rgba16f|r11g11b10f]\n"
           "                       [--ticks A:B|A: | --from T [--to T | --duration T]]\n"
           "                       [--segment KEY] [--hls-dir DIR] [--progress-fd N] [--poster FILE.png]\n"
           "                       [--codec C] [--crf N | --bitrate RATE] [--preset P]\n"
           "                       [--pix-fmt yuv420p|yuv444p] [--hw auto|off|nvenc|vaapi]\n"
           "                       [--audio on|off] [--audio-bitrate RATE] [--loudness LUFS] [--wav FILE]\n"
           "                       [--jobs N|auto]\n\n"
           "Renders every tick of a replay headless and writes one video frame per tick\n"
           "(60 frames a second, exact).  The output type comes from the extension (any\n"
           "case) or --format: %s.\n"
           "The output appears only when complete; a failed render leaves nothing.\n"
           "REPLAY '-' reads the replay from standard input.\n\n"
           "  -o OUT             output file ('/dev/null' and other devices are streamed), an\n"
           "                     image sequence pattern such as frames/f%%06d.png, or '-': a\n"
           "                     stream on standard output (Y4M unless --format says nut or mkv);\n"
           "                     a reader that closes it early ends the render with the frame\n"
           "                     it stopped at and exit status 4\n"
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
           "                     --ticks, written only by the render whose range holds it (another\n"
           "                     says it wrote none, unless it is a --segment)\n"
           "  --backend B        GL backend (default egl, falling back to osmesa)\n"
           "  --stage-file FILE  the look to use instead of stages/<replay's stage>.stage\n"
           "                     (docs/stages.md)\n"
           "  --passes[=MODE]    time every render pass: a summary table at the end (default)\n"
           "                     or one line per frame (frames); skipped passes are listed\n"
           "  --mask             alpha = the fighters' mask, no HUD: RGBA cut-outs for artwork;\n"
           "                     needs an image pattern output (.png)\n"
           "  --no-hud           leave out bars, timer and announcements\n"
           "  --hdr-format F     the HDR buffer: rgba16f (default) or r11g11b10f (no alpha)\n"
           "  --ticks A:B        write only ticks A to B-1 (A: to the end; an end past the replay's\n"
           "                     is clamped to it, with a note), bit for bit the frames a full render\n"
           "                     writes there: the game runs from tick 0 and the effects that\n"
           "                     carry history (water, snow, mist, LSPSM) are warmed up first;\n"
           "                     image names and --hashes lines are numbered A..B-1\n"
           "  --from T, --to T, --duration T\n"
           "                     the same range in time: T is seconds (12.5), MM:SS (1:05) or\n"
           "                     HH:MM:SS (0:01:05.5), rounded to the nearest tick (1/60 s);\n"
           "                     --from alone renders to the end; not with --ticks\n"
           "  --segment KEY      write a segment that 'ringside join' can put together with the\n"
           "                     others (.mp4, .mkv or .webm): first frame a keyframe, closed GOP,\n"
           "                     timestamps from tick A; beside it OUT.seg, its manifest (KEY,\n"
           "                     ticks, sizes, checksums), written last.  KEY ([A-Za-z0-9._:-],\n"
           "                     at most 64) names the job and attempt; --hashes, if given, must\n"
           "                     be OUT with its extension replaced by .hashes (docs/segments.md)\n"
           "  --hls-dir DIR      also cut the video (.mp4 or .mkv, H.264 or HEVC) at its keyframes\n"
           "                     into HLS pieces in DIR, with the whole match's sound (DIR/track.K.ts,\n"
           "                     made once by a process of its own, 10 s a part): what 'ringside\n"
           "                     serve' streams while a job renders (docs/service.md, Watching\n"
           "                     while it renders).  With --segment the render ends when its\n"
           "                     pieces are cut and leaves the rest of the track to that process\n"
           "  --progress-fd N    also report progress on file descriptor N, for programs\n"
           "                     (ringside serve): 'frames DONE TOTAL' lines, 'desync TICK'\n"
           "                     if the replay's state hashes stop matching, and 'hls-failed'\n"
           "                     when the video is written but --hls-dir's pieces are not\n"
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
           CLI_LOG_HELP
           "\nThe replay's state-hash checkpoints are checked as the game runs: a replay that\n"
           "desyncs (inputs that no longer produce the recorded game) fails with the first\n"
           "tick that differs, and nothing is written.\n\n"
           "examples:\n"
           "  ringside render demos/dojo.rsr -o dojo.mp4\n"
           "                     the default job: 640x360, standard quality, AAC sound\n"
           "  ringside render m.rsr -o m.webm --size 1280x720 --quality high\n"
           "                     720p VP9, 2x2 pixels drawn per output pixel\n"
           "  ringside render m.rsr --from 1:00 --duration 10 -o clip.mkv\n"
           "                     ten seconds from the first minute\n"
           "  cat m.rsr | ringside render - -o - | ffplay -\n"
           "                     a replay from a pipe, watched as it renders (Y4M)\n"
           "  ringside render m.rsr -o frames/f%%06d.png --ticks 600:660\n"
           "                     one second as PNG images f000600.png .. f000659.png\n",
           cap_sink_formats(), CLI_SIZE_MIN, R_RENDER_MAX, cli_quality_help(), CAP_MAX_SCALE, CAP_MAX_PBO, CAP_DEFAULT_PBO, CAP_DEFAULT_QUEUE, JOB_POSTER_AFTER_KO, JOB_AUDIO_LUFS_MIN,
           JOB_AUDIO_LUFS_MAX, JOB_AUDIO_LUFS_DEFAULT, JOB_SPLIT_MIN_FRAMES);
}

/* long-only options (no letter): the encoder's */
enum { OPT_CODEC = 0x200, OPT_CRF, OPT_BITRATE, OPT_PRESET, OPT_PIXFMT, OPT_HW, OPT_JOBS, OPT_FROM, OPT_TO, OPT_DURATION,
       OPT_HLS_DIR };

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

static const struct option opts[] = {
    {"output", required_argument, 0, 'o'},     {"size", required_argument, 0, 's'},
    {"render-size", required_argument, 0, 'r'}, {"capture", required_argument, 0, 'c'},
    {"downscale", required_argument, 0, 'd'},  {"pbo", required_argument, 0, 'p'},
    {"queue", required_argument, 0, 'Q'},      {"hashes", required_argument, 0, 'H'},
    {"backend", required_argument, 0, 'b'},    {"filter", required_argument, 0, 'F'},    {"stage-file", required_argument, 0, 'T'},
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
    {"jobs", required_argument, 0, OPT_JOBS}, {"from", required_argument, 0, OPT_FROM},
    {"to", required_argument, 0, OPT_TO},     {"duration", required_argument, 0, OPT_DURATION},
    {"hls-dir", required_argument, 0, OPT_HLS_DIR}, {0}};

/* What the command line asks for. */
typedef struct render_opts {
    const char *replay, *out, *hashes, *backend, *segment, *format, *poster, *hls_dir;
    bool overwrite, quiet;
    bool audio_off;           /* --audio off given: --hls-dir's pieces get no sound */
    int progress;             /* rs_progress_mode, or RS_PROGRESS_AUTO */
    cap_desc cd;
    cap_enc enc;
    job_audio audio;
    const r_preset *quality;
    r_game_opts go;
    int passes;               /* 1 summary, 2 per frame */
    long first, end;          /* --ticks; end -1: the whole replay */
    bool ticks_given;
    long from, to, duration;  /* --from, --to, --duration in ticks; -1: not given */
    long progress_fd;
    int jobs;                 /* 0: auto */
    cap_pixfmt fmt;           /* RGBA for an image pattern, else I420 */
    char seg_hashes[1100], seg_manifest[1100];
} render_opts;

/* Picks one of two words for an option: *out = the value of the one given. */
static bool word2(const char *opt, const char *arg, const char *a, int va, const char *b, int vb, int *out)
{
    if (!strcmp(arg, a))
        *out = va;
    else if (!strcmp(arg, b))
        *out = vb;
    else {
        cli_error("render", "%s '%s': expected %s or %s", opt, arg, a, b);
        return false;
    }
    return true;
}

/* --ticks A:B, or A: (to the end) */
static bool parse_ticks(render_opts *o, const char *arg)
{
    char *colon = strchr(arg, ':'), a[32];
    if (!colon || (size_t)(colon - arg) >= sizeof a) {
        cli_error("render", "--ticks '%s': expected A:B or A:, such as 600:660", arg);
        return false;
    }
    memcpy(a, arg, (size_t)(colon - arg));
    a[colon - arg] = 0;
    if (!cli_int("--ticks start", a, 0, 100000000, &o->first))
        return false;
    o->end = -1; /* "A:": to the replay's end */
    if (colon[1] && !cli_int("--ticks end", colon + 1, 1, 100000000, &o->end))
        return false;
    if (o->end >= 0 && o->end <= o->first) {
        cli_error("render", "--ticks '%s': the end must be after the start", arg);
        return false;
    }
    return true;
}

/* The encoder's options (long only). */
static bool encoder_option(cap_enc *enc, int c, const char *arg)
{
    long v;
    switch (c) {
    case OPT_CODEC:
        if (cap_codec_parse(arg, &enc->codec))
            return true;
        cli_error("render", "--codec '%s': expected h264, hevc, vp9 or av1", arg);
        return false;
    case OPT_CRF: if (!cli_int("--crf", arg, 1, 255, &v)) return false; enc->crf = (int)v; return true;
    case OPT_BITRATE:
        if (cap_bitrate_parse(arg, &enc->bitrate))
            return true;
        cli_error("render", "--bitrate '%s': expected bits a second such as 4M, 800k or 2500000 (10k..1000M)", arg);
        return false;
    case OPT_PRESET: snprintf(enc->preset, sizeof enc->preset, "%s", arg); return true;
    case OPT_PIXFMT:
        if (cap_chroma_parse(arg, &enc->chroma))
            return true;
        cli_error("render", "--pix-fmt '%s': expected yuv420p or yuv444p", arg);
        return false;
    default: /* OPT_HW */
        if (cap_hw_parse(arg, &enc->hw))
            return true;
        cli_error("render", "--hw '%s': expected auto, off, nvenc or vaapi", arg);
        return false;
    }
}

/* How the frames are drawn and captured. */
static bool picture_option(render_opts *o, int c, const char *arg)
{
    cap_desc *cd = &o->cd;
    long v;
    int k;
    switch (c) {
    case 's': return cli_out_size("--size", arg, &cd->w, &cd->h);
    case 'r': return cli_size("--render-size", arg, R_RENDER_MAX, &cd->src_w, &cd->src_h);
    case 'L': return (o->quality = cli_quality("render", arg)) != NULL;
    case 'c':
        if (!word2("--capture", arg, "async", CAP_ASYNC, "sequential", CAP_SEQUENTIAL, &k))
            return false;
        cd->mode = (cap_mode)k;
        return true;
    case 'd':
        if (!word2("--downscale", arg, "gpu", CAP_DS_GPU, "cpu", CAP_DS_CPU, &k))
            return false;
        cd->downscale = (cap_downscale)k;
        return true;
    case 'p': if (!cli_int("--pbo", arg, 1, CAP_MAX_PBO, &v)) return false; cd->pbo = (int)v; return true;
    case 'Q':
        if (!cli_int("--queue", arg, 0, 1000, &v))
            return false;
        cd->queue = (int)v;
        cd->no_writer = v == 0;
        return true;
    case 'F':
        if (cap_filter_parse(arg, &cd->filter))
            return true;
        cli_error("render", "--filter '%s': expected box, bilinear, nearest or lanczos3", arg);
        return false;
    case 'T': o->go.stage_file = arg; return true;
    case 'P': return cli_passes("render", arg, &o->passes);
    case 'M': o->go.mask = true; return true;
    case 'U': o->go.no_hud = true; return true;
    default: /* 'X' */
        if (!cli_hdr_format(arg, &k))
            return false;
        o->go.hdr_format = r_game_hdr_of(k);
        return true;
    }
}

/* One option; -1 to go on, else the exit status (--help: RS_EXIT_OK). */
static int render_option(render_opts *o, int c, const char *arg, char **argv)
{
    long v;
    switch (c) {
    case 's': case 'r': case 'L': case 'c': case 'd': case 'p': case 'Q': case 'F': case 'T': case 'P': case 'M': case 'U':
    case 'X':
        return picture_option(o, c, arg) ? -1 : RS_EXIT_USAGE;
    case OPT_CODEC: case OPT_CRF: case OPT_BITRATE: case OPT_PRESET: case OPT_PIXFMT: case OPT_HW:
        return encoder_option(&o->enc, c, arg) ? -1 : RS_EXIT_USAGE;
    case JOB_AUDIO_OPT_AUDIO: case JOB_AUDIO_OPT_BITRATE: case JOB_AUDIO_OPT_LOUDNESS: case JOB_AUDIO_OPT_WAV:
        if (!job_audio_option(&o->audio, "render", c, arg))
            return RS_EXIT_USAGE;
        o->audio_off = o->audio.mode == JOB_AUDIO_OFF; /* asked for: a segment is silent anyway */
        return -1;
    case 'o': o->out = arg; return -1;
    case 'K': o->ticks_given = true; return parse_ticks(o, arg) ? -1 : RS_EXIT_USAGE;
    case OPT_FROM: return cli_time("--from", arg, &o->from) ? -1 : RS_EXIT_USAGE;
    case OPT_TO: return cli_time("--to", arg, &o->to) ? -1 : RS_EXIT_USAGE;
    case OPT_DURATION: return cli_time("--duration", arg, &o->duration) ? -1 : RS_EXIT_USAGE;
    case 'H': o->hashes = arg; return -1;
    case OPT_HLS_DIR: o->hls_dir = arg; return -1;
    case 'S':
        if (!cap_seg_key_ok(arg)) {
            cli_error("render", "--segment '%s': expected a key of 1 to %d characters from A-Z a-z 0-9 . _ : -", arg,
                      CAP_SEG_KEY_MAX);
            return RS_EXIT_USAGE;
        }
        o->segment = arg;
        return -1;
    case 'b': o->backend = arg; return -1;
    case 'G': return cli_int("--progress-fd", arg, 3, 1023, &o->progress_fd) ? -1 : RS_EXIT_USAGE;
    case 'h': help(); return RS_EXIT_OK;
    case 'y': o->overwrite = true; return -1;
    case 'n': o->overwrite = false; return -1;
    case 'f': o->format = arg; return -1;
    case 'g': return cli_progress_mode("render", arg, &o->progress) ? -1 : RS_EXIT_USAGE;
    case 'O': o->poster = arg; return -1;
    case OPT_JOBS:
        if (!strcmp(arg, "auto"))
            o->jobs = 0;
        else if (!cli_int("--jobs", arg, 1, JOB_SPLIT_MAX, &v))
            return RS_EXIT_USAGE;
        else
            o->jobs = (int)v;
        return -1;
    default: return cli_bad_option("render", argv);
    }
}

/* --from / --to / --duration (seconds) into the tick range --ticks takes */
static bool time_range(render_opts *o)
{
    if (o->from < 0 && o->to < 0 && o->duration < 0)
        return true;
    if (o->ticks_given) {
        cli_error("render", "--ticks and --from/--to/--duration say the same thing: give one of them");
        return false;
    }
    if (o->to >= 0 && o->duration >= 0) {
        cli_error("render", "--to and --duration both say where to stop: give one of them");
        return false;
    }
    o->first = o->from < 0 ? 0 : o->from;
    o->end = o->to >= 0 ? o->to : o->duration >= 0 ? o->first + o->duration : -1;
    if (o->end >= 0 && o->end <= o->first) {
        cli_error("render", "--from/--to/--duration: the end (%.3f s) must be after the start (%.3f s)", o->end / 60.0,
                  o->first / 60.0);
        return false;
    }
    return true;
}

/* What can be refused from the options alone; -1 to go on, else the exit status. */
static int check_options(render_opts *o)
{
    rs_err err = {0};
    if (!time_range(o))
        return RS_EXIT_USAGE;
    if (!o->out) {
        cli_error("render", "-o OUT is required");
        return RS_EXIT_USAGE;
    }
    if (!strcmp(o->out, "-") && o->hashes && !strcmp(o->hashes, "-")) {
        cli_error("render", "-o - and --hashes - both write to standard output: give --hashes a file");
        return RS_EXIT_USAGE;
    }
    if (!strcmp(o->out, "-") && isatty(1)) {
        cli_error("render", "-o -: standard output is a terminal; pipe it into a program or a file");
        return RS_EXIT_USAGE;
    }
    o->fmt = strchr(o->out, '%') ? CAP_RGBA : CAP_I420;
    if (o->go.mask && o->fmt != CAP_RGBA) {
        cli_error("render", "--mask writes RGBA images: give -o an image pattern such as cut/f%%04d.png, not %s", o->out);
        return RS_EXIT_USAGE;
    }
    if (o->segment) {
        /* join finds a segment's list by name, so there is one name for it */
        cap_seg_hashes_path(o->out, o->seg_hashes, sizeof o->seg_hashes);
        cap_seg_manifest_path(o->out, o->seg_manifest, sizeof o->seg_manifest);
        if (!cap_seg_format_of(o->out)) {
            cli_error("render", "--segment writes .mp4, .mkv or .webm, not %s", o->out);
            return RS_EXIT_USAGE;
        }
        if (o->hashes && strcmp(o->hashes, o->seg_hashes) != 0) {
            cli_error("render", "--segment: --hashes must be %s (where join looks for it), not %s", o->seg_hashes, o->hashes);
            return RS_EXIT_USAGE;
        }
    }
    if (o->hls_dir) {
        const char *f = cap_seg_format_of(o->out);
        if (!f || !strcmp(f, "webm") || o->enc.codec == CAP_CODEC_VP9 || o->enc.codec == CAP_CODEC_AV1) {
            cli_error("render", "--hls-dir: HLS pieces are H.264 or HEVC from a .mp4 or .mkv file, not %s%s", o->out,
                      f && strcmp(f, "webm") ? " with --codec vp9 or av1" : "");
            return RS_EXIT_USAGE;
        }
    }
    o->go.quiet = o->quiet;
    o->go.q = o->quality->q;
    if (!o->cd.src_w) /* the quality's scale, unless --render-size said */
        r_preset_render_size(o->quality, o->cd.w, o->cd.h, R_RENDER_MAX, &o->cd.src_w, &o->cd.src_h);
    if (!cap_check_sizes_for(o->fmt, o->cd.src_w, o->cd.src_h, o->cd.w, o->cd.h, &err)) {
        cli_error("render", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    return -1;
}

/* The command line into o; -1 to go on, else the exit status. */
static int parse_options(int argc, char **argv, render_opts *o)
{
    *o = (render_opts){.progress = RS_PROGRESS_AUTO, .cd = {.w = 640, .h = 360}, .quality = &r_presets[R_PRESET_DEFAULT],
                       .end = -1, .progress_fd = -1, .from = -1, .to = -1, .duration = -1};
    o->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    int c, status;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:hyn", opts, NULL)) != -1)
        if ((status = render_option(o, c, optarg, argv)) >= 0)
            return status;
    if (optind + 1 != argc) {
        cli_error("render", optind >= argc ? "a REPLAY file is required" : "unexpected argument '%s'", argv[argc - 1]);
        return cli_usage_error("render");
    }
    o->replay = argv[optind];
    return check_options(o);
}

/* A render under way: what it holds, released by render_free. */
typedef struct render_run {
    render_opts *o;
    rs_err err;
    rp_replay rp;
    uint64_t first, end;      /* the ticks drawn */
    cap_sink sink;
    job_poster poster;
    job_out outs;
    plat *p;
    r_game *r;
    r_target t;
    int split;                /* segments drawn at once (--jobs), 1: this process draws */
} render_run;

/* --jobs: how many segments; may create the context (kept in run->p). */
static int plan_split(render_run *run)
{
    render_opts *o = run->o;
    bool splittable = o->fmt == CAP_I420 && !o->format && !o->segment && !o->passes && !o->audio.wav && cap_seg_format_of(o->out);
    if (o->jobs > 1 && !splittable) {
        cli_error("render", "--jobs %d: only a .mp4, .mkv or .webm file is rendered in segments at once (not %s%s)", o->jobs,
                  o->segment ? "with --segment" : o->passes ? "with --passes" : o->audio.wav ? "with --wav" : o->format ? "with --format" : o->out,
                  "");
        return RS_EXIT_USAGE;
    }
    run->split = 1;
    if (splittable && o->jobs != 1) {
        uint64_t frames = run->end - run->first;
        run->split = o->jobs ? (frames < (uint64_t)o->jobs ? (int)frames : o->jobs) : job_split_auto(frames);
        if (o->jobs == 0 && run->split > 1) {
            /* auto: a software rasteriser gains, a GPU does not need it; the
             * context this render would draw with says which (and is kept if so) */
            if (!(run->p = plat_create(&(plat_desc){.backend = o->backend, .hidden = true}, &run->err)))
                return cli_plat_status(&run->err);
            if (!software_gl())
                run->split = 1;
            else
                plat_destroy(run->p), run->p = NULL;
        }
    }
    return -1;
}

/* Everything that can be checked without rendering, first; -1 to go on. */
static int prepare(render_run *run)
{
    render_opts *o = run->o;
    rs_err *err = &run->err;
    if (!rp_read(o->replay, &run->rp, err))
        return RS_EXIT_FAIL;
    const char *name = strcmp(o->replay, "-") ? o->replay : RP_STDIN_NAME;
    double len_s = (double)run->rp.ticks / 60.0;
    if (o->first >= (long)run->rp.ticks) {
        if (o->ticks_given)
            rs_fail(err, JOB_ERR_TICKS, "%s: --ticks %ld: starts past the replay's end (%" PRIu64 " ticks)", name, o->first,
                    run->rp.ticks);
        else
            rs_fail(err, JOB_ERR_TICKS, "%s: --from %.3f s: starts past the replay's end (%.3f s, %" PRIu64 " ticks)", name,
                    o->first / 60.0, len_s, run->rp.ticks);
        return RS_EXIT_USAGE;
    }
    if (o->end > (long)run->rp.ticks) { /* as ffmpeg's -t past the end: clamped, with a word */
        if (rs_log_on(RS_LOG_WARNING)) {
            if (o->ticks_given)
                fprintf(stderr, "ringside render: --ticks %ld:%ld: the replay ends at tick %" PRIu64 ", so ticks %ld:%" PRIu64
                                " are drawn\n",
                        o->first, o->end, run->rp.ticks, o->first, run->rp.ticks);
            else
                fprintf(stderr, "ringside render: the replay ends at %.3f s, so %.3f s to %.3f s are drawn (not to %.3f s)\n",
                        len_s, o->first / 60.0, len_s, o->end / 60.0);
        }
        o->end = (long)run->rp.ticks;
    }
    run->first = (uint64_t)o->first, run->end = o->end < 0 ? run->rp.ticks : (uint64_t)o->end;
    if (!job_poster_plan(&run->poster, o->poster, &run->rp, run->first, run->end, err) ||
        !cap_sink_for_format(o->out, o->format, o->cd.w, o->cd.h, &run->sink, err))
        return err->code == CAP_ERR_OUTPUT ? RS_EXIT_USAGE : RS_EXIT_FAIL; /* a name we cannot write is bad usage */
    /* every output this render writes, checked before anything is touched */
    run->outs.pattern = run->sink.fmt == CAP_RGBA;
    run->outs.first = run->first, run->outs.end = run->end;
    if (!job_out_check(&run->outs)) {
        err->msg[0] = 0; /* said */
        return RS_EXIT_FAIL;
    }
    run->sink.index_base = run->first; /* frame numbers are ticks: f%04d.png of --ticks 600:660 is f0600..f0659 */
    run->sink.segment = o->segment != NULL;
    run->sink.closed_gop = o->hls_dir != NULL; /* x265 opens its GOPs otherwise: no place to cut */
    bool usage;
    if (!job_audio_check(&o->audio, "render", &run->sink, &usage, err))
        return usage ? RS_EXIT_USAGE : RS_EXIT_FAIL;
    render_meta(&run->sink, o->replay, &run->rp);
    if (!cap_sink_encoder(&run->sink, &o->enc, err))
        return err->code == CAP_ERR_ENC_SETTING ? RS_EXIT_USAGE : RS_EXIT_FAIL;
    if (run->sink.enc_note[0])
        cli_info("render", "%s", run->sink.enc_note); /* once: the choice is made here, for the whole run */
    /* --jobs: segments drawn at once by processes of their own, then joined
     * (job_split.h), where the output can be joined */
    return plan_split(run);
}

/* "640x360", or "640x360, the scene at 480x270" when the quality draws
 * the scene smaller (r_quality.scene_pct, or stage_pct: the look's own
 * size, r_stage.standard_scene_pct) */
static void drawn_at(const render_opts *o, int stage_pct, char *out, size_t n)
{
    const cap_desc *cd = &o->cd;
    int sw, sh;
    r_scene_size(r_scene_pct(&o->quality->q, stage_pct), cd->src_w, cd->src_h, &sw, &sh);
    if (sw == cd->src_w && sh == cd->src_h)
        snprintf(out, n, "%dx%d", cd->src_w, cd->src_h);
    else
        snprintf(out, n, "%dx%d, the scene at %dx%d", cd->src_w, cd->src_h, sw, sh);
}

/* The replay read from standard input, written (rp_write: checked, read
 * back) into a temporary folder the segments' processes can read ($TMPDIR,
 * else /tmp); path gets the file's name, stdin_copy_free removes both. */
static bool stdin_copy(const rp_replay *rp, char *path, size_t n, rs_err *err)
{
    const char *dir = getenv("TMPDIR");
    snprintf(path, n, "%s/ringside-stdin-XXXXXX", dir && *dir ? dir : "/tmp");
    if (!mkdtemp(path)) {
        rs_fail(err, JOB_ERR_PROCESS, "%s: cannot keep the replay from standard input for the segments: %s", path,
                strerror(errno));
        path[0] = 0;
        return false;
    }
    size_t l = strlen(path);
    snprintf(path + l, n - l, "/replay.rsr");
    if (rp_write(path, rp, err))
        return true;
    path[l] = 0;
    rmdir(path);
    path[0] = 0;
    return false;
}

static void stdin_copy_free(char *path)
{
    if (!path[0])
        return;
    unlink(path);
    char *slash = strrchr(path, '/');
    *slash = 0;
    rmdir(path);
}

/* The segments of a parallel render, each a process of its own, joined. */
static int render_split(render_run *run, int argc, char **argv)
{
    render_opts *o = run->o;
    /* what every segment would refuse, refused once here: the look */
    r_stage look;
    if (o->go.stage_file ? !r_stage_load(&look, o->go.stage_file, &run->err) : !r_stage_for_game(&look, run->rp.stage, &run->err))
        return RS_EXIT_FAIL;
    /* the user's options that decide the pictures and the encoding, for every segment */
    const char *pass[96];
    int np = 0, c;
    optind = 1;
    while ((c = getopt_long(argc, argv, "o:hyn", opts, NULL)) != -1 && np < 94) {
        if (!for_segments(c))
            continue;
        for (const struct option *op = opts; op->name; op++)
            if (op->val == c) {
                static char name[96][40];
                snprintf(name[np], sizeof name[np], "--%s", op->name);
                pass[np] = name[np];
                np++;
                if (op->has_arg == required_argument)
                    pass[np++] = optarg;
                break;
            }
    }
    if (rs_log_explicit && np < 94) { /* main took --loglevel from argv: the segments say as much (or as little) */
        pass[np++] = "--loglevel";
        pass[np++] = rs_log_name(rs_log_level);
    }
    pass[np] = NULL;
    char exe[1100], what[160];
    ssize_t ne = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (ne <= 0)
        return rs_fail(&run->err, JOB_ERR_PROCESS, "cannot find this program (/proc/self/exe): %s", strerror(errno)), RS_EXIT_FAIL;
    exe[ne] = 0;
    const cap_desc *cd = &o->cd;
    char drawn[64];
    drawn_at(o, look.standard_scene_pct, drawn, sizeof drawn);
    snprintf(what, sizeof what, "%dx%d (drawn at %s, quality %s)", cd->w, cd->h, drawn, o->quality->name);
    /* a replay from standard input: the segments read a copy of it */
    char copy[PATH_MAX] = "";
    if (!strcmp(o->replay, "-") && !stdin_copy(&run->rp, copy, sizeof copy, &run->err))
        return RS_EXIT_FAIL;
    job_split_desc jd = {.exe = exe, .replay = copy[0] ? copy : o->replay, .out = o->out, .first = run->first, .end = run->end, .jobs = run->split,
                         .pass = pass, .rp = &run->rp, .sink = &run->sink, .audio = &o->audio, .hashes = o->hashes,
                         .poster = run->poster.due ? o->poster : NULL, .overwrite = o->overwrite,
                         .progress = o->quiet ? RS_PROGRESS_OFF : (rs_progress_mode)o->progress, .progress_fd = (int)o->progress_fd,
                         .quiet = o->quiet, .what = what, .said = run->sink.enc_note, .stop = &stop_requested};
    int status = job_split_run(&jd, &run->err);
    stdin_copy_free(copy);
    return status;
}

/* The frames, one a tick, into the capture; false with run->err filled. */
static bool draw_frames(render_run *run, cap *cp, job_render *j, double *secs)
{
    render_opts *o = run->o;
    rs_err *err = &run->err;
    uint64_t total = run->end - run->first;
    int pfd = (int)o->progress_fd;
    rs_progress prog;
    rs_progress_start(&prog, "render", "frames", total, o->quiet ? RS_PROGRESS_OFF : (rs_progress_mode)o->progress);
    double last_report = 0;
    cli_progress_fd(pfd, 0, total, &last_report);
    bool ok = job_render_begin(j, &(job_render_desc){.rp = &run->rp, .game = run->r, .target = &run->t, .cap = cp,
                                                     .name = o->replay, .first = run->first, .end = run->end},
                               err);
    while (ok && j->tick < run->end) {
        uint64_t tick = j->tick; /* every tick is a frame */
        if (stop_requested) {
            ok = false;
            rs_fail(err, JOB_ERR_INTERRUPTED, "%s: interrupted at frame %" PRIu64 " of %" PRIu64 "; the partial output was removed",
                    o->out, tick, run->end);
            break;
        }
        ok = job_render_next(j, err) > 0 && job_poster_frame(&run->poster, tick, &run->t, o->cd.w, o->cd.h, err);
        if (j->desync)
            break;
        rs_progress_update(&prog, tick + 1 - run->first);
        cli_progress_fd(pfd, tick + 1 - run->first, total, &last_report);
    }
    if (j->desync) {
        /* the render's own words: the replay's message, and that no output is left */
        ok = false;
        size_t n = strlen(err->msg);
        snprintf(err->msg + n, sizeof err->msg - n, "; nothing written");
        if (pfd >= 0)
            dprintf(pfd, "desync %" PRIu64 "\n", j->desync);
    }
    *secs = rs_progress_end(&prog);
    return ok;
}

/* The lines a finished render prints (at the info level). */
static void summary(const render_run *run, const cap_stats *st, const job_render *j, double secs)
{
    const render_opts *o = run->o;
    const cap_desc *cd = &o->cd;
    char said[300], drawn[64];
    drawn_at(o, r_game_stage(run->r)->standard_scene_pct, drawn, sizeof drawn); /* the look it drew */
    job_audio_describe(&o->audio, &run->sink, said, sizeof said);
    fprintf(stderr,
            "ringside render: wrote %s: %" PRIu64 " frames %dx%d (drawn at %s, quality %s) in %.1f s, %.1f fps; %s capture, "
            "%s downscale, pbo %d, queue %d, high-water %d, %" PRIu64 " fence waits%s%s%s\n", /* the encoder last */
            o->out, st->frames, cd->w, cd->h, drawn, o->quality->name, secs, secs > 0 ? st->frames / secs : 0.0,
            cd->mode == CAP_SEQUENTIAL ? "sequential" : "async",
            (cd->downscale ? cd->downscale : (cd->mode == CAP_SEQUENTIAL ? CAP_DS_CPU : CAP_DS_GPU)) == CAP_DS_GPU ? "gpu" : "cpu",
            cd->pbo ? cd->pbo : CAP_DEFAULT_PBO, cd->no_writer || cd->mode == CAP_SEQUENTIAL ? 0 : cd->queue ? cd->queue : CAP_DEFAULT_QUEUE,
            st->high_water, st->fence_waits, said, run->sink.enc_name[0] ? "; encoder " : "", run->sink.enc_name);
    if (run->poster.due)
        fprintf(stderr, "ringside render: poster %s: frame %" PRIu64 " (%s)\n", run->poster.path, run->poster.tick,
                job_poster_why_name(run->poster.why));
    if (run->first > 0)
        fprintf(stderr,
                "ringside render: warm-up for tick %" PRIu64 ": the effects' history from tick %" PRIu64 " (%" PRIu64
                " ticks advanced, %" PRIu64 " of them drawn) in %.2f s; the frames took %.2f s (docs/effects.md, History)\n",
                run->first, j->warm_from, run->first - j->warm_from, j->warm_drawn, j->ms_warm / 1e3, j->ms_draw / 1e3);
}

/* This process draws every frame: the outputs opened, the frames, then
 * the outputs in place together. */
static int render_here(render_run *run)
{
    render_opts *o = run->o;
    rs_err *err = &run->err;
    if (!job_out_open(&run->outs, err))
        return RS_EXIT_FAIL;
    o->cd.hashes = run->outs.hash_file;
    o->cd.hashes_name = o->hashes;
    if (!job_audio_plan(&o->audio, &run->sink, &run->rp, o->replay, run->first, run->end, err))
        return RS_EXIT_FAIL;
    double t0 = rs_now();
    if (!run->p && !(run->p = plat_create(&(plat_desc){.backend = o->backend, .hidden = true}, err)))
        return cli_plat_status(err);
    double t1 = rs_now();
    if (!(run->r = r_game_create_opts(&o->go, err)) || !r_game_prepare(run->r, run->rp.stage, err) ||
        !r_target_create(&run->t, o->cd.src_w, o->cd.src_h, err))
        return RS_EXIT_FAIL;
    cli_debug("render", "GL: %s (%s), %s, %s; start-up %.3f s: context %.3f s, renderer and stage %.3f s",
              plat_backend_name(run->p), plat_detail(run->p), glcaps.renderer, glcaps.version, rs_now() - t0, t1 - t0,
              rs_now() - t1);
    if (o->passes)
        r_game_passes(run->r, o->passes == 2, stderr);
    cap *cp = cap_open(&o->cd, &run->sink, err);
    if (!cp)
        return RS_EXIT_FAIL;
    job_render j;
    double secs;
    bool ok = draw_frames(run, cp, &j, &secs);
    if (o->passes)
        r_game_report(run->r, stderr);
    cap_stats st;
    if (!cap_close(cp, ok, &st, err) || !job_out_commit(&run->outs, err))
        return RS_EXIT_FAIL;
    if (!o->quiet)
        summary(run, &st, &j, secs);
    /* a poster asked for and not written says so, even without the summary (a
     * segment's is skipped on purpose: the segment that draws it writes it) */
    if (o->poster && !run->poster.due && !o->segment && rs_log_on(RS_LOG_WARNING))
        fprintf(stderr,
                "ringside render: --poster %s: not written: its frame, tick %" PRIu64 " (%s), is outside --ticks %" PRIu64
                ":%" PRIu64 "\n",
                o->poster, run->poster.tick, job_poster_why_name(run->poster.why), run->first, run->end);
    return RS_EXIT_OK;
}

/* --hls-dir: the track begun before the frames; after them the output,
 * in place, cut into HLS pieces (job_hls.h).  A failure of the cut leaves
 * the video (it is good) and exits 1. */
static bool hls_start(render_run *run, job_hls *h)
{
    const render_opts *o = run->o;
    /* the sound bank (0.3 s) built before the track's maker is forked,
     * when this render mixes the match too: then both have it */
    if (!o->audio_off && (o->audio.mode == JOB_AUDIO_ON || o->audio.wav))
        au_bank_get(0);
    job_hls_desc d = {.dir = o->hls_dir, .video = o->out, .segment = o->segment, .hashes = o->hashes != NULL,
                      .rp = &run->rp, .name = o->replay, .lufs = o->audio.lufs, .bitrate = o->audio.bitrate,
                      .silent = o->audio_off, .first = run->first, .end = run->end};
    return job_hls_start(h, &d, &run->err);
}

static int hls_finish(render_run *run, job_hls *h, int status)
{
    double t0 = rs_now();
    if (!job_hls_finish(h, status == RS_EXIT_OK, &run->err)) {
        /* the video is good: a program (ringside serve) keeps it and lists no pieces */
        if (status == RS_EXIT_OK && run->o->progress_fd >= 0)
            dprintf((int)run->o->progress_fd, "hls-failed\n");
        return status == RS_EXIT_OK ? RS_EXIT_FAIL : status;
    }
    if (status == RS_EXIT_OK)
        cli_debug("render", "HLS pieces of %s in %s: waited %.2f s for the match's sound, the cut %.2f s in all",
                  run->o->out, run->o->hls_dir, h->wait_s, rs_now() - t0);
    return status;
}

int cmd_render(int argc, char **argv)
{
    render_opts o;
    int status = parse_options(argc, argv, &o);
    if (status >= 0)
        return status;
    render_run run = {.o = &o};
    run.outs = (job_out){.cmd = "render", .overwrite = o.overwrite, .video = o.out, .hashes = o.hashes,
                         .manifest = o.segment ? o.seg_manifest : NULL, .key = o.segment, .replay = o.replay,
                         .poster = &run.poster, .audio = &o.audio};
    /* Ctrl-C and SIGTERM from here on end the render cleanly (nothing
     * partial left), also during start-up: the GL context, shaders and the
     * IBL prefilter can take seconds, and outputs are created before the
     * first frame.  (A background job of a script starts with SIGINT
     * ignored; the handler replaces that too.) */
    stop_requested = 0;
    struct sigaction sa = {0}, old_int, old_term, old_pipe, ign = {0};
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, &old_int);
    sigaction(SIGTERM, &sa, &old_term);
    /* a reader that closes -o - early is an error we report (the frame it
     * stopped at, exit status 4), not a silent death by SIGPIPE */
    ign.sa_handler = SIG_IGN;
    sigaction(SIGPIPE, &ign, &old_pipe);
    status = prepare(&run);
    job_hls hls = {0};
    if (status < 0 && o.hls_dir && !hls_start(&run, &hls))
        status = RS_EXIT_FAIL;
    if (status < 0)
        status = run.split > 1 ? render_split(&run, argc, argv) : render_here(&run);
    if (o.hls_dir)
        status = hls_finish(&run, &hls, status);
    sigaction(SIGINT, &old_int, NULL);
    sigaction(SIGTERM, &old_term, NULL);
    sigaction(SIGPIPE, &old_pipe, NULL);
    if (status == RS_EXIT_FAIL && run.err.code == CAP_ERR_PIPE_CLOSED)
        status = RS_EXIT_PIPE;
    if (status != RS_EXIT_OK && run.err.msg[0])
        cli_error("render", "%s", run.err.msg);
    job_out_abandon(&run.outs);
    job_audio_free(&o.audio);
    if (run.p) {
        r_target_destroy(&run.t);
        r_game_destroy(run.r);
        plat_destroy(run.p);
    }
    rp_free(&run.rp);
    return status;
}
