/* svc_store: the durable job queue behind `ringside serve`.
 *
 * One small table of function pointers per backend (raylib's platform
 * contract, Redis's habit): svc_store_sqlite.c (embedded default, one
 * daemon per database file) and svc_store_pg.c (PostgreSQL through libpq,
 * any number of daemons on any number of machines).  Adding a backend is
 * adding a file and a line in svc_store_open.
 *
 * The rules every backend keeps (tests/test_svc_store.c checks them on each):
 *  - submit commits the job before it returns, so an id given to a client
 *    always survives a crash;
 *  - claim hands the oldest queued job to exactly one owner, sets its lease
 *    (claimed_until = now + lease_s, the database's clock) and adds one to
 *    its attempts;
 *  - attempts count render failures only: a unit whose lease expired (its
 *    daemon crashed, stopped or was cut off) gets its attempt back and
 *    counts one more lost lease instead, so daemon crashes never fail a
 *    job that did nothing wrong; a unit that has lost SVC_LOST_MAX leases
 *    (a job that kills its daemon every time) fails its job;
 *  - heartbeat, finish and release act only while the row is still running
 *    and owned by the caller: a job whose lease was taken away (reaped, or
 *    cancelled by DELETE) cannot be finished by its old owner;
 *  - reap turns expired leases back into queued jobs (no attempt charged),
 *    or into failed ones ("lost its daemon N times (lease expired)") once
 *    they reach SVC_LOST_MAX; a job is never retried forever;
 *  - times are Unix seconds from the database's clock, so machines with
 *    skewed clocks still agree on leases.
 *
 * Units (docs/service.md, "Segments").  What a worker claims is a unit of a
 * job, not the job: an unsplit job (segment_ticks 0, or a replay no longer
 * than one segment) is one WHOLE unit, a split job is `segments` SEGMENT
 * units of segment_ticks ticks each (the last shorter) plus one JOIN unit.
 * Each unit has its own lease, heartbeat, attempts and error, and the rules
 * above hold per unit:
 *  - claim hands out the queued unit of the oldest job that has one, the
 *    lowest index first; a JOIN only once every SEGMENT of its job is done;
 *  - heartbeat, finish, release and rejoin name the job and the owner: an
 *    owner (one worker slot) holds at most one unit at a time, so (job,
 *    owner, running) is that unit;
 *  - finish(DONE) of a SEGMENT marks it done (its attempt's files are the
 *    ones to join: done_attempt) and counts one more render (renders: a
 *    segment finished twice shows 2); finish(DONE) of the WHOLE or the
 *    JOIN unit makes the job done; finish(FAILED) of any unit fails the job;
 *  - a unit that runs out of attempts fails the whole job with its own
 *    reason ("gave up after N attempts: segment K (ticks A-B): why");
 *  - when a job ends (failed, cancelled) its units still queued or running
 *    are cancelled: their owners' heartbeats answer "not ours";
 *  - the job row is the units summed: state (running while any unit runs),
 *    attempts (the most any unit took), frames_done (the frames of its
 *    segments), fps (of its running units), owner and claimed_until (of a
 *    running unit).
 * Lock order (PostgreSQL): a job's row, then its units; every change holds
 * the job's row, so two daemons never see a job half-changed.
 *
 * Threads: a store handle is one database connection guarded by its own
 * mutex; any thread may call it.  The daemon opens one handle for its
 * supervisor loop and one for the HTTP threads. */
#ifndef SVC_STORE_H
#define SVC_STORE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "../runtime/util/rs_err.h"

/* The states, in the order of the database's integer column. */
#define SVC_STATES(X) X(QUEUED, "queued") X(RUNNING, "running") X(DONE, "done") X(FAILED, "failed") X(CANCELLED, "cancelled")
typedef enum {
#define X(id, s) SVC_##id,
    SVC_STATES(X)
#undef X
    SVC_NSTATES
} svc_state;
const char *svc_state_name(int st);

/* Error ids (rs_err.h) of every backend.  "No such job" and "already
 * over" are not errors: get and cancel say them in their return values. */
#define SVC_STORE_ERRORS(X)                                                                \
    X(SPEC, "the queue setting names no backend or no database")                           \
    X(NOT_BUILT, "this build has no driver for that backend")                              \
    X(OPEN, "cannot open or connect to the queue database")                                \
    X(SCHEMA, "not a ringside queue (other tables or columns), or no schema could be made") \
    X(BUSY, "the database stayed locked past the busy timeout")                            \
    X(QUERY, "a statement failed")                                                         \
    X(CONNECTION, "lost the connection to the database and could not reconnect")           \
    X(TOO_LARGE, "the replay is too large to queue")                                       \
    X(FILE, "a file to store in the queue, or fetched from it, could not be read or written") \
    X(NOMEM, "out of memory")

