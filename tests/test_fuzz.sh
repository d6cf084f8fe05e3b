#!/bin/sh
# The libFuzzer targets (make fuzz), each run for a bounded time on its
# seed corpus: a crash, leak, timeout or sanitizer report fails the case
# and leaves the input that caused it (crash-*) in the case's folder, its
# bytes in Base64 at the end of the case's output; such an input goes into
# the corpus as a regression case (tests/fuzz/<target>/, or demos/ for the
# replay reader).  docs/testing.md, "Fuzzing", lists the targets and says
# how to run one for an hour.  FUZZ_CI_SECONDS sets the time of each
# (default 6: eight targets on a 2-core CI machine).  The targets the
# chosen cases need are built first, by one make call.
. "$(dirname "$0")/lib.sh"
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SECS=${FUZZ_CI_SECONDS:-6}

# case: target, longest input, seed folders (read only; new inputs go to ./corpus)
target() {
    case $1 in
    replay_reader) echo "replay 65536" ;;
    http_wire) echo "wire 4096 $ROOT/tests/fuzz/wire" ;;
    stage_files) echo "stage 4096 $ROOT/stages $ROOT/tests/fuzz/stage" ;;
    service_config) echo "config 4096 $ROOT/tests/fuzz/config" ;;
    movie_sources) echo "y4m 4096 $ROOT/tests/fuzz/y4m" ;;
    segment_files) echo "seg 4096 $ROOT/tests/fuzz/seg" ;;
    http_parsers) echo "http 4096 $ROOT/tests/fuzz/http" ;;
    upload_form) echo "upload 8192 $ROOT/tests/fuzz/upload" ;;
    esac
}
CASES=${T_ONLY:-replay_reader http_wire stage_files service_config movie_sources segment_files http_parsers upload_form}

# One make call for the targets of the cases that run (T_CASES: tests/run.sh's tiers).
build_rc=0
if ! command -v clang >/dev/null 2>&1; then
    build_rc=2
else
    want=""
    for c in $CASES; do
        case " ${T_CASES:-$c} " in *" $c "*) ;; *) continue ;; esac
        # shellcheck disable=SC2046 # the words of target's line
        set -- $(target "$c")
        want="$want build/fuzz/fuzz_$1"
    done
    # shellcheck disable=SC2086
    [ -z "$want" ] || make -s -j2 -C "$ROOT" $want >"$T_TMP/build.log" 2>&1 || build_rc=1
fi

# run CASE: its target on its seeds for SECS seconds
run() {
    case $build_rc in
    1) cat "$T_TMP/build.log"; return 1 ;;
    2) t_skip_install "no clang (tools/deps.sh test installs it)" ;;
    esac
    # shellcheck disable=SC2046 # the words of target's line
    set -- $(target "$1")
    t=$1 max=$2
    shift 2
    mkdir -p corpus
    if [ "$t" = replay ]; then
        mkdir -p seeds && cp "$ROOT"/demos/*.rsr "$ROOT"/tests/golden/dojo-format1.rsr seeds/ || return 1
        set -- seeds
    fi
    "$ROOT/build/fuzz/fuzz_$t" -max_total_time="$SECS" -max_len="$max" -artifact_prefix=./ -print_final_stats=1 \
        corpus "$@" >fuzz.log 2>&1
    rc=$?
    grep -E "^stat::number_of_executed_units|^stat::new_units_added" fuzz.log | tr '\n' ' '
    echo
    if [ $rc != 0 ] || ls crash-* leak-* timeout-* >/dev/null 2>&1; then
        tail -30 fuzz.log
        echo "fuzz_$t failed (exit $rc): $(ls crash-* leak-* timeout-* 2>/dev/null | tr '\n' ' ')"
        return 1
    fi
}

t_replay_reader() { run replay_reader; }
t_http_wire() { run http_wire; }
t_stage_files() { run stage_files; }
t_service_config() { run service_config; }
t_movie_sources() { run movie_sources; }
t_segment_files() { run segment_files; }
t_http_parsers() { run http_parsers; }
t_upload_form() { run upload_form; }

# shellcheck disable=SC2086
t_run $CASES
t_done
