#include "rp.h"

#include <errno.h>
#include <inttypes.h>
#include <stdio.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../util/rs_file.h"
#include "../util/rs_hash.h"

const char *rp_error_text(int code)
{
    static const char *const text[] = {
#define X(id, t) t,
        RP_ERRORS(X)
#undef X
    };
    return rs_err_text_of(code, RS_ERR_MOD_RP, text, (int)(sizeof text / sizeof text[0]));
}

/* An error of a helper from another module (rs_file) as one of ours. */
static bool recode(rs_err *err, int code)
{
    if (err)
        err->code = code;
    return false;
}

/* ---------- little-endian writer ---------- */
typedef struct wbuf {
    uint8_t *p;
    size_t n, cap;
    bool oom;
} wbuf;

static void wb_put(wbuf *w, const void *d, size_t n)
{
    if (w->oom)
        return;
    if (w->n + n > w->cap) {
        size_t cap = w->cap ? w->cap * 2 : 4096;
        while (cap < w->n + n)
            cap *= 2;
        uint8_t *np = realloc(w->p, cap);
        if (!np) {
            w->oom = true;
            return;
        }
        w->p = np;
        w->cap = cap;
    }
    memcpy(w->p + w->n, d, n);
    w->n += n;
}

static void wb_u(wbuf *w, uint64_t v, int bytes)
{
    uint8_t b[8];
    for (int k = 0; k < bytes; k++)
        b[k] = (uint8_t)(v >> (8 * k));
    wb_put(w, b, (size_t)bytes);
}

static void wb_varint(wbuf *w, uint64_t v)
{
    uint8_t b[10];
    int n = 0;
    do {
        b[n] = (uint8_t)(v & 0x7f);
        v >>= 7;
        if (v)
            b[n] |= 0x80;
        n++;
    } while (v);
    wb_put(w, b, (size_t)n);
}

static void encode_inputs(wbuf *w, const rp_replay *rp)
{
    uint64_t t = 0;
    while (t < rp->ticks) {
        g_input a = rp->inputs[2 * t], b = rp->inputs[2 * t + 1];
        uint64_t run = 1;
        while (t + run < rp->ticks && rp->inputs[2 * (t + run)] == a && rp->inputs[2 * (t + run) + 1] == b)
            run++;
        wb_varint(w, run);
        wb_put(w, &a, 1);
        wb_put(w, &b, 1);
        t += run;
    }
}

bool rp_encode(const rp_replay *rp, uint8_t **out, size_t *len, rs_err *err)
{
    wbuf w = {0};
    /* the format the struct says: a replay re-encodes as it was read (its
     * hashes are of its format: rp_recorded_hash) */
    bool v1 = rp->version == 1;
    wb_put(&w, RP_MAGIC, 4);
    wb_u(&w, rp->version >= 1 && rp->version <= RP_VERSION ? (uint64_t)rp->version : RP_VERSION, 2);
    wb_u(&w, 0, 2); /* flags */
    wb_u(&w, (uint64_t)rp->stage, 4);
    wb_u(&w, rp->seed, 8);
    wb_u(&w, rp->ticks, 8);
    wb_u(&w, (uint64_t)rp->interval, 2);
    wb_u(&w, (uint64_t)rp->kind[0], 1);
    wb_u(&w, (uint64_t)rp->kind[1], 1);
    wb_u(&w, rp->winner < 0 ? 0xff : (uint64_t)rp->winner, 1);
    wb_u(&w, (uint64_t)rp->rounds[0], 1);
    wb_u(&w, (uint64_t)rp->rounds[1], 1);
    wb_u(&w, 0, 1); /* reserved */
    if (!v1)
        wb_u(&w, rp->game_version, 4);
    wbuf in = {0};
    encode_inputs(&in, rp);
    wb_u(&w, in.n, 4);
    wb_put(&w, in.p, in.n);
    bool in_oom = in.oom;
    free(in.p);
    wb_u(&w, rp->ncheck, 4);
    for (size_t k = 0; k < rp->ncheck; k++)
        wb_u(&w, rp->checkpoints[k], 8);
    wb_u(&w, rp->final_hash, 8);
    if (w.oom || in_oom) {
        free(w.p);
        return rs_fail(err, RP_ERR_NOMEM, "out of memory encoding a replay of %llu ticks", (unsigned long long)rp->ticks);
    }
    wb_u(&w, rs_crc32(0, w.p, w.n), 4);
    if (w.oom) {
        free(w.p);
        return rs_fail(err, RP_ERR_NOMEM, "out of memory encoding a replay");
    }
    *out = w.p;
    *len = w.n;
    return true;
}

