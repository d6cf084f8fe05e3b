/* svc_http_recv.h: between the program's recv() (svc_http_recv.c) and the
 * connection guard (svc_http_guard.c), which implements the two checks. */
#ifndef SVC_HTTP_RECV_H
#define SVC_HTTP_RECV_H

#include <stdbool.h>
#include <stddef.h>

/* Whether fd is a watched connection already refused (its reads fail). */
bool http_recv_refused(int fd);
/* n bytes fd received; false: the connection is refused now (answered). */
bool http_recv_seen(int fd, const void *buf, size_t n);
/* Whether libmicrohttpd's recv() calls reach svc_http_recv.c's. */
bool http_recv_hooked(void);

#endif
