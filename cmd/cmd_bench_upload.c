/* ringside bench upload: the three ways of getting a 4:2:0 movie frame onto
 * the Y/Cb/Cr textures (player/mv_up.h), measured side by side in one run.
 *
 * Every mode plays the same synthetic frames the way mv_player drives it on
 * one 60 Hz tick, as fast as possible (no pacing):
 *   produce     the decoder writes the frame into its slot (memcpy): client
 *               memory for direct and pbo, mapped GPU memory for persistent
 *   direct      mv_up_upload: glTexSubImage2D from client memory
 *   pbo         mv_up_commit (textures from the buffer filled last tick),
 *               then mv_up_stage of the next frame into the other buffer
 *   persistent  wait for the slot's fence (ring of 3), then mv_up_upload
 *               from the slot's offset in the persistently mapped buffer
 * then the conversion draw into an offscreen target of the frame's size.
 *
 * "total" is throughput: one glFinish at the end of the run.  "synced" is a
 * shorter run with glFinish after every frame, which is what a vsync'd
 * present waits for; a PBO path that silently synchronises shows up there
 * and in the GL column, not in a guess. */
#include <getopt.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../player/mv.h"
#include "../player/mv_csp.h"
#include "../player/mv_up.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_target.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "job_err.h"

#define MAX_RUNS 15
#define NFRAMES 8 /* distinct synthetic frames */
#define NSLOTS 3  /* decoder slots; the persistent ring */
#define WARMUP 10

typedef struct sample {
    double total, synced, produce, copy, gl, fence, waits; /* ms per frame; waits: count per run */
} sample;

typedef struct mode_res {
    int mode;
    mv_up *u;
    bool avail;
    char why[256];
    sample s[MAX_RUNS];
    sample med;
} mode_res;

typedef struct bench {
    mv_info info;
    size_t bytes;
    uint8_t *frames[NFRAMES];
    r_target t;
    int w, h;
} bench;

static void help(void)
{
    printf("usage: ringside bench upload [--frames N] [--size WxH] [--modes LIST] [--runs N]\n"
           "                             [--csv FILE] [--backend egl|osmesa] [-y|-n] [-q|-v]\n\n"
           "Plays synthetic 4:2:0 movie frames (BT.709, 60 fps, %d distinct frames) through\n"
           "each texture upload path the movie player has, the way the player drives it on\n"
           "one 60 Hz tick, as fast as possible, and prints milliseconds per frame:\n"
           "  direct      glTexSubImage2D from client memory\n"
           "  pbo         two pixel-unpack buffers in ping-pong: define the textures from\n"
           "              the buffer filled last tick, copy the next frame into the other\n"
           "  persistent  one persistently mapped buffer (glBufferStorage): the decoder\n"
           "              writes into it directly, a fence per slot (ring of %d)\n"
           "Columns: total (wall / frames, one glFinish at the end), synced (glFinish after\n"
           "every frame, a shorter run), produce (the decoder's write into the slot), copy\n"
           "(memcpy into the PBO), GL (CPU time inside the upload GL calls), fence (waits\n"
           "for a busy persistent slot).  Each figure is the median of interleaved runs.\n\n"
           "  --frames N       frames per run (default 300; 1 to 100000)\n"
           "  --size WxH       frame size (default 1280x768)\n"
           "  --modes LIST     comma list of direct, pbo, persistent (default all)\n"
           "  --runs N         runs per mode, report medians (default 3; 1 to %d)\n"
           "  --csv FILE       also write one row per mode as CSV ('-': standard output); its\n"
           "                   folder must exist\n"
           "  -y, -n           replace an existing --csv FILE, or refuse it (the default)\n"
           "  --backend B      egl or osmesa (default egl, falling back to osmesa)\n"
           CLI_LOG_HELP,
           NFRAMES, NSLOTS, MAX_RUNS);
}

/* Moving gradients: every frame and every plane differs from the last. */
static void synth(const mv_info *i, int k, uint8_t *dst)
{
    uint8_t *y = dst, *cb = dst + (size_t)i->w * i->h, *cr = cb + (size_t)i->cw * i->ch;
    for (int r = 0; r < i->h; r++) {
        uint8_t *row = y + (size_t)r * i->w;
        for (int c = 0; c < i->w; c++) {
            int v = (c * 219 / (i->w > 1 ? i->w - 1 : 1) + r / 4 + k * 23) % 220; /* 0..219 */
            row[c] = (uint8_t)(16 + (v < 110 ? v * 2 : (219 - v) * 2)); /* a triangle wave: 16..234 */
        }
    }
    for (int r = 0; r < i->ch; r++)
        for (int c = 0; c < i->cw; c++) {
            size_t o = (size_t)r * i->cw + (size_t)c;
            cb[o] = (uint8_t)(16 + (c * 2 + k * 29) % 225);
            cr[o] = (uint8_t)(16 + (r * 3 + (c >> 2) + k * 37) % 225);
        }
}

