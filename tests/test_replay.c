/* runtime/replay: encode/decode round trip, size, every corruption case
 * with its byte offset, randomized corruption, desync localisation, and
 * writes that fail cleanly. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "../runtime/game/g_ai.h"
#include "../runtime/replay/rp.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_hash.h"
#include "../runtime/util/rs_img.h"
#include "t.h"

/* A recorded CPU match of at most `ticks` ticks. */
static void record(rp_replay *out, uint64_t seed, int stage, uint64_t ticks)
{
    g_state st;
    g_ai a, b;
    g_init(&st, stage, seed);
    g_ai_init(&a, 0, 2, seed);
    g_ai_init(&b, 1, 2, seed + 1);
    rp_recorder rec;
    rp_rec_init(&rec, stage, seed, RP_CPU, RP_CPU);
    rs_err e = {0};
    while (st.tick < ticks) {
        g_input in[2] = {g_ai_input(&a, &st), g_ai_input(&b, &st)};
        g_step(&st, in, NULL);
        T_ASSERTF(rp_rec_tick(&rec, in, &st, &e), "%s", e.msg);
    }
    *out = rec.rp;
}

static void encode(const rp_replay *rp, uint8_t **buf, size_t *n)
{
    rs_err e = {0};
    T_ASSERTF(rp_encode(rp, buf, n, &e), "%s", e.msg);
}

static void t_roundtrip(void)
{
    rp_replay rp, back;
    record(&rp, 3, 1, 5000);
    uint8_t *buf;
    size_t n;
    encode(&rp, &buf, &n);
    rs_err e = {0};
    T_ASSERTF(rp_decode(buf, n, "mem", &back, &e), "%s", e.msg);
    T_EQ(back.ticks, rp.ticks);
    T_EQ(back.stage, 1);
    T_EQ(back.seed, 3);
    T_EQ(back.ncheck, rp.ticks / 60);
    T_EQ(back.final_hash, rp.final_hash);
    T_ASSERT(!memcmp(back.inputs, rp.inputs, (size_t)rp.ticks * 2));
    T_ASSERT(!memcmp(back.checkpoints, rp.checkpoints, rp.ncheck * 8));
    rp_verify_result res;
    T_ASSERT(rp_verify(&back, NULL, NULL, NULL, &res, &e));
    T_ASSERT(res.ok);
    free(buf);
    rp_free(&rp);
    rp_free(&back);
}

static void t_three_minutes_under_16k(void)
{
    for (uint64_t seed = 1; seed <= 4; seed++) {
        rp_replay rp;
        record(&rp, seed, (int)(seed % G_STAGES), 180 * G_HZ);
        uint8_t *buf;
        size_t n;
        encode(&rp, &buf, &n);
        T_ASSERTF(n < 16 * 1024, "seed %llu: %zu bytes", (unsigned long long)seed, n);
        free(buf);
        rp_free(&rp);
    }
}

/* Patches bytes, recomputes the CRC, expects decode to fail with id
 * `code` and a message holding `want`. */
static void expect_bad(const uint8_t *good, size_t n, size_t off, const void *bytes, size_t k, bool fix_crc, int code,
                       const char *want1, const char *want2)
{
    uint8_t *b = malloc(n);
    memcpy(b, good, n);
    memcpy(b + off, bytes, k);
    if (fix_crc) {
        uint32_t c = rs_crc32(0, b, n - 4);
        for (int i = 0; i < 4; i++)
            b[n - 4 + (size_t)i] = (uint8_t)(c >> (8 * i));
    }
    rp_replay rp;
    rs_err e = {0};
    T_ASSERTF(!rp_decode(b, n, "x.rsr", &rp, &e), "patch at %zu accepted", off);
    T_ASSERTF(e.code == code, "patch at %zu: %s, want %s (%s)", off, rp_error_text(e.code), rp_error_text(code), e.msg);
    T_CONTAINS(e.msg, "x.rsr: ");
    T_CONTAINS(e.msg, want1);
    if (want2)
        T_CONTAINS(e.msg, want2);
    T_ASSERT(rp.inputs == NULL && rp.checkpoints == NULL);
    free(b);
}

