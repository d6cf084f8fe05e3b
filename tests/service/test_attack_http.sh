#!/bin/sh
# The HTTP server under attack (docs/service.md, "On a network"): floods of idle and slow
# connections, endless and stalled uploads, malformed requests, foreign
# Host and Origin headers.  Loopback only (127.0.0.x); every case is
# bounded to seconds.  The clients are tests/service/attack.py.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

ATTACK="python3 $SVC_SRC/tests/service/attack.py"

port_of() { echo "${SVC_URL##*:}"; }

# enough descriptors for 1,000 client sockets in this shell (and the daemon's)
need_fds() {
    [ "$(ulimit -n)" -ge 1500 ] || ulimit -n "$(ulimit -Hn)" 2>/dev/null
    [ "$(ulimit -n)" -ge 1500 ] || t_skip_env "ulimit -n is $(ulimit -n) (hard $(ulimit -Hn)): 1,000 connections need more"
}

# /healthz from ADDR: the median of 10 tries must be under 100 ms, none failing
healthz_fast() { # ADDR
    r=$($ATTACK latency "$(port_of)" --from "$1" --tries 10 --timeout 2)
    echo "healthz from $1 under load: $r"
    set -- $r
    [ "$6" = 0 ] && python3 -c "import sys; sys.exit(0 if float('$2') < 100 else 1)" || return 1
}

metric() { # NAME (with labels) [ADDR]: its value
    curl -s --interface "${2:-127.0.0.1}" "$SVC_URL/metrics" | awk -v m="$1" '$1 == m { print $2 }'
}

code_of() { # curl args...: the status code
    curl -s -o resp.txt -w '%{http_code}' "$@"
}

t_slowloris_from_one_address() {
    need_fds
    svc_start d --header-timeout 60 --max-connections-per-ip 256 || return 1
    $ATTACK hold "$(port_of)" slowloris 1000 --every 1 --seconds 20 >hold.txt &
    h=$!
    sleep 4
    healthz_fast 127.0.0.2 || { kill $h; return 1; }
    open=$(metric ringside_http_connections 127.0.0.2)
    kill $h; wait $h 2>/dev/null
    echo "connections open during the attack: $open"
    # the per-address cap held the excess off (the 256 + ours)
    [ "$open" -ge 200 ] && [ "$open" -le 260 ] || { echo "open connections $open, want <= 256 + a few"; return 1; }
    [ "$(code_of "$SVC_URL/healthz")" = 200 ] || return 1
}

t_idle_from_a_hundred_addresses() {
    need_fds
    svc_start d --header-timeout 60 || return 1
    $ATTACK hold "$(port_of)" idle 1000 --from 127.0.0.2-101 --seconds 20 >hold.txt &
    h=$!
    sleep 4
    healthz_fast 127.0.0.1 || { kill $h; return 1; }
    open=$(metric ringside_http_connections)
    kill $h; wait $h 2>/dev/null
    cat hold.txt
    echo "connections open during the attack: $open"
    [ "$open" -ge 1000 ] || { echo "only $open connections held, want 1,000"; return 1; }
    [ "$(code_of "$SVC_URL/healthz")" = 200 ] || return 1
}

t_header_timeout_cuts_slow_and_idle() {
    svc_start d --header-timeout 2 || return 1
    $ATTACK hold "$(port_of)" slowloris 20 --every 0.5 --seconds 10 >slow.txt &
    s=$!
    $ATTACK hold "$(port_of)" idle 20 --every 0.5 --seconds 10 >idle.txt &
    i=$!
    wait $s $i
    cat slow.txt idle.txt
    [ "$(tail -1 slow.txt)" = "closed 20" ] && [ "$(tail -1 idle.txt)" = "closed 20" ] || return 1
    n=$(metric 'ringside_http_connections_cut_total{reason="header_timeout"}')
    [ "$n" = 40 ] || { echo "header_timeout cuts: $n, want 40"; return 1; }
    [ "$(code_of "$SVC_URL/healthz")" = 200 ] || return 1
}

t_endless_chunked_upload_cut_at_max_upload() {
    svc_start d --max-upload 64K || return 1
    r=$($ATTACK chunked "$(port_of)" --seconds 5)
    echo "$r"
    set -- $r
    [ "$4" = 413 ] || { echo "no 413 for an endless chunked upload"; return 1; }
    [ "$2" -lt $((16 << 20)) ] || { echo "$2 bytes sent before the cut"; return 1; }
    [ "$(metric 'ringside_http_connections_cut_total{reason="max_upload"}')" = 1 ] || return 1
    [ "$(code_of "$SVC_URL/healthz")" = 200 ] || return 1
}

t_stalled_upload_cut_by_min_body_rate() {
    svc_start d --header-timeout 2 --min-body-rate 1000000 || return 1
    $ATTACK hold "$(port_of)" stalled 5 --every 0.5 --seconds 10 >hold.txt
    cat hold.txt
    [ "$(tail -1 hold.txt)" = "closed 5" ] || return 1
    [ "$(metric 'ringside_http_connections_cut_total{reason="min_body_rate"}')" = 5 ] || return 1
    [ "$(code_of "$SVC_URL/healthz")" = 200 ] || return 1
}

