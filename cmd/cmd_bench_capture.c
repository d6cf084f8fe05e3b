/* ringside bench capture: sequential against asynchronous capture, and each
 * against the pipeline's slowest stage, measured in one run.
 *
 * Every configuration renders the same frames of the same replay (the
 * dojo demo from tick 600, after the intro) at the same sizes into the same
 * kind of sink; only the capture path changes. */
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../capture/cap.h"
#include "bench_chart.h"
#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/render/r_quality.h"
#include "job_render.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_game.h"
#include "../runtime/render/r_target.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "job_err.h"

#define MAX_RUNS 9

typedef struct run {
    char name[32];
    double fps_each[MAX_RUNS];
    cap_mode mode;
    cap_downscale ds;
    int pbo, queue; /* queue 0: no writer thread */
    int kind;       /* 0 capture, 1 render-only, 2 writer-only */
    double fps, ms_render, rss_mb;
    cap_stats st;
} run;

typedef struct bench {
    rp_replay rp;
    uint64_t start;
    int frames, sw, sh, w, h;
    const char *out; /* sink path */
    r_game *r;
    r_target t;
    uint8_t *mem; /* frames captured once, for writer-only */
    plat *p;
} bench;

static void reset_peak_rss(void)
{
    FILE *f = fopen("/proc/self/clear_refs", "w"); /* "5": reset the peak RSS (Linux) */
    if (f) {
        fputs("5", f);
        fclose(f);
    }
}

static double peak_rss_mb(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    char line[256];
    double kb = 0;
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "VmHWM:", 6))
            kb = atof(line + 6);
    if (f)
        fclose(f);
    return kb / 1024;
}

/* A sink that keeps frames in memory (to feed writer-only). */
static bool mem_open(cap_sink *s, rs_err *e)
{
    (void)s, (void)e;
    return true;
}
static bool mem_write(cap_sink *s, const uint8_t *frame, uint64_t index, rs_err *e)
{
    (void)e;
    bench *b = s->impl;
    size_t n = cap_frame_bytes(CAP_I420, b->w, b->h);
    memcpy(b->mem + n * index, frame, n);
    return true;
}
static bool mem_close(cap_sink *s, bool ok, rs_err *e)
{
    (void)s, (void)e;
    return ok;
}
static const cap_sink_ops mem_ops = {"memory", mem_open, mem_write, mem_close};

/* The frames from b->start through j (its seek done before the clock
 * starts), drawn and, with c, captured.  Render time is simulate + draw
 * calls (job_render's ms_draw), not the capture. */
static bool draw_frames(job_render *j, cap *c, double *render_ms, rs_err *err)
{
    j->d.cap = c;
    int more;
    while ((more = job_render_next(j, err)) > 0) {
    }
    *render_ms = j->ms_draw;
    return more == 0;
}

