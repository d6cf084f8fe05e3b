/* job_err: the error ids (rs_err.h) of the command and job layer: cmd/,
 * the jobs (job_render, job_poster, job_split, job_out) and the commands
 * and benchmarks built on them.  An error passed up from another module
 * keeps that module's id (CAP_ERR_*, RP_ERR_*, ...); these are for what
 * this layer itself finds wrong.
 *
 * Exit statuses are not ids: each command maps its failures to 0/1/2 (and
 * join's 3) itself, and no command branches on these ids for that. */
#ifndef JOB_ERR_H
#define JOB_ERR_H

#include "../runtime/util/rs_err.h"

#define JOB_ERRORS(X)                                                                               \
    X(ARG, "a job was given a bad descriptor (a missing field, a range it cannot split)")          \
    X(TICKS, "the ticks asked for are past the replay's end, or too few for the frames asked")     \
    X(DRAW, "the renderer could not draw a frame (or warm up for one)")                            \
    X(INTERRUPTED, "interrupted (Ctrl-C or SIGTERM); the partial outputs were removed")           \
    X(PROCESS, "cannot start a process of a parallel render (pipe, fork, this program's path)")   \
    X(SEGMENT, "a segment of a parallel render failed or ended by a signal")                        \
    X(CREATE, "cannot create an output or its folder (no folder, no permission)")                  \
    X(WRITE, "writing an output or putting it in place failed (disk full, I/O error, rename)")    \
    X(NOMEM, "out of memory")                                                                       \
    X(GL, "GL errors while a benchmark ran or checked its pictures")                                \
    X(VERIFY, "a picture differs from what it must be, or a benchmark's replay desynced")         \
    X(LIMIT, "the size asked for is more than this GL context or screen can take")                 \
    X(SCRIPT, "an attract script is unreadable or malformed")                                       \
    X(CHART, "a chart cannot be drawn (not .png, no cairo, cairo failed, too many bars)")          \
    X(NO_RESULT, "a benchmark measured nothing")

typedef enum job_error {
    JOB_ERR_BASE = RS_ERR_BASE(RS_ERR_MOD_JOB),
#define X(id, text) JOB_ERR_##id,
    JOB_ERRORS(X)
#undef X
        JOB_ERR_END
} job_error;

const char *job_error_text(int code);

#endif
