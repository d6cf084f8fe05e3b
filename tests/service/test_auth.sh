#!/bin/sh
# API tokens of `ringside serve` as an attacker meets them: real HTTP over
# loopback (curl), the real SQLite queue.  Tokens come from
# `ringside serve token`; only their hashes are stored.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

# the status of a request: code METHOD PATH [curl options...]
code() {
    m=$1 p=$2
    shift 2
    curl -s -o body.txt -w '%{http_code}' -X "$m" "$@" "$SVC_URL$p"
}

# a token for NAME in the queue of ./d: token NAME [add options...]
token() {
    n=$1
    shift
    "$RS_BIN" serve token add "$n" --data d "$@" 2>add.err || { cat add.err; return 1; }
}

submit_as() { # TOKEN FILE -> id
    body=$(curl -s -X POST --data-binary @"$2" -H "Authorization: Bearer $1" "$SVC_URL/jobs?name=$(basename "$2")")
    id=$(echo "$body" | json_get id 2>/dev/null)
    case "$id" in '' | null | *[!0-9]*) echo "submit failed: $body" >&2; return 1 ;; esac
    echo "$id"
}

t_token_commands() {
    a=$(token alice) || return 1
    echo "$a" | grep -Eq '^rs_[A-Za-z0-9_-]{43}$' || { echo "token '$a'"; return 1; }
    grep -q "cannot be shown again" add.err || { cat add.err; return 1; }
    token ops --operator --max-queued 5 >/dev/null || return 1
    expect_fail 1 "exists already" "$RS_BIN" serve token add alice --data d || return 1
    expect_fail 2 "only digits" "$RS_BIN" serve token add 42 --data d || return 1
    expect_fail 2 "which one\? add, list or revoke" "$RS_BIN" serve token --data d || return 1
    "$RS_BIN" serve token list --data d >list.txt || return 1
    grep -Eq '^1 +alice +no +20 +7200 ' list.txt && grep -Eq '^2 +ops +yes +5 +0 ' list.txt || { cat list.txt; return 1; }
    # the token itself is in no listing and not in the database
    ! grep -q "$a" list.txt || { echo "list shows the token"; return 1; }
    ! grep -aq "$a" d/queue.db* || { echo "the queue holds the token in clear"; return 1; }
    "$RS_BIN" serve token revoke alice --data d 2>rev.err || { cat rev.err; return 1; }
    "$RS_BIN" serve token revoke 2 --data d 2>rev.err || { cat rev.err; return 1; }
    "$RS_BIN" serve token list --data d | grep -Eq '^1 +alice +no .*Z +[0-9-]+T' || return 1
    expect_fail 1 "no token named" "$RS_BIN" serve token revoke nobody --data d || return 1
}

t_every_route_wants_a_token() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o a.rsr || return 1
    a=$(token alice) || return 1
    svc_start d $SVC_FAST || return 1
    grep -q "API tokens required (1 active)" d.log || { cat d.log; return 1; }
    id=$(submit_as "$a" a.rsr) || return 1
    # every route of the route table (ringside serve routes), none listed by hand:
    # those it marks TOKEN yes answer 401 without a valid one, the open ones never
    "$RS_BIN" serve routes >routes.txt || return 1
    guarded=0
    while read -r rm rp rtok rest <&3; do
        [ "$rm" = METHOD ] && continue
        rp=$(printf '%s' "$rp" | sed "s/:id/$id/; s/:ts/0.ts/")
        if [ "$rtok" = no ]; then
            c=$(code "$rm" "$rp")
            [ "$c" != 401 ] || { echo "$rm $rp is open but answered 401"; return 1; }
            continue
        fi
        guarded=$((guarded + 1))
        c=$(code "$rm" "$rp" -D h.txt)
        [ "$c" = 401 ] || { echo "$rm $rp without a token: $c $(cat body.txt)"; return 1; }
        grep -qi '^WWW-Authenticate: Bearer' h.txt || { echo "$rm $rp: no WWW-Authenticate"; cat h.txt; return 1; }
        c=$(code "$rm" "$rp" -H "Authorization: Bearer rs_$(head -c 32 /dev/urandom | base64 | tr -dc a-zA-Z | head -c 43)")
        [ "$c" = 401 ] || { echo "$rm $rp with a made-up token: $c"; return 1; }
        c=$(code "$rm" "$rp" -H "Authorization: Basic YTpi")
        [ "$c" = 401 ] || { echo "$rm $rp with Basic: $c"; return 1; }
    done 3<routes.txt
    [ "$guarded" -ge 10 ] || { echo "only $guarded routes need a token"; cat routes.txt; return 1; }
    # an upload without a token is refused before its body is read
    head -c 200000 /dev/urandom >big.bin
    [ "$(code POST /jobs --data-binary @big.bin)" = 401 ] || return 1
    # open: the dashboard and /healthz
    [ "$(code GET /)" = 200 ] && [ "$(code GET /healthz)" = 200 ] || { echo "/ or /healthz not open"; return 1; }
    # the token works; lookalikes do not: one character changed, one missing, one more
    [ "$(code GET "/jobs/$id" -H "Authorization: Bearer $a")" = 200 ] || { cat body.txt; return 1; }
    last=$(printf '%s' "$a" | tail -c 1)
    other=$( [ "$last" = A ] && echo B || echo A)
    for t in "${a%?}$other" "${a%?}" "${a}A" "$(printf '%s' "$a" | tr a-z A-Z)" "$a $a"; do
        [ "$(code GET "/jobs/$id" -H "Authorization: Bearer $t")" = 401 ] || { echo "token lookalike '$t' accepted"; return 1; }
    done
    "$RS_BIN" serve token revoke alice --data d 2>/dev/null || return 1
    [ "$(code GET "/jobs/$id" -H "Authorization: Bearer $a")" = 401 ] || { cat body.txt; return 1; }
    grep -q "token 'alice' was revoked" body.txt || { cat body.txt; return 1; }
    svc_stop
}