static void t_corruption_cases(void)
{
    rp_replay rp;
    record(&rp, 11, 0, 700);
    uint8_t *g;
    size_t n;
    encode(&rp, &g, &n);
    const uint8_t v4[2] = {4, 0}, v0[2] = {0, 0}, zero4[4] = {0}, zero8[8] = {0}, big8[8] = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff, 0, 0};
    const uint8_t st99[4] = {99, 0, 0, 0}, iv0[2] = {0, 0}, k3 = 3, w7 = 7, flag[2] = {1, 0}, r9 = 9;
    expect_bad(g, n, 0, "RSRQ", 4, false, RP_ERR_MAGIC, "not a ringside replay", "byte 0");
    expect_bad(g, n, 4, v4, 2, false, RP_ERR_VERSION, "format version 4 at byte 4", "this build reads 1 to 3");
    expect_bad(g, n, 4, v0, 2, false, RP_ERR_VERSION, "format version 0 at byte 4", "this build reads 1 to 3");
    expect_bad(g, n, 100, "\xAA", 1, false, RP_ERR_CHECKSUM, "checksum mismatch", "file damaged");
    expect_bad(g, n, 6, flag, 2, true, RP_ERR_FIELD, "unknown flags", "byte 6");
    expect_bad(g, n, 8, st99, 4, true, RP_ERR_FIELD, "stage id 99 at byte 8", NULL);
    expect_bad(g, n, 20, zero8, 8, true, RP_ERR_FIELD, "tick count 0 at byte 20", NULL);
    expect_bad(g, n, 20, big8, 8, true, RP_ERR_FIELD, "out of range", "byte 20");
    expect_bad(g, n, 28, iv0, 2, true, RP_ERR_FIELD, "checkpoint interval 0 at byte 28", NULL);
    expect_bad(g, n, 30, &k3, 1, true, RP_ERR_FIELD, "player 1 kind 3 at byte 30", NULL);
    expect_bad(g, n, 32, &w7, 1, true, RP_ERR_FIELD, "winner 7 at byte 32", NULL);
    expect_bad(g, n, 32, &k3, 1, true, RP_ERR_FIELD, "winner 3 at byte 32", NULL); /* the first past 0..2 */
    expect_bad(g, n, 33, &r9, 1, true, RP_ERR_FIELD, "rounds won 9 at byte 33", NULL);
    expect_bad(g, n, 35, &k3, 1, true, RP_ERR_FIELD, "reserved byte 35 is 3", NULL);
    expect_bad(g, n, 36, zero4, 4, true, RP_ERR_FIELD, "game version 0 at byte 36", NULL);
    const uint8_t long_in[4] = {0xff, 0xff, 0, 0};
    expect_bad(g, n, 40, long_in, 4, true, RP_ERR_FIELD, "input section length 65535 at byte 40", NULL);
    /* input section: a run past the tick count, opposite directions */
    const uint8_t huge_run[5] = {0xff, 0xff, 0xff, 0x7f, 0x00};
    expect_bad(g, n, 44, huge_run, 4, true, RP_ERR_FIELD, "goes past the tick count", "byte 44");
    const uint8_t updown[3] = {0x01, 0x03, 0x00}; /* run 1, p1 = up|down */
    expect_bad(g, n, 44, updown, 3, true, RP_ERR_FIELD, "holds opposite directions", "byte 45");
    /* truncated: everything from a valid prefix (fails at the CRC or a
     * section check, never reads past the end) */
    rp_replay out;
    rs_err e = {0};
    for (size_t cut = 0; cut < n; cut += (cut < 64 ? 1 : 37)) {
        T_ASSERTF(!rp_decode(g, cut, "x.rsr", &out, &e), "a %zu-byte prefix was accepted", cut);
        T_ASSERTF(cut < 4 ? e.code == RP_ERR_MAGIC : e.code == RP_ERR_TRUNCATED || e.code == RP_ERR_CHECKSUM,
                  "%zu-byte prefix: %s (%s)", cut, rp_error_text(e.code), e.msg);
        T_CONTAINS(e.msg, "x.rsr");
    }
    /* trailing garbage with a fixed CRC */
    uint8_t *longer = malloc(n + 3);
    memcpy(longer, g, n - 4);
    memset(longer + n - 4, 0, 3);
    uint32_t c = rs_crc32(0, longer, n - 1);
    for (int i = 0; i < 4; i++)
        longer[n - 1 + (size_t)i] = (uint8_t)(c >> (8 * i));
    T_ASSERT(!rp_decode(longer, n + 3, "x.rsr", &out, &e));
    T_EQ(e.code, RP_ERR_FIELD);
    T_CONTAINS(e.msg, "unexpected bytes");
    free(longer);
    /* one checkpoint short, the file otherwise whole (count, hashes and CRC
     * agree): readers index checkpoints up to ticks / interval */
    T_ASSERT(rp.ncheck >= 2);
    rp.ncheck--;
    uint8_t *shorter;
    size_t ns;
    encode(&rp, &shorter, &ns);
    rp.ncheck++;
    T_ASSERT(!rp_decode(shorter, ns, "x.rsr", &out, &e));
    T_EQ(e.code, RP_ERR_FIELD);
    char want[64];
    snprintf(want, sizeof want, "%zu checkpoints at byte", rp.ncheck - 1);
    T_CONTAINS(e.msg, want);
    snprintf(want, sizeof want, "expected %zu (ticks / interval)", rp.ncheck);
    T_CONTAINS(e.msg, want);
    free(shorter);
    free(g);
    rp_free(&rp);
}