/* ---------- strict reader ---------- */
typedef struct rbuf {
    const uint8_t *p;
    size_t n, o;
    const char *name;
    rs_err *err;
} rbuf;

static bool need(rbuf *r, size_t n, const char *what)
{
    if (r->n - r->o < n)
        return rs_fail(r->err, RP_ERR_TRUNCATED, "%s: truncated at byte %zu: expected %s (%zu bytes), file has %zu",
                       r->name, r->o, what, n, r->n - r->o);
    return true;
}

static bool rd_u(rbuf *r, int bytes, uint64_t *v, const char *what)
{
    if (!need(r, (size_t)bytes, what))
        return false;
    uint64_t x = 0;
    for (int k = 0; k < bytes; k++)
        x |= (uint64_t)r->p[r->o + (size_t)k] << (8 * k);
    r->o += (size_t)bytes;
    *v = x;
    return true;
}

static bool rd_varint(rbuf *r, size_t end, uint64_t *v)
{
    uint64_t x = 0;
    size_t start = r->o;
    for (int shift = 0; shift < 35; shift += 7) {
        if (r->o >= end)
            return rs_fail(r->err, RP_ERR_TRUNCATED, "%s: truncated run length at byte %zu (input section ends at %zu)",
                           r->name, start, end);
        uint8_t b = r->p[r->o++];
        x |= (uint64_t)(b & 0x7f) << shift;
        if (!(b & 0x80)) {
            *v = x;
            return true;
        }
    }
    return rs_fail(r->err, RP_ERR_FIELD, "%s: run length at byte %zu is longer than 5 bytes", r->name, start);
}

#define BAD(...) rs_fail(err, RP_ERR_FIELD, __VA_ARGS__)

/* The magic, the format version and the checksum over the whole file,
 * checked before any field is trusted; then r->n ends where the checksum
 * begins. */
static bool rd_frame(rbuf *r, rp_replay *rp)
{
    const uint8_t *buf = r->p;
    size_t len = r->n;
    const char *name = r->name;
    rs_err *err = r->err;
    uint64_t v;
    if (len > RP_MAX_FILE)
        return rs_fail(err, RP_ERR_TOO_BIG, "%s: %zu bytes is larger than the %u-byte limit for replays", name, len,
                       RP_MAX_FILE);
    if (len < 4 || memcmp(buf, RP_MAGIC, 4) != 0)
        return rs_fail(err, RP_ERR_MAGIC, "%s: not a ringside replay: expected \"RSRP\" at byte 0", name);
    if (!rd_u(r, 4, &v, "magic") || !rd_u(r, 2, &v, "format version"))
        return false;
    if (v < 1 || v > RP_VERSION)
        return rs_fail(err, RP_ERR_VERSION, "%s: format version %llu at byte 4 is not supported (this build reads 1 to %d)",
                       name, (unsigned long long)v, RP_VERSION);
    rp->version = (int)v;
    size_t header = v == 1 ? RP_HEADER_BYTES_V1 : RP_HEADER_BYTES;
    /* the checksum covers everything, so check it before trusting any field */
    if (len < header + 4 + 4 + 8 + 4)
        return rs_fail(err, RP_ERR_TRUNCATED, "%s: truncated: %zu bytes, a version %d replay has at least %zu", name, len,
                       rp->version, header + 20);
    uint32_t stored = (uint32_t)buf[len - 4] | (uint32_t)buf[len - 3] << 8 | (uint32_t)buf[len - 2] << 16 |
                      (uint32_t)buf[len - 1] << 24;
    uint32_t crc = rs_crc32(0, buf, len - 4);
    if (crc != stored)
        return rs_fail(err, RP_ERR_CHECKSUM,
                       "%s: checksum mismatch at byte %zu: stored %08x, computed %08x (file damaged or truncated)",
                       name, len - 4, stored, crc);
    r->n = len - 4; /* from here on, fields end where the checksum begins */
    return true;
}

