#!/bin/sh
# Uploads are verified in full before they are queued (docs/service.md,
# "Uploads"): a desynced replay and a replay of another game version get 400
# with their own words, a good one (format 1 or 2) is queued, an oversized
# one is refused before any simulation.  The render's own desync check still
# stands behind it (a replay changed in the queue).  Real HTTP, SQLite.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

post() { # FILE WANT_CODE PATTERN
    code=$(curl -s -o resp.json -w '%{http_code}' -X POST --data-binary @"$1" "$SVC_URL/jobs?name=$1")
    [ "$code" = "$2" ] || { echo "$1: HTTP $code, want $2: $(cat resp.json)"; return 1; }
    json_get error <resp.json | grep -Eq -- "$3" || { echo "$1: answer lacks /$3/: $(cat resp.json)"; return 1; }
}

t_desync_and_other_game_refused_at_upload() {
    "$RS_BIN" record --ai --quiet --seconds 4 --seed 8 -o ok.rsr || return 1
    "$SVC_BIN_DIR/tests/simhash-O2" --flip 70 6 ok.rsr bad.rsr || return 1
    "$SVC_BIN_DIR/tests/simhash-O2" --game-version 9 ok.rsr other.rsr || return 1
    "$SVC_BIN_DIR/tests/simhash-O2" --game-version 0 ok.rsr v1.rsr || return 1
    svc_start d $SVC_FAST || return 1
    post bad.rsr 400 "^bad.rsr: desync at tick 120: .*last matching checkpoint: tick 60" || return 1
    post other.rsr 400 "^other.rsr: recorded by another version of the game \(replay: 9, this build: [0-9]+\)$" || return 1
    # refused before queueing: no job row was made
    [ "$(curl -s "$SVC_URL/jobs" | json_get jobs | grep -c id)" = 0 ] || { curl -s "$SVC_URL/jobs"; return 1; }
    grep -q "upload refused (400): bad.rsr: desync at tick 120" d.log || { cat d.log; return 1; }
    code=$(curl -s -o resp.json -w '%{http_code}' -X POST --data-binary @ok.rsr "$SVC_URL/jobs?name=ok.rsr")
    [ "$code" = 201 ] || { echo "ok.rsr: HTTP $code: $(cat resp.json)"; return 1; }
    [ "$(json_get frames_total <resp.json)" = 240 ] || { cat resp.json; return 1; }
    id=$(svc_submit v1.rsr) || return 1
    svc_wait_state "$id" done 60 || return 1
    svc_stop
}

# An oversized upload is refused by its size, an overlong one by its
# declared length: both before the replay is decoded or simulated.
t_cheap_checks_first() {
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 8 -o long.rsr || return 1
    "$SVC_BIN_DIR/tests/simhash-O2" --flip 70 6 long.rsr longbad.rsr || return 1
    svc_start d $SVC_FAST --max-seconds 10 --max-upload 1K || return 1
    { cat longbad.rsr; head -c 2000 /dev/zero; } >big.rsr # a desynced replay, and too big
    post big.rsr 413 "over the limit of 1024 bytes" || return 1
    svc_stop
    svc_start e $SVC_FAST --max-seconds 10 || return 1
    post longbad.rsr 400 "lasts 20 s; this service renders at most 10 s" || return 1
    svc_stop
}

# The render still checks every checkpoint: a replay changed in the queue
# after its upload was verified fails at its tick, and is not retried.
t_render_still_finds_a_desync() {
    "$RS_BIN" record --ai --quiet --seconds 20 --seed 6 -o long.rsr || return 1
    "$RS_BIN" record --ai --quiet --seconds 4 --seed 8 -o ok.rsr || return 1
    "$SVC_BIN_DIR/tests/simhash-O2" --flip 70 6 ok.rsr bad.rsr || return 1
    svc_start d $SVC_FAST || return 1
    a=$(svc_submit long.rsr) || return 1
    svc_wait_state "$a" running 30 || return 1
    id=$(svc_submit ok.rsr) || return 1 # queued behind a: the one worker is busy
    python3 -c 'import sqlite3, sys
db = sqlite3.connect(sys.argv[1], timeout=10)
db.execute("UPDATE jobs SET replay = ? WHERE id = ? AND state = 0", (open(sys.argv[2], "rb").read(), int(sys.argv[3])))
db.commit()
sys.exit(0 if db.total_changes == 1 else 1)' d/queue.db bad.rsr "$id" || { echo "job $id was no longer queued"; return 1; }
    curl -s -o /dev/null -X DELETE "$SVC_URL/jobs/$a"
    svc_wait_state "$id" failed 60 || return 1
    [ "$(svc_field "$id" desync_tick)" = 120 ] || { curl -s "$SVC_URL/jobs/$id"; return 1; }
    svc_field "$id" error | grep -q "desync at tick 120" || { svc_field "$id" error; return 1; }
    [ "$(svc_field "$id" attempts)" = 1 ] || return 1 # the replay's fault: not retried
    svc_stop
}

t_run ${T_ONLY:-desync_and_other_game_refused_at_upload cheap_checks_first render_still_finds_a_desync}
t_done
