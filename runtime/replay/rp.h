/* Replay files (.rsr): key inputs of both players, tick by tick, with state
 * hash checkpoints.  The format is documented in docs/replay-format.md.
 *
 * Reading is strict and bounded: every error names the file, the byte
 * offset and what was expected, and nothing is allocated beyond what the
 * file's own (checked) sizes justify, capped by RP_MAX_FILE and
 * RP_MAX_TICKS. */
#ifndef RP_H
#define RP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "../game/g_game.h"
#include "../util/rs_err.h"

#define RP_MAGIC "RSRP"
#define RP_VERSION 3         /* what the recorder writes; the reader also takes 1 and 2 */
#define RP_HEADER_BYTES 40    /* version 2; version 1 has no game version: 36 */
#define RP_HEADER_BYTES_V1 36
#define RP_MAX_FILE (64u << 20)
#define RP_MAX_TICKS (7ull * 24 * 3600 * G_HZ) /* a week of play */
#define RP_DEFAULT_INTERVAL 60

/* Error ids (rs_err.h): what a caller or a test can tell apart. */
#define RP_ERRORS(X)                                                                   \
    X(OPEN, "cannot open or read the replay file")                                     \
    X(TOO_BIG, "larger than the size limit for replays")                               \
    X(MAGIC, "not a ringside replay (no RSRP magic)")                                  \
    X(VERSION, "format version not supported by this build")                          \
    X(TRUNCATED, "the file ends before a field it needs")                              \
    X(CHECKSUM, "checksum mismatch: the file is damaged or truncated")                 \
    X(FIELD, "a header field or input run is out of range or inconsistent")            \
    X(NOMEM, "out of memory")                                                          \
    X(WRITE, "writing the replay (or a hash list) failed, or its read-back differs")   \
    X(RECORD, "nothing to save, or a recording longer than the tick limit")            \
    X(DESYNC, "the inputs no longer reproduce the recorded state hashes")                \
    X(GAME_VERSION, "recorded by another version of the game")

typedef enum rp_error {
    RP_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_RP),
#define X(id, text) RP_ERR_##id,
    RP_ERRORS(X)
#undef X
        RP_ERR_END
} rp_error;

const char *rp_error_text(int code);

enum { RP_HUMAN = 0, RP_CPU = 1 };

typedef struct rp_replay {
    int version;          /* format version: 1 or 2; rp_encode writes this one */
    uint32_t game_version; /* G_GAME_VERSION it was recorded with; 0 in a format-1
                              file, which records none (taken as this build's) */
    int stage;
    uint64_t seed;
    uint64_t ticks;
    int interval;         /* ticks between checkpoints */
    int kind[2];          /* RP_HUMAN / RP_CPU */
    int winner;           /* first match: -1 unfinished, 0 draw, 1, 2 */
    int rounds[2];        /* rounds won in the first match (or so far) */
    g_input *inputs;      /* 2 * ticks: p1, p2 for tick 1, then tick 2, ... */
    uint64_t *checkpoints; /* hash after tick k * interval, k = 1..ncheck */
    size_t ncheck;
    uint64_t final_hash;  /* hash after the last tick */
    size_t input_bytes;   /* size of the encoded input section */
} rp_replay;

/* --- recording --- */
typedef struct rp_recorder {
    rp_replay rp;
    size_t cap_ticks, cap_check;
    bool failed;
} rp_recorder;

void rp_rec_init(rp_recorder *r, int stage, uint64_t seed, int kind1, int kind2);
/* After g_step: the inputs of that tick and the state they produced. */
bool rp_rec_tick(rp_recorder *r, const g_input in[2], const g_state *after, rs_err *err);
/* Writes the file (.part, read back and compared, then renamed).  The
 * recorder keeps its data; free it with rp_free(&r->rp). */
bool rp_rec_save(rp_recorder *r, const char *path, rs_err *err);

