#!/bin/sh
# How fast a finished unit's bytes go into PostgreSQL and back: the two ways
# a farm of daemons without a shared disk could keep them in the queue's
# database (bytea rows of CHUNK KiB, or a large object), for the
# choice between them (docs/service.md, "Several machines").
#
#   tools/pg-blob-bench.sh [-c CHUNK_KIB] [-r RUNS] FILE...
#
# Builds tools/pg-blob-bench.c against libpq, starts a throwaway
# PostgreSQL server on loopback (tests/pg.sh), and for each FILE (a
# segment's MP4, a finished video) prints write and read MB/s, median of
# RUNS (default 5), and what the bytes take on the server.  Needs
# tools/deps.sh service (postgresql, libpq-dev).
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
chunk=1024 runs=5
while getopts c:r:h opt; do
    case $opt in
    c) chunk=$OPTARG ;;
    r) runs=$OPTARG ;;
    h) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) exit 2 ;;
    esac
done
shift $((OPTIND - 1))
[ $# -ge 1 ] || { echo "usage: tools/pg-blob-bench.sh [-c CHUNK_KIB] [-r RUNS] FILE..." >&2; exit 2; }
for f in "$@"; do [ -r "$f" ] || { echo "pg-blob-bench: cannot read $f" >&2; exit 1; }; done
tmp=$(mktemp -d)
. "$here/tests/pg.sh"
trap 'pg_stop >/dev/null 2>&1; rm -rf "$tmp"' EXIT INT TERM
cc -O2 -o "$tmp/pg-blob-bench" "$here/tools/pg-blob-bench.c" -I"$(pg_config --includedir)" -lpq
chmod 755 "$tmp"
pg_start "$tmp/pg"
for f in "$@"; do "$tmp/pg-blob-bench" "$PG_URI" "$f" "$chunk" "$runs"; done
