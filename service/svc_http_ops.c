/* svc_http_ops: the routes for operators and their tools: /healthz (for
 * load balancers and the dashboard's form), /metrics (Prometheus text
 * format), the dashboard page and the HLS player it loads (hls.js). */
#include <fcntl.h>
#include <inttypes.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#if defined(RS_HAVE_MHD)
#include "svc_http_local.h"
#include "../runtime/util/rs_file.h"
#include "../runtime/util/rs_version.h"

void http_count_rejected(svc_daemon *d)
{
    pthread_mutex_lock(&d->mu);
    d->uploads_rejected++;
    pthread_mutex_unlock(&d->mu);
}

enum MHD_Result http_health(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    (void)q;
    int64_t counts[SVC_NSTATES];
    rs_err err = {0};
    bool ok = d->http_store->ops->counts(d->http_store, counts, &err);
    int busy = 0;
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++)
        busy += d->live[i].job != 0;
    bool draining = d->draining;
    pthread_mutex_unlock(&d->mu);
    svc_buf b = {0};
    svc_buf_printf(&b, "{\"ok\":%s,\"queue\":\"%s\",\"workers\":%d,\"busy\":%d,\"draining\":%s,\"version\":\"%s\"",
                   ok ? "true" : "false", d->http_store->ops->name, d->cfg.workers, busy, draining ? "true" : "false",
                   RS_VERSION);
    /* what the dashboard's upload form offers: the default and the bounds (a fixed
     * render_size bounds the sizes too: downscale only) */
    int mw = d->cfg.max_width, mh = d->cfg.max_height;
    if (d->cfg.render_width && (d->cfg.render_width < mw || d->cfg.render_height < mh))
        mw = d->cfg.render_width < mw ? d->cfg.render_width : mw, mh = d->cfg.render_height < mh ? d->cfg.render_height : mh;
    svc_buf_printf(&b, ",\"default_size\":\"%dx%d\",\"max_size\":\"%dx%d\",\"default_format\":\"%s\",\"default_quality\":\"%s\"",
                   d->cfg.width, d->cfg.height, mw, mh, d->cfg.format, d->cfg.quality);
    /* and the encoder's choices a job may make (settings codecs, presets,
     * min_crf; "*": whatever the encoder takes) */
    svc_buf_add(&b, ",\"codecs\":", 10);
    svc_json_str(&b, d->cfg.codecs[0] ? d->cfg.codecs : "*");
    svc_buf_add(&b, ",\"presets\":", 11);
    svc_json_str(&b, d->cfg.presets[0] ? d->cfg.presets : "*");
    svc_buf_printf(&b, ",\"min_crf\":%d", d->cfg.min_crf);
    if (ok)
        svc_buf_printf(&b, ",\"queued\":%" PRId64 ",\"running\":%" PRId64 "}\n", counts[SVC_QUEUED], counts[SVC_RUNNING]);
    else {
        svc_buf_add(&b, ",\"error\":", 9);
        svc_json_str(&b, err.msg);
        svc_buf_add(&b, "}\n", 2);
    }
    return http_reply_json(c, ok ? 200 : svc_http_status(err.code), &b);
}