/* The header after the version: flags, stage, seed, ticks, checkpoint
 * interval, the players, the result and (version 2) the game version,
 * each against its range. */
static bool rd_header(rbuf *r, rp_replay *rp)
{
    const char *name = r->name;
    rs_err *err = r->err;
    uint64_t v;
    if (!rd_u(r, 2, &v, "flags"))
        return false;
    if (v != 0)
        return BAD("%s: unknown flags 0x%llx at byte 6 (expected 0)", name, (unsigned long long)v);
    if (!rd_u(r, 4, &v, "stage id"))
        return false;
    if (v >= G_STAGES)
        return BAD("%s: stage id %llu at byte 8 does not exist (expected 0..%d)", name, (unsigned long long)v,
                   G_STAGES - 1);
    rp->stage = (int)v;
    if (!rd_u(r, 8, &rp->seed, "seed") || !rd_u(r, 8, &rp->ticks, "tick count"))
        return false;
    if (rp->ticks == 0 || rp->ticks > RP_MAX_TICKS)
        return BAD("%s: tick count %llu at byte 20 is out of range (expected 1..%llu)", name,
                   (unsigned long long)rp->ticks, (unsigned long long)RP_MAX_TICKS);
    if (!rd_u(r, 2, &v, "checkpoint interval"))
        return false;
    if (v < 1 || v > 3600)
        return BAD("%s: checkpoint interval %llu at byte 28 is out of range (expected 1..3600)", name,
                   (unsigned long long)v);
    rp->interval = (int)v;
    for (int i = 0; i < 2; i++) {
        if (!rd_u(r, 1, &v, "player kind"))
            return false;
        if (v > RP_CPU)
            return BAD("%s: player %d kind %llu at byte %zu is unknown (expected 0 human or 1 cpu)", name, i + 1,
                       (unsigned long long)v, r->o - 1);
        rp->kind[i] = (int)v;
    }
    if (!rd_u(r, 1, &v, "winner"))
        return false;
    if (v != 0xff && v > 2)
        return BAD("%s: winner %llu at byte 32 is invalid (expected 0, 1, 2 or 255)", name, (unsigned long long)v);
    rp->winner = v == 0xff ? -1 : (int)v;
    for (int i = 0; i < 2; i++) {
        if (!rd_u(r, 1, &v, "rounds won"))
            return false;
        if (v > G_MAX_ROUNDS)
            return BAD("%s: rounds won %llu at byte %zu is more than %d", name, (unsigned long long)v, r->o - 1,
                       G_MAX_ROUNDS);
        rp->rounds[i] = (int)v;
    }
    if (!rd_u(r, 1, &v, "reserved byte"))
        return false;
    if (v != 0)
        return BAD("%s: reserved byte 35 is %llu (expected 0)", name, (unsigned long long)v);
    if (rp->version >= 2) {
        if (!rd_u(r, 4, &v, "game version"))
            return false;
        if (v == 0)
            return BAD("%s: game version 0 at byte 36 (expected 1 or more)", name);
        rp->game_version = (uint32_t)v;
    }
    return true;
}

