/* libFuzzer target for the replay reader: `make fuzz` builds it,
 * `make fuzz-run FUZZ_SECONDS=600` runs it on the demo replays as seeds.
 * The seeds hold two formats (the format-3 demos, with the game version,
 * and tests/golden/dojo-format1.rsr without).  A decoded replay is also
 * verified (as this build's game, whatever game version it records, so the
 * simulation sees every input the parser accepts), and whatever is accepted
 * must survive re-encoding in its own format with its own game version. */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include "../runtime/replay/rp.h"

#include <string.h>

#include "../runtime/util/rs_hash.h"

static void one(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

/* Each input is decoded as it is, and again with its last four bytes
 * replaced by the right CRC-32, so mutations get past the checksum and
 * reach every field check behind it. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    one(data, size);
    if (size >= 8 && size <= RP_MAX_FILE) {
        uint8_t *copy = malloc(size);
        memcpy(copy, data, size);
        uint32_t c = rs_crc32(0, copy, size - 4);
        for (int i = 0; i < 4; i++)
            copy[size - 4 + (size_t)i] = (uint8_t)(c >> (8 * i));
        one(copy, size);
        free(copy);
    }
    return 0;
}

static void one(const uint8_t *data, size_t size)
{
    rp_replay rp;
    rs_err err;
    if (rp_decode(data, size, "fuzz", &rp, &err)) {
        if (rp.ticks <= 20000) { /* keep each run fast */
            rp_verify_result res;
            uint32_t game = rp.game_version;
            bool refused = !rp_verify(&rp, NULL, NULL, NULL, &res, &err) && err.code == RP_ERR_GAME_VERSION;
            if (refused != (game != 0 && game != G_GAME_VERSION))
                __builtin_trap(); /* refused for the game version exactly when it is another one */
            rp.game_version = 0;
            rp_verify(&rp, NULL, NULL, NULL, &res, &err);
            rp.game_version = game;
        }
        uint8_t *buf;
        size_t n;
        if (rp_encode(&rp, &buf, &n, &err)) {
            rp_replay again;
            /* what we accept, we re-encode to something we accept */
            if (!rp_decode(buf, n, "fuzz-reencoded", &again, &err))
                __builtin_trap();
            if (again.version != rp.version || again.game_version != rp.game_version)
                __builtin_trap();
            rp_free(&again);
            free(buf);
        }
        rp_free(&rp);
    }
}
