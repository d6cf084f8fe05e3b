/* Test tool, built twice (-O0 and -O2) to compare optimisation levels.
 *   simhash REPLAY                    prints "tick hash" for every tick
 *   simhash --flip TICK BIT IN OUT    writes IN with one input bit flipped at
 *                                     TICK (1-based, player 1), re-encoded with
 *                                     a valid checksum: a replay that desyncs
 *   simhash --winner W IN OUT         writes IN claiming winner W in its header
 *   simhash --game-version V IN OUT   writes IN as recorded by game version V
 *                                     (0: as format 1, which records none) */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../runtime/replay/rp.h"

int main(int argc, char **argv)
{
    rs_err err = {0};
    rp_replay rp;
    if (argc == 2) {
        if (!rp_read(argv[1], &rp, &err)) {
            fprintf(stderr, "simhash: %s\n", err.msg);
            return 1;
        }
        rp_verify_result res;
        bool ok = rp_verify(&rp, stdout, NULL, NULL, &res, &err);
        rp_free(&rp);
        return ok && res.ok ? 0 : 1;
    }
    if (argc == 6 && !strcmp(argv[1], "--flip")) {
        unsigned long long tick = strtoull(argv[2], NULL, 10);
        int bit = atoi(argv[3]);
        if (!rp_read(argv[4], &rp, &err)) {
            fprintf(stderr, "simhash: %s\n", err.msg);
            return 1;
        }
        if (tick < 1 || tick > rp.ticks || bit < 0 || bit > 7) {
            fprintf(stderr, "simhash: tick or bit out of range\n");
            return 1;
        }
        rp.inputs[2 * (tick - 1)] ^= (g_input)(1u << bit);
        bool ok = rp_write(argv[5], &rp, &err);
        if (!ok)
            fprintf(stderr, "simhash: %s\n", err.msg);
        rp_free(&rp);
        return ok ? 0 : 1;
    }
    if (argc == 5 && (!strcmp(argv[1], "--winner") || !strcmp(argv[1], "--game-version"))) {
        if (!rp_read(argv[3], &rp, &err)) {
            fprintf(stderr, "simhash: %s\n", err.msg);
            return 1;
        }
        if (!strcmp(argv[1], "--winner"))
            rp.winner = atoi(argv[2]);
        else {
            rp.game_version = (uint32_t)strtoul(argv[2], NULL, 10);
            rp_set_format(&rp, rp.game_version ? RP_VERSION : 1);
        }
        bool ok = rp_write(argv[4], &rp, &err);
        if (!ok)
            fprintf(stderr, "simhash: %s\n", err.msg);
        rp_free(&rp);
        return ok ? 0 : 1;
    }
    fprintf(stderr, "usage: simhash REPLAY | simhash --flip TICK BIT IN OUT | simhash --winner W IN OUT | simhash --game-version V IN OUT\n");
    return 2;
}