/* The input section: its length, then runs of (tick count, P1's input,
 * P2's input) that cover the ticks exactly, into rp->inputs. */
static bool rd_inputs(rbuf *r, rp_replay *rp)
{
    const char *name = r->name;
    rs_err *err = r->err;
    uint64_t v;
    size_t len_at = r->o;
    if (!rd_u(r, 4, &v, "input section length"))
        return false;
    size_t body_end = r->n;
    if (v > body_end - r->o)
        return BAD("%s: input section length %llu at byte %zu runs past the end of the file (%zu bytes left)", name,
                   (unsigned long long)v, len_at, body_end - r->o);
    /* each run is at least 3 bytes and covers at least one tick */
    if (v < 3 || v > 3 * rp->ticks)
        return BAD("%s: input section length %llu at byte %zu does not fit %llu ticks", name, (unsigned long long)v,
                   len_at, (unsigned long long)rp->ticks);
    rp->input_bytes = (size_t)v;
    size_t in_end = r->o + (size_t)v;
    rp->inputs = malloc((size_t)rp->ticks * 2);
    if (!rp->inputs)
        return rs_fail(err, RP_ERR_NOMEM, "%s: out of memory for %llu ticks", name, (unsigned long long)rp->ticks);
    uint64_t t = 0;
    while (r->o < in_end) {
        size_t at = r->o;
        uint64_t run = 0;
        if (!rd_varint(r, in_end, &run))
            return false;
        if (run == 0 || run > rp->ticks - t)
            return BAD("%s: run of %llu ticks at byte %zu goes past the tick count %llu (at tick %llu)", name,
                       (unsigned long long)run, at, (unsigned long long)rp->ticks, (unsigned long long)t);
        if (in_end - r->o < 2)
            return rs_fail(err, RP_ERR_TRUNCATED, "%s: truncated input run at byte %zu: expected two input bytes", name,
                           r->o);
        g_input a = r->p[r->o], b = r->p[r->o + 1];
        for (int i = 0; i < 2; i++) {
            g_input x = i ? b : a;
            if (!g_input_valid(x))
                return BAD("%s: player %d input 0x%02x at byte %zu (tick %llu) holds opposite directions", name, i + 1, x,
                           r->o + (size_t)i, (unsigned long long)t + 1);
        }
        r->o += 2;
        for (uint64_t k = 0; k < run; k++) {
            rp->inputs[2 * (t + k)] = a;
            rp->inputs[2 * (t + k) + 1] = b;
        }
        t += run;
    }
    if (t != rp->ticks)
        return BAD("%s: input runs cover %llu ticks, the header says %llu (input section ends at byte %zu)", name,
                   (unsigned long long)t, (unsigned long long)rp->ticks, in_end);
    return true;
}

/* The checkpoint hashes, one an interval, and the final hash: the body's end. */
static bool rd_checkpoints(rbuf *r, rp_replay *rp)
{
    const char *name = r->name;
    rs_err *err = r->err;
    uint64_t v;
    if (!rd_u(r, 4, &v, "checkpoint count"))
        return false;
    uint64_t want = rp->ticks / (uint64_t)rp->interval;
    if (v != want)
        return BAD("%s: %llu checkpoints at byte %zu, expected %llu (ticks / interval)", name, (unsigned long long)v,
                   r->o - 4, (unsigned long long)want);
    if (!need(r, (size_t)v * 8 + 8, "checkpoint hashes and the final hash"))
        return false;
    rp->ncheck = (size_t)v;
    rp->checkpoints = malloc(rp->ncheck ? rp->ncheck * 8 : 1);
    if (!rp->checkpoints)
        return rs_fail(err, RP_ERR_NOMEM, "%s: out of memory", name);
    for (size_t k = 0; k < rp->ncheck; k++)
        rd_u(r, 8, &rp->checkpoints[k], "checkpoint");
    rd_u(r, 8, &rp->final_hash, "final hash");
    if (r->o != r->n)
        return BAD("%s: %zu unexpected bytes at byte %zu before the checksum", name, r->n - r->o, r->o);
    return true;
}

