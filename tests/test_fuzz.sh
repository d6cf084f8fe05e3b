#!/bin/sh
# The libFuzzer targets (make fuzz), each run for a bounded time on its
# seed corpus: a crash, leak or sanitizer report fails the case and leaves
# the input that caused it (crash-*) in the case's folder; such an input
# goes into the corpus as a regression case (tests/fuzz/<target>/, or
# demos/ for the replay reader).  docs/testing.md, "Fuzzing", says how to
# run one for an hour.  FUZZ_CI_SECONDS sets the time (default 15).
. "$(dirname "$0")/lib.sh"
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SECS=${FUZZ_CI_SECONDS:-15}

# build TARGET: make's rule for it, in the source tree's build/fuzz
build() {
    command -v clang >/dev/null 2>&1 || { t_skip_install "no clang (tools/deps.sh test installs it)"; return 2; }
    make -s -C "$ROOT" "build/fuzz/$1" >build.log 2>&1 || { cat build.log; return 1; }
}

# run TARGET MAXLEN SEEDS...: new inputs go to ./corpus, the seeds are read only
run() {
    t=$1 max=$2
    shift 2
    mkdir -p corpus
    "$ROOT/build/fuzz/$t" -max_total_time="$SECS" -max_len="$max" -artifact_prefix=./ -print_final_stats=1 \
        corpus "$@" >fuzz.log 2>&1
    rc=$?
    grep -E "^stat::number_of_executed_units|^stat::new_units_added" fuzz.log | tr '\n' ' '
    echo
    if [ $rc != 0 ] || ls crash-* leak-* timeout-* >/dev/null 2>&1; then
        tail -30 fuzz.log
        echo "$t failed (exit $rc): $(ls crash-* leak-* timeout-* 2>/dev/null | tr '\n' ' ')"
        return 1
    fi
}

t_replay_reader() {
    build fuzz_replay
    case $? in 1) return 1 ;; 2) return 0 ;; esac
    mkdir -p seeds && cp "$ROOT"/demos/*.rsr "$ROOT"/tests/golden/dojo-format1.rsr seeds/ || return 1
    run fuzz_replay 65536 seeds
}

t_http_wire() {
    build fuzz_wire
    case $? in 1) return 1 ;; 2) return 0 ;; esac
    run fuzz_wire 4096 "$ROOT/tests/fuzz/wire"
}

t_run ${T_ONLY:-replay_reader http_wire}
t_done