t_tokens_see_only_their_jobs() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o a.rsr || return 1
    a=$(token alice) && b=$(token bob) && o=$(token ops --operator) || return 1
    svc_start d $SVC_FAST || return 1
    ja=$(submit_as "$a" a.rsr) && jb=$(submit_as "$b" a.rsr) || return 1
    SVC_AUTH="Authorization: Bearer $o"
    for j in $ja $jb; do
        i=0
        until [ "$(curl -s -H "$SVC_AUTH" "$SVC_URL/jobs/$j" | json_get state)" = done ]; do
            sleep 0.2; i=$((i + 1)); [ $i -lt 300 ] || { echo "job $j not done"; return 1; }
        done
    done
    A="Authorization: Bearer $a"
    for p in "/jobs/$jb" "/jobs/$jb/video" "/jobs/$jb/hashes" "/jobs/$jb/stream.m3u8" "/jobs/$jb/stream/0.ts"; do
        [ "$(code GET "$p" -H "$A")" = 404 ] || { echo "alice GET $p: $(cat body.txt)"; return 1; }
    done
    # ... bob's own stream is there (a 1 s job, rendered whole, cut at the end)
    for p in "/jobs/$jb/stream.m3u8" "/jobs/$jb/stream/0.ts"; do
        [ "$(code GET "$p" -H "Authorization: Bearer $b")" = 200 ] || { echo "bob GET $p: $(cat body.txt)"; return 1; }
    done
    [ "$(code DELETE "/jobs/$jb" -H "$A")" = 404 ] || { echo "alice DELETE bob's job: $(cat body.txt)"; return 1; }
    [ "$(code GET "/jobs/$ja/video" -H "$A")" = 200 ] || { echo "alice's own video"; return 1; }
    ids=$(curl -s -H "$A" "$SVC_URL/jobs" | python3 -c 'import json,sys; print(" ".join(str(j["id"]) for j in json.load(sys.stdin)["jobs"]))')
    [ "$ids" = "$ja" ] || { echo "alice lists '$ids', want '$ja'"; return 1; }
    # the operator sees and fetches both
    ids=$(curl -s -H "$SVC_AUTH" "$SVC_URL/jobs" | python3 -c 'import json,sys; print(" ".join(str(j["id"]) for j in json.load(sys.stdin)["jobs"]))')
    [ "$ids" = "$jb $ja" ] || { echo "operator lists '$ids'"; return 1; }
    [ "$(code GET "/jobs/$jb/video" -H "$SVC_AUTH")" = 200 ] || return 1
    # and cancels bob's queued job, which alice could not
    jc=$(submit_as "$b" a.rsr) || return 1
    c=$(code DELETE "/jobs/$jc" -H "$A")
    [ "$c" = 404 ] || { echo "alice cancels bob's: $c"; return 1; }
    c=$(code DELETE "/jobs/$jc" -H "$SVC_AUTH")
    [ "$c" = 200 ] || [ "$c" = 409 ] || { echo "operator cancel: $c $(cat body.txt)"; return 1; }
    svc_stop
}

