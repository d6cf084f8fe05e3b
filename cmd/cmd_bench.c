/* ringside bench: benchmarks that print ratios measured in one run.
 *
 *   bench platform   the headless backends side by side on the smoke scene:
 *                    context start-up, draw, draw + glReadPixels.
 *   bench sim        a synthetic long CPU-vs-CPU replay (24 hours by default):
 *                    record, encode, decode and verify speed, sizes. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/game/g_ai.h"
#include "../runtime/gl/rgl.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_progress.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_smoke.h"
#include "job_err.h"

static void help(void)
{
    printf("usage: ringside bench platform [--size WxH] [--frames N] [--runs N] [--csv FILE] [-y|-n]\n"
           "       ringside bench sim [--hours H] [--csv FILE] [-y|-n] [--progress tty|plain|off] [-q|-v]\n"
           "       ringside bench capture [--frames N] [--sink mp4|y4m|null] ... (see bench capture --help)\n"
           "       ringside bench accuracy [--frames N] ... (see bench accuracy --help)\n"
           "       ringside bench upload [--frames N] [--modes LIST] ... (see bench upload --help)\n"
           "       ringside bench encode [--frames N] [--codecs LIST] ... (see bench encode --help)\n"
           "       ringside bench audio [--replay FILE] [--csv FILE] ... (see bench audio --help)\n"
           "       ringside bench quality [--size WxH] [--frames N] ... (see bench quality --help)\n\n"
           "bench platform times every headless backend built in (egl, osmesa) in one run\n"
           "on the smoke scene: context start-up, draw (glFinish), and draw + full-frame\n"
           "glReadPixels.  Each figure is the median over the runs; the ratio line compares\n"
           "backends measured side by side, which is what to trust on a noisy machine.\n\n"
           "bench sim records a synthetic CPU-vs-CPU replay of H hours of continuous\n"
           "matches (default 24: 5,184,000 ticks), encodes it, decodes it and verifies\n"
           "every checkpoint, printing ticks per second for each step and the sizes.\n\n"
           "  --size WxH    platform: frame size (default 1280x720)\n"
           "  --frames N    platform: frames per run (default 60)\n"
           "  --runs N      platform: runs per backend (default 5)\n"
           "  --hours H     sim: hours of matches, 1..168 (default 24)\n"
           "  --csv FILE    also write the table as CSV ('-': standard output, after the table);\n"
           "                its folder must exist\n"
           "  -y, -n        replace an existing --csv FILE, or refuse it, naming it (the default)\n"
           "  --progress M  sim: tty, plain (a line every 5 s and the last) or off; default\n"
           "                tty on a terminal, else plain\n"
           CLI_LOG_HELP);
}

static void on_progress(uint64_t done, uint64_t total, void *user)
{
    (void)total;
    rs_progress_update(user, done);
}

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, cmp_double);
    return n % 2 ? v[n / 2] : (v[n / 2 - 1] + v[n / 2]) / 2;
}

typedef struct result {
    const char *backend;
    double create_ms, draw_ms, read_ms;
    char renderer[128];
} result;

static bool bench_backend(const char *name, int w, int h, int frames, int runs, result *r, rs_err *err)
{
    memset(r, 0, sizeof *r);
    r->backend = name;
    double t0 = now_ms();
    plat *p = plat_create(&(plat_desc){.backend = name, .hidden = true}, err);
    if (!p)
        return false;
    r_smoke *s = r_smoke_create(w, h, err);
    if (!s) {
        plat_destroy(p);
        return false;
    }
    r->create_ms = now_ms() - t0;
    snprintf(r->renderer, sizeof r->renderer, "%s", glcaps.renderer);
    uint8_t *px = malloc((size_t)w * h * 4);
    if (!px) {
        r_smoke_destroy(s);
        plat_destroy(p);
        return rs_fail(err, JOB_ERR_NOMEM, "out of memory for a %dx%d frame", w, h);
    }
    double draw[64], rd[64];
    r_smoke_draw(s); /* warm-up: shader JIT, first allocation */
    gl.Finish();
    for (int run = 0; run < runs; run++) {
        t0 = now_ms();
        for (int f = 0; f < frames; f++) {
            r_smoke_draw(s);
            gl.Finish();
        }
        draw[run] = (now_ms() - t0) / frames;
        t0 = now_ms();
        for (int f = 0; f < frames; f++) {
            r_smoke_draw(s);
            r_smoke_read(s, px);
        }
        rd[run] = (now_ms() - t0) / frames;
    }
    r->draw_ms = median(draw, runs);
    r->read_ms = median(rd, runs);
    free(px);
    r_smoke_destroy(s);
    plat_destroy(p);
    return true;
}

