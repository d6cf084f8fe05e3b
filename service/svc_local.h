/* The daemon's shared state: what the supervisor loop (svc_daemon.c) and
 * the HTTP threads (svc_http.c) both see, built by svc_serve (svc_main.c).
 * Private to service/: the rest of the program sees svc.h.
 *
 * DESIGN (threads):
 *  - the supervisor thread (main) owns workers[], the supervisor's store
 *    handle and every child process: it claims jobs, spawns and reaps
 *    renders, reads their pipes, sends heartbeats and runs the watchdog;
 *  - libmicrohttpd's threads answer requests through their own store
 *    handle (svc_store handles lock themselves) and read the live numbers
 *    below under mu: the supervisor publishes them, HTTP only reads;
 *  - signals only set stop (Redis's habit); the supervisor notices it
 *    within one poll interval and drains. */
#ifndef SVC_LOCAL_H
#define SVC_LOCAL_H

#include <pthread.h>
#include <signal.h>
#include <stdbool.h>
#include <stdint.h>
#include <sys/types.h>

#include "svc_config.h"
#include "svc_store.h"

/* A unit's render log: its last SVC_LOG_LINES lines of stderr, each cut
 * at SVC_LOG_LINE - 1 bytes, as long as the line reader's buffer (GET
 * /jobs/N/log; the render's summary line runs to about 300). */
#define SVC_LOG_LINES 40
#define SVC_LOG_LINE 1024

typedef struct svc_live {
    int64_t job;     /* 0: idle */
    pid_t pid;
    int kind, index; /* the unit (svc_unit_kind, its index) */
    int64_t done, total; /* frames of the unit */
    double fps;
    /* what the last heartbeat stored: the job's row holds the units' sums
     * as of their heartbeats, so a reader adds done - beat_done */
    int64_t beat_done;
    double beat_fps;
    char log[SVC_LOG_LINES * SVC_LOG_LINE]; /* the running unit's log so far, one line per '\n' */
} svc_live;

typedef struct svc_net svc_net; /* svc_http_guard.c: connections, deadlines, upload budget */
typedef struct svc_events svc_events; /* svc_http_events.c: the open event streams */

typedef struct svc_daemon {
    svc_config cfg;
    svc_store *store;      /* the supervisor's handle */
    svc_store *http_store; /* the HTTP threads' handle */
    char owner[SVC_OWNER_MAX]; /* "host:pid": who holds our leases */
    char exe[1024];        /* this binary: the workers run `ringside render` */
    char dashboard[1024];  /* service/dashboard.html under the data root ("" if not found) */
    char hls_js[1024];     /* hls.min.js under the data root ("" if not found) */
    volatile sig_atomic_t stop; /* 1: drain; 2: a second signal, stop now */
    unsigned short port;   /* the port actually bound */
    svc_net *net;          /* the HTTP server's connection table (locks itself) */
    svc_events *events;    /* GET /jobs/events's streams and their thread (locks itself) */

    pthread_mutex_t mu;    /* guards everything below */
    bool draining;         /* POST /jobs answers 503 */
    svc_live *live;        /* cfg.workers entries */
    uint64_t frames_rendered, jobs_done, jobs_failed, jobs_retried, worker_crashes, watchdog_kills;
    uint64_t uploads_rejected;
} svc_daemon;

/* the HTTP layer (svc_http*.c, svc_upload.c; its files share svc_http_local.h) */
/* Error ids (rs_err.h) of the service, each with the HTTP status a request
 * that fails with it gets and its text: one list, so an id cannot lack a
 * status (svc_http_status reads the middle column). */