bool rp_decode(const uint8_t *buf, size_t len, const char *name, rp_replay *rp, rs_err *err)
{
    memset(rp, 0, sizeof *rp);
    rbuf r = {buf, len, 0, name, err};
    if (!rd_frame(&r, rp) || !rd_header(&r, rp))
        return false;
    if (rd_inputs(&r, rp) && rd_checkpoints(&r, rp))
        return true;
    rp_free(rp);
    return false;
}

void rp_free(rp_replay *rp)
{
    free(rp->inputs);
    free(rp->checkpoints);
    rp->inputs = NULL;
    rp->checkpoints = NULL;
}

/* standard input to its end, at most max bytes (more: RP_ERR_TOO_BIG) */
static uint8_t *read_stdin(size_t max, size_t *len, rs_err *err)
{
    size_t cap = 64 * 1024, n = 0;
    uint8_t *buf = malloc(cap);
    while (buf) {
        if (n == cap) {
            uint8_t *more = cap > max ? NULL : realloc(buf, cap * 2);
            if (!more) {
                free(buf);
                if (cap > max)
                    rs_fail(err, RP_ERR_TOO_BIG, "%s: more than %zu bytes: not a replay", RP_STDIN_NAME, max);
                else
                    rs_fail(err, RP_ERR_OPEN, "%s: out of memory", RP_STDIN_NAME);
                return NULL;
            }
            buf = more, cap *= 2;
        }
        ssize_t r = read(0, buf + n, cap - n);
        if (r == 0) {
            *len = n;
            return buf;
        }
        if (r < 0 && errno == EINTR)
            continue;
        if (r < 0) {
            rs_fail(err, RP_ERR_OPEN, "%s: cannot read: %s", RP_STDIN_NAME, strerror(errno));
            free(buf);
            return NULL;
        }
        n += (size_t)r;
    }
    rs_fail(err, RP_ERR_OPEN, "%s: out of memory", RP_STDIN_NAME);
    return NULL;
}

bool rp_read(const char *path, rp_replay *rp, rs_err *err)
{
    memset(rp, 0, sizeof *rp);
    size_t n;
    if (!strcmp(path, "-")) {
        uint8_t *in = read_stdin(RP_MAX_FILE, &n, err);
        if (!in)
            return false;
        bool ok = rp_decode(in, n, RP_STDIN_NAME, rp, err);
        free(in);
        return ok;
    }
    uint8_t *buf = (uint8_t *)rs_read_file(path, RP_MAX_FILE, &n, err);
    if (!buf)
        return recode(err, err && err->code == RS_FILE_ERR_TOO_BIG ? RP_ERR_TOO_BIG : RP_ERR_OPEN);
    bool ok = rp_decode(buf, n, path, rp, err);
    free(buf);
    return ok;
}

static bool same(const rp_replay *a, const rp_replay *b)
{
    return a->version == b->version && a->game_version == b->game_version && a->stage == b->stage && a->seed == b->seed && a->ticks == b->ticks && a->interval == b->interval &&
           a->kind[0] == b->kind[0] && a->kind[1] == b->kind[1] && a->winner == b->winner &&
           a->rounds[0] == b->rounds[0] && a->rounds[1] == b->rounds[1] && a->ncheck == b->ncheck &&
           a->final_hash == b->final_hash && !memcmp(a->inputs, b->inputs, (size_t)a->ticks * 2) &&
           (a->ncheck == 0 || !memcmp(a->checkpoints, b->checkpoints, a->ncheck * 8));
}