static void t_oversized_file(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/huge.rsr", t_tmpdir());
    FILE *f = fopen(path, "wb");
    T_ASSERT(f && ftruncate(fileno(f), (off_t)RP_MAX_FILE + 1) == 0);
    fclose(f);
    rp_replay rp;
    rs_err e = {0};
    T_ASSERT(!rp_read(path, &rp, &e));
    T_EQ(e.code, RP_ERR_TOO_BIG);
    T_CONTAINS(e.msg, "huge.rsr: larger than the limit");
    T_ASSERT(!rp_read("/nonexistent/a.rsr", &rp, &e));
    T_EQ(e.code, RP_ERR_OPEN);
    T_CONTAINS(e.msg, "/nonexistent/a.rsr: cannot open");
}

static void t_random_corruption(void)
{
    /* thousands of random mutations, half with a repaired CRC so the
     * deeper checks are reached: never a crash, never an inconsistent
     * result */
    rp_replay rp;
    record(&rp, 21, 2, 1500);
    uint8_t *g;
    size_t n;
    encode(&rp, &g, &n);
    uint8_t *b = malloc(n + 64);
    srand(99);
    int accepted = 0;
    for (int iter = 0; iter < 4000; iter++) {
        size_t len = n;
        memcpy(b, g, n);
        int muts = 1 + rand() % 4;
        for (int k = 0; k < muts; k++) {
            switch (rand() % 3) {
            case 0: b[(size_t)rand() % len] ^= (uint8_t)(1u << (rand() % 8)); break;
            case 1: b[(size_t)rand() % len] = (uint8_t)rand(); break;
            default: len = len > 8 ? (size_t)rand() % len + 1 : len; break;
            }
        }
        if (iter % 2 && len > 4) {
            uint32_t c = rs_crc32(0, b, len - 4);
            for (int i = 0; i < 4; i++)
                b[len - 4 + (size_t)i] = (uint8_t)(c >> (8 * i));
        }
        rp_replay out;
        rs_err e = {0};
        if (rp_decode(b, len, "fuzz.rsr", &out, &e)) {
            accepted++;
            T_ASSERT(out.ticks >= 1 && out.ncheck == out.ticks / (uint64_t)out.interval);
            /* whatever is accepted re-encodes to a file that decodes the same */
            uint8_t *re;
            size_t rn;
            rp_replay again;
            encode(&out, &re, &rn);
            T_ASSERT(rp_decode(re, rn, "again", &again, &e));
            T_ASSERT(again.ticks == out.ticks && again.final_hash == out.final_hash &&
                     !memcmp(again.inputs, out.inputs, (size_t)out.ticks * 2));
            free(re);
            rp_free(&again);
            rp_free(&out);
        } else {
            T_ASSERTF(RS_ERR_MODULE(e.code) == RS_ERR_MOD_RP && e.code != RP_ERR_NOMEM, "code %d: %s", e.code, e.msg);
            T_CONTAINS(e.msg, "fuzz.rsr: ");
        }
    }
    T_ASSERT(accepted > 0 && accepted < 4000); /* some repaired mutations are valid files */
    free(b);
    free(g);
    rp_free(&rp);
}