t_upload_memory_full_is_503() {
    svc_start d --upload-memory 2M --min-body-rate 0 || return 1
    head -c 1000 /dev/zero >small.bin
    $ATTACK hold "$(port_of)" stalled 2 --seconds 30 >hold.txt &
    h=$!
    i=0
    while [ "$(metric ringside_http_upload_bytes_reserved)" != 2097152 ]; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 50 ] || { kill $h; echo "the stalled uploads reserved nothing"; return 1; }
    done
    code=$(curl -s -D h.txt -o resp.txt -w '%{http_code}' --data-binary @small.bin "$SVC_URL/jobs")
    kill $h; wait $h 2>/dev/null
    [ "$code" = 503 ] || { echo "upload with upload_memory full: $code $(cat resp.txt)"; return 1; }
    grep -qi '^Retry-After: 5' h.txt || { cat h.txt; return 1; }
    grep -q upload_memory resp.txt || { cat resp.txt; return 1; }
    # the stalled uploads' room comes back when they end
    i=0
    while [ "$(metric ringside_http_upload_bytes_reserved)" != 0 ]; do
        sleep 0.2; i=$((i + 1)); [ $i -lt 50 ] || { echo "upload memory never released"; return 1; }
    done
    code=$(code_of --data-binary @small.bin "$SVC_URL/jobs")
    [ "$code" = 400 ] || { echo "after the release: $code $(cat resp.txt)"; return 1; }
}

t_malformed_requests() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o good.rsr || return 1
    svc_start d || return 1
    port=$(port_of)
    raw() { printf "$1" | $ATTACK raw "$port" --timeout 5; }
    want() { # CODE WHAT GOT
        [ "$3" = "$1" ] || { echo "$2: HTTP $3, want $1 $(cat resp.txt 2>/dev/null)"; return 1; }
    }
    want 501 "Transfer-Encoding: gzip" "$(raw 'POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: gzip\r\n\r\nabc')" || return 1
    want 400 "%00 in the path" "$(code_of "$SVC_URL/jobs/1%00")" || return 1
    want 400 "%00 in the query" "$(code_of --data-binary @good.rsr "$SVC_URL/jobs?format=mp4%00")" || return 1
    want 400 "%1f in the query" "$(code_of "$SVC_URL/jobs?limit=1%1f")" || return 1
    want 400 "HTTP/1.1 without Host" "$(raw 'GET /healthz HTTP/1.1\r\n\r\n')" || return 1
    want 400 "a space before a colon" "$(raw 'GET /healthz HTTP/1.1\r\nHost: 127.0.0.1\r\nX-A : b\r\n\r\n')" || return 1
    want 400 "?sise=1" "$(code_of --data-binary @good.rsr "$SVC_URL/jobs?sise=1")" || return 1
    grep -q "unknown query parameter sise" resp.txt || { cat resp.txt; return 1; }
    want 400 "/healthz?x=1" "$(code_of "$SVC_URL/healthz?x=1")" || return 1
    # a chunk size of 2^64-1 ends with the header deadline's cousin, the body rate
    r=$(raw 'POST /jobs HTTP/1.1\r\nHost: 127.0.0.1\r\nTransfer-Encoding: chunked\r\n\r\nffffffffffffffff\r\nabc')
    [ "$r" != "" ] || return 1
    # what is well formed still works
    want 200 "GET /jobs?limit=5" "$(code_of "$SVC_URL/jobs?limit=5")" || return 1
    want 201 "POST /jobs?size=160x90&format=webm&name=x" \
        "$(code_of --data-binary @good.rsr "$SVC_URL/jobs?size=160x90&format=webm&name=x.rsr")" || return 1
    want 200 "healthz" "$(code_of "$SVC_URL/healthz")" || return 1
}

