#!/bin/sh
# tools/upload-storm.sh [--clients N] [--rounds R] [--mb M] URL
#
# N curl clients at once, R rounds, each sending an M MiB chunked upload
# (POST URL/jobs, Transfer-Encoding: chunked) that is over the daemon's
# max_upload: every one should read the 413.  Prints a line per round and
# a total of statuses and curl exit codes ("413 x400" is all read; a curl
# exit 55 or 56 is a reset that overtook the answer).  docs/service.md,
# "Malformed requests", has what it measured.
#
#   ringside serve --listen 127.0.0.1:8080 &
#   tools/upload-storm.sh --clients 40 --rounds 10 --mb 100 http://127.0.0.1:8080
set -eu
clients=40 rounds=10 mb=100
while [ $# -gt 0 ]; do
    case "$1" in
    --clients) clients=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --mb) mb=$2; shift 2 ;;
    -h | --help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "upload-storm.sh: unknown option $1" >&2; exit 2 ;;
    *) break ;;
    esac
done
[ $# -eq 1 ] || { echo "usage: tools/upload-storm.sh [--clients N] [--rounds R] [--mb M] URL" >&2; exit 2; }
url=$1
command -v curl >/dev/null 2>&1 || { echo "upload-storm.sh: needs curl" >&2; exit 1; }
tmp=$(mktemp -d "${TMPDIR:-/tmp}/storm-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
head -c $((mb << 20)) /dev/zero >"$tmp/body"
r=1
while [ $r -le "$rounds" ]; do
    i=1
    while [ $i -le "$clients" ]; do
        (code=$(curl -s -o /dev/null -w '%{http_code}' -H 'Transfer-Encoding: chunked' -H 'Expect:' \
            --data-binary @"$tmp/body" "$url/jobs" 2>/dev/null) && rc=0 || rc=$?
         echo "$code curl=$rc" >"$tmp/r$r.$i") &
        i=$((i + 1))
    done
    wait
    echo "round $r: $(cat "$tmp"/r$r.* | sort | uniq -c | awk '{printf "%s%s %s x%d", (NR > 1 ? ", " : ""), $2, $3, $1}')"
    r=$((r + 1))
done
echo "total: $(cat "$tmp"/r* | sort | uniq -c | awk '{printf "%s%s %s x%d", (NR > 1 ? ", " : ""), $2, $3, $1}')"