static void t_flipped_input_desyncs_at_its_checkpoint(void)
{
    rp_replay rp;
    record(&rp, 5, 0, 3000);
    const uint64_t flips[] = {1, 59, 60, 61, 1234, 2999, 3000};
    for (size_t i = 0; i < sizeof flips / sizeof flips[0]; i++) {
        uint64_t t = flips[i];
        rp_replay m = rp;
        m.inputs = malloc((size_t)rp.ticks * 2);
        memcpy(m.inputs, rp.inputs, (size_t)rp.ticks * 2);
        m.inputs[2 * (t - 1)] ^= G_IN_GUARD;
        rp_verify_result res;
        rs_err e = {0};
        T_ASSERT(rp_verify(&m, NULL, NULL, NULL, &res, &e));
        T_ASSERTF(!res.ok, "flip at tick %llu not detected", (unsigned long long)t);
        uint64_t want = (t + 59) / 60 * 60;
        T_ASSERTF(res.desync_tick == want, "flip at %llu: desync reported at %llu, want %llu", (unsigned long long)t,
                  (unsigned long long)res.desync_tick, (unsigned long long)want);
        T_EQ(res.last_good_tick, want - 60);
        free(m.inputs);
    }
    rp_free(&rp);
}

static void t_write_read_back_and_failures(void)
{
    rp_replay rp, back;
    record(&rp, 8, 1, 600);
    char path[512], part[600];
    snprintf(path, sizeof path, "%s/a.rsr", t_tmpdir());
    snprintf(part, sizeof part, "%s.part", path);
    rs_err e = {0};
    T_ASSERTF(rp_write(path, &rp, &e), "%s", e.msg);
    T_ASSERT(access(part, F_OK) != 0);
    T_ASSERTF(rp_read(path, &back, &e), "%s", e.msg);
    T_EQ(back.final_hash, rp.final_hash);
    rp_free(&back);
    snprintf(path, sizeof path, "%s/none/a.rsr", t_tmpdir());
    T_ASSERT(!rp_write(path, &rp, &e));
    T_EQ(e.code, RP_ERR_WRITE);
    T_CONTAINS(e.msg, "cannot create");
    /* disk full half way: error, nothing left behind */
    signal(SIGXFSZ, SIG_IGN);
    struct rlimit old, rl;
    T_ASSERT(getrlimit(RLIMIT_FSIZE, &old) == 0);
    rl = (struct rlimit){200, old.rlim_max}; /* soft only: it can be raised back */
    T_ASSERT(setrlimit(RLIMIT_FSIZE, &rl) == 0);
    snprintf(path, sizeof path, "%s/full.rsr", t_tmpdir());
    snprintf(part, sizeof part, "%s.part", path);
    T_ASSERT(!rp_write(path, &rp, &e));
    T_EQ(e.code, RP_ERR_WRITE);
    T_CONTAINS(e.msg, "full.rsr: write failed");
    T_ASSERT(access(path, F_OK) != 0 && access(part, F_OK) != 0);
    T_ASSERT(setrlimit(RLIMIT_FSIZE, &old) == 0);
    rp_free(&rp);
}

static void t_short_recording(void)
{
    /* under one checkpoint interval: no checkpoints at all, still valid */
    rp_replay rp, back;
    record(&rp, 2, 0, 30);
    T_EQ(rp.ncheck, 0);
    char path[512];
    snprintf(path, sizeof path, "%s/short.rsr", t_tmpdir());
    rs_err e = {0};
    T_ASSERTF(rp_write(path, &rp, &e), "%s", e.msg);
    T_ASSERTF(rp_read(path, &back, &e), "%s", e.msg);
    rp_verify_result res;
    T_ASSERT(rp_verify(&back, NULL, NULL, NULL, &res, &e) && res.ok);
    rp_free(&rp);
    rp_free(&back);
}

static void t_header_result_checked(void)
{
    rp_replay rp;
    record(&rp, 4, 0, 60 * 200); /* long enough for the first match to end */
    T_ASSERT(rp.winner > 0);
    rp.winner = 3 - rp.winner;
    rp_verify_result res;
    rs_err e = {0};
    T_ASSERT(rp_verify(&rp, NULL, NULL, NULL, &res, &e));
    T_ASSERT(!res.ok && res.header_mismatch && res.desync_tick == 0);
    rp_free(&rp);
}

