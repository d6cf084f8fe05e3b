#!/bin/sh
# Several machines in one: PostgreSQL and three daemons, each in a network
# namespace of its own (an address on a private network of veth pairs and
# a bridge, made here) and a mount namespace of its own (its data and
# output directories on a tmpfs only it sees: nothing on disk in common).
# One split job is uploaded to host a, rendered by b and c as well, watched
# from a while it renders; then host b is killed and its namespace torn
# down mid-job, and the job still finishes with the direct render's hashes
# and nothing left behind.  Needs root (namespaces); skipped otherwise.
here=$(cd "$(dirname "$0")/.." && pwd)
: "${RS_BIN:=$(dirname "$here")/build/ringside}"
. "$here/lib.sh"
. "$here/service/svc_lib.sh"
. "$here/pg.sh"
trap 'exit 143' TERM INT HUP

NET=10.211.0      # the private network, inside the namespaces only
NS=rs$$h          # namespace names: ${NS}sw (the bridge), ${NS}pg, ${NS}a ...

on() { # HOST CMD...: CMD inside HOST's network namespace
    h=$1
    shift
    ip netns exec "$NS$h" "$@"
}

hosts_down() {
    for p in $SVC_PIDS; do kill -KILL "$p" 2>/dev/null; done
    pg_stop
    # whatever still runs in a namespace (a render, a client) goes with it
    for h in a b c pg sw; do
        for p in $(ip netns pids "$NS$h" 2>/dev/null); do kill -KILL "$p" 2>/dev/null; done
        ip netns del "$NS$h" 2>/dev/null
    done
}

# the bridge in ${NS}sw; host H gets eth0 with NET.N, its peer on the bridge
hosts_net() {
    ip netns add "${NS}sw" || return 1
    ip -n "${NS}sw" link add br0 type bridge && ip -n "${NS}sw" link set br0 up || return 1
    n=1
    for h in pg a b c; do
        ip netns add "$NS$h" &&
            ip -n "${NS}sw" link add "p$h" type veth peer name eth0 netns "$NS$h" &&
            ip -n "${NS}sw" link set "p$h" master br0 up &&
            ip -n "$NS$h" addr add "$NET.$n/24" dev eth0 &&
            ip -n "$NS$h" link set eth0 up && ip -n "$NS$h" link set lo up || return 1
        n=$((n + 1))
    done
}

# HOST N [serve options]: its daemon on NET.N:8080, its directories on a
# tmpfs mounted over ./host in a mount namespace of its own, its host name
# rs-HOST (a UTS namespace: the name its leases carry)
host_start() {
    h=$1 n=$2
    shift 2
    ip netns exec "$NS$h" unshare -m -u --propagation private \
        sh -c 'hostname "$0" && mount -t tmpfs -o size=256m "$0" "$1" && shift && exec "$@"' \
        "rs-$h" "$PWD/host" "$RS_BIN" serve --listen "$NET.$n:8080" --data "$PWD/host/data" --queue "$PG_URI" \
        "$@" >>"$h.log" 2>&1 &
    eval "pid_$h=$!"
    SVC_PIDS="$SVC_PIDS $!"
    i=0
    until on "$h" curl -sf "http://$NET.$n:8080/healthz" >/dev/null 2>&1; do
        sleep 0.1; i=$((i + 1))
        [ $i -lt 150 ] || { echo "host $h did not come up:"; cat "$h.log"; return 1; }
    done
}

api() { # HOST N PATH [curl options]: GET PATH on host N, from host HOST
    h=$1 n=$2 p=$3
    shift 3
    on "$h" curl -sf -H "Authorization: Bearer $TOKEN" "$@" "http://$NET.$n:8080$p"
}

now() { date +%s.%N; }
# what the case measured: in its log, and in RS_TEST_OUT/hosts.txt when that is set
say() {
    echo "$*"
    [ -z "${RS_TEST_OUT:-}" ] || echo "$*" >>"$RS_TEST_OUT/hosts.txt"
}
since() { python3 -c 'import sys; print(f"{float(sys.argv[1]) - float(sys.argv[2]):.1f}")' "$(now)" "$1"; }

