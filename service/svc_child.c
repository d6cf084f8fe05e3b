/* svc_child: starting a child with its pipes, reading them in lines, and
 * its exit status in words (svc_child.h). */
#define _GNU_SOURCE /* pipe2, O_CLOEXEC, close_range */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <sys/resource.h>
#include <unistd.h>

#include "svc_child.h"
#include "svc_local.h"

bool svc_child_start(const char *exe, char *const argv[], int nice, pid_t *pid_out, int *prog_fd, int *err_fd, rs_err *err)
{
    int prog[2], errp[2];
    if (pipe2(prog, O_CLOEXEC) != 0)
        return rs_fail(err, SVC_ERR_SYSTEM, "pipe: %s", strerror(errno));
    if (pipe2(errp, O_CLOEXEC) != 0) {
        close(prog[0]), close(prog[1]);
        return rs_fail(err, SVC_ERR_SYSTEM, "pipe: %s", strerror(errno));
    }
    pid_t parent = getpid();
    pid_t pid = fork();
    if (pid < 0) {
        close(prog[0]), close(prog[1]), close(errp[0]), close(errp[1]);
        return rs_fail(err, SVC_ERR_SYSTEM, "fork: %s", strerror(errno));
    }
    if (pid == 0) {
        /* the child: only async-signal-safe calls until exec */
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent)
            _exit(127);
        /* its own process group: Ctrl-C at the daemon's terminal (or a
         * signal to the daemon's group) reaches the daemon, which decides */
        setpgid(0, 0);
        if (nice > 0) /* before exec: every thread the render starts inherits it */
            setpriority(PRIO_PROCESS, 0, nice);
        int devnull = open("/dev/null", O_RDWR);
        if (devnull < 0 || dup2(devnull, 0) < 0 || dup2(devnull, 1) < 0 || dup2(errp[1], 2) < 0 ||
            dup2(prog[1], 3) < 0)
            _exit(127);
        /* dup2 clears close-on-exec on 0..3; everything else (the HTTP
         * sockets, the database) was opened with it or is closed here */
        close_range(4, ~0U, 0);
        struct sigaction sa = {0};
        sa.sa_handler = SIG_DFL;
        sigaction(SIGTERM, &sa, NULL);
        sigaction(SIGINT, &sa, NULL);
        sigaction(SIGPIPE, &sa, NULL);
        sigset_t none;
        sigemptyset(&none);
        sigprocmask(SIG_SETMASK, &none, NULL);
        execv(exe, argv);
        static const char msg[] = "ringside serve: cannot run the renderer\n";
        ssize_t r = write(2, msg, sizeof msg - 1);
        (void)r;
        _exit(127);
    }
    close(prog[1]);
    close(errp[1]);
    *prog_fd = prog[0];
    *err_fd = errp[0];
    fcntl(*prog_fd, F_SETFL, O_NONBLOCK);
    fcntl(*err_fd, F_SETFL, O_NONBLOCK);
    *pid_out = pid;
    return true;
}

void svc_child_close(int *fd)
{
    if (*fd >= 0)
        close(*fd);
    *fd = -1;
}

bool svc_child_read(int *fd, char *buf, size_t cap, size_t *len, void (*line)(void *ctx, char *text), void *ctx)
{
    while (*fd >= 0) {
        ssize_t n = read(*fd, buf + *len, cap - 1 - *len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
            return true;
        if (n <= 0) {
            svc_child_close(fd);
            if (*len) { /* an unterminated last line */
                buf[*len] = 0;
                line(ctx, buf);
                *len = 0;
            }
            return false;
        }
        *len += (size_t)n;
        buf[*len] = 0;
        char *start = buf, *nl;
        while ((nl = strchr(start, '\n'))) {
            *nl = 0;
            line(ctx, start);
            start = nl + 1;
        }
        *len = (size_t)(buf + *len - start);
        memmove(buf, start, *len);
        if (*len == cap - 1) /* a line longer than the buffer: take it as it is */
            *len = 0;
    }
    return false;
}

void svc_child_status(int status, char *out, size_t n)
{
    if (WIFEXITED(status))
        snprintf(out, n, "exit status %d", WEXITSTATUS(status));
    else if (WIFSIGNALED(status))
        snprintf(out, n, "killed by signal %d (%s)", WTERMSIG(status), strsignal(WTERMSIG(status)));
    else
        snprintf(out, n, "status %d", status);
}