static void t_empty_recording_refused(void)
{
    rp_recorder rec;
    rp_rec_init(&rec, 0, 1, RP_CPU, RP_CPU);
    rs_err e = {0};
    char path[512];
    snprintf(path, sizeof path, "%s/empty.rsr", t_tmpdir());
    T_ASSERT(!rp_rec_save(&rec, path, &e));
    T_EQ(e.code, RP_ERR_RECORD);
    T_CONTAINS(e.msg, "nothing recorded");
}

/* Every id has a text, and no two share one: an id added to RP_ERRORS
 * without a meaningful text fails here. */
static void t_error_ids_have_texts(void)
{
    T_EQ(RS_ERR_MODULE(RP_ERR_BASE + 1), RS_ERR_MOD_RP);
    T_EQ(RS_ERR_MODULE(RP_ERR_END - 1), RS_ERR_MOD_RP);
    T_ASSERT(!strcmp(rs_err_module_name(RP_ERR_DESYNC), "replay"));
    for (int a = RP_ERR_BASE + 1; a < RP_ERR_END; a++) {
        const char *t = rp_error_text(a);
        T_ASSERTF(t[0] && strcmp(t, "?") && strcmp(t, "ok"), "id %d has no text", a);
        for (int b = RP_ERR_BASE + 1; b < a; b++)
            T_ASSERTF(strcmp(t, rp_error_text(b)), "ids %d and %d share the text \"%s\"", b, a, t);
    }
    T_ASSERT(!strcmp(rp_error_text(0), "ok") && !strcmp(rp_error_text(RP_ERR_END), "?"));
}

static void t_demos_verify(void)
{
    static const char *const names[] = {"dojo", "harbor", "temple"};
    for (int i = 0; i < 3; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/demos/%s.rsr", RS_SOURCE_DIR, names[i]);
        rp_replay rp;
        rs_err e = {0};
        T_ASSERTF(rp_read(path, &rp, &e), "%s", e.msg);
        T_EQ(rp.stage, i);
        rp_verify_result res;
        T_ASSERT(rp_verify(&rp, NULL, NULL, NULL, &res, &e));
        T_ASSERTF(res.ok, "%s desyncs at tick %llu (regenerate with make demo-replays after a rule change)", path,
                  (unsigned long long)res.desync_tick);
        T_EQ(res.winner, rp.winner);
        rp_free(&rp);
    }
}

/* A format-1 file (the demos before the game version: tests/golden keeps
 * dojo as it was) reads as the same match as today's demo (its hashes the
 * same state hashes, which format 3 keys with the kinds),
 * records no game version, verifies, and re-encodes to itself byte for
 * byte; its own field offsets (input section at 40) are still checked. */
static void t_format1_still_read(void)
{
    size_t n1;
    rs_err e = {0};
    uint8_t *f1 = (uint8_t *)rs_read_file(RS_SOURCE_DIR "/tests/golden/dojo-format1.rsr", RP_MAX_FILE, &n1, &e);
    T_ASSERTF(f1, "%s", e.msg);
    rp_replay a, b;
    T_ASSERTF(rp_decode(f1, n1, "v1.rsr", &a, &e), "%s", e.msg);
    T_ASSERTF(rp_read(RS_SOURCE_DIR "/demos/dojo.rsr", &b, &e), "%s", e.msg);
    T_EQ(a.version, 1);
    T_EQ(a.game_version, 0);
    T_EQ(b.version, RP_VERSION);
    T_EQ(b.game_version, G_GAME_VERSION);
    T_ASSERT(a.stage == b.stage && a.seed == b.seed && a.ticks == b.ticks && a.winner == b.winner &&
             a.final_hash == rp_recorded_hash(&b, b.final_hash) && a.ncheck == b.ncheck && a.input_bytes == b.input_bytes);
    T_ASSERT(!memcmp(a.inputs, b.inputs, (size_t)a.ticks * 2));
    for (size_t k = 0; k < a.ncheck; k++)
        T_ASSERTF(a.checkpoints[k] == rp_recorded_hash(&b, b.checkpoints[k]), "checkpoint %zu", k);
    rp_verify_result res;
    T_ASSERTF(rp_verify(&a, NULL, NULL, NULL, &res, &e) && res.ok, "%s", e.msg);
    uint8_t *re;
    size_t rn;
    encode(&a, &re, &rn);
    T_ASSERT(rn == n1 && !memcmp(re, f1, n1));
    const uint8_t huge_run[5] = {0xff, 0xff, 0xff, 0x7f, 0x00};
    expect_bad(f1, n1, 40, huge_run, 4, true, RP_ERR_FIELD, "goes past the tick count", "byte 40");
    free(re);
    free(f1);
    rp_free(&a);
    rp_free(&b);
}

