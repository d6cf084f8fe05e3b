#!/usr/bin/env python3
"""attack.py: the hostile HTTP clients of test_attack_http.sh (and of the
figures in docs/service.md, "On a network").  Loopback only.

  attack.py hold PORT MODE N [--from A.B.C.D-E] [--every S] [--seconds T]
      opens N connections (spread over the source addresses) and holds them:
      MODE idle sends nothing, slowloris sends a header line every S s,
      stalled sends a 1 MiB upload but its last byte.  Prints
      "opened K refused R", then "closed K" when the server cut them.
  attack.py latency PORT [--from ADDR] [--tries N] [--timeout S]
      GET /healthz N times; prints "median_ms M max_ms X failed F"
  attack.py chunked PORT [--seconds T]
      an endless chunked POST /jobs; prints "sent BYTES status CODE"
  attack.py raw PORT [--timeout S] < REQUEST
      sends the bytes of stdin as they are; prints the status line's code
  attack.py linger PORT [--token T] [--after BYTES]
      an endless chunked POST /jobs that goes on sending BYTES after the
      answer begins to arrive (as a client's bytes in flight do), then
      reads it; prints "status CODE end clean|reset sent BYTES": clean when
      every byte was taken and the answer ended with the connection's end
  attack.py rps PORT [--clients C] [--seconds T]
      keep-alive GET /healthz loops; prints "rps R"
"""
import argparse
import socket
import statistics
import sys
import threading
import time


def addrs(spec):
    """'127.0.0.2-101' -> ['127.0.0.2', ..., '127.0.0.101']"""
    base, _, last = spec.rpartition('.')
    lo, _, hi = last.partition('-')
    return ['%s.%d' % (base, k) for k in range(int(lo), int(hi or lo) + 1)]


def connect(port, src, timeout=2.0):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    s.settimeout(timeout)
    if src:
        s.bind((src, 0))
    s.connect(('127.0.0.1', port))
    return s


def status_of(s, timeout):
    s.settimeout(timeout)
    data = b''
    while b'\r\n' not in data:
        b = s.recv(4096)
        if not b:
            break
        data += b
    parts = data.split(b' ', 2)
    return int(parts[1]) if len(parts) > 1 and parts[1].isdigit() else 0


def cmd_hold(a):
    srcs = addrs(a.src) if a.src else [None]
    socks, refused = [], 0
    for k in range(a.n):
        try:
            s = connect(a.port, srcs[k % len(srcs)])
            if a.mode == 'slowloris':
                s.sendall(b'GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n')
            elif a.mode == 'stalled':
                s.sendall(b'POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/octet-stream\r\n'
                          b'Content-Length: 1048576\r\n\r\n')
                s.sendall(b'\0' * (1048576 - 1))
            socks.append(s)
        except OSError:
            refused += 1
    print('opened %d refused %d' % (len(socks), refused), flush=True)
    end = time.time() + a.seconds
    closed = set()
    while time.time() < end and len(closed) < len(socks):
        for i, s in enumerate(socks):
            if i in closed:
                continue
            try:
                if a.mode == 'slowloris':
                    s.sendall(b'X-a: b\r\n')
                s.setblocking(False)
                try:
                    if s.recv(65536) == b'':
                        closed.add(i)
                except BlockingIOError:
                    pass
            except OSError:
                closed.add(i)
        time.sleep(a.every)
    print('closed %d' % len(closed), flush=True)


def healthz(port, src, timeout):
    t = time.time()
    s = connect(port, src, timeout)
    s.sendall(b'GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n')
    code = status_of(s, timeout)
    s.close()
    return code, (time.time() - t) * 1000


def cmd_latency(a):
    ms, failed = [], 0
    for _ in range(a.tries):
        try:
            code, t = healthz(a.port, a.src, a.timeout)
            if code == 200:
                ms.append(t)
            else:
                failed += 1
        except OSError:
            failed += 1
    if ms:
        print('median_ms %.1f max_ms %.1f failed %d' % (statistics.median(ms), max(ms), failed))
    else:
        print('median_ms - max_ms - failed %d' % failed)