t_quotas_answer_429() {
    "$RS_BIN" record --ai --quiet --seconds 12 --seed 4 -o long.rsr || return 1
    "$RS_BIN" record --ai --quiet --seconds 2 --seed 5 -o short.rsr || return 1
    q=$(token queuer --max-queued 1 --seconds-per-hour 0) || return 1
    h=$(token hourly --max-queued 0 --seconds-per-hour 3) || return 1
    svc_start d $SVC_FAST --workers 1 || return 1
    submit_as "$q" long.rsr >/dev/null || return 1
    c=$(code POST "/jobs?name=long.rsr" --data-binary @long.rsr -H "Authorization: Bearer $q" -D h.txt)
    [ "$c" = 429 ] || { echo "second job of max_queued 1: $c $(cat body.txt)"; return 1; }
    grep -Eqi '^Retry-After: [0-9]+' h.txt || { cat h.txt; return 1; }
    grep -q "max_queued 1" body.txt || { cat body.txt; return 1; }
    submit_as "$h" short.rsr >/dev/null || return 1
    c=$(code POST "/jobs?name=short.rsr" --data-binary @short.rsr -H "Authorization: Bearer $h" -D h.txt)
    [ "$c" = 429 ] || { echo "4 s of a 3 s hour: $c $(cat body.txt)"; return 1; }
    ra=$(sed -n 's/^[Rr]etry-[Aa]fter: \([0-9]*\).*/\1/p' h.txt)
    [ "$ra" -gt 3500 ] && [ "$ra" -le 3600 ] || { echo "Retry-After '$ra': want the hour left of the first job"; return 1; }
    grep -q "seconds_per_hour 3" body.txt || { cat body.txt; return 1; }
    svc_stop
}

t_beyond_loopback() {
    mkdir -p d
    # bounded: a daemon that wrongly starts is killed after 10 s (exit 124)
    expect_fail 1 "no API token: make one first with 'ringside serve token add NAME'" \
        timeout 10 "$RS_BIN" serve --listen 0.0.0.0:0 --data d || return 1
    a=$(token alice) || return 1
    "$RS_BIN" serve --listen 0.0.0.0:0 --data d $SVC_FAST >d.log 2>&1 &
    SVC_PID=$!
    SVC_PIDS="$SVC_PID"
    trap svc_cleanup EXIT
    i=0
    until port=$(sed -n 's/.*listening on http:\/\/0\.0\.0\.0:\([0-9]*\)\/.*/\1/p' d.log) && [ -n "$port" ]; do
        sleep 0.1; i=$((i + 1)); [ $i -lt 100 ] || { cat d.log; return 1; }
    done
    SVC_URL="http://127.0.0.1:$port"
    grep -q "API tokens required (1 active): listening beyond loopback" d.log || { cat d.log; return 1; }
    [ "$(code GET /jobs)" = 401 ] || { echo "no token: $(cat body.txt)"; return 1; }
    [ "$(code GET /jobs -H "Authorization: Bearer $a")" = 200 ] || { cat body.txt; return 1; }
    # all tokens revoked: still 401, never open (it listens beyond loopback)
    "$RS_BIN" serve token revoke alice --data d 2>/dev/null || return 1
    [ "$(code GET /jobs)" = 401 ] || { echo "after revoking the last token: $(cat body.txt)"; return 1; }
    svc_stop
}

t_loopback_without_tokens_is_open() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o a.rsr || return 1
    svc_start d $SVC_FAST || return 1
    grep -q "API tokens not required" d.log || { cat d.log; return 1; }
    id=$(svc_submit a.rsr) || return 1
    [ "$(code GET "/jobs/$id")" = 200 ] && [ "$(code GET /metrics)" = 200 ] || return 1
    # the first token turns them on, without a restart
    token alice >/dev/null || return 1
    [ "$(code GET "/jobs/$id")" = 401 ] || { echo "a token exists, yet: $(cat body.txt)"; return 1; }
    svc_stop
}

t_run ${T_ONLY:-token_commands every_route_wants_a_token tokens_see_only_their_jobs quotas_answer_429 \
    beyond_loopback loopback_without_tokens_is_open}
t_done