/* A replay of other game rules is refused before any simulation, with its
 * own id and both versions named; the version survives a round trip; a
 * render's tick check that desyncs on one names the version as the cause. */
static void t_other_game_version(void)
{
    rp_replay rp, back;
    record(&rp, 5, 0, 3000);
    rp.game_version = G_GAME_VERSION + 1;
    uint8_t *buf;
    size_t n;
    encode(&rp, &buf, &n);
    rs_err e = {0};
    T_ASSERTF(rp_decode(buf, n, "x.rsr", &back, &e), "%s", e.msg);
    T_EQ(back.game_version, G_GAME_VERSION + 1);
    rp_verify_result res;
    T_ASSERT(!rp_verify(&back, NULL, NULL, NULL, &res, &e));
    T_EQ(e.code, RP_ERR_GAME_VERSION);
    char want[128];
    snprintf(want, sizeof want, "recorded by another version of the game (replay: %d, this build: %d)",
             G_GAME_VERSION + 1, G_GAME_VERSION);
    T_ASSERTF(!strcmp(e.msg, want), "%s", e.msg);
    T_ASSERT(!rp_check_game(&back, "x.rsr", &e));
    T_CONTAINS(e.msg, "x.rsr: recorded by another version of the game");
    back.inputs[2 * (1234 - 1)] ^= G_IN_GUARD;
    g_state st;
    g_init(&st, back.stage, back.seed);
    size_t next = 0;
    uint64_t t = 0;
    for (bool ok = true; ok && t < back.ticks; t++) {
        g_step(&st, &back.inputs[2 * t], NULL);
        ok = rp_check_tick(&back, &st, t + 1, &next, "x.rsr", &e);
    }
    T_EQ(t, 1260);
    T_EQ(e.code, RP_ERR_GAME_VERSION);
    T_CONTAINS(e.msg, "x.rsr: desync at tick 1260: ");
    T_CONTAINS(e.msg, want);
    free(buf);
    rp_free(&back);
    rp_free(&rp);
}

/* G_GAME_VERSION must change when the rules do: a short CPU match's final
 * hash is pinned to it.  When this fails, the rules changed: bump
 * G_GAME_VERSION (runtime/game/g_game.h), put the new pair here, and run
 * make demo-replays. */
static void t_game_version_pinned_to_rules(void)
{
    static const struct {
        int game_version;
        uint64_t hash;
    } pin = {1, 0x56d8bf9bdcd7e1d4ull};
    rp_replay rp;
    record(&rp, 1, 0, 600);
    uint64_t state = rp_recorded_hash(&rp, rp.final_hash); /* the game's own hash, whatever the format keys it with */
    T_ASSERTF(G_GAME_VERSION != pin.game_version || state == pin.hash,
              "the rules changed (hash %016llx, pinned %016llx) but G_GAME_VERSION is still %d: bump it",
              (unsigned long long)state, (unsigned long long)pin.hash, G_GAME_VERSION);
    T_ASSERTF(G_GAME_VERSION == pin.game_version, "G_GAME_VERSION %d: pin its hash %016llx here", G_GAME_VERSION,
              (unsigned long long)state);
    rp_free(&rp);
}

/* rp_check_tick, tick by tick, agrees with rp_verify: a clean replay passes
 * every tick; a flipped input fails at the first checkpoint after it, with
 * RP_ERR_DESYNC and a message naming the file and the tick. */
static void t_check_tick_agrees_with_verify(void)
{
    rp_replay rp;
    record(&rp, 5, 0, 3000);
    for (int flip = 0; flip < 2; flip++) {
        rp_replay m = rp;
        m.inputs = malloc((size_t)rp.ticks * 2);
        memcpy(m.inputs, rp.inputs, (size_t)rp.ticks * 2);
        if (flip)
            m.inputs[2 * (1234 - 1)] ^= G_IN_GUARD;
        g_state st;
        g_init(&st, m.stage, m.seed);
        size_t next = 0;
        uint64_t failed = 0;
        rs_err e = {0};
        for (uint64_t t = 0; t < m.ticks && !failed; t++) {
            g_step(&st, &m.inputs[2 * t], NULL);
            if (!rp_check_tick(&m, &st, t + 1, &next, "x.rsr", &e))
                failed = t + 1;
        }
        if (!flip) {
            T_EQ(failed, 0);
            T_EQ(next, m.ncheck);
        } else {
            T_EQ(failed, 1260);
            T_EQ(e.code, RP_ERR_DESYNC);
            T_ASSERTF(strstr(e.msg, "x.rsr: desync at tick 1260: ") == e.msg, "%s", e.msg);
        }
        free(m.inputs);
    }
    rp_free(&rp);
}

