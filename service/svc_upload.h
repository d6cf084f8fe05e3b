/* svc_upload: an upload on its way to becoming a job, with no HTTP in it.
 *
 * The body as it arrives (raw, or the replay part of a multipart form),
 * the job's parameters (form fields, else query parameters), the checks a
 * replay must pass, and a token's quotas.  The request phases (svc_http.c)
 * feed it; tests drive it directly.  Private to service/. */
#ifndef SVC_UPLOAD_H
#define SVC_UPLOAD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "svc_config.h"
#include "svc_store.h"
#include "../capture/cap_enc.h"
#include "../runtime/util/rs_err.h"

/* The job parameters a client may set, each with its room (characters + 1).
 * The one list: the form fields, the query parameters, POST /jobs's row of
 * the route table (SVC_JOB_PARAM_LIST) and the encoder's request all come
 * from it.  The file name ("name") is apart: it has three sources. */
#define SVC_JOB_PARAMS(X)                                                                                              \
    X(size, 32)                                                                                                        \
    X(format, 16)                                                                                                      \
    X(codec, 16)                                                                                                       \
    X(crf, 8)                                                                                                          \
    X(bitrate, 16)                                                                                                     \
    X(preset, CAP_ENC_PRESET_MAX)                                                                                      \
    X(pix_fmt, 16)                                                                                                     \
    X(audio, 8)                                                                                                        \
    X(quality, 16)
#define SVC_JOB_PARAM_NAME(name, room) #name ","
/* "size,format,...,quality,name": what POST /jobs takes in its query */
#define SVC_JOB_PARAM_LIST SVC_JOB_PARAMS(SVC_JOB_PARAM_NAME) "name"

typedef struct svc_job_params {
#define X(name, room) char name[room];
    SVC_JOB_PARAMS(X)
#undef X
} svc_job_params;

typedef struct svc_upload {
    long limit;       /* max_upload: more is dropped and too_large set */
    uint8_t *body;
    size_t len, cap;
    bool too_large, oom;
    const char *bad;  /* a malformed body: refused (400) once it is all read */
    char name[SVC_NAME_MAX];
    svc_job_params p;
} svc_upload;

/* Body bytes.  False only when out of memory (oom set); past the limit the
 * body is dropped, too_large set, and the rest is counted but not kept. */
bool svc_upload_append(svc_upload *u, const void *data, size_t n);
/* The file name from a form's filename, ?name= or X-Filename: its last path
 * element, control characters as '_'.  NULL or "" leaves the name as it is. */
void svc_upload_name(svc_upload *u, const char *name);
/* A piece of a multipart field at offset off of its value: the replay
 * ("replay" or "file") or a job parameter (one too long is dropped); any
 * other field is ignored.  False only when out of memory. */
bool svc_upload_field(svc_upload *u, const char *key, const char *filename, const char *data, uint64_t off,
                      size_t size);
/* A job parameter from the query, unless the form gave it.  False
 * (SVC_ERR_BAD_PARAM) when it is longer than its room; an unknown key is
 * ignored (the route table refuses those before). */
bool svc_upload_param(svc_upload *u, const char *key, const char *value, rs_err *err);
void svc_upload_free(svc_upload *u);

/* The job an upload asks for: the configured defaults, the parameters and
 * the replay checked (svc_check_upload), the replay's bytes lent to j
 * (u keeps them).  False with err (SVC_ERR_BAD_PARAM, the encoder's and the
 * replay's ids) when anything is refused. */
bool svc_upload_job(const svc_config *cfg, svc_upload *u, svc_job *j, rs_err *err);

/* A token's quotas against job j (frames_total known).  1: within them;
 * 0: over one (msg says which, *retry the seconds until a new try may
 * pass); -1: the queue failed (err). */
int svc_upload_quota(svc_store *s, const svc_token *t, const svc_job *j, char *msg, size_t n, int64_t *retry,
                     rs_err *err);

#endif