t_three_hosts_no_shared_disk() {
    [ "$(id -u)" = 0 ] || t_skip_env "needs root: it makes network and mount namespaces"
    if ! ip netns add "${NS}probe" 2>/dev/null; then
        t_skip_env "cannot make a network namespace here (ip netns add failed: no CAP_SYS_ADMIN?)"
    fi
    ip netns del "${NS}probe"
    SVC_ON_EXIT=hosts_down
    trap svc_cleanup EXIT
    hosts_net || { echo "could not make the namespaces' network"; return 1; }
    mkdir -p host
    pgdir=$(mktemp -d "${TMPDIR:-/tmp}/ringside-pg-XXXXXX") || return 1
    PG_WRAP="ip netns exec ${NS}pg" PG_LISTEN=$NET.1
    export PG_WRAP PG_LISTEN
    pg_start "$pgdir"
    rc=$?
    [ "$rc" = 77 ] && t_skip_install "PostgreSQL is not installed (tools/deps.sh service installs it)"
    [ "$rc" = 0 ] || return 1
    # the daemons listen beyond loopback, so the queue needs a token first
    TOKEN=$(on a "$RS_BIN" serve token add ops --operator --queue "$PG_URI" -q) || return 1
    [ -n "$TOKEN" ] || return 1
    "$RS_BIN" record --ai --quiet --stage temple --seconds 20 --seed 8 -o m.rsr || return 1
    "$RS_BIN" render m.rsr -o direct.mp4 --render-size 160x90 --size 160x90 --hashes direct.hashes --quiet || return 1
    n=2
    for h in a b c; do
        host_start $h $n $SVC_FAST --workers 1 --segment-seconds 2 || return 1
        n=$((n + 1))
    done
    grep -q "kept in the queue" a.log || { cat a.log; return 1; }
    # each host's directory is its own: a file made on a is not on b
    on a nsenter -t "$pid_a" -m touch "$PWD/host/data/only-on-a" &&
        ! on b nsenter -t "$pid_b" -m test -e "$PWD/host/data/only-on-a" && [ ! -e host/data/only-on-a ] ||
        { echo "the hosts' directories are not their own"; return 1; }

    t0=$(now)
    id=$(on a curl -sf -H "Authorization: Bearer $TOKEN" --data-binary @m.rsr "http://$NET.2:8080/jobs?name=m.rsr" |
        json_get id) || return 1
    # watched from a while it renders: a piece another host rendered, listed and fetched through a
    other=""
    until [ -n "$other" ]; do
        api a 2 "/jobs/$id/stream.m3u8" >live.m3u8 2>/dev/null
        api a 2 "/jobs/$id" >job.json || return 1
        st=$(json_get state <job.json)
        [ "$st" = running ] || { echo "job $id is $st before a piece of b or c was listed"; cat job.json; return 1; }
        [ -n "${tf:-}" ] || ! grep -q '\.ts$' live.m3u8 || tf=$(since "$t0")
        # a listed piece of a segment done by another host (owner "rs-H:PID-nonce/slot")
        other=$(python3 - job.json live.m3u8 <<'EOF'
import json, sys
j = json.load(open(sys.argv[1]))
listed = {l.strip() for l in open(sys.argv[2]) if l.strip().endswith(".ts")}
for s in j.get("segments", []):
    w = s.get("worker") or ""
    if s["state"] == "done" and f"stream/{s['ticks'][0]}.ts" in listed and not w.startswith("rs-a:"):
        print(s["ticks"][0], w)
        break
EOF
)
        sleep 0.2
    done
    say "first piece listed on a ${tf:-?} s after the upload; watched through a: piece $other"
    tick=${other%% *}
    api a 2 "/jobs/$id/stream/$tick.ts" -o piece.ts || { echo "a cannot serve piece $tick"; return 1; }

    # host b dies mid-job: killed, its namespace torn down
    i=0
    until pgrep -P "$pid_b" >/dev/null; do
        sleep 0.1; i=$((i + 1))
        [ $i -lt 600 ] || { echo "b never rendered again"; return 1; }
    done
    kill -KILL "$pid_b"
    ip netns del "${NS}b"
    tk=$(now)
    i=0
    while :; do
        st=$(api a 2 "/jobs/$id" | json_get state)
        [ "$st" = done ] && break
        [ "$st" = failed ] && { api a 2 "/jobs/$id"; return 1; }
        sleep 0.5; i=$((i + 1))
        [ $i -lt 600 ] || { echo "job $id not done 300 s after b died"; return 1; }
    done
    say "b killed $(python3 -c 'import sys; print(f"{float(sys.argv[1]) - float(sys.argv[2]):.1f}")' "$tk" "$t0") s after the upload; done $(since "$t0") s after the upload, $(since "$tk") s after b died"
    grep -q "re-queued (its lease expired" a.log c.log || { echo "nobody took back b's unit"; return 1; }
    api c 4 "/jobs/$id/hashes" -o c.hashes && cmp c.hashes direct.hashes || { echo "the hashes differ"; return 1; }
    api a 2 "/jobs/$id/video" -o a.mp4 && [ "$(frames_of a.mp4)" = 1200 ] || { echo "a's video"; return 1; }
    # nothing left behind: no segment in the queue, no hidden file on a or c
    [ "$(pg_psql "SELECT COUNT(*) FROM job_files WHERE job_id = $id AND name LIKE 'seg/%'")" = 0 ] || return 1
    i=0
    while on a nsenter -t "$pid_a" -m ls -A "$PWD/host/data/videos" | grep -q "^\.job" ||
        on c nsenter -t "$pid_c" -m ls -A "$PWD/host/data/videos" | grep -q "^\.job"; do
        sleep 0.5; i=$((i + 1))
        [ $i -lt 30 ] || { echo "hidden files stayed"; return 1; }
    done
}

t_run three_hosts_no_shared_disk
t_done