static void produce(bench *b, mode_res *m, int slot, int k, double *ms)
{
    double t0 = rs_now();
    memcpy(mv_up_slot(m->u, slot), b->frames[k % NFRAMES], b->bytes);
    *ms += (rs_now() - t0) * 1e3;
}

static void draw(bench *b, mode_res *m)
{
    gl.BindFramebuffer(GL_FRAMEBUFFER, b->t.fbo);
    mv_up_draw(m->u, b->w, b->h);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

/* PBO: a frame staged ahead, as the player has after its first tick. */
static void prime(bench *b, mode_res *m, int k)
{
    if (m->mode == MV_UP_PBO && !mv_up_has_staged(m->u)) {
        double ms = 0;
        produce(b, m, k % NSLOTS, k, &ms);
        mv_up_stage(m->u, k % NSLOTS);
    }
}

/* One tick showing frame k.  *produce_ms, *fence_ms, *waits accumulate. */
static void tick(bench *b, mode_res *m, int k, double *produce_ms, double *fence_ms, double *waits)
{
    mv_up *u = m->u;
    int slot = k % NSLOTS;
    switch (m->mode) {
    case MV_UP_DIRECT:
        produce(b, m, slot, k, produce_ms);
        mv_up_upload(u, slot);
        break;
    case MV_UP_PBO:
        if (mv_up_has_staged(u))
            mv_up_commit(u); /* frame k, copied last tick */
        produce(b, m, (k + 1) % NSLOTS, k + 1, produce_ms);
        mv_up_stage(u, (k + 1) % NSLOTS);
        break;
    case MV_UP_PERSISTENT: {
        double t0 = rs_now();
        if (mv_up_busy(u, slot, false)) {
            (*waits)++;
            mv_up_busy(u, slot, true);
        }
        *fence_ms += (rs_now() - t0) * 1e3;
        produce(b, m, slot, k, produce_ms);
        mv_up_upload(u, slot);
        break;
    }
    }
    draw(b, m);
    gl.Flush();
}

/* frames ticks from frame `first`; sync: glFinish after every frame.
 * Returns ms per frame of wall time; the rest into *s (per frame). */
static double run_mode(bench *b, mode_res *m, int first, int frames, bool sync, sample *s)
{
    mv_up_stats a, z;
    double produce_ms = 0, fence_ms = 0, waits = 0;
    prime(b, m, first);
    gl.Finish(); /* nothing from before in the timed window */
    mv_up_stats_get(m->u, &a);
    double t0 = rs_now();
    for (int f = 0; f < frames; f++) {
        tick(b, m, first + f, &produce_ms, &fence_ms, &waits);
        if (sync)
            gl.Finish();
    }
    gl.Finish();
    double wall = (rs_now() - t0) * 1e3 / frames;
    mv_up_stats_get(m->u, &z);
    if (s) {
        s->total = wall;
        s->produce = produce_ms / frames;
        s->copy = (z.copy_ms - a.copy_ms) / frames;
        s->gl = (z.upload_ms - a.upload_ms) / frames;
        s->fence = fence_ms / frames;
        s->waits = waits;
    }
    return wall;
}

/* The floor: the conversion draw alone, textures unchanged, glFinish after
 * every frame.  Returns ms per frame. */
static double draw_only(bench *b, mode_res *m, int frames)
{
    gl.Finish();
    double t0 = rs_now();
    for (int f = 0; f < frames; f++) {
        draw(b, m);
        gl.Finish();
    }
    return (rs_now() - t0) * 1e3 / frames;
}

/* Shows a flat frame (Y, Cb, Cr) through the mode's path and reads back
 * the middle row of the target. */
static void show_and_read(bench *b, mode_res *m, int slot, const uint8_t ycc[3], uint8_t *row)
{
    const mv_info *i = &b->info;
    size_t ny = (size_t)i->w * i->h, nc = (size_t)i->cw * i->ch;
    if (m->mode == MV_UP_PERSISTENT)
        mv_up_busy(m->u, slot, true);
    uint8_t *dst = mv_up_slot(m->u, slot);
    memset(dst, ycc[0], ny);
    memset(dst + ny, ycc[1], nc);
    memset(dst + ny + nc, ycc[2], nc);
    if (m->mode == MV_UP_PBO) {
        mv_up_commit(m->u); /* whatever was staged goes first */
        mv_up_stage(m->u, slot);
        mv_up_commit(m->u);
    } else {
        mv_up_upload(m->u, slot);
    }
    draw(b, m);
    gl.Finish();
    gl.BindFramebuffer(GL_FRAMEBUFFER, b->t.fbo);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, b->h / 2, b->w, 1, GL_RGBA, GL_UNSIGNED_BYTE, row);
    gl.PixelStorei(GL_PACK_ALIGNMENT, 4);
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
}