bool rp_write(const char *path, const rp_replay *rp, rs_err *err)
{
    uint8_t *buf;
    size_t n;
    if (!rp_encode(rp, &buf, &n, err))
        return false;
    bool written = rs_write_part(path, buf, n, err);
    free(buf);
    if (!written)
        return recode(err, RP_ERR_WRITE);
    char part[PATH_MAX + 8];
    rs_part_path(path, part, sizeof part);
    /* read back what is on disk: it must decode to exactly what we recorded */
    rp_replay back;
    if (!rp_read(part, &back, err)) {
        unlink(part);
        rs_err_prefix(err, "%s: read-back failed", path);
        return recode(err, RP_ERR_WRITE);
    }
    bool eq = same(rp, &back);
    rp_free(&back);
    if (!eq) {
        unlink(part);
        return rs_fail(err, RP_ERR_WRITE, "%s: read-back differs from what was recorded", path);
    }
    return rs_commit_file(path, err) || recode(err, RP_ERR_WRITE);
}

/* ---------- recording ---------- */

void rp_rec_init(rp_recorder *r, int stage, uint64_t seed, int kind1, int kind2)
{
    memset(r, 0, sizeof *r);
    r->rp.version = RP_VERSION;
    r->rp.game_version = G_GAME_VERSION;
    r->rp.stage = stage;
    r->rp.seed = seed;
    r->rp.interval = RP_DEFAULT_INTERVAL;
    r->rp.kind[0] = kind1;
    r->rp.kind[1] = kind2;
    r->rp.winner = -1;
}

bool rp_rec_tick(rp_recorder *r, const g_input in[2], const g_state *after, rs_err *err)
{
    rp_replay *rp = &r->rp;
    if (r->failed)
        return false;
    if (rp->ticks >= RP_MAX_TICKS) {
        r->failed = true;
        return rs_fail(err, RP_ERR_RECORD, "replay longer than %llu ticks", (unsigned long long)RP_MAX_TICKS);
    }
    if (rp->ticks == r->cap_ticks) {
        size_t cap = r->cap_ticks ? r->cap_ticks * 2 : 4096;
        g_input *ni = realloc(rp->inputs, cap * 2);
        if (!ni) {
            r->failed = true;
            return rs_fail(err, RP_ERR_NOMEM, "out of memory recording tick %llu", (unsigned long long)rp->ticks);
        }
        rp->inputs = ni;
        r->cap_ticks = cap;
    }
    rp->inputs[2 * rp->ticks] = g_input_clean(in[0]);
    rp->inputs[2 * rp->ticks + 1] = g_input_clean(in[1]);
    rp->ticks++;
    uint64_t h = rp_recorded_hash(rp, g_hash(after));
    rp->final_hash = h;
    if (rp->ticks % (uint64_t)rp->interval == 0) {
        if (rp->ncheck == r->cap_check) {
            size_t cap = r->cap_check ? r->cap_check * 2 : 256;
            uint64_t *nc = realloc(rp->checkpoints, cap * 8);
            if (!nc) {
                r->failed = true;
                return rs_fail(err, RP_ERR_NOMEM, "out of memory recording checkpoints");
            }
            rp->checkpoints = nc;
            r->cap_check = cap;
        }
        rp->checkpoints[rp->ncheck++] = h;
    }
    if (rp->winner < 0) {
        rp->rounds[0] = after->f[0].rounds_won;
        rp->rounds[1] = after->f[1].rounds_won;
        if (after->phase == G_PHASE_MATCH_END)
            rp->winner = after->match_winner;
    }
    return true;
}

bool rp_rec_save(rp_recorder *r, const char *path, rs_err *err)
{
    if (r->rp.ticks == 0)
        return rs_fail(err, RP_ERR_RECORD, "%s: nothing recorded (0 ticks)", path);
    return rp_write(path, &r->rp, err);
}

/* ---------- verification ---------- */

/* The key of a pair of player kinds (format 3): splitmix64 of the pair,
 * never 0, different for each of the four pairs. */
static uint64_t kinds_key(int k0, int k1)
{
    uint64_t z = 0x5253525020000000ull + (uint64_t)(k0 * 2 + k1 + 1) * 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return (z ^ (z >> 31)) | 1;
}

