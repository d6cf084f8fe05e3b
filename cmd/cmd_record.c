/* ringside record: a headless CPU-vs-CPU match written as a replay.  No GL. */
#include <getopt.h>
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "../runtime/util/rs_log.h"
#include "../runtime/game/g_ai.h"
#include "../runtime/game/g_game.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_progress.h"

#define MATCH_LIMIT_S 600

static void help(void)
{
    printf("usage: ringside record --ai -o FILE [-y|-n] [--seconds N] [--seed S] [--stage NAME] [--level L]\n"
           "                       [--progress tty|plain|off] [-q|-v]\n\n"
           "Plays a CPU-vs-CPU match headless (no GL needed) and writes it as a replay\n"
           "(.rsr, see docs/replay-format.md).  The file is read back and compared with\n"
           "what was recorded before it is put in place.\n\n"
           "  --ai          both players are the CPU (required: to record people, use\n"
           "                'ringside play --record')\n"
           "  -o FILE       output replay (its folder must exist)\n"
           "  -y            replace FILE if it exists (--overwrite)\n"
           "  -n            refuse an existing FILE, naming it (--no-overwrite; the default,\n"
           "                ringside never asks)\n"
           "  --seconds N   record exactly N seconds of game time; matches follow one\n"
           "                another (default: until the first match is over, at most %d s)\n"
           "  --seed S      game and CPU random seed (default 1)\n"
           "  --stage NAME  dojo, harbor, temple, shallows, snowfield, mistvale, plaza or quarry, or 0..%d\n                (default dojo)\n"
           "  --level L     CPU skill 0..3 (default 2)\n"
           "  --progress M  tty (a line redrawn in place), plain (a line every 5 s and the\n"
           "                last, for logs) or off; default tty on a terminal, else plain\n"
           CLI_LOG_HELP,
           MATCH_LIMIT_S, G_STAGES - 1);
}

int cmd_record(int argc, char **argv)
{
    static const struct option opts[] = {{"ai", no_argument, 0, 'a'},          {"output", required_argument, 0, 'o'},
                                         {"seconds", required_argument, 0, 's'}, {"seed", required_argument, 0, 'S'},
                                         {"stage", required_argument, 0, 't'},  {"level", required_argument, 0, 'l'},
                                         {"help", no_argument, 0, 'h'},
                                         {"overwrite", no_argument, 0, 'y'},    {"no-overwrite", no_argument, 0, 'n'},
                                         {"progress", required_argument, 0, 'g'},
                                         {0}};
    const char *out = NULL;
    bool ai = false, quiet = !rs_log_on(RS_LOG_INFO), overwrite = false;
    int progress = RS_PROGRESS_AUTO;
    long seconds = 0, level = 2;
    uint64_t seed = 1;
    int stage = 0, c;
    optind = 1;
    opterr = 0;
    while ((c = getopt_long(argc, argv, "o:hyn", opts, NULL)) != -1) {
        switch (c) {
        case 'a': ai = true; break;
        case 'o': out = optarg; break;
        case 's':
            if (!cli_int("--seconds", optarg, 1, (long)(RP_MAX_TICKS / G_HZ), &seconds))
                return RS_EXIT_USAGE;
            break;
        case 'S':
            if (!cli_u64("--seed", optarg, &seed))
                return RS_EXIT_USAGE;
            break;
        case 't':
            if (!cli_stage(optarg, &stage))
                return RS_EXIT_USAGE;
            break;
        case 'l':
            if (!cli_int("--level", optarg, 0, 3, &level))
                return RS_EXIT_USAGE;
            break;
        case 'h': help(); return RS_EXIT_OK;
        case 'y': overwrite = true; break;
        case 'n': overwrite = false; break;
        case 'g': if (!cli_progress_mode("record", optarg, &progress)) return RS_EXIT_USAGE; break;
        default: return cli_bad_option("record", argv);
        }
    }
    if (optind < argc) {
        cli_error("record", "unexpected argument '%s'", argv[optind]);
        return cli_usage_error("record");
    }
    if (!ai) {
        cli_error("record", "--ai is required (headless recording is CPU vs CPU; use 'ringside play --record' for people)");
        return RS_EXIT_USAGE;
    }
    if (!out) {
        cli_error("record", "-o FILE is required");
        return RS_EXIT_USAGE;
    }
    if (!cli_out_ok("record", out, overwrite))
        return RS_EXIT_FAIL;

    rs_err err = {0};
    g_state st;
    g_ai cpu[2];
    g_init(&st, stage, seed);
    g_ai_init(&cpu[0], 0, (int)level, seed);
    g_ai_init(&cpu[1], 1, (int)level, seed + 1);
    rp_recorder rec;
    rp_rec_init(&rec, stage, seed, RP_CPU, RP_CPU);
    uint64_t limit = seconds ? (uint64_t)seconds * G_HZ : (uint64_t)MATCH_LIMIT_S * G_HZ;
    rs_progress prog;
    rs_progress_start(&prog, "record", "ticks", limit, quiet ? RS_PROGRESS_OFF : (rs_progress_mode)progress);
    int status = RS_EXIT_FAIL;
    while (st.tick < limit) {
        g_input in[2] = {g_ai_input(&cpu[0], &st), g_ai_input(&cpu[1], &st)};
        g_step(&st, in, NULL);
        if (!rp_rec_tick(&rec, in, &st, &err))
            goto done;
        if (!seconds && st.phase == G_PHASE_MATCH_END && st.phase_ticks == G_MATCH_END_TICKS - 1)
            break; /* the last tick of the winner announcement: the next would start a new match */
        if ((st.tick & 0xfff) == 0)
            rs_progress_update(&prog, st.tick);
    }
    rs_progress_update(&prog, st.tick); /* updates are every 4096 ticks; the last line says where it ended */
    rs_progress_end(&prog);
    if (!rp_rec_save(&rec, out, &err))
        goto done;
    const rp_replay *rp = &rec.rp;
    char result[64];
    if (rp->winner > 0)
        snprintf(result, sizeof result, "winner P%d (%d-%d)", rp->winner, rp->rounds[0], rp->rounds[1]);
    else
        snprintf(result, sizeof result, "%s (%d-%d)", rp->winner == 0 ? "draw" : "match unfinished", rp->rounds[0],
                 rp->rounds[1]);
    cli_info("record", "wrote %s: %" PRIu64 " ticks (%.2f s), stage %s, seed %" PRIu64 ", %s", out, rp->ticks,
             rp->ticks / (double)G_HZ, g_stages[stage].name, seed, result);
    status = RS_EXIT_OK;
done:
    if (status != RS_EXIT_OK)
        cli_error("record", "%s", err.msg);
    rp_free(&rec.rp);
    return status;
}