static bool do_run(bench *b, run *r, rs_err *err)
{
    job_render j; /* seeks to b->start: simulation only, not timed */
    if (!job_render_begin(&j, &(job_render_desc){.rp = &b->rp, .game = b->r, .target = &b->t, .first = b->start,
                                                 .end = b->start + (uint64_t)b->frames, .no_check = true},
                          err))
        return false;
    reset_peak_rss();
    double t0 = rs_now(), render_ms = 0;
    if (r->kind == 1) { /* render only */
        if (!draw_frames(&j, NULL, &render_ms, err))
            return false;
        gl.Finish();
    } else if (r->kind == 2) { /* writer only: frames from memory into the sink */
        cap_sink s;
        if (!cap_sink_for(b->out, b->w, b->h, &s, err) || !s.ops->open(&s, err))
            return false;
        size_t n = cap_frame_bytes(CAP_I420, b->w, b->h);
        t0 = rs_now();
        bool ok = true;
        for (int f = 0; f < b->frames && ok; f++)
            ok = s.ops->write(&s, b->mem + n * (size_t)f, (uint64_t)f, err);
        if (!s.ops->close(&s, ok, err) || !ok)
            return false;
        r->st.ms_write = (rs_now() - t0) * 1e3;
        r->st.frames = (uint64_t)b->frames;
    } else {
        cap_sink s;
        bool to_mem = r->kind == 3;
        if (to_mem) {
            memset(&s, 0, sizeof s);
            s.ops = &mem_ops;
            s.impl = b;
            s.w = b->w;
            s.h = b->h;
        } else if (!cap_sink_for(b->out, b->w, b->h, &s, err)) {
            return false;
        }
        cap *c = cap_open(&(cap_desc){.src_w = b->sw, .src_h = b->sh, .w = b->w, .h = b->h, .mode = r->mode,
                                      .downscale = r->ds, .pbo = r->pbo, .queue = r->queue, .no_writer = r->mode == CAP_ASYNC && r->queue == 0},
                          &s, err);
        if (!c)
            return false;
        bool ok = draw_frames(&j, c, &render_ms, err);
        if (!cap_close(c, ok, &r->st, err) || !ok)
            return false;
    }
    double secs = rs_now() - t0;
    r->fps = b->frames / secs;
    r->ms_render = render_ms / b->frames;
    r->rss_mb = peak_rss_mb();
    if (unlink(b->out) != 0 && strncmp(b->out, "/dev/", 5) != 0) {
        /* the benchmark's output is scratch */
    }
    return true;
}

static void help(void)
{
    printf("usage: ringside bench capture [--frames N] [--runs N] [--size WxH] [--quality Q] [--render-size WxH]\n"
           "                              [--sink mp4|y4m|null] [--csv FILE] [--chart FILE.png] [-y|-n] [-q|-v]\n\n"
           "Renders %s same frames of demos/dojo.rsr (from tick 600) through every capture\n"
           "configuration and prints fps and milliseconds per frame for each stage:\n"
           "render-only, writer-only (frames from memory to the sink), sequential (CPU\n"
           "downscale, all on the game thread), and async with PBO rings 1/2/3 and writer\n"
           "queues 0/8/120.  The ratios async/sequential and async/min(render-only,\n"
           "writer-only) are measured in the same run (medians of interleaved runs).\n\n"
           "  --frames N         frames per configuration (default 300)\n"
           "  --size WxH         output size (default 640x360)\n"
           "  --quality Q        the renderer's preset, as render --quality (default standard)\n"
           "  --render-size WxH  render size (default: the quality's, from the output size)\n"
           "  --sink S           mp4 (H.264, default), y4m (raw, disk-bound) or null\n"
           "  --runs N           repeat every configuration N times, report medians (default 3)\n"
           "  --csv FILE         the table as CSV (default out/bench-capture.csv)\n"
           "  --chart FILE       bar chart of fps as PNG, and SVG beside it (default\n"
           "                     out/bench-capture.png; '' for none)\n"
           "  -y, -n             replace a --csv or --chart FILE given here, or refuse it (the\n"
           "                     default); the defaults under out/ are replaced each run.\n"
           "                     --csv - writes to standard output\n"
           CLI_LOG_HELP,
           "the");
}

/* What the command line asks for, beyond the sizes that go into bench. */
typedef struct capture_opts {
    long nrep;
    const r_preset *quality;
    const char *sink, *csv, *chart;
    bool quiet, overwrite, user_csv, user_chart;
} capture_opts;