typedef enum svc_store_error {
    SVC_STORE_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_SVC_STORE),
#define X(id, text) SVC_STORE_ERR_##id,
    SVC_STORE_ERRORS(X)
#undef X
        SVC_STORE_ERR_END
} svc_store_error;

const char *svc_store_error_text(int code);

#define SVC_NAME_MAX 128
#define SVC_ERROR_MAX 512
#define SVC_OWNER_MAX 128

/* A claimable piece of a job.  Zero is the default: the WHOLE job. */
#define SVC_UNIT_KINDS(X) X(WHOLE, "whole") X(SEGMENT, "segment") X(JOIN, "join")
typedef enum {
#define X(id, s) SVC_UNIT_##id,
    SVC_UNIT_KINDS(X)
#undef X
} svc_unit_kind;
const char *svc_unit_kind_name(int kind);

typedef struct svc_unit {
    int kind;                    /* svc_unit_kind */
    int index;                   /* SEGMENT: 0-based position; JOIN: the segment count; WHOLE: 0 */
    int64_t first_tick, end_tick; /* ticks first..end-1 (the JOIN and WHOLE: the whole replay) */
    int state;                   /* svc_state */
    int attempts;                /* claims of this unit so far */
    char owner[SVC_OWNER_MAX];   /* the worker slot holding it while running */
    int64_t claimed_until, started, finished;
    int64_t frames_done;
    double fps;
    char error[SVC_ERROR_MAX];   /* why its last attempt ended */
    int renders;                 /* times it was finished done: 1 = rendered once */
    char done_by[SVC_OWNER_MAX]; /* the worker slot that finished it */
    int done_attempt;            /* the claim whose files are its output (0: not done) */
    int lost;                    /* leases it lost (its daemon gone): not charged as attempts */
    int claim;                   /* this claim's number, attempts + lost: names its files, so a
                                    render cut off from the queue never writes the next claim's */
} svc_unit;

/* The identity a split job's segment files carry (render --segment KEY):
 * "job<id>-<nonce>", a new nonce per job, so files of another job or of a
 * reused job id (a new queue, the same output directory) are never joined. */
#define SVC_KEY_MAX 48

typedef struct svc_job {
    int64_t id;
    int state;                   /* svc_state */
    char name[SVC_NAME_MAX];     /* the uploaded file's name, for people ("dojo.rsr") */
    int width, height;           /* output video size */
    char format[8];              /* "mp4", "webm", "mkv" */
    int64_t frames_done, frames_total;
    double fps;                  /* render speed of the running attempt */
    int attempts;                /* charged attempts so far (the running one included) */
    int lost;                    /* leases lost by its units (the most of any unit) */
    bool expired;                /* done, and its files were removed by retention */
    int64_t desync_tick;         /* first checkpoint tick that differed; -1: none */
    char error[SVC_ERROR_MAX];   /* why it failed (or why the last attempt did) */
    char owner[SVC_OWNER_MAX];   /* "host:pid" of the daemon running it */
    int64_t created, started, finished, claimed_until; /* Unix seconds; 0: not yet */
    int segment_ticks;           /* submit: split into segments this long (0: unsplit) */
    int first_segment_ticks;     /* submit: the first segment this long, doubling (svc_plan_segments) */
    int segments;                /* how many it was split into (0: unsplit, one WHOLE unit) */
    char key[SVC_KEY_MAX];       /* "job<id>-<nonce>" */
    int64_t token_id;            /* the API token that submitted it (0: none; svc_token) */
    /* the replay's header, read at upload (rp.h): stage -1 for a job queued
     * before these were kept (nothing known) */
    int stage;                   /* g_stages index */
    int kind[2];                 /* RP_HUMAN / RP_CPU */
    int winner;                  /* first match: -1 unfinished, 0 draw, 1, 2 */
    int rounds[2];
    /* encoder options the job asked for, checked at upload against the
     * operator's bounds: "codec=hevc crf=24 preset=fast pix_fmt=yuv444p"
     * (any of them; "" = the render's defaults) */
    char encode[160];
    svc_unit unit;               /* claim: the unit handed out (the rest leave it zero) */
    /* the replay: submit reads it, claim fills it (malloc'd; svc_job_free) */
    uint8_t *replay;
    size_t replay_len;
} svc_job;