enum MHD_Result http_metrics(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    (void)q;
    int64_t counts[SVC_NSTATES];
    rs_err err = {0};
    if (!d->http_store->ops->counts(d->http_store, counts, &err))
        return http_reply(c, svc_http_status(err.code), "text/plain", err.msg, strlen(err.msg));
    svc_buf b = {0};
    svc_buf_printf(&b, "# HELP ringside_queue_depth Jobs waiting for a worker.\n# TYPE ringside_queue_depth gauge\n"
                       "ringside_queue_depth %" PRId64 "\n",
                   counts[SVC_QUEUED]);
    svc_buf_printf(&b, "# HELP ringside_jobs Jobs in the queue by state (every daemon of the queue).\n"
                       "# TYPE ringside_jobs gauge\n");
    for (int s = 0; s < SVC_NSTATES; s++)
        svc_buf_printf(&b, "ringside_jobs{state=\"%s\"} %" PRId64 "\n", svc_state_name(s), counts[s]);
    double fps = 0;
    int busy = 0;
    pthread_mutex_lock(&d->mu);
    for (int i = 0; i < d->cfg.workers; i++)
        if (d->live[i].job) {
            busy++;
            fps += d->live[i].kind == SVC_UNIT_JOIN ? 0 : d->live[i].fps;
        }
    uint64_t frames = d->frames_rendered, done = d->jobs_done, failed = d->jobs_failed, retried = d->jobs_retried;
    uint64_t crashes = d->worker_crashes, wd = d->watchdog_kills, rejected = d->uploads_rejected;
    pthread_mutex_unlock(&d->mu);
    svc_buf_printf(&b,
                   "# HELP ringside_frames_rendered_total Frames rendered by this daemon's workers.\n"
                   "# TYPE ringside_frames_rendered_total counter\nringside_frames_rendered_total %" PRIu64 "\n"
                   "# HELP ringside_render_fps Frames per second of this daemon's running renders, summed.\n"
                   "# TYPE ringside_render_fps gauge\nringside_render_fps %.2f\n"
                   "# HELP ringside_workers Render processes this daemon may run.\n"
                   "# TYPE ringside_workers gauge\nringside_workers %d\n"
                   "# HELP ringside_workers_busy Render processes running now.\n"
                   "# TYPE ringside_workers_busy gauge\nringside_workers_busy %d\n"
                   "# HELP ringside_jobs_finished_total Jobs this daemon finished, by result.\n"
                   "# TYPE ringside_jobs_finished_total counter\n"
                   "ringside_jobs_finished_total{result=\"done\"} %" PRIu64 "\n"
                   "ringside_jobs_finished_total{result=\"failed\"} %" PRIu64 "\n"
                   "# HELP ringside_jobs_retried_total Attempts that failed and were re-queued.\n"
                   "# TYPE ringside_jobs_retried_total counter\nringside_jobs_retried_total %" PRIu64 "\n"
                   "# HELP ringside_worker_failures_total Render processes that crashed, failed or were killed.\n"
                   "# TYPE ringside_worker_failures_total counter\nringside_worker_failures_total %" PRIu64 "\n"
                   "# HELP ringside_watchdog_kills_total Renders killed for making no progress.\n"
                   "# TYPE ringside_watchdog_kills_total counter\nringside_watchdog_kills_total %" PRIu64 "\n"
                   "# HELP ringside_uploads_rejected_total Uploads refused (bad, too large).\n"
                   "# TYPE ringside_uploads_rejected_total counter\nringside_uploads_rejected_total %" PRIu64 "\n",
                   frames, fps, d->cfg.workers, busy, done, failed, retried, crashes, wd, rejected);
    http_guard_metrics(d->net, &b);
    http_events_metrics(d, &b);
    if (b.oom)
        return MHD_NO;
    enum MHD_Result r = http_reply(c, 200, "text/plain; version=0.0.4", b.p, b.len);
    svc_buf_free(&b);
    return r;
}

enum MHD_Result http_dashboard(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    (void)q;
    rs_err err = {0};
    size_t len;
    char *html = d->dashboard[0] ? rs_read_file(d->dashboard, 1 << 20, &len, &err) : NULL;
    if (!html) {
        const char *msg = "<!doctype html><title>ringside</title><p>The dashboard page (service/dashboard.html) "
                          "was not found; the API is at /jobs, /healthz and /metrics.";
        return http_reply(c, 200, "text/html; charset=utf-8", msg, strlen(msg));
    }
    enum MHD_Result r = http_reply(c, 200, "text/html; charset=utf-8", html, len);
    free(html);
    return r;
}

/* hls.js (npm's, installed by `make web`; docs/service.md, "Dashboard"):
 * the dashboard loads it to play a live stream where the browser has no
 * HLS of its own.  Open, as the page is. */
enum MHD_Result http_hls_js(svc_daemon *d, struct MHD_Connection *c, req *q)
{
    (void)q;
    int fd = d->hls_js[0] ? open(d->hls_js, O_RDONLY | O_CLOEXEC) : -1;
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        if (fd >= 0)
            close(fd);
        return http_error(c, SVC_ERR_NOT_FOUND, NULL, NULL,
                          "hls.js is not installed with this daemon ('make web' fetches it from npm): the dashboard "
                          "plays live streams only where the browser plays HLS itself");
    }
    const http_file f = {.type = "text/javascript; charset=utf-8", .cache = "max-age=3600"};
    return http_send_file(c, fd, (uint64_t)st.st_size, &f);
}

#endif