def cmd_chunked(a):
    s = connect(a.port, None)
    s.sendall(b'POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n'
              b'Content-Type: application/octet-stream\r\n\r\n')
    chunk = b'10000\r\n' + b'\0' * 0x10000 + b'\r\n'
    sent, end = 0, time.time() + a.seconds
    try:
        while time.time() < end:
            s.sendall(chunk)
            sent += 0x10000
    except OSError:
        pass
    try:
        code = status_of(s, 2)
    except OSError:
        code = 0
    print('sent %d status %d' % (sent, code))


def cmd_raw(a):
    s = connect(a.port, None)
    s.sendall(sys.stdin.buffer.read())
    try:
        print(status_of(s, a.timeout))
    except OSError:
        print(0)


def cmd_linger(a):
    import select
    s = connect(a.port, None)
    auth = ('Authorization: Bearer %s\r\n' % a.token).encode() if a.token else b''
    s.sendall(b'POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\n' + auth +
              b'Transfer-Encoding: chunked\r\nContent-Type: application/octet-stream\r\n\r\n')
    chunk = b'4000\r\n' + b'\0' * 0x4000 + b'\r\n'
    sent, answered, end, reset = 0, None, time.time() + 10, False
    s.settimeout(1)
    while time.time() < end:
        if answered is None and select.select([s], [], [], 0)[0]:
            answered = sent
        if answered is not None and sent - answered >= a.after:
            break
        try:
            s.sendall(chunk)
            sent += len(chunk)
        except OSError:
            reset = True
            break
    data = b''
    try:
        s.shutdown(socket.SHUT_WR)
        s.settimeout(5)
        while True:
            b = s.recv(65536)
            if not b:
                break
            data += b
    except OSError:
        reset = True
    parts = data.split(b' ', 2)
    code = int(parts[1]) if len(parts) > 1 and parts[1].isdigit() else 0
    print('status %d end %s sent %d' % (code, 'reset' if reset else 'clean', sent))


def cmd_rps(a):
    counts = [0] * a.clients
    end = time.time() + a.seconds

    def loop(i):
        try:
            keep_asking(i)
        except OSError as e:
            print('client %d: %s' % (i, e), file=sys.stderr)

    def keep_asking(i):
        s = connect(a.port, None)
        req = b'GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n'
        buf = b''
        while time.time() < end:
            s.sendall(req)
            while True:  # one response: headers, then Content-Length bytes
                head, sep, rest = buf.partition(b'\r\n\r\n')
                if sep:
                    n = 0
                    for line in head.split(b'\r\n'):
                        if line.lower().startswith(b'content-length:'):
                            n = int(line.split(b':')[1])
                    if len(rest) >= n:
                        buf = rest[n:]
                        break
                buf += s.recv(65536)
            counts[i] += 1

    ts = [threading.Thread(target=loop, args=(i,)) for i in range(a.clients)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    print('rps %.0f' % (sum(counts) / a.seconds))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest='cmd', required=True)
    h = sub.add_parser('hold')
    h.add_argument('port', type=int)
    h.add_argument('mode', choices=['idle', 'slowloris', 'stalled'])
    h.add_argument('n', type=int)
    h.add_argument('--from', dest='src')
    h.add_argument('--every', type=float, default=3)
    h.add_argument('--seconds', type=float, default=30)
    l = sub.add_parser('latency')
    l.add_argument('port', type=int)
    l.add_argument('--from', dest='src')
    l.add_argument('--tries', type=int, default=20)
    l.add_argument('--timeout', type=float, default=2)
    c = sub.add_parser('chunked')
    c.add_argument('port', type=int)
    c.add_argument('--seconds', type=float, default=10)
    r = sub.add_parser('raw')
    r.add_argument('port', type=int)
    r.add_argument('--timeout', type=float, default=5)
    g = sub.add_parser('linger')
    g.add_argument('port', type=int)
    g.add_argument('--token')
    g.add_argument('--after', type=int, default=1 << 20)
    q = sub.add_parser('rps')
    q.add_argument('port', type=int)
    q.add_argument('--clients', type=int, default=4)
    q.add_argument('--seconds', type=float, default=5)
    a = p.parse_args()
    {'hold': cmd_hold, 'latency': cmd_latency, 'chunked': cmd_chunked, 'raw': cmd_raw, 'linger': cmd_linger,
     'rps': cmd_rps}[a.cmd](a)


if __name__ == '__main__':
    main()