/* Format 3 binds the header's player kinds into the hashes: a CPU player
 * relabelled human, with the CRC made right again, no longer verifies, and
 * the message says which kinds it was recorded with; format 2 (kinds not
 * bound) still verifies, and re-keying the hashes is all a format change is. */
static void t_kinds_bound_to_hashes(void)
{
    rp_replay rp;
    record(&rp, 5, 0, 300);
    T_EQ(rp.version, 3);
    uint8_t *g;
    size_t n;
    encode(&rp, &g, &n);
    g[30] = RP_HUMAN; /* P1 relabelled */
    uint32_t c = rs_crc32(0, g, n - 4);
    for (int i = 0; i < 4; i++)
        g[n - 4 + (size_t)i] = (uint8_t)(c >> (8 * i));
    rp_replay back;
    rs_err e = {0};
    T_ASSERTF(rp_decode(g, n, "x.rsr", &back, &e), "%s", e.msg);
    rp_verify_result res;
    T_ASSERT(rp_verify(&back, NULL, NULL, NULL, &res, &e));
    T_ASSERT(!res.ok && res.kinds_altered && res.kinds_recorded[0] == RP_CPU && res.kinds_recorded[1] == RP_CPU);
    char why[300];
    rp_desync_text(&res, why, sizeof why);
    T_ASSERTF(strstr(why, "not the ones it was recorded with (P1 cpu, P2 cpu)"), "%s", why);
    /* the renderer's tick-by-tick check says the same */
    g_state st;
    g_init(&st, back.stage, back.seed);
    size_t next = 0;
    bool ok = true;
    for (uint64_t t = 0; t < back.ticks && ok; t++) {
        g_step(&st, &back.inputs[2 * t], NULL);
        ok = rp_check_tick(&back, &st, t + 1, &next, "x.rsr", &e);
    }
    T_ASSERTF(!ok && strstr(e.msg, "the header was altered"), "%s", e.msg);
    rp_free(&back);
    free(g);
    /* the same match as format 2: the state hashes themselves, kinds free */
    rp_replay v2 = rp;
    v2.checkpoints = malloc(rp.ncheck * 8);
    memcpy(v2.checkpoints, rp.checkpoints, rp.ncheck * 8);
    rp_set_format(&v2, 2);
    T_ASSERT(v2.final_hash != rp.final_hash);
    T_ASSERT(rp_verify(&v2, NULL, NULL, NULL, &res, &e) && res.ok);
    v2.kind[0] = RP_HUMAN;
    T_ASSERT(rp_verify(&v2, NULL, NULL, NULL, &res, &e) && res.ok);
    free(v2.checkpoints);
    rp_free(&rp);
}

T_MAIN({"kinds_bound_to_hashes", t_kinds_bound_to_hashes}, {"roundtrip", t_roundtrip}, {"three_minutes_under_16k", t_three_minutes_under_16k},
       {"corruption_cases", t_corruption_cases}, {"oversized_file", t_oversized_file},
       {"random_corruption", t_random_corruption},
       {"flipped_input_desyncs_at_its_checkpoint", t_flipped_input_desyncs_at_its_checkpoint},
       {"write_read_back_and_failures", t_write_read_back_and_failures}, {"short_recording", t_short_recording},
       {"header_result_checked", t_header_result_checked}, {"empty_recording_refused", t_empty_recording_refused},
       {"error_ids_have_texts", t_error_ids_have_texts}, {"demos_verify", t_demos_verify},
       {"check_tick_agrees_with_verify", t_check_tick_agrees_with_verify},
       {"format1_still_read", t_format1_still_read}, {"other_game_version", t_other_game_version},
       {"game_version_pinned_to_rules", t_game_version_pinned_to_rules})