void svc_job_free(svc_job *j);

/* The segments a job of `total` ticks is split into: their end ticks in
 * ends[0..n-1] (the first starts at 0, each next where the one before
 * ends); returns n, 0 for a job rendered whole.  seg <= 0: never split.
 * first in 1..seg-1: the first segment is `first` ticks long and each
 * next one twice the one before, up to seg (the first seconds of a job
 * are rendered, and can be watched, soon), split when total > first;
 * otherwise every segment is seg long, split when total > seg.  A last
 * segment shorter than the first is merged into the one before.  At most
 * max ends are written (the count returned is the plan's). */
int svc_plan_segments(int64_t total, int64_t seg, int64_t first, int64_t *ends, int max);

/* DESIGN: a daemon killed by its job (memory exhausted, say) dies before
 * it can tell a render failure from its own death, so lost leases are not
 * charged; this bound is what stops such a job from killing daemon after
 * daemon.  10: a sound job loses a lease only when its daemon dies, and
 * ten daemon deaths during one unit means the unit is the likelier cause. */
#define SVC_LOST_MAX 10

/* What reap did to one unit (the restart log names each). */
typedef struct svc_reaped {
    int64_t id;
    svc_unit unit; /* as it was when reaped (its lost count not yet raised) */
    bool failed;   /* the job failed: SVC_LOST_MAX leases lost */
} svc_reaped;

/* An API token (svc_auth.h): what the queue knows of it.  The token itself
 * is never stored, only its hash. */
typedef struct svc_token {
    int64_t id;
    char name[SVC_NAME_MAX];
    bool is_operator;     /* sees and acts on every job */
    int max_queued;       /* its jobs queued or running at once (0: no cap) */
    int seconds_per_hour; /* game seconds it may submit in any hour (0: no cap) */
    int64_t created, revoked, last_used; /* Unix seconds; 0: not (yet) */
} svc_token;

/* What a token's quotas are measured against (token_usage). */
typedef struct svc_usage {
    int64_t active;      /* its jobs queued or running */
    int64_t hour_frames; /* frames of its jobs created in the last hour */
    int64_t oldest;      /* when the oldest of those was created (0: none) */
    int64_t now;         /* the database's clock */
} svc_usage;

/* A job waiting or running, as the queue order sees it (pending). */
typedef struct svc_pending {
    int64_t id;
    int state;           /* SVC_QUEUED or SVC_RUNNING */
    int64_t frames_left; /* frames_total - frames_done as of the last heartbeat */
} svc_pending;

/* Files in the queue (docs/service.md, "Several machines").  Daemons
 * that share no disk keep what a unit made (a segment and its manifest,
 * hashes and poster; its stream pieces), the finished video with its
 * hashes and poster, and the render log in the queue's database beside the
 * replay, by name:
 *   seg/sI-aK.FMT, seg/sI-aK.FMT.seg, seg/sI-aK.hashes, seg/sI-aK.png
 *   stream/tTICK.ts, stream/uFIRST.idx (each machine makes its own track)
 *   video.FMT, hashes, poster.png, log
 * and a daemon that needs one it does not have fetches it (svc_files.c).
 * A name is written once per claim (segments carry their claim), so its
 * bytes never change once stored, except by the same bytes again. */
typedef struct svc_file {
    const char *name; /* in the queue */
    const char *path; /* on this machine */
} svc_file;
#define SVC_FILE_CHUNK (1 << 20) /* the bytes of one row */

typedef struct svc_store svc_store;