uint64_t rp_recorded_hash(const rp_replay *rp, uint64_t state_hash)
{
    return rp->version >= 3 ? state_hash ^ kinds_key(rp->kind[0], rp->kind[1]) : state_hash;
}

void rp_set_format(rp_replay *rp, int version)
{
    rp_replay was = *rp;
    rp->version = version;
    /* XOR is its own inverse: the old key off, the new one on */
    for (size_t k = 0; k < rp->ncheck; k++)
        rp->checkpoints[k] = rp_recorded_hash(rp, rp_recorded_hash(&was, rp->checkpoints[k]));
    rp->final_hash = rp_recorded_hash(rp, rp_recorded_hash(&was, rp->final_hash));
}

/* A format-3 hash that does not match: do other player kinds make it match? */
static bool kinds_that_match(const rp_replay *rp, uint64_t state_hash, uint64_t want, int kinds[2])
{
    for (int a = 0; rp->version >= 3 && a < 2; a++)
        for (int b = 0; b < 2; b++)
            if ((a != rp->kind[0] || b != rp->kind[1]) && (state_hash ^ kinds_key(a, b)) == want) {
                kinds[0] = a, kinds[1] = b;
                return true;
            }
    return false;
}

bool rp_check_game(const rp_replay *rp, const char *name, rs_err *err)
{
    if (rp->game_version == 0 || rp->game_version == G_GAME_VERSION)
        return true;
    return rs_fail(err, RP_ERR_GAME_VERSION, "%s%srecorded by another version of the game (replay: %lu, this build: %d)",
                   name ? name : "", name ? ": " : "", (unsigned long)rp->game_version, G_GAME_VERSION);
}

bool rp_verify(const rp_replay *rp, FILE *hashes, void (*progress)(uint64_t, uint64_t, void *), void *user,
               rp_verify_result *res, rs_err *err)
{
    memset(res, 0, sizeof *res);
    res->winner = -1;
    if (!rp_check_game(rp, NULL, err))
        return false;
    g_state st;
    g_init(&st, rp->stage, rp->seed);
    size_t next = 0;
    for (uint64_t t = 0; t < rp->ticks; t++) {
        g_step(&st, &rp->inputs[2 * t], NULL);
        if (res->winner < 0) {
            res->rounds[0] = st.f[0].rounds_won;
            res->rounds[1] = st.f[1].rounds_won;
            if (st.phase == G_PHASE_MATCH_END)
                res->winner = st.match_winner;
        }
        bool at_check = (t + 1) % (uint64_t)rp->interval == 0;
        bool last = t + 1 == rp->ticks;
        if (hashes || at_check || last) {
            uint64_t h = g_hash(&st);
            if (hashes && fprintf(hashes, "%llu %016llx\n", (unsigned long long)(t + 1), (unsigned long long)h) < 0)
                return rs_fail(err, RP_ERR_WRITE, "writing the hash list failed at tick %llu",
                               (unsigned long long)(t + 1));
            uint64_t want = at_check ? rp->checkpoints[next] : rp->final_hash, hr = rp_recorded_hash(rp, h);
            if ((at_check || last) && hr != want) {
                res->desync_tick = t + 1;
                res->want = want;
                res->got = hr;
                res->kinds_altered = kinds_that_match(rp, h, want, res->kinds_recorded);
                return true; /* verified: not ok */
            }
            if (at_check) {
                next++;
                res->last_good_tick = t + 1;
            }
            if (last && hr != rp->final_hash) {
                res->desync_tick = t + 1;
                res->want = rp->final_hash;
                res->got = hr;
                res->kinds_altered = kinds_that_match(rp, h, rp->final_hash, res->kinds_recorded);
                return true;
            }
        }
        if (progress && ((t + 1) & 0xffff) == 0)
            progress(t + 1, rp->ticks, user);
    }
    if (res->winner != rp->winner || res->rounds[0] != rp->rounds[0] || res->rounds[1] != rp->rounds[1]) {
        res->header_mismatch = true; /* hashes agree, the header's summary does not */
        return true;
    }
    res->ok = true;
    return true;
}