/* The command line into b and o, checked; -1 to go on, else the exit status. */
static int parse_options(int argc, char **argv, bench *b, capture_opts *o)
{
    static const struct option opts[] = {{"frames", required_argument, 0, 'f'}, {"size", required_argument, 0, 's'},
                                         {"render-size", required_argument, 0, 'r'}, {"sink", required_argument, 0, 'k'},
                                         {"csv", required_argument, 0, 'c'},    {"chart", required_argument, 0, 'C'},
                                         {"help", no_argument, 0, 'h'},
                                         {"runs", required_argument, 0, 'R'},   {"quality", required_argument, 0, 'L'},
                                         {"overwrite", no_argument, 0, 'y'},    {"no-overwrite", no_argument, 0, 'n'},
                                         {0}};
    *o = (capture_opts){.nrep = 3, .quality = &r_presets[R_PRESET_DEFAULT], .sink = "mp4", .csv = "out/bench-capture.csv",
                        .chart = "out/bench-capture.png"};
    o->quiet = !rs_log_on(RS_LOG_INFO); /* -q, --loglevel (main took them) */
    long v;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'f': if (!cli_int("--frames", optarg, 10, 100000, &v)) return RS_EXIT_USAGE; b->frames = (int)v; break;
        case 's': if (!cli_size("--size", optarg, 8192, &b->w, &b->h)) return RS_EXIT_USAGE; break;
        case 'r': if (!cli_size("--render-size", optarg, R_RENDER_MAX, &b->sw, &b->sh)) return RS_EXIT_USAGE; break;
        case 'L': if (!(o->quality = cli_quality("bench", optarg))) return RS_EXIT_USAGE; break;
        case 'k':
            if (strcmp(optarg, "mp4") && strcmp(optarg, "y4m") && strcmp(optarg, "null")) {
                cli_error("bench", "--sink '%s': expected mp4, y4m or null", optarg);
                return RS_EXIT_USAGE;
            }
            o->sink = optarg;
            break;
        case 'c': o->csv = optarg; o->user_csv = true; break;
        case 'C': o->chart = optarg; o->user_chart = true; break;
        case 'y': o->overwrite = true; break;
        case 'n': o->overwrite = false; break;
        case 'R': if (!cli_int("--runs", optarg, 1, MAX_RUNS, &o->nrep)) return RS_EXIT_USAGE; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    rs_err err = {0};
    if (!b->sw)
        r_preset_render_size(o->quality, b->w, b->h, R_RENDER_MAX, &b->sw, &b->sh);
    if (!cap_check_sizes(b->sw, b->sh, b->w, b->h, &err)) {
        cli_error("bench", "%s", err.msg);
        return RS_EXIT_USAGE;
    }
    if (o->chart && *o->chart && !bench_chart_check(o->chart, &err)) { /* before minutes of runs, not after */
        cli_error("bench", "--chart %s", err.msg);
        return RS_EXIT_USAGE;
    }
    if ((o->user_csv && *o->csv && !cli_out_ok("bench", o->csv, o->overwrite)) ||
        (o->user_chart && *o->chart && !cli_out_ok("bench", o->chart, o->overwrite)))
        return RS_EXIT_FAIL;
    return -1;
}

/* The demo, the sink's folder, the context, the renderer and the memory
 * for writer-only's frames. */
static bool setup(bench *b, const capture_opts *o, rs_err *err)
{
    const char *data = rs_data_dir(err);
    char demo[1200];
    if (data)
        snprintf(demo, sizeof demo, "%s/demos/dojo.rsr", data);
    if (!data || !rp_read(demo, &b->rp, err))
        return false;
    if (b->rp.ticks < b->start + (uint64_t)b->frames)
        return rs_fail(err, JOB_ERR_TICKS, "%s has %" PRIu64 " ticks; --frames %d from tick %" PRIu64 " needs more", demo,
                       b->rp.ticks, b->frames, b->start);
    cap_sink probe;
    if (strcmp(o->sink, "null") && (!rs_mkdirs_for(b->out, err) || !cap_sink_for(b->out, b->w, b->h, &probe, err)))
        return false;
    if (!(b->p = plat_create(&(plat_desc){.hidden = true}, err)) ||
        !(b->r = r_game_create_opts(&(r_game_opts){.q = o->quality->q}, err)))
        return false;
    b->mem = malloc(cap_frame_bytes(CAP_I420, b->w, b->h) * (size_t)b->frames);
    if (!b->mem)
        return rs_fail(err, JOB_ERR_NOMEM, "out of memory for %d frames", b->frames);
    return r_target_create(&b->t, b->sw, b->sh, err);
}