#define SVC_ERRORS(X)                                                                          \
    X(EMPTY, 400, "empty upload")                                                              \
    X(TOO_LARGE, 413, "the upload is over max_upload")                                         \
    X(TOO_LONG, 400, "the replay lasts longer than max_seconds")                               \
    X(REPLAY, 400, "the upload is not a replay this service can render")                       \
    X(DESYNC, 400, "the replay's inputs do not reproduce its recorded state hashes")           \
    X(GAME_VERSION, 400, "the replay was recorded by another version of the game")             \
    X(BAD_BODY, 400, "a malformed request body")                                               \
    X(BAD_PARAM, 400, "a bad request parameter (size, format, limit, before)")                 \
    X(NOT_FOUND, 404, "no such job or resource, or the file does not exist yet")               \
    X(CONFLICT, 409, "the job is already over")                                                \
    X(GONE, 410, "a finished job's file is missing on this server")                            \
    X(RANGE, 416, "the byte range asked for is outside the file")                              \
    X(METHOD, 405, "the resource does not take that method")                                   \
    X(DRAINING, 503, "the daemon is shutting down and takes no new jobs")                      \
    X(AUTH, 401, "no API token, or an unknown or revoked one")                                 \
    X(QUOTA, 429, "the API token's quota is used up for now")                                  \
    X(NOMEM, 500, "out of memory")                                                             \
    X(BAD_REQUEST, 400, "a malformed request (control characters, header syntax)")             \
    X(HOST, 421, "the Host header names no host this daemon serves")                           \
    X(ORIGIN, 403, "a state-changing request from a foreign web page (Origin)")                \
    X(CODING, 501, "a transfer coding the daemon does not understand")                        \
    X(BUSY, 503, "uploads in progress hold all of upload_memory")                              \
    X(SYSTEM, 500, "a system call failed (pipe, fork, random bytes, the lock file)")           \
    X(DATA_DIR, 500, "the data directory is missing or not writable")                          \
    X(LOCKED, 500, "another daemon serves this SQLite queue")                                  \
    X(LISTEN, 500, "the HTTP server cannot listen on the configured address")                  \
    X(NO_HTTP, 500, "this build has no HTTP server (libmicrohttpd)")                           \
    X(NO_TOKENS, 500, "the daemon listens beyond this machine and the queue has no API token")    \
    X(SUPERVISOR, 500, "the daemon's supervisor stopped on an error")                          \
    X(SEGMENTS, 500, "a job's segments are not all rendered, so it cannot be joined yet")      \
    X(TOKEN_EXISTS, 409, "an API token with that name exists already")                         \
    X(TOKEN_UNKNOWN, 404, "no API token with that name or id")                                 \
    X(STREAMS, 503, "the daemon holds as many event streams as it takes")                      \
    X(KEEP, 500, "a unit's files could not be kept in the queue (files = queue)")               \
    X(RERENDER, 503, "a damaged stream piece's segment is being rendered again")

typedef enum svc_error {
    SVC_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_SVC),
#define X(id, status, text) SVC_ERR_##id,
    SVC_ERRORS(X)
#undef X
        SVC_ERR_END
} svc_error;

const char *svc_error_text(int code);
/* The HTTP status for an error id (svc_http_reply.c): SVC ids by their row of SVC_ERRORS,
 * every queue store id 503 (the queue is unavailable), anything else 500. */
unsigned svc_http_status(int code);

struct MHD_Daemon;
struct MHD_Daemon *svc_http_start(svc_daemon *d, rs_err *err);
/* Stops the HTTP threads and the connection reaper. */
void svc_http_stop(svc_daemon *d, struct MHD_Daemon *h);
/* Checks an upload and fills the job (frames_total from the replay); the
 * message says what is wrong.  Exposed for tests. */
bool svc_check_upload(const svc_config *cfg, const uint8_t *data, size_t len, const char *name, svc_job *j,
                      rs_err *err);
/* "bytes=A-B" against a file of size len: 1 ok (*first..*last), 0 no
 * usable range (serve it all), -1 unsatisfiable (416). */
int svc_parse_range(const char *h, uint64_t len, uint64_t *first, uint64_t *last);

/* svc_daemon.c */
int svc_run(svc_daemon *d);
/* Expired leases (every running unit when all: the SQLite daemon starting
 * up) back to the queue, no attempt charged; logs what became of each.
 * Returns how many, or -1. */
int svc_reap_leases(svc_daemon *d, bool all, rs_err *err);

/* svc_files.c: a unit's files and the command that makes them, cleaning
 * up (the layout is described there). */
typedef struct svc_unit_files {
    char replay[1024];  /* DATA/work/jobN-PID-SLOT.rsr: the child's copy of the replay */
    char out[1100];     /* what the child writes (-o) */
    char hashes[1100];  /* its --hashes */
    char segdir[1100];  /* a split job's segment directory ("" unsplit) */
    char poster[1100];  /* its --poster ("" for the join, which takes a segment's) */
    char stream[1100];  /* its --hls-dir: the job's stream folder ("" for the join, or a job
                           that cannot be streamed) */
} svc_unit_files;
/* "OUTPUT/N.stream/KEY": the job's live stream (capture/cap_hls.h: the
 * match's sound, the pieces, an index per unit).  The key (a new nonce per
 * job) keeps a reused job id from meeting an older queue's pieces.  False
 * ("" in out) when the job cannot be streamed: MPEG-TS pieces carry H.264
 * or HEVC, so a .webm job or a vp9/av1 one has no stream. */
bool svc_stream_dir(const svc_config *cfg, const svc_job *j, char *out, size_t n);
/* A finished render's stream pieces as it wrote them (f->stream): the
 * index of u's ticks there, and every piece the bytes it names, read back
 * as a viewer will get them.  True for a job without a stream; false with
 * why filled ("its stream pieces do not check: ..."). */