typedef struct svc_store_ops {
    const char *name; /* "sqlite", "postgres" */
    /* j: name, width, height, format, frames_total, segment_ticks, replay,
     * replay_len.  Fills j->id, j->created, j->segments and j->key, with
     * the job's units; committed before it returns. */
    bool (*submit)(svc_store *s, svc_job *j, rs_err *err);
    /* 1: claimed the next queued unit (see above) into out->unit, with its
     * job and replay in out; 0: nothing to claim; -1: error. */
    int (*claim)(svc_store *s, const char *owner, int lease_s, svc_job *out, rs_err *err);
    /* Extends the lease of owner's unit of job id and records its progress
     * (frames of the unit).  1: still ours; 0: not ours any more (cancelled,
     * reaped, finished elsewhere, the job failed): stop the worker; -1:
     * error (keep going; the lease may still be valid). */
    int (*heartbeat)(svc_store *s, int64_t id, const char *owner, int lease_s, int64_t frames_done,
                     int64_t frames_total, double fps, rs_err *err);
    /* The end of an attempt of owner's unit: state SVC_DONE (see above) or
     * SVC_FAILED (no retry: a desync, say; the job fails), with error and
     * desync_tick (-1: none).  1: recorded; 0: not ours any more (nothing
     * changed); -1: error. */
    int (*finish)(svc_store *s, int64_t id, const char *owner, int state, const char *error, int64_t desync_tick,
                  int64_t frames_done, rs_err *err);
    /* An attempt that did not finish: the unit back to queued with error as
     * the reason, or the job failed ("gave up after N attempts: error")
     * when the unit's attempts have reached max_attempts.  count_attempt
     * false (a clean shutdown, a full disk) gives the attempt back.
     * 1: released; 0: not ours; -1: error. */
    int (*release)(svc_store *s, int64_t id, const char *owner, const char *error, bool count_attempt,
                   int max_attempts, rs_err *err);
    /* Running units whose lease has expired (all running units when all is
     * true: the single daemon of an SQLite file starting up) go back to
     * queued with their attempt given back and one more lost lease, error
     * "lease expired (worker or daemon lost)"; at SVC_LOST_MAX lost leases
     * the job fails.  What happened to each, up to max, into out (may be
     * NULL).  Returns how many were reaped, or -1. */
    int (*reap)(svc_store *s, bool all, svc_reaped *out, int max, rs_err *err);
    /* The join found bad segments (missing, truncated, not matching their
     * manifests): owner's JOIN unit goes back to waiting, its attempt given
     * back, and the segments bad[0..nbad-1] back to queued with why (their
     * files are the caller's to delete), or the job fails when one of them
     * has used max_attempts.  1: done; 0: not ours (or not a join); -1. */
    int (*rejoin)(svc_store *s, int64_t id, const char *owner, const int *bad, int nbad, const char *why,
                  int max_attempts, rs_err *err);
    /* A stream piece of job id's segment index is damaged or missing where
     * a daemon must serve it: the segment, done, goes back to queued (its
     * claim's files no longer the ones to join; its listed pieces stay
     * listed) with why, and a join already running goes back to waiting
     * (its attempt given back; its owner's heartbeat answers "not ours").
     * 1: re-queued; 0: not (no such segment, not done, the job done or
     * over, or the segment at max_attempts); -1: error. */
    int (*redo)(svc_store *s, int64_t id, int index, const char *why, int max_attempts, rs_err *err);
    /* The units of job id by index (segments, then the join; or the one
     * WHOLE unit), up to max into out.  Returns the count, or -1. */
    int (*units)(svc_store *s, int64_t id, svc_unit *out, int max, rs_err *err);
    /* 1: found; 0: no such job; -1: error.  out->replay stays NULL. */
    int (*get)(svc_store *s, int64_t id, svc_job *out, rs_err *err);
    /* Newest first, ids below before_id (0: from the newest), only token
     * token_id's jobs (0: every job); up to limit rows into out.  Returns
     * the count, or -1. */
    int (*list)(svc_store *s, int64_t token_id, int64_t before_id, int limit, svc_job *out, rs_err *err);
    /* Queued or running -> cancelled.  1: cancelled; 0: no such job;
     * 2: already over (done, failed or cancelled); -1: error. */
    int (*cancel)(svc_store *s, int64_t id, rs_err *err);
    /* Done jobs finished more than age_s ago (the database's clock), not
     * yet expired, whose video was made on host (done by "host:..."; NULL
     * or "": on any host, for files kept in the queue): up
     * to max ids into out, oldest first.  Returns the count, or -1. */
    int (*expiring)(svc_store *s, int64_t age_s, const char *host, int64_t *out, int max, rs_err *err);
    /* Done job id's files were removed by retention: it says so from now
     * on (expired).  1: marked; 0: no such done job; -1: error. */
    int (*expire)(svc_store *s, int64_t id, rs_err *err);
    /* A job that is over (done, failed, cancelled) leaves the queue with its
     * units.  1: removed; 0: no such job; 2: not over (queued or running:
     * cancel it first); -1: error. */
    int (*remove)(svc_store *s, int64_t id, rs_err *err);
    /* Jobs per state. */
    bool (*counts)(svc_store *s, int64_t by_state[SVC_NSTATES], rs_err *err);
    /* A failed job back to queued, from the start: every unit queued with
     * attempts, lost leases and errors cleared (a split job's segments too:
     * their files went when it failed); the job's error, desync tick and
     * times cleared.  1: re-queued; 0: no such
     * job; 2: not failed; -1: error. */
    int (*retry)(svc_store *s, int64_t id, rs_err *err);
    /* The queue in claim order: the queued and running jobs, oldest first,
     * up to max into out.  Returns the count, or -1. */
    int (*pending)(svc_store *s, svc_pending *out, int max, rs_err *err);
    /* The recent render speed: frames per second of wall time of the last
     * `last` jobs done (their frames over finished - started, summed);
     * 0 when none is done yet. */
    bool (*speed)(svc_store *s, int last, double *fps, rs_err *err);
    /* API tokens.  token_add: t's name, is_operator and quotas, with hash
     * (svc_token_hash); fills t->id and t->created.  1: added; 0: a token
     * of that name exists (revoked ones too: names are never reused); -1. */
    int (*token_add)(svc_store *s, svc_token *t, const char *hash, rs_err *err);
    /* Every token, oldest first, up to max into out.  Returns the count, or -1. */
    int (*token_list)(svc_store *s, svc_token *out, int max, rs_err *err);
    /* The token named which, or else with the id which spells.  1: revoked
     * now; 2: it was already; 0: no such token; -1.  out: the token. */
    int (*token_revoke)(svc_store *s, const char *which, svc_token *out, rs_err *err);
    /* The token whose hash this is (revoked ones too: out->revoked says),
     * its last_used brought up to the minute.  1, 0 (none), -1. */
    int (*token_find)(svc_store *s, const char *hash, svc_token *out, rs_err *err);
    /* Tokens not revoked, or -1. */
    int64_t (*token_active)(svc_store *s, rs_err *err);
    bool (*token_usage)(svc_store *s, int64_t token_id, svc_usage *out, rs_err *err);
    /* Files in the queue (above).  file_put stores files[0..n-1] of job id
     * in one transaction, each replacing a file of its name; nothing when
     * keep names a file the job holds already.  1: stored; 2: kept; 0: no
     * such job, or one that failed or was cancelled; -1: error (a file that
     * cannot be read: err names it). */
    int (*file_put)(svc_store *s, int64_t id, const svc_file *files, int n, const char *keep, rs_err *err);
    /* Job id's file name into path (written beside it and renamed: a
     * reader of path never sees half).  1: fetched; 0: not stored; -1. */
    int (*file_get)(svc_store *s, int64_t id, const char *name, const char *path, rs_err *err);
    /* len bytes added at the end of job id's file name.  1, 0 (no such job), -1. */
    int (*file_append)(svc_store *s, int64_t id, const char *name, const void *data, size_t len, rs_err *err);
    /* Job id's files whose names start with prefix ("": all) removed;
     * returns the rows removed, or -1. */
    int64_t (*file_drop)(svc_store *s, int64_t id, const char *prefix, rs_err *err);
    /* The bytes job id holds in the queue, or -1. */
    int64_t (*file_bytes)(svc_store *s, int64_t id, rs_err *err);
    void (*close)(svc_store *s);
} svc_store_ops;