/* The median of v[0..n-1] (sorted in place). */
static double median(double *v, long n)
{
    for (long x = 1; x < n; x++) /* insertion sort: a handful of values */
        for (long y = x; y > 0 && v[y] < v[y - 1]; y--) {
            double t = v[y];
            v[y] = v[y - 1];
            v[y - 1] = t;
        }
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

/* Every configuration, interleaved, o->nrep times; each fps the median. */
static bool measure(bench *b, const capture_opts *o, run *runs, int *nrun, rs_err *err)
{
    /* frames for writer-only, captured once (not timed) */
    run prep = {.kind = 3, .mode = CAP_SEQUENTIAL, .ds = CAP_DS_GPU};
    if (!do_run(b, &prep, err))
        return false;
    int n = 0;
    runs[n++] = (run){.name = "render-only", .kind = 1};
    runs[n++] = (run){.name = "writer-only", .kind = 2};
    runs[n++] = (run){.name = "sequential", .mode = CAP_SEQUENTIAL};
    const int pbos[3] = {1, 2, 3}, queues[3] = {0, 8, 120};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            run *r = &runs[n++];
            *r = (run){.mode = CAP_ASYNC, .pbo = pbos[i], .queue = queues[j]};
            snprintf(r->name, sizeof r->name, "async pbo%d q%d", pbos[i], queues[j]);
        }
    *nrun = n;
    /* the configurations interleaved, nrep times; each figure is the median */
    for (int rep = 0; rep < o->nrep; rep++)
        for (int i = 0; i < n; i++) {
            if (!o->quiet && isatty(2))
                fprintf(stderr, "\rbench capture: run %d of %ld, %-16s   ", rep + 1, o->nrep, runs[i].name);
            if (!do_run(b, &runs[i], err))
                return false;
            runs[i].fps_each[rep] = runs[i].fps;
        }
    for (int i = 0; i < n; i++) {
        double v2[MAX_RUNS];
        memcpy(v2, runs[i].fps_each, sizeof v2);
        runs[i].fps = median(v2, o->nrep);
    }
    if (!o->quiet && isatty(2))
        fprintf(stderr, "\r%60s\r", "");
    return true;
}

/* The table on standard output, with the ratios the benchmark is for. */
static void print_table(const bench *b, const capture_opts *o, const run *runs, int nrun)
{
    printf("bench capture: %d frames of demos/dojo.rsr, quality %s, drawn %dx%d, out %dx%d, sink %s, %s\n", b->frames,
           o->quality->name, b->sw, b->sh,
           b->w, b->h, o->sink, glcaps.renderer);
    printf("fps: median of %ld interleaved runs; stage times and peaks: the last run\n", o->nrep);
    printf("%-16s %7s %8s %8s %8s %8s %8s %8s %8s %5s %7s\n", "config", "fps", "render", "dscale", "readbk", "fence",
           "map+cp", "q-wait", "write", "hwm", "rss MB");
    bool null_sink = !strcmp(o->sink, "null");
    for (int i = 0; i < nrun; i++) {
        const run *r = &runs[i];
        double n = (double)b->frames;
        if (null_sink && r->kind == 2) { /* nothing to write: no rate to show */
            printf("%-16s %7s %8s %8s %8s %8s %8s %8s %8s %5s %7s\n", r->name, "-", "-", "-", "-", "-", "-", "-", "-", "-",
                   "-");
            continue;
        }
        printf("%-16s %7.1f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %5d %7.0f\n", r->name, r->fps, r->ms_render,
               r->st.ms_downscale / n, r->st.ms_readback / n, r->st.ms_fence_wait / n, r->st.ms_map_copy / n,
               r->st.ms_queue_wait / n, r->st.ms_write / n, r->st.high_water, r->rss_mb);
    }
    printf("(ms per frame; render = simulate + draw calls on the game thread; write = writer thread in the sink)\n");
    double render_only = runs[0].fps, writer_only = null_sink ? 1e300 : runs[1].fps, seq = runs[2].fps;
    const run *def = &runs[3 + 1 * 3 + 2]; /* pbo 2, queue 120: the defaults */
    double slowest = render_only < writer_only ? render_only : writer_only;
    printf("async (pbo 2, queue 120) / sequential:                 %.2fx  (goal >= 1.8x here, >= 4x on a GPU)\n",
           def->fps / seq);
    if (null_sink)
        printf("async / render-only %.1f fps (the null sink has no writer stage): %.2f   (goal >= 0.9)\n", render_only,
               def->fps / slowest);
    else
        printf("async / min(render-only %.1f, writer-only %.1f fps):   %.2f   (goal >= 0.9)\n", render_only,
               writer_only, def->fps / slowest);
}