/* A broken path must not report fast nonsense: two different flat frames
 * (a grey, then a colour that needs all three planes) must each come out
 * as the colour the BT.709 maths says, across the whole row. */
static bool verify(bench *b, mode_res *m, rs_err *err)
{
    static const uint8_t ycc[2][3] = {{180, 128, 128}, {100, 100, 170}};
    size_t n = (size_t)b->w * 4;
    uint8_t *row = malloc(n);
    if (!row)
        return rs_fail(err, JOB_ERR_NOMEM, "out of memory");
    rgl_check("bench upload: before verify");
    mv_csp csp;
    mv_csp_make(b->info.matrix, b->info.full_range, &csp);
    for (int f = 0; f < 2; f++) {
        show_and_read(b, m, f % NSLOTS, ycc[f], row);
        if (!rgl_check("bench upload: verify")) {
            free(row);
            return rs_fail(err, JOB_ERR_GL, "%s upload: GL errors while verifying the picture", mv_up_name(m->mode));
        }
        double rgb[3];
        mv_csp_apply(&csp, ycc[f][0], ycc[f][1], ycc[f][2], rgb);
        int want[3], black = 1;
        for (int ch = 0; ch < 3; ch++) {
            double v = rgb[ch] < 0 ? 0 : rgb[ch] > 1 ? 1 : rgb[ch];
            want[ch] = (int)(v * 255 + 0.5);
        }
        for (int x = 0; x < b->w; x++) {
            const uint8_t *px = row + 4 * x;
            black &= px[0] < 8 && px[1] < 8 && px[2] < 8;
            for (int ch = 0; ch < 3; ch++)
                if (abs(px[ch] - want[ch]) > 4) {
                    rs_fail(err, JOB_ERR_VERIFY,
                            "%s upload: %s: pixel (%d, %d) is %d,%d,%d, expected about %d,%d,%d from Y/Cb/Cr "
                            "%d/%d/%d: the path is broken",
                            mv_up_name(m->mode), black ? "the frame drawn is black" : "wrong picture", x, b->h / 2,
                            px[0], px[1], px[2], want[0], want[1], want[2], ycc[f][0], ycc[f][1], ycc[f][2]);
                    free(row);
                    return false;
                }
        }
    }
    free(row);
    return true;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median_of(const sample *s, int n, size_t off)
{
    double v[MAX_RUNS];
    for (int i = 0; i < n; i++)
        v[i] = *(const double *)((const char *)&s[i] + off);
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

static bool parse_modes(const char *arg, int *modes, int *n)
{
    char buf[256];
    snprintf(buf, sizeof buf, "%s", arg);
    *n = 0;
    for (char *save = NULL, *t = strtok_r(buf, ",", &save); t; t = strtok_r(NULL, ",", &save)) {
        int m = mv_up_parse(t);
        if (m < 0) {
            cli_error("bench", "--modes: unknown mode '%s' (expected direct, pbo, persistent)", t);
            return false;
        }
        bool dup = false;
        for (int i = 0; i < *n; i++)
            dup |= modes[i] == m;
        if (!dup)
            modes[(*n)++] = m;
    }
    if (!*n) {
        cli_error("bench", "--modes '%s': expected a comma list of direct, pbo, persistent", arg);
        return false;
    }
    return true;
}

/* One run of the benchmark: the options, the context, the results. */
typedef struct upload {
    bench b;
    long frames, nrep;
    int modes[MV_UP_COUNT], nmode;
    const char *csv, *backend;
    bool quiet, overwrite;
    int nsync;                 /* frames of the synced runs */
    plat *p;
    mode_res res[MV_UP_COUNT];
    int navail;
    mode_res *any;             /* the first mode available (draws the floor), or NULL */
    const mode_res *direct;    /* direct upload, if measured: the ratios' base */
    double floor_ms;           /* draw only */
    rs_err err;
} upload;

/* The command line into u, checked; -1 to go on, else the exit status. */
static int parse_options(int argc, char **argv, upload *u)
{
    static const struct option opts[] = {{"frames", required_argument, 0, 'f'}, {"size", required_argument, 0, 's'},
                                         {"modes", required_argument, 0, 'm'},  {"runs", required_argument, 0, 'R'},
                                         {"csv", required_argument, 0, 'c'},    {"backend", required_argument, 0, 'b'},
                                         {"help", no_argument, 0, 'h'},
                                         {"overwrite", no_argument, 0, 'y'},    {"no-overwrite", no_argument, 0, 'n'},
                                         {0}};
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'f': if (!cli_int("--frames", optarg, 1, 100000, &u->frames)) return RS_EXIT_USAGE; break;
        case 's': if (!cli_size("--size", optarg, 8192, &u->b.w, &u->b.h)) return RS_EXIT_USAGE; break;
        case 'm': if (!parse_modes(optarg, u->modes, &u->nmode)) return RS_EXIT_USAGE; break;
        case 'R': if (!cli_int("--runs", optarg, 1, MAX_RUNS, &u->nrep)) return RS_EXIT_USAGE; break;
        case 'c': u->csv = optarg; break;
        case 'y': u->overwrite = true; break;
        case 'n': u->overwrite = false; break;
        case 'b':
            if (strcmp(optarg, "egl") && strcmp(optarg, "osmesa") && strcmp(optarg, "auto")) {
                cli_error("bench", "--backend '%s': expected egl or osmesa", optarg);
                return RS_EXIT_USAGE;
            }
            u->backend = optarg;
            break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    if (optind < argc) {
        cli_error("bench", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("bench");
    }
    if (u->csv && *u->csv && !cli_out_ok("bench", u->csv, u->overwrite))
        return RS_EXIT_FAIL;
    u->nsync = (int)u->frames / 4;
    if (u->nsync < 30)
        u->nsync = 30;
    if (u->nsync > u->frames)
        u->nsync = (int)u->frames;
    return -1;
}

/* The synthetic frames, the context and the target; -1 to go on, else
 * the exit status. */
static int setup(upload *u)
{
    bench *b = &u->b;
    b->info = (mv_info){.w = b->w, .h = b->h, .sx = 1, .sy = 1, .matrix = MV_BT709, .full_range = false,
                        .chroma_loc = MV_CHROMA_LEFT, .fps_num = 60, .fps_den = 1, .sar_num = 1, .sar_den = 1,
                        .frames = NFRAMES};
    snprintf(b->info.codec, sizeof b->info.codec, "synthetic");
    snprintf(b->info.pixfmt, sizeof b->info.pixfmt, "yuv420p");
    mv_info_planes(&b->info);
    b->bytes = mv_frame_bytes(&b->info);
    for (int k = 0; k < NFRAMES; k++) {
        if (!(b->frames[k] = malloc(b->bytes)))
            return rs_fail(&u->err, JOB_ERR_NOMEM, "out of memory for %d frames of %zu bytes", NFRAMES, b->bytes), RS_EXIT_FAIL;
        synth(&b->info, k, b->frames[k]);
    }
    if (!(u->p = plat_create(&(plat_desc){.backend = u->backend, .hidden = true}, &u->err)))
        return cli_plat_status(&u->err);
    if (!u->quiet && *plat_fallback_reason(u->p))
        fprintf(stderr, "ringside bench: egl unavailable, using %s: %s\n", plat_backend_name(u->p),
                plat_fallback_reason(u->p));
    if (b->w > glcaps.max_texture_size || b->h > glcaps.max_texture_size) {
        rs_fail(&u->err, JOB_ERR_LIMIT, "--size %dx%d: this context's textures stop at %d", b->w, b->h,
                glcaps.max_texture_size);
        return RS_EXIT_USAGE;
    }
    return r_target_create(&b->t, b->w, b->h, &u->err) ? -1 : RS_EXIT_FAIL;
}

/* Every mode: create (persistent may be unavailable), check the picture, warm up. */
static bool prepare_modes(upload *u)
{
    for (int i = 0; i < u->nmode; i++) {
        mode_res *m = &u->res[i];
        m->mode = u->modes[i];
        rs_err e = {0};
        if (!(m->u = mv_up_create(&u->b.info, m->mode, NSLOTS, &e))) {
            if (e.code == MV_ERR_UNSUPPORTED && m->mode == MV_UP_PERSISTENT) {
                snprintf(m->why, sizeof m->why, "%s", e.msg);
                continue;
            }
            u->err = e;
            return false;
        }
        if (!verify(&u->b, m, &u->err))
            return false;
        run_mode(&u->b, m, 0, WARMUP, false, NULL);
        m->avail = true;
        u->navail++;
    }
    for (int i = 0; i < u->nmode && !u->any; i++)
        if (u->res[i].avail)
            u->any = &u->res[i];
    return true;
}

/* The modes interleaved, nrep times; each figure is the median. */
static bool measure(upload *u)
{
    double floor_each[MAX_RUNS];
    for (int rep = 0; u->any && rep < u->nrep; rep++) {
        floor_each[rep] = draw_only(&u->b, u->any, u->nsync);
        for (int i = 0; i < u->nmode; i++) {
            mode_res *m = &u->res[i];
            if (!m->avail)
                continue;
            if (!u->quiet && isatty(2))
                fprintf(stderr, "\rbench upload: run %d of %ld, %-10s   ", rep + 1, u->nrep, mv_up_name(m->mode));
            run_mode(&u->b, m, 0, (int)u->frames, false, &m->s[rep]);
            m->s[rep].synced = run_mode(&u->b, m, (int)u->frames, u->nsync, true, NULL);
            if (!rgl_check("bench upload"))
                return rs_fail(&u->err, JOB_ERR_GL, "%s upload: GL errors during the run", mv_up_name(m->mode));
        }
    }
    long nrep = u->nrep;
    if (u->any) {
        qsort(floor_each, (size_t)nrep, sizeof *floor_each, cmp_double);
        u->floor_ms = nrep % 2 ? floor_each[nrep / 2] : (floor_each[nrep / 2 - 1] + floor_each[nrep / 2]) / 2;
    }
    if (!u->quiet && isatty(2))
        fprintf(stderr, "\r%60s\r", "");
    for (int i = 0; i < u->nmode; i++) {
        mode_res *m = &u->res[i];
        if (!m->avail)
            continue;
        int n = (int)nrep;
        m->med = (sample){median_of(m->s, n, offsetof(sample, total)),   median_of(m->s, n, offsetof(sample, synced)),
                          median_of(m->s, n, offsetof(sample, produce)), median_of(m->s, n, offsetof(sample, copy)),
                          median_of(m->s, n, offsetof(sample, gl)),      median_of(m->s, n, offsetof(sample, fence)),
                          median_of(m->s, n, offsetof(sample, waits))};
    }
    for (int i = 0; i < u->nmode; i++)
        if (u->res[i].avail && u->res[i].mode == MV_UP_DIRECT)
            u->direct = &u->res[i];
    return true;
}

/* The table on standard output. */
static void print_table(const upload *u)
{
    const bench *b = &u->b;
    const mode_res *res = u->res, *direct = u->direct;
    printf("bench upload: %dx%d 4:2:0 (BT.709 limited) at 60 fps, %ld frames x %ld runs (synced: %d frames), "
           "medians\n",
           b->w, b->h, u->frames, u->nrep, u->nsync);
    printf("renderer: %s, GL %d.%d, %s (%s)\n", glcaps.renderer, glcaps.major, glcaps.minor, plat_backend_name(u->p),
           plat_detail(u->p));
    printf("%-11s %8s %8s %8s %8s %8s %8s %6s %7s %9s\n", "mode", "total", "synced", "produce", "copy", "GL", "fence",
           "waits", "fps", "vs direct");
    for (int i = 0; i < u->nmode; i++) {
        const mode_res *m = &res[i];
        if (!m->avail) {
            printf("%-11s unavailable: %s\n", mv_up_name(m->mode), m->why);
            continue;
        }
        char ratio[16] = "-";
        if (direct)
            snprintf(ratio, sizeof ratio, "%.2f", m->med.total / direct->med.total);
        printf("%-11s %8.3f %8.3f %8.3f %8.3f %8.3f %8.3f %6.0f %7.1f %9s\n", mv_up_name(m->mode), m->med.total,
               m->med.synced, m->med.produce, m->med.copy, m->med.gl, m->med.fence, m->med.waits,
               1000.0 / m->med.total, ratio);
    }
    printf("(ms per frame; total = wall / frames with one glFinish at the end, produce and draw included;\n"
           " synced = glFinish after every frame; copy = memcpy into the PBO; GL = CPU inside the upload calls;\n"
           " fence = waiting for a busy persistent slot, waits = how often per run; vs direct = total / direct's;\n"
           " 60 fps leaves %.2f ms per frame)\n",
           1000.0 / 60);
    if (u->any)
        printf("draw only (the conversion draw, no upload, glFinish every frame): %.3f ms per frame\n", u->floor_ms);
    if (u->navail > 1) {
        const mode_res *ft = NULL, *fs = NULL;
        for (int i = 0; i < u->nmode; i++) {
            const mode_res *m = &res[i];
            if (!m->avail)
                continue;
            if (!ft || m->med.total < ft->med.total)
                ft = m;
            if (!fs || m->med.synced < fs->med.synced)
                fs = m;
        }
        printf("fastest: %s by throughput (%.3f ms), %s synced (%.3f ms)\n", mv_up_name(ft->mode), ft->med.total,
               mv_up_name(fs->mode), fs->med.synced);
    }
}

/* --csv: one row a mode. */
static bool write_csv(upload *u)
{
    const bench *b = &u->b;
    const char *backend = plat_backend_name(u->p);
    FILE *f = cli_text_open("bench", u->csv, u->overwrite);
    bool ok = f && fprintf(f, "mode,available,width,height,frames,runs,synced_frames,total_ms,synced_ms,"
                              "produce_ms,copy_ms,gl_ms,fence_wait_ms,fence_waits,fps,vs_direct,draw_only_ms,backend,"
                              "renderer,note\n") > 0;
    for (int i = 0; ok && i < u->nmode; i++) {
        const mode_res *m = &u->res[i];
        if (!m->avail) {
            char fl[32] = "";
            if (u->any)
                snprintf(fl, sizeof fl, "%.4f", u->floor_ms);
            ok = fprintf(f, "%s,0,%d,%d,%ld,%ld,%d,,,,,,,,,,%s,%s,\"%s\",\"%s\"\n", mv_up_name(m->mode), b->w,
                         b->h, u->frames, u->nrep, u->nsync, fl, backend, glcaps.renderer, m->why) > 0;
            continue;
        }
        char ratio[16] = "";
        if (u->direct)
            snprintf(ratio, sizeof ratio, "%.4f", m->med.total / u->direct->med.total);
        ok = fprintf(f, "%s,1,%d,%d,%ld,%ld,%d,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%.0f,%.2f,%s,%.4f,%s,\"%s\",\n",
                     mv_up_name(m->mode), b->w, b->h, u->frames, u->nrep, u->nsync, m->med.total, m->med.synced,
                     m->med.produce, m->med.copy, m->med.gl, m->med.fence, m->med.waits, 1000.0 / m->med.total,
                     ratio, u->floor_ms, backend, glcaps.renderer) > 0;
    }
    if (f && cli_fclose(f) != 0)
        ok = false;
    if (!ok && !u->err.msg[0])
        rs_fail(&u->err, JOB_ERR_WRITE, "%s: cannot write", u->csv);
    return ok;
}

/* The modes measured, the table, the CSV. */
static int run_modes(upload *u)
{
    if (!prepare_modes(u) || !measure(u))
        return RS_EXIT_FAIL;
    print_table(u);
    return u->csv && *u->csv && !write_csv(u) ? RS_EXIT_FAIL : RS_EXIT_OK;
}

int bench_upload(int argc, char **argv)
{
    upload *u = calloc(1, sizeof *u);
    if (!u)
        return RS_EXIT_FAIL;
    *u = (upload){.b = {.w = 1280, .h = 768}, .frames = 300, .nrep = 3,
                  .modes = {MV_UP_DIRECT, MV_UP_PBO, MV_UP_PERSISTENT}, .nmode = 3};
    u->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    int status = parse_options(argc, argv, u);
    if (status < 0)
        status = setup(u);
    if (status < 0)
        status = run_modes(u);
    if (status != RS_EXIT_OK && u->err.msg[0])
        cli_error("bench", "%s", u->err.msg);
    if (u->p) {
        for (int i = 0; i < MV_UP_COUNT; i++)
            mv_up_destroy(u->res[i].u);
        r_target_destroy(&u->b.t);
        plat_destroy(u->p);
    }
    for (int k = 0; k < NFRAMES; k++)
        free(u->b.frames[k]);
    free(u);
    return status;
}
