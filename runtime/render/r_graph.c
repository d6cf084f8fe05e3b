#include "r_graph.h"
#include "r_err.h"

#include <string.h>
#include <time.h>

static double now_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec / 1e6;
}

void r_graph_init(r_graph *g, uint32_t persistent, const char *const *names, int n)
{
    memset(g, 0, sizeof *g);
    g->persistent = persistent;
    for (int i = 0; i < n && i < 32; i++)
        g->resource[i] = names[i];
}

static const char *res_name(const r_graph *g, uint32_t bits)
{
    for (int i = 0; i < 32; i++)
        if (bits & (1u << i))
            return g->resource[i] ? g->resource[i] : "?";
    return "?";
}

bool r_graph_add(r_graph *g, const r_pass *p, rs_err *err)
{
    if (g->n >= R_GRAPH_MAX)
        return rs_fail(err, R_ERR_GRAPH, "render graph: more than %d passes", R_GRAPH_MAX);
    if (!p->name || !p->run || !p->needed)
        return rs_fail(err, R_ERR_GRAPH, "render graph: pass %d has no name, run or needed", g->n);
    if (r_graph_find(g, p->name) >= 0)
        return rs_fail(err, R_ERR_GRAPH, "render graph: two passes named '%s'", p->name);
    uint32_t available = g->persistent;
    for (int i = 0; i < g->n; i++)
        available |= g->pass[i].writes;
    uint32_t missing = (p->reads | p->may_read) & ~available;
    if (missing)
        return rs_fail(err, R_ERR_GRAPH, "render graph: pass '%s' reads '%s', which no earlier pass writes", p->name,
                       res_name(g, missing));
    g->pass[g->n++] = *p;
    return true;
}

int r_graph_find(const r_graph *g, const char *name)
{
    for (int i = 0; i < g->n; i++)
        if (!strcmp(g->pass[i].name, name))
            return i;
    return -1;
}

void r_graph_timing(r_graph *g, r_graph_frame_fn fn, void *user)
{
    if (g->timing)
        return;
    g->timing = true;
    g->on_frame = fn;
    g->on_frame_user = user;
    /* Timer queries are core in 3.3, the version every backend gives us.
     * A pair of GL_TIMESTAMP queries per pass rather than GL_TIME_ELAPSED:
     * llvmpipe (Mesa 22) reports the first TIME_ELAPSED query after a flush
     * as the absolute clock (hours), and timestamps also need no nesting
     * rules should a pass ever time itself. */
    g->gpu_timer = gl.GenQueries && gl.GetQueryObjectui64v && gl.QueryCounter;
    g->serial = rgl_is_software();
    if (g->gpu_timer)
        gl.GenQueries(R_GRAPH_LAG * R_GRAPH_MAX * 2, &g->query[0][0][0]);
}

static void collect(r_graph *g, int s)
{
    if (!g->slot[s].pending)
        return;
    double gpu[R_GRAPH_MAX] = {0};
    for (int i = 0; i < g->n; i++) {
        if (!(g->slot[s].ran & ((r_graph_mask)1 << i)))
            continue;
        r_pass_stats *st = &g->stats[i];
        double c = g->slot[s].cpu_ms[i];
        st->cpu_ms += c;
        if (c > st->cpu_max_ms)
            st->cpu_max_ms = c;
        if (g->gpu_timer) {
            GLuint64 t0 = 0, t1 = 0;
            gl.GetQueryObjectui64v(g->query[s][i][0], GL_QUERY_RESULT, &t0);
            gl.GetQueryObjectui64v(g->query[s][i][1], GL_QUERY_RESULT, &t1);
            gpu[i] = t1 > t0 ? (double)(t1 - t0) / 1e6 : 0.0;
            st->gpu_ms += gpu[i];
            if (gpu[i] > st->gpu_max_ms)
                st->gpu_max_ms = gpu[i];
        }
    }
    if (g->on_frame)
        g->on_frame(g->on_frame_user, g->slot[s].frame, g->slot[s].ran, g->gpu_timer ? gpu : NULL, g->slot[s].cpu_ms);
    g->slot[s].pending = false;
}