/* --csv and --chart. */
static bool write_outputs(const bench *b, const capture_opts *o, run *runs, int nrun, rs_err *err)
{
    const char *csv = o->csv, *chart = o->chart, *sink = o->sink;
    bool null_sink = !strcmp(sink, "null");
    if (csv && *csv) {
        FILE *f = cli_bench_open("bench", csv, o->user_csv, o->overwrite);
        bool ok = f != NULL;
        if (ok)
            ok = fprintf(f, "config,fps,render_ms,downscale_ms,readback_ms,fence_ms,map_copy_ms,queue_wait_ms,write_ms,"
                            "high_water,rss_mb,frames,render_w,render_h,w,h,sink\n") > 0;
        for (int i = 0; ok && i < nrun; i++) {
            const run *r = &runs[i];
            double n = (double)b->frames;
            if (null_sink && r->kind == 2) { /* empty fields: no writer stage */
                ok = fprintf(f, "%s,,,,,,,,,,,%d,%d,%d,%d,%d,%s\n", r->name, b->frames, b->sw, b->sh, b->w, b->h, sink) > 0;
                continue;
            }
            ok = fprintf(f, "%s,%.2f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%.3f,%d,%.0f,%d,%d,%d,%d,%d,%s\n", r->name, r->fps,
                         r->ms_render, r->st.ms_downscale / n, r->st.ms_readback / n, r->st.ms_fence_wait / n,
                         r->st.ms_map_copy / n, r->st.ms_queue_wait / n, r->st.ms_write / n, r->st.high_water,
                         r->rss_mb, b->frames, b->sw, b->sh, b->w, b->h, sink) > 0;
        }
        if (f && cli_fclose(f) != 0)
            ok = false;
        if (!ok)
            return rs_fail(err, JOB_ERR_WRITE, "%s: cannot write", csv);
    }
    if (chart && *chart) {
        const run *def = &runs[3 + 1 * 3 + 2];
        bench_bar bars[16];
        int nb = 0;
        for (int i = 0; i < nrun; i++)
            if (!(null_sink && runs[i].kind == 2))
                bars[nb++] = (bench_bar){runs[i].name, runs[i].fps, &runs[i] == def || i == 2};
        char title[128];
        snprintf(title, sizeof title, "capture fps, %dx%d to %dx%d, %s", b->sw, b->sh, b->w, b->h, sink);
        bench_chart bc = {title, "frames per second (fps), higher is better", "fps", bars, nb};
        if (!bench_chart_write(chart, &bc, err))
            return false;
    }
    return true;
}

int bench_capture(int argc, char **argv)
{
    bench b = {.frames = 300, .w = 640, .h = 360, .start = 600};
    capture_opts o;
    int status = parse_options(argc, argv, &b, &o);
    if (status >= 0)
        return status;
    rs_err err = {0};
    char outpath[64];
    snprintf(outpath, sizeof outpath, !strcmp(o.sink, "null") ? "null:" : "out/bench-capture-scratch.%s", o.sink);
    b.out = outpath;
    run runs[16];
    int nrun = 0;
    status = RS_EXIT_FAIL;
    if (setup(&b, &o, &err) && measure(&b, &o, runs, &nrun, &err)) {
        print_table(&b, &o, runs, nrun);
        if (write_outputs(&b, &o, runs, nrun, &err))
            status = RS_EXIT_OK;
    }
    if (status != RS_EXIT_OK)
        cli_error("bench", "%s", err.msg);
    if (b.p) {
        r_target_destroy(&b.t);
        r_game_destroy(b.r);
        plat_destroy(b.p);
    }
    free(b.mem);
    rp_free(&b.rp);
    return status;
}