struct svc_store {
    const svc_store_ops *ops;
};

/* "sqlite:PATH" or a bare path ending in .db: SQLite (WAL);
 * "postgres://..." or "postgresql://...": PostgreSQL (libpq conninfo URI).
 * Creates the schema if it is missing, and brings a queue made before
 * units existed up to date (its queued and running jobs become WHOLE
 * units).  lease_s: the lease of the daemon using it (PostgreSQL's
 * timeouts derive from it).  NULL with err filled on failure. */
svc_store *svc_store_open(const char *spec, int lease_s, rs_err *err);
svc_store *svc_store_sqlite_open(const char *path, rs_err *err);
/* lease_s (the daemon's lease): the connection gives up on a silent or
 * stalled server well within it (keepalives, TCP user timeout, connect and
 * statement timeouts; each overridable in the URI). */
svc_store *svc_store_pg_open(const char *conninfo, int lease_s, rs_err *err);

/* The standard reason texts, shared so every backend words them alike. */
#define SVC_LEASE_EXPIRED "lease expired (worker or daemon lost)"
/* "lost its daemon N times (lease expired)" */
#define SVC_LOST_FMT "lost its daemon %d times (lease expired)"
/* "gave up after N attempts: why" into out. */
void svc_dead_letter(char *out, size_t n, int attempts, const char *why);
/* What a unit's messages start with in its job's error: "" (WHOLE),
 * "segment K (ticks A-B): " or "join: ". */
void svc_unit_context(char *out, size_t n, const svc_unit *u);

#endif