r_graph_mask r_graph_run(r_graph *g, void *user)
{
    return r_graph_run_skip(g, user, 0);
}

r_graph_mask r_graph_run_skip(r_graph *g, void *user, r_graph_mask skip)
{
    int s = (int)(g->frame % R_GRAPH_LAG);
    if (g->timing)
        collect(g, s);
    r_graph_mask ran = 0;
    uint32_t produced = g->persistent;
    g->ran_now = 0;
    for (int i = 0; i < g->n; i++) {
        const r_pass *p = &g->pass[i];
        if (skip & ((r_graph_mask)1 << i)) {
            produced |= p->writes;
            continue;
        }
        if (!p->needed(user)) {
            g->stats[i].skips++;
            continue;
        }
        uint32_t missing = p->reads & ~produced;
        if (missing) {
            if (!g->error[0])
                snprintf(g->error, sizeof g->error, "frame %llu: pass '%s' needs '%s', whose writer was skipped",
                         (unsigned long long)g->frame, p->name, res_name(g, missing));
            g->stats[i].skips++;
            continue;
        }
        double t0 = g->timing ? now_ms() : 0;
        if (g->timing && g->gpu_timer)
            gl.QueryCounter(g->query[s][i][0], GL_TIMESTAMP);
        p->run(user);
        if (g->timing && g->serial)
            gl.Finish();
        if (g->timing && g->gpu_timer)
            gl.QueryCounter(g->query[s][i][1], GL_TIMESTAMP);
        if (g->timing)
            g->slot[s].cpu_ms[i] = now_ms() - t0;
        g->stats[i].runs++;
        ran |= (r_graph_mask)1 << i;
        g->ran_now = ran;
        produced |= p->writes;
    }
    if (g->timing) {
        g->slot[s].pending = true;
        g->slot[s].frame = g->frame;
        g->slot[s].ran = ran;
    }
    g->last_ran = ran;
    g->frame++;
    return ran;
}

void r_graph_flush(r_graph *g)
{
    if (!g->timing)
        return;
    for (uint64_t k = 0; k < R_GRAPH_LAG; k++) /* oldest first */
        collect(g, (int)((g->frame + k) % R_GRAPH_LAG));
}

void r_graph_release(r_graph *g)
{
    if (g->timing && g->gpu_timer)
        gl.DeleteQueries(R_GRAPH_LAG * R_GRAPH_MAX * 2, &g->query[0][0][0]);
    g->timing = false;
}

const char *r_graph_error(const r_graph *g)
{
    return g->error;
}

void r_graph_report(const r_graph *g, FILE *f)
{
    fprintf(f, "%-16s %8s %8s %10s %10s %10s\n", "pass", "runs", "skipped", g->gpu_timer ? "gpu ms" : "gpu ms(-)",
            "gpu max", "cpu ms");
    double tg = 0, tc = 0;
    for (int i = 0; i < g->n; i++) {
        const r_pass_stats *st = &g->stats[i];
        double n = st->runs ? (double)st->runs : 1;
        fprintf(f, "%-16s %8llu %8llu", g->pass[i].name, (unsigned long long)st->runs, (unsigned long long)st->skips);
        if (st->runs && g->gpu_timer)
            fprintf(f, " %10.3f %10.3f", st->gpu_ms / n, st->gpu_max_ms);
        else
            fprintf(f, " %10s %10s", "-", "-");
        fprintf(f, " %10.3f\n", st->runs ? st->cpu_ms / n : 0.0);
        uint64_t frames = st->runs + st->skips;
        if (frames) {
            tg += st->gpu_ms / (double)frames;
            tc += st->cpu_ms / (double)frames;
        }
    }
    fprintf(f, "%-16s %8s %8s %10.3f %10s %10.3f   (per frame, all passes)\n", "total", "", "", g->gpu_timer ? tg : 0.0,
            "", tc);
}
