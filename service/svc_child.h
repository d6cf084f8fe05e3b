/* svc_child: the daemon's child processes (renders and joins) as
 * processes: starting one with its two pipes, reading a pipe's lines as
 * they come, and saying how one ended.  What the lines mean and what an
 * ending does to the unit are svc_daemon.c's.  Private to service/. */
#ifndef SVC_CHILD_H
#define SVC_CHILD_H

#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

#include "../runtime/util/rs_err.h"

/* Runs exe with argv: stdin and stdout on /dev/null, its stderr into
 * *err_fd and its fd 3 into *prog_fd (the read ends, close-on-exec and
 * non-blocking).  The child gets its own process group (Ctrl-C at the
 * daemon's terminal reaches the daemon, which decides), dies with the
 * daemon (PR_SET_PDEATHSIG), and inherits no other descriptor, no signal
 * handler and no blocked signal; nice > 0 runs it at that niceness (a
 * job's later segments: SVC_LATER_NICE).  False with err filled when a
 * pipe or the fork fails. */
#define SVC_LATER_NICE 10
bool svc_child_start(const char *exe, char *const argv[], int nice, pid_t *pid, int *prog_fd, int *err_fd, rs_err *err);

/* Reads what *fd holds now into buf (cap bytes, *len of them a partial
 * line kept from the last call) and hands each whole line, without its
 * newline, to line(ctx, text).  At EOF or a read error *fd is closed (set
 * to -1), an unterminated last line is handed too, and the result is
 * false; true while the pipe is open.  A line longer than the buffer is
 * dropped. */
bool svc_child_read(int *fd, char *buf, size_t cap, size_t *len, void (*line)(void *ctx, char *text), void *ctx);

/* Closes *fd if open and sets it to -1. */
void svc_child_close(int *fd);

/* "exit status 1", "killed by signal 9 (Killed)": a waitpid status in
 * words. */
void svc_child_status(int status, char *out, size_t n);

#endif