bool rp_check_tick(const rp_replay *rp, const g_state *st, uint64_t done, size_t *next, const char *name,
                   rs_err *err)
{
    bool at_check = done % (uint64_t)rp->interval == 0 && *next < rp->ncheck;
    bool last = done == rp->ticks;
    if (!at_check && !last)
        return true;
    uint64_t sh = g_hash(st), h = rp_recorded_hash(rp, sh), want = at_check ? rp->checkpoints[(*next)++] : rp->final_hash;
    if (h == want && (!last || h == rp->final_hash))
        return true;
    if (h == want) /* the checkpoint matched, the final hash (same tick) did not */
        want = rp->final_hash;
    int kinds[2];
    if (kinds_that_match(rp, sh, want, kinds))
        return rs_fail(err, RP_ERR_DESYNC,
                       "%s: the header's player kinds (P1 %s, P2 %s, bytes 30-31) are not the ones it was recorded "
                       "with (P1 %s, P2 %s): the header was altered",
                       name, rp->kind[0] ? "cpu" : "human", rp->kind[1] ? "cpu" : "human", kinds[0] ? "cpu" : "human",
                       kinds[1] ? "cpu" : "human");
    rs_fail(err, RP_ERR_DESYNC,
            "%s: desync at tick %llu: the game's state hash %016llx is not the replay's %016llx (its inputs "
            "no longer reproduce the recorded match)",
            name, (unsigned long long)done, (unsigned long long)h, (unsigned long long)want);
    rs_err why = {0};
    if (!rp_check_game(rp, NULL, &why) && err) { /* the likely reason, in place of the generic one */
        char *paren = strstr(err->msg, " (its inputs");
        if (paren)
            snprintf(paren, sizeof err->msg - (size_t)(paren - err->msg), ": %s", why.msg);
        err->code = RP_ERR_GAME_VERSION;
    }
    return false;
}

bool rp_peek_ticks(const uint8_t *buf, size_t len, uint64_t *ticks)
{
    enum { TICKS_AT = 20 }; /* magic 4, version 2, flags 2, stage 4, seed 8 */
    if (len < TICKS_AT + 8 || memcmp(buf, RP_MAGIC, 4) != 0)
        return false;
    *ticks = 0;
    for (int k = 0; k < 8; k++)
        *ticks |= (uint64_t)buf[TICKS_AT + k] << (8 * k);
    return true;
}

void rp_desync_text(const rp_verify_result *res, char *out, size_t n)
{
    if (res->kinds_altered)
        snprintf(out, n,
                 "the header's player kinds (bytes 30-31) are not the ones it was recorded with (P1 %s, P2 %s): the "
                 "header was altered",
                 res->kinds_recorded[0] ? "cpu" : "human", res->kinds_recorded[1] ? "cpu" : "human");
    else if (res->desync_tick <= res->last_good_tick) /* the same state matched a checkpoint: the final hash is bad */
        snprintf(out, n,
                 "the final hash at tick %" PRIu64 " is %016" PRIx64 ", recorded %016" PRIx64
                 ", though the checkpoint at tick %" PRIu64 " matched: the recorded final hash is damaged",
                 res->desync_tick, res->got, res->want, res->last_good_tick);
    else
        snprintf(out, n,
                 "desync at tick %" PRIu64 ": state hash %016" PRIx64 ", recorded %016" PRIx64
                 " (last matching checkpoint: tick %" PRIu64 "; the inputs diverge in ticks %" PRIu64 "..%" PRIu64 ")",
                 res->desync_tick, res->got, res->want, res->last_good_tick, res->last_good_tick + 1,
                 res->desync_tick);
}