t_host_and_origin() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o good.rsr || return 1
    svc_start d || return 1
    want() { [ "$3" = "$1" ] || { echo "$2: HTTP $3, want $1 $(cat resp.txt)"; return 1; }; }
    want 421 "Host: evil.example" "$(code_of -H 'Host: evil.example' "$SVC_URL/jobs")" || return 1
    grep -q allowed_hosts resp.txt || { cat resp.txt; return 1; }
    want 421 "Host: evil.example:80" "$(code_of -H 'Host: evil.example:80' "$SVC_URL/healthz")" || return 1
    want 200 "Host: LOCALHOST:1" "$(code_of -H 'Host: LOCALHOST:1' "$SVC_URL/healthz")" || return 1
    want 200 "Host: [::1]" "$(code_of -H 'Host: [::1]' "$SVC_URL/healthz")" || return 1
    want 403 "POST with a foreign Origin" \
        "$(code_of -H 'Origin: http://evil.example' --data-binary @good.rsr "$SVC_URL/jobs")" || return 1
    want 403 "DELETE with a foreign Origin" "$(code_of -X DELETE -H 'Origin: null' "$SVC_URL/jobs/1")" || return 1
    # lookalikes of our own origin: a suffix, a prefix, userinfo, another port or
    # scheme, a trailing slash or dot; each is a foreign page
    hp=${SVC_URL#http://}
    for o in "http://$hp.evil.example" "http://evil.$hp" "http://user@$hp" "http://${hp%:*}:1" "https://$hp" \
        "http://$hp/" "http://$hp." "http://$hp http://evil.example"; do
        want 403 "POST with Origin '$o'" "$(code_of -H "Origin: $o" --data-binary @good.rsr "$SVC_URL/jobs")" || return 1
    done
    # lookalikes of the hosts we serve
    for h in localhost.evil.example evil.localhost 127.0.0.1.nip.io localhost. 127.0.0.2 '[::2]' '[::1].evil' \
        '127.0.0.1 evil.example'; do
        want 421 "Host: '$h'" "$(code_of -H "Host: $h" "$SVC_URL/healthz")" || return 1
    done
    # a foreign page may not change anything, but reading is the browser's business (no CORS headers)
    want 200 "GET with a foreign Origin" "$(code_of -D h.txt -H 'Origin: http://evil.example' "$SVC_URL/jobs")" || return 1
    ! grep -qi '^Access-Control' h.txt || { cat h.txt; return 1; }
    # our own page (the dashboard) posts with our own origin
    want 201 "POST from our own origin" \
        "$(code_of -H "Origin: $SVC_URL" --data-binary @good.rsr "$SVC_URL/jobs?name=own.rsr")" || return 1
    # allowed_hosts names what is accepted; * accepts any
    svc_stop
    svc_start d2 --allowed-hosts 'render.example, 127.0.0.1' || return 1
    want 200 "listed Host" "$(code_of -H 'Host: Render.Example:8080' "$SVC_URL/healthz")" || return 1
    want 421 "localhost unlisted" "$(code_of -H 'Host: localhost' "$SVC_URL/healthz")" || return 1
    svc_stop
    svc_start d3 --allowed-hosts '*' || return 1
    want 200 "Host: anything with *" "$(code_of -H 'Host: evil.example' "$SVC_URL/healthz")" || return 1
}

t_cors_when_configured() {
    "$RS_BIN" record --ai --quiet --seconds 1 --seed 3 -o good.rsr || return 1
    svc_start d --cors-origins 'http://app.example' || return 1
    want() { [ "$3" = "$1" ] || { echo "$2: HTTP $3, want $1 $(cat resp.txt)"; return 1; }; }
    want 204 "preflight" "$(code_of -D pre.txt -X OPTIONS -H 'Origin: http://app.example' \
        -H 'Access-Control-Request-Method: POST' "$SVC_URL/jobs")" || return 1
    for h in 'Access-Control-Allow-Origin: http://app.example' 'Access-Control-Allow-Methods: GET, POST, DELETE' \
        'Access-Control-Allow-Headers: Authorization, Content-Type' 'Access-Control-Max-Age: ' 'Vary: Origin'; do
        grep -qi "^$h" pre.txt || { echo "preflight lacks $h:"; cat pre.txt; return 1; }
    done
    want 201 "POST from the listed origin" "$(code_of -D post.txt -H 'Origin: http://app.example' \
        --data-binary @good.rsr "$SVC_URL/jobs")" || return 1
    grep -qi '^Access-Control-Allow-Origin: http://app.example' post.txt || { cat post.txt; return 1; }
    want 403 "POST from another origin" "$(code_of -D other.txt -H 'Origin: http://evil.example' \
        --data-binary @good.rsr "$SVC_URL/jobs")" || return 1
    ! grep -qi '^Access-Control-Allow-Origin' other.txt || { cat other.txt; return 1; }
    # lookalikes of the listed origin get neither the right to post nor CORS headers
    for o in http://app.example.evil http://evil-app.example http://app.example:8080 https://app.example \
        http://user@app.example 'http://app.example, http://evil.example'; do
        want 403 "POST from '$o'" "$(code_of -D other.txt -H "Origin: $o" --data-binary @good.rsr "$SVC_URL/jobs")" ||
            return 1
        ! grep -qi '^Access-Control-Allow-Origin' other.txt || { cat other.txt; return 1; }
    done
    want 200 "GET from another origin" "$(code_of -D get.txt -H 'Origin: http://evil.example' "$SVC_URL/jobs")" || return 1
    ! grep -qi '^Access-Control-Allow-Origin' get.txt && grep -qi '^Vary: Origin' get.txt || { cat get.txt; return 1; }
}

t_run ${T_ONLY:-slowloris_from_one_address idle_from_a_hundred_addresses header_timeout_cuts_slow_and_idle \
    endless_chunked_upload_cut_at_max_upload stalled_upload_cut_by_min_body_rate upload_memory_full_is_503 \
    malformed_requests host_and_origin cors_when_configured}
t_done