static int bench_sim(int argc, char **argv)
{
    static const struct option opts[] = {{"hours", required_argument, 0, 'H'},
                                         {"csv", required_argument, 0, 'c'},
                                         {"help", no_argument, 0, 'h'},
                                         {"overwrite", no_argument, 0, 'y'},
                                         {"no-overwrite", no_argument, 0, 'n'},
                                         {"progress", required_argument, 0, 'g'},
                                         {0}};
    long hours = 24;
    const char *csv = NULL;
    bool quiet = !rs_log_on(RS_LOG_INFO), overwrite = false;
    int progress = RS_PROGRESS_AUTO;
    int c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'H':
            if (!cli_int("--hours", optarg, 1, 168, &hours))
                return RS_EXIT_USAGE;
            break;
        case 'c': csv = optarg; break;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'g': if (!cli_progress_mode("bench", optarg, &progress)) return RS_EXIT_USAGE; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv);
        }
    }
    if (csv && !cli_out_ok("bench", csv, overwrite))
        return RS_EXIT_FAIL;
    rs_progress_mode pmode = quiet ? RS_PROGRESS_OFF : (rs_progress_mode)progress;
    uint64_t ticks = (uint64_t)hours * 3600 * G_HZ;
    rs_err err = {0};
    g_state st;
    g_ai cpu[2];
    g_init(&st, 1, 2024);
    g_ai_init(&cpu[0], 0, 2, 11);
    g_ai_init(&cpu[1], 1, 3, 12);
    rp_recorder rec;
    rp_rec_init(&rec, 1, 2024, RP_CPU, RP_CPU);
    rs_progress prog;
    int status = RS_EXIT_FAIL;
    uint8_t *buf = NULL;
    size_t len = 0, size_3min = 0;
    rp_replay back = {0};

    rs_progress_start(&prog, "record", "ticks", ticks, pmode);
    while (st.tick < ticks) {
        g_input in[2] = {g_ai_input(&cpu[0], &st), g_ai_input(&cpu[1], &st)};
        g_step(&st, in, NULL);
        if (!rp_rec_tick(&rec, in, &st, &err))
            goto done;
        if ((st.tick & 0xffff) == 0)
            rs_progress_update(&prog, st.tick);
        if (st.tick == 180 * G_HZ) { /* the size of a 3-minute replay */
            uint8_t *b3;
            if (!rp_encode(&rec.rp, &b3, &size_3min, &err))
                goto done;
            free(b3);
        }
    }
    rs_progress_update(&prog, st.tick); /* the last line says all */
    double t_rec = rs_progress_end(&prog);
    double t0 = rs_now();
    if (!rp_encode(&rec.rp, &buf, &len, &err))
        goto done;
    double t_enc = rs_now() - t0;
    t0 = rs_now();
    if (!rp_decode(buf, len, "synthetic replay", &back, &err))
        goto done;
    double t_dec = rs_now() - t0;
    rs_progress_start(&prog, "verify", "ticks", ticks, pmode);
    rp_verify_result res;
    bool ran = rp_verify(&back, NULL, on_progress, &prog, &res, &err);
    if (ran)
        rs_progress_update(&prog, ticks);
    double t_ver = rs_progress_end(&prog);
    if (!ran)
        goto done;
    if (!res.ok) {
        rs_fail(&err, JOB_ERR_VERIFY, "synthetic replay desynced at tick %llu: the simulation is not deterministic",
                (unsigned long long)res.desync_tick);
        goto done;
    }
    printf("bench sim: %ld h of CPU-vs-CPU matches, %llu ticks, %d matches finished, stage %s\n", hours,
           (unsigned long long)ticks, st.matches, g_stages[st.stage].name);
    printf("%-22s %12s %14s\n", "step", "seconds", "ticks/s");
    printf("%-22s %12.3f %14.0f\n", "record (AI + hash)", t_rec, ticks / t_rec);
    printf("%-22s %12.3f %14.0f\n", "encode", t_enc, ticks / t_enc);
    printf("%-22s %12.3f %14.0f\n", "decode", t_dec, ticks / t_dec);
    printf("%-22s %12.3f %14.0f\n", "verify (simulate)", t_ver, ticks / t_ver);
    printf("replay size: %zu bytes for %ld h (%.1f bytes/s of play); a 3-minute replay: %zu bytes\n", len, hours,
           len / (hours * 3600.0), size_3min);
    printf("verify: all %zu checkpoints and the final hash match; goal >= 200000 ticks/s: %s\n", back.ncheck,
           ticks / t_ver >= 200000 ? "met" : "NOT met");
    if (csv) {
        FILE *f = cli_text_open("bench", csv, overwrite);
        bool wrote = f && fprintf(f, "hours,ticks,record_tps,encode_tps,decode_tps,verify_tps,bytes,bytes_3min\n"
                                     "%ld,%llu,%.0f,%.0f,%.0f,%.0f,%zu,%zu\n",
                                  hours, (unsigned long long)ticks, ticks / t_rec, ticks / t_enc, ticks / t_dec,
                                  ticks / t_ver, len, size_3min) > 0;
        if (f && cli_fclose(f) != 0)
            wrote = false;
        if (!wrote) {
            rs_fail(&err, JOB_ERR_WRITE, "%s: cannot write", csv);
            goto done;
        }
    }
    status = RS_EXIT_OK;
