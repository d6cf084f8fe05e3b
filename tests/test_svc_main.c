/* svc_serve (service/svc_main.c), the daemon's entry point, through its
 * public header only: the start-up failures it must report and leave
 * nothing running for.  The daemon itself runs in tests/service/. */
#include <fcntl.h>
#include <stdio.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "../service/svc.h"
#include "t.h"

static void settings(svc_config *c, const char *data)
{
    rs_err e = {0};
    svc_config_defaults(c);
    T_ASSERTF(svc_config_set(c, "data", data, &e), "%s", e.msg);
    T_ASSERTF(svc_config_set(c, "log_level", "error", &e), "%s", e.msg);
    T_ASSERTF(svc_config_finish(c, &e), "%s", e.msg);
}

static void t_data_not_a_directory(void)
{
    char data[512];
    snprintf(data, sizeof data, "%s/file", t_tmpdir());
    FILE *f = fopen(data, "w");
    T_ASSERT(f && fclose(f) == 0);
    svc_config c;
    settings(&c, data);
    rs_err e = {0};
    T_ASSERT(!svc_serve(&(svc_desc){.config = &c}, &e));
    T_ASSERTF(strstr(e.msg, data) && strstr(e.msg, "not a directory"), "%s", e.msg);
}

/* An SQLite queue serves one daemon: a second one is refused at start-up
 * and names the process holding the lock. */
static void t_sqlite_queue_locked(void)
{
    char data[512], db[600], lock[700];
    snprintf(data, sizeof data, "%s/d", t_tmpdir());
    svc_config c;
    settings(&c, data);
    snprintf(db, sizeof db, "%s/queue.db", data);
    snprintf(lock, sizeof lock, "%s.lock", db);
    T_ASSERTF(!strcmp(c.queue, db) || !strcmp(c.queue + strlen("sqlite:"), db), "queue %s", c.queue);
    T_ASSERT(mkdir(data, 0755) == 0);
    int fd = open(lock, O_RDWR | O_CREAT, 0644);
    T_ASSERT(fd >= 0 && flock(fd, LOCK_EX | LOCK_NB) == 0);
    T_ASSERT(write(fd, "4242\n", 5) == 5);
    rs_err e = {0};
    T_ASSERT(!svc_serve(&(svc_desc){.config = &c}, &e));
    T_ASSERTF(strstr(e.msg, "another daemon (process 4242)"), "%s", e.msg);
    close(fd);
}

T_MAIN({"data_not_a_directory", t_data_not_a_directory}, {"sqlite_queue_locked", t_sqlite_queue_locked})
