/* ringside smoke: a real headless render of the smoke scene to an image,
 * checked against its CPU reference. */
#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/platform/plat.h"
#include "../runtime/render/r_smoke.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_img.h"
#include "job_err.h"

static void help(void)
{
    printf("usage: ringside smoke [-o FILE] [-y|-n] [--size WxH] [--backend egl|osmesa|glfw] [--no-check]\n"
           "                      [-q|-v]\n\n"
           "Renders the smoke test scene headless through shaders/smoke.* and writes it\n"
           "as .png or .ppm.  The picture is compared with its exact CPU\n"
           "reference; if any pixel differs, nothing is written and the exit status is 1.\n\n"
           "  -o FILE        output image (default: out/smoke.png, replaced each run, out/\n"
           "                 created); a FILE given here must be in a folder that exists\n"
           "  -y             replace FILE if it exists (--overwrite)\n"
           "  -n             refuse an existing FILE, naming it (--no-overwrite; the default)\n"
           "  --size WxH     picture size (default 1280x720; %d..max texture size)\n"
           "  --backend B    GL backend (default egl, falling back to osmesa)\n"
           "  --no-check     skip the comparison with the CPU reference\n"
           CLI_LOG_HELP,
           R_SMOKE_MIN_SIZE);
}

int cmd_smoke(int argc, char **argv)
{
    static const struct option opts[] = {{"output", required_argument, 0, 'o'},
                                         {"size", required_argument, 0, 's'},
                                         {"backend", required_argument, 0, 'b'},
                                         {"no-check", no_argument, 0, 'N'},
                                         {"help", no_argument, 0, 'h'},
                                         {"overwrite", no_argument, 0, 'y'},
                                         {"no-overwrite", no_argument, 0, 'n'},
                                         {0}};
    const char *out = NULL; /* NULL: out/smoke.png, ours to replace */
    bool overwrite = false;
    int w = 1280, h = 720, c;
    bool check = true;
    plat_desc d = {.hidden = true};
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'o': out = optarg; break;
        case 's':
            if (!cli_size("--size", optarg, 16384, &w, &h))
                return RS_EXIT_USAGE;
            break;
        case 'b': d.backend = optarg; break;
        case 'N': check = false; break;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'h': help(); return RS_EXIT_OK;
        default: return cli_bad_option("smoke", argv);
        }
    }
    if (optind < argc) {
        cli_error("smoke", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("smoke");
    }
    if (w < R_SMOKE_MIN_SIZE || h < R_SMOKE_MIN_SIZE) {
        cli_error("smoke", "--size %dx%d: each side must be at least %d", w, h, R_SMOKE_MIN_SIZE);
        return RS_EXIT_USAGE;
    }
    bool named = out != NULL;
    if (!named)
        out = "out/smoke.png";
    const char *dot = strrchr(out, '.');
    if (!dot || (strcmp(dot, ".png") && strcmp(dot, ".ppm"))) {
        cli_error("smoke", "%s: unknown image extension (expected .png or .ppm)", out);
        return RS_EXIT_USAGE;
    }
    if (named && !cli_out_ok("smoke", out, overwrite))
        return RS_EXIT_FAIL;

    int status = RS_EXIT_FAIL;
    rs_err err = {0};
    uint8_t *px = NULL, *ref = NULL;
    r_smoke *s = NULL;
    plat *p = plat_create(&d, &err);
    if (!p) {
        status = cli_plat_status(&err);
        goto fail;
    }
    if (plat_fallback_reason(p)[0])
        if (rs_log_on(RS_LOG_WARNING))
            fprintf(stderr, "ringside smoke: egl unavailable, using %s: %s\n", plat_backend_name(p),
                plat_fallback_reason(p));
    if (!(s = r_smoke_create(w, h, &err)))
        goto fail;
    px = malloc((size_t)w * h * 4);
    ref = malloc((size_t)w * h * 4);
    if (!px || !ref) {
        rs_fail(&err, JOB_ERR_NOMEM, "out of memory for a %dx%d picture", w, h);
        goto fail;
    }
    r_smoke_draw(s);
    r_smoke_read(s, px);
    /* check first: a wrong picture never lands under the requested name */
    if (check) {
        r_smoke_reference(w, h, ref);
        size_t first, bad = r_smoke_compare(px, ref, w, h, &first);
        if (bad) {
            rs_fail(&err, JOB_ERR_VERIFY,
                    "%s: not written: %zu of %zu pixels differ from the reference (first at x=%zu y=%zu: got "
                    "%u,%u,%u want %u,%u,%u)",
                    out, bad, (size_t)w * h, first % w, first / w, px[4 * first], px[4 * first + 1], px[4 * first + 2],
                    ref[4 * first], ref[4 * first + 1], ref[4 * first + 2]);
            goto fail;
        }
    }
    if ((!named && !rs_mkdirs_for(out, &err)) || !rs_image_write(out, w, h, 4, px, &err))
        goto fail;
    if (rs_log_on(RS_LOG_INFO))
        fprintf(stderr, "ringside smoke: wrote %s (%dx%d, %s%s)\n", out, w, h, plat_backend_name(p),
            check ? ", matches the reference exactly" : "");
    status = RS_EXIT_OK;
fail:
    if (status != RS_EXIT_OK)
        cli_error("smoke", "%s", err.msg);
    free(px);
    free(ref);
    r_smoke_destroy(s);
    plat_destroy(p);
    return status;
}