done:
    if (status != RS_EXIT_OK)
        cli_error("bench", "%s", err.msg);
    free(buf);
    rp_free(&back);
    rp_free(&rec.rp);
    return status;
}

int cmd_bench(int argc, char **argv)
{
    if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
        help();
        return argc < 2 ? RS_EXIT_USAGE : RS_EXIT_OK;
    }
    if (!strcmp(argv[1], "sim"))
        return bench_sim(argc - 1, argv + 1);
    if (!strcmp(argv[1], "capture"))
        return bench_capture(argc - 1, argv + 1);
    if (!strcmp(argv[1], "accuracy"))
        return bench_accuracy(argc - 1, argv + 1);
    if (!strcmp(argv[1], "upload"))
        return bench_upload(argc - 1, argv + 1);
    if (!strcmp(argv[1], "encode"))
        return bench_encode(argc - 1, argv + 1);
    if (!strcmp(argv[1], "audio"))
        return bench_audio(argc - 1, argv + 1);
    if (!strcmp(argv[1], "quality"))
        return bench_quality(argc - 1, argv + 1);
    if (strcmp(argv[1], "platform") != 0) {
        cli_error("bench", "unknown benchmark '%s' (expected: platform, sim, capture, accuracy, upload, encode, audio, quality)",
                  argv[1]);
        return RS_EXIT_USAGE;
    }
    static const struct option opts[] = {{"size", required_argument, 0, 's'},  {"frames", required_argument, 0, 'f'},
                                         {"runs", required_argument, 0, 'r'},  {"csv", required_argument, 0, 'c'},
                                         {"help", no_argument, 0, 'h'},
                                         {"overwrite", no_argument, 0, 'y'},   {"no-overwrite", no_argument, 0, 'n'},
                                         {0}};
    int w = 1280, h = 720, c;
    long frames = 60, runs = 5;
    const char *csv = NULL;
    bool overwrite = false;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc - 1, argv + 1, "hyn", opts, NULL)) != -1) {
        switch (c) {
        case 's':
            if (!cli_size("--size", optarg, 8192, &w, &h))
                return RS_EXIT_USAGE;
            break;
        case 'f':
            if (!cli_int("--frames", optarg, 1, 100000, &frames))
                return RS_EXIT_USAGE;
            break;
        case 'r':
            if (!cli_int("--runs", optarg, 1, 64, &runs))
                return RS_EXIT_USAGE;
            break;
        case 'c': csv = optarg; break;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("bench", argv + 1);
        }
    }
    if (csv && !cli_out_ok("bench", csv, overwrite))
        return RS_EXIT_FAIL;
    if (w < R_SMOKE_MIN_SIZE || h < R_SMOKE_MIN_SIZE) {
        cli_error("bench", "--size %dx%d: each side must be at least %d", w, h, R_SMOKE_MIN_SIZE);
        return RS_EXIT_USAGE;
    }
    static const char *const names[] = {"egl", "osmesa"};
    result res[2];
    int nres = 0;
    printf("bench platform: smoke scene %dx%d, %ld frames x %ld runs, medians\n", w, h, frames, runs);
    printf("%-8s %10s %14s %19s %8s  %s\n", "backend", "create ms", "draw ms/frame", "draw+read ms/frame", "fps",
           "renderer");
    for (int i = 0; i < 2; i++) {
        if (!plat_backend_built(names[i]))
            continue;
        rs_err err = {0};
        if (!bench_backend(names[i], w, h, (int)frames, (int)runs, &res[nres], &err)) {
            printf("%-8s unavailable: %s\n", names[i], err.msg);
            continue;
        }
        result *r = &res[nres++];
        printf("%-8s %10.1f %14.3f %19.3f %8.1f  %s\n", r->backend, r->create_ms, r->draw_ms, r->read_ms,
               1000.0 / r->read_ms, r->renderer);
    }
    if (nres == 2)
        printf("ratio osmesa/egl: draw %.2f, draw+read %.2f (>1: osmesa slower)\n", res[1].draw_ms / res[0].draw_ms,
               res[1].read_ms / res[0].read_ms);
    if (csv && nres) {
        FILE *f = cli_text_open("bench", csv, overwrite);
        if (!f)
            return RS_EXIT_FAIL;
        fprintf(f, "backend,width,height,frames,runs,create_ms,draw_ms,draw_read_ms,fps,renderer\n");
        for (int i = 0; i < nres; i++)
            fprintf(f, "%s,%d,%d,%ld,%ld,%.3f,%.4f,%.4f,%.2f,\"%s\"\n", res[i].backend, w, h, frames, runs,
                    res[i].create_ms, res[i].draw_ms, res[i].read_ms, 1000.0 / res[i].read_ms, res[i].renderer);
        if (cli_fclose(f) != 0) {
            cli_error("bench", "%s: write failed", csv);
            return RS_EXIT_FAIL;
        }
    }
    return nres ? RS_EXIT_OK : RS_EXIT_FAIL;
}