bool svc_unit_stream_ok(const svc_unit_files *f, const svc_unit *u, char *why, size_t n);
void svc_unit_paths(const svc_config *cfg, const svc_job *j, int slot, svc_unit_files *f);
/* The child's argv: `ringside render` for a WHOLE unit or a SEGMENT,
 * `ringside join` for the JOIN, whose segment files come from units (the
 * job's, with each segment's done_attempt).  NULL with err filled when a
 * segment is not done.  Free with svc_argv_free. */
char **svc_unit_argv(const svc_config *cfg, const svc_job *j, const svc_unit_files *f, const svc_unit *units, int n,
                     rs_err *err);
void svc_argv_free(char **argv);
/* "OUTPUT/N.EXT": a finished job's files, all named here: the video
 * (EXT its format), N.hashes, the poster N.png and the render log N.log
 * (the log gathers every unit's attempts, appended as each ends). */
void svc_job_file(const svc_config *cfg, int64_t id, const char *ext, char *out, size_t n);
/* Appends one unit attempt's log block to the job's log: with files =
 * queue to the queue's, else (or when the queue fails) to OUTPUT/N.log in
 * one write (units of a split job may end at once, on several daemons). */
void svc_job_log_append(svc_store *st, const svc_config *cfg, int64_t id, const char *block, size_t len);
/* line (a render's message) into out with the unit's temporary file names
 * replaced by the names the client knows: a whole job's or the join's
 * video, hash list and poster (OUTPUT/N.EXT) instead of
 * OUTPUT/.jobN-PID-aK.EXT.  A segment's files keep their names: they are
 * the segment's own. */
void svc_client_names(const svc_config *cfg, const svc_job *j, const svc_unit_files *f, const char *line, char *out,
                      size_t n);
/* "SEGDIR/sI-aK.ext" */
void svc_segment_path(char *out, size_t n, const char *segdir, int index, int attempt, const char *ext);
/* Segment I's files as attempt K wrote them (video, hashes, manifest, temporaries). */
void svc_segment_remove(const char *segdir, int index, int attempt);
/* A directory and what is in it. */
void svc_remove_dir(const char *path);
/* Everything hidden of job id in the output directory (".jobN-..."): its
 * segments, temporaries of crashed renders and joins.  For a job that is over. */
void svc_remove_job_files(const svc_config *cfg, int64_t id);
/* N.fmt, N.hashes, N.png, N.log and everything hidden of job id: the
 * number of visible files removed.  For a job that is over. */
int svc_remove_job_outputs(const svc_config *cfg, int64_t id, const char *format);
/* OUTPUT/N.stream and everything in it (a job failed, cancelled, deleted
 * or expired: its stream goes with its video).  1 when there was one. */
int svc_remove_job_stream(const svc_config *cfg, int64_t id);
/* Leftovers of jobs that are over or unknown, and of dead daemons' work
 * files; finished jobs past retention.  startup: no render of ours runs
 * yet, so files under our own pid are an earlier daemon's. */
void svc_sweep(svc_daemon *d, bool startup);

/* svc_keep.c: a job's files kept in the queue, for daemons that share no
 * disk (files = queue; svc_store.h, "Files in the queue"). */
bool svc_keep_on(const svc_config *cfg);
/* What j's unit made, stored before its done mark when files = queue
 * (else nothing, true): a segment's video, manifest, hashes and poster
 * (if it made one) under "seg/"; a WHOLE render's or a join's video,
 * hashes and poster from their places (svc_job_file); a segment's or a
 * WHOLE render's stream pieces and index when stream is true (unless the
 * queue holds that unit's index already).  note gets "; kept in the queue
 * in N ms" ("" when files = local). */
bool svc_keep_unit(svc_store *st, const svc_config *cfg, const svc_job *j, const svc_unit_files *f, bool stream,
                   char *note, size_t n, rs_err *err);
/* files = queue: segment index's files as claim attempt made them leave
 * the queue (a bad segment), or with index -1 every segment's (the job
 * is joined); a failure is logged. */
void svc_keep_drop(svc_store *st, const svc_config *cfg, int64_t id, int index, int attempt);
/* Job id's file name at path: 1 there already or fetched, 0 not in the
 * queue, -1 error. */
int svc_fetch(svc_store *st, int64_t id, const char *name, const char *path, rs_err *err);
/* The files of the segments in u[0..n-1] (as done_attempt made them) that
 * are missing here, fetched; false on an error of the queue or the disk
 * (one the queue lacks is left for the join to find). */
bool svc_fetch_segments(svc_store *st, const svc_job *j, const svc_unit_files *f, const svc_unit *u, int n,
                        rs_err *err);

#endif