/* --- bytes and files --- */
/* Encodes into a malloc'd buffer. */
bool rp_encode(const rp_replay *rp, uint8_t **out, size_t *len, rs_err *err);
/* name is used in messages (a path, or "upload"). */
bool rp_decode(const uint8_t *buf, size_t len, const char *name, rp_replay *rp, rs_err *err);
/* The tick count a replay's header declares (byte 20), read without
 * decoding or checking anything else: what a service looks at before it
 * spends 2 bytes a tick decoding.  False when buf is too short or not a
 * replay. */
bool rp_peek_ticks(const uint8_t *buf, size_t len, uint64_t *ticks);
/* path "-": standard input, named RP_STDIN_NAME in messages */
#define RP_STDIN_NAME "standard input"
bool rp_read(const char *path, rp_replay *rp, rs_err *err);
bool rp_write(const char *path, const rp_replay *rp, rs_err *err);
void rp_free(rp_replay *rp);

/* --- verification: simulation only, no GL --- */
/* The replay was recorded by this build's game rules (G_GAME_VERSION), or
 * records none (format 1).  Otherwise fails with RP_ERR_GAME_VERSION:
 * "NAME: recorded by another version of the game (replay: X, this build: Y)"
 * (no "NAME: " when name is NULL). */
bool rp_check_game(const rp_replay *rp, const char *name, rs_err *err);

typedef struct rp_verify_result {
    bool ok;
    uint64_t desync_tick;   /* first checkpoint tick whose hash differs (0 if none) */
    uint64_t last_good_tick; /* last checkpoint that matched */
    uint64_t want, got;
    int winner;             /* of the first match, as simulated */
    int rounds[2];
    bool header_mismatch;   /* every hash matched, but the header's winner or rounds do not */
    bool kinds_altered;     /* format 3: the hashes match with other player kinds than the header's */
    int kinds_recorded[2];  /* those kinds */
} rp_verify_result;

/* A state hash as a replay of this format records it: format 3 binds the
 * header's player kinds into every checkpoint and the final hash (the
 * state hash XOR a key of the two kinds), so a header whose kinds were
 * changed no longer verifies; formats 1 and 2 record the state hash. */
uint64_t rp_recorded_hash(const rp_replay *rp, uint64_t state_hash);
/* The replay as another format version records it: rp->version set and
 * every hash re-keyed (the same match, verifying as before). */
void rp_set_format(rp_replay *rp, int version);

/* What a failed verification found, as one clause for a message: "desync
 * at tick T: state hash X, recorded Y (last matching checkpoint: tick L;
 * the inputs diverge in ticks L+1..T)", or, when only the final hash
 * differs though the checkpoint at its tick matched, that the recorded
 * final hash is what is damaged. */
void rp_desync_text(const rp_verify_result *res, char *out, size_t n);

/* Checks the game version (rp_check_game: returns false, nothing
 * simulated), then steps the game through every tick; checks every
 * checkpoint and the final hash.  hashes (optional) gets "tick hash" per tick.  progress (optional)
 * is called every 2^16 ticks. */
bool rp_verify(const rp_replay *rp, FILE *hashes, void (*progress)(uint64_t done, uint64_t total, void *user),
               void *user, rp_verify_result *res, rs_err *err);

/* rp_verify's check one tick at a time, for callers that re-simulate the
 * replay themselves (render): after `done` ticks, with the game in state st,
 * the state hash must equal the checkpoint due at that tick (every interval
 * ticks) and, after the last tick, the final hash.  *next counts the
 * checkpoints passed: start it at 0 and call once per tick, in order.
 * Ticks with nothing due pass without hashing.  A mismatch fails with
 * RP_ERR_DESYNC: "NAME: desync at tick T: the game's state hash ... is not
 * the replay's ...", or RP_ERR_GAME_VERSION with the same words and
 * rp_check_game's when the replay was recorded by other game rules (a
 * renderer may go on with such a replay as long as it reproduces). */
bool rp_check_tick(const rp_replay *rp, const g_state *st, uint64_t done, size_t *next, const char *name,
                   rs_err *err);

#endif
