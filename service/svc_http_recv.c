/* svc_http_recv: the bytes libmicrohttpd reads, seen before it parses them.
 *
 * DESIGN: libmicrohttpd 0.9.75 reads a plain connection with recv() and
 * offers no hook on the raw bytes: its callbacks get the target and the
 * headers as C strings, already cut at a NUL.  This file defines recv()
 * itself; the dynamic linker binds libmicrohttpd's calls to the program's
 * definition (the executable comes first in symbol lookup), which calls
 * the next one (libc's, or a sanitizer's) and hands what a watched
 * connection received to the connection guard (http_guard_recv), which
 * checks it (svc_wire.c) and may refuse the connection.  Any other
 * descriptor (the database's socket, a child's pipe) passes straight
 * through.  http_recv_hooked() says whether the binding took (a static
 * link would not), so the daemon can say so rather than check nothing.
 * No <sys/socket.h> here: its fortified inline recv() would clash. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <pthread.h>
#include <stdbool.h>
#include <stddef.h>
#include <sys/types.h>

#include "svc_http_recv.h"

#if defined(RS_HAVE_MHD)
ssize_t recv(int fd, void *buf, size_t len, int flags);

typedef ssize_t (*recv_fn)(int, void *, size_t, int);
static recv_fn next_recv;
static pthread_once_t once = PTHREAD_ONCE_INIT;

static void find_next(void)
{
    next_recv = (recv_fn)dlsym(RTLD_NEXT, "recv");
}

ssize_t recv(int fd, void *buf, size_t len, int flags)
{
    pthread_once(&once, find_next);
    if (!next_recv) {
        errno = ENOSYS;
        return -1;
    }
    if (http_recv_refused(fd)) {
        errno = ECONNRESET;
        return -1;
    }
    ssize_t n = next_recv(fd, buf, len, flags);
    if (n > 0 && !(flags & 2 /* MSG_PEEK */) && !http_recv_seen(fd, buf, (size_t)n)) {
        errno = ECONNRESET; /* refused: libmicrohttpd closes its descriptor, the answer is out */
        return -1;
    }
    return n;
}

bool http_recv_hooked(void)
{
    return dlsym(RTLD_DEFAULT, "recv") == (void *)recv;
}
#endif
