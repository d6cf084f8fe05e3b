#!/bin/sh
# Runs every test binary in BUILD/tests and every tests/test_*.sh, and sums
# their "N passed, N failed, N skipped" lines into one final line.
#   tests/run.sh BUILD [NAME]    NAME: run only tests/test_NAME*
#   RS_SUITE=service tests/run.sh BUILD   the service's end-to-end tests
#                                         (tests/service/test_*.sh: make test-service)
#   RS_TIER=asan tests/run.sh BUILD       only what tests/asan.tier lists (make asan):
#                                         whole suites, or some of their cases
#   RS_TIMES=PREFIX                       also write the suite and case times to
#                                         PREFIX.suites and PREFIX.cases
set -u
# One X server for the whole run, so the GLFW backend is tested too; tests
# that need "no display" unset DISPLAY themselves.  xvfb-run -a takes the
# first free display from RS_XVFB_FROM (99): two runs started at once (CI's
# asan and service phases) look from different numbers, or both may take
# the same one.
if [ -z "${DISPLAY:-}" ] && [ -z "${RS_IN_XVFB:-}" ] && command -v xvfb-run >/dev/null 2>&1; then
    RS_IN_XVFB=1 exec xvfb-run -n "${RS_XVFB_FROM:-99}" -a -s "-screen 0 1280x1024x24 -nolisten tcp" sh "$0" "$@"
fi
build=${1:-build}
only=${2:-}
here=$(cd "$(dirname "$0")" && pwd)
export RS_BIN="$(cd "$build" && pwd)/ringside"
# Leaks inside Mesa/LLVM are not ours: suppress them by library, keep ours.
export LSAN_OPTIONS="suppressions=$here/lsan.supp:print_suppressions=0"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"

# The IBL cache: a fresh one per run, so no test depends on (or fills) the
# user's ~/.cache and the second stage load in a run is still served from it.
RINGSIDE_CACHE=$(mktemp -d "${TMPDIR:-/tmp}/ringside-cache-XXXXXX")
export RINGSIDE_CACHE
# Diff images of failed golden tests land here.
export RS_TEST_OUT="$(cd "$build" && pwd)/test-output"
mkdir -p "$RS_TEST_OUT"

pass=0 fail=0 skip=0 ran=0
start=$(date +%s)
# the cost of every suite and case, for the tables at the end (and for
# whoever adds a test: docs/testing.md, "The budget")
times=$(mktemp -d)
trap 'rm -rf "$RINGSIDE_CACHE" "$times"' EXIT
if [ -n "${RS_SUITE:-}" ]; then
    set -- "$here/$RS_SUITE"/test_*.sh
else
    set -- "$build"/tests/test_* "$here"/test_*.sh
fi
tier=""
if [ -n "${RS_TIER:-}" ]; then
    tier=$here/$RS_TIER.tier
    [ -f "$tier" ] || { echo "FAIL: RS_TIER=$RS_TIER: no $tier"; echo "0 passed, 1 failed, 0 skipped"; exit 1; }
fi
left_out=""
for t in "$@"; do
    [ -e "$t" ] || continue
    name=$(basename "$t" .sh)
    case "$name" in *.d|*.o) continue ;; esac
    [ -z "$only" ] || case "$name" in test_"$only"*) ;; *) continue ;; esac
    # a tier: the suite's line of the tier file ("SUITE all" or "SUITE CASE..."), or not at all
    cases=all
    if [ -n "$tier" ]; then
        cases=$(awk -v s="$(basename "$t")" '{ sub(/#.*/, "") } $1 == s { $1 = ""; sub(/^ +/, ""); sub(/ +$/, ""); print; found = 1 }
            END { if (!found) print "-" }' "$tier")
        if [ "$cases" = "-" ]; then
            left_out="$left_out $(basename "$t")"
            continue
        fi
    fi
    echo "== $name${tier:+ ($RS_TIER tier: $cases)}"
    log=$(mktemp)
    ran=$((ran + 1))
    # a hang must fail the run, not stall CI: 20 minutes per test program
    t0=$(date +%s%N)
    if [ "${t%.sh}" != "$t" ]; then
        if [ "$cases" = all ]; then
            timeout -k 10 1200 sh "$t" >"$log" 2>&1
        else
            T_CASES=$cases timeout -k 10 1200 sh "$t" >"$log" 2>&1
        fi
    elif [ "$cases" = all ]; then
        timeout -k 10 1200 "$t" >"$log" 2>&1
    else
        # shellcheck disable=SC2046 # one "=CASE" argument per case
        timeout -k 10 1200 "$t" $(for c in $cases; do printf '=%s ' "$c"; done) >"$log" 2>&1
    fi
    rc=$?
    secs=$(awk -v a="$t0" -v b="$(date +%s%N)" 'BEGIN { printf "%.1f", (b - a) / 1e9 }')
    echo "$secs $(basename "$t") $(grep -cE '^(ok  |skip|FAIL) ' "$log")" >>"$times/suites"
    sed -n 's/^\(ok  \|skip\|FAIL\) *\([^ ]*\).* (\([0-9.]*\) s)$/\3 \2/p' "$log" >>"$times/cases"
    # 124: timed out; 137: killed when it would not stop
    timed_out=0
    [ "$rc" = 124 ] || [ "$rc" = 137 ] && timed_out=1
    [ "$timed_out" = 0 ] || echo "FAIL $name: timed out after 20 minutes" >>"$log"
    # a tier that names a case the suite no longer has must not pass quietly
    if [ "$cases" != all ] && [ "$timed_out" = 0 ]; then
        n_ran=$(grep -cE '^(ok  |skip|FAIL) ' "$log")
        n_named=$(echo "$cases" | wc -w)
        [ "$n_ran" = "$n_named" ] || {
            echo "FAIL $name: tests/$RS_TIER.tier names $n_named cases, $n_ran ran (a name the suite does not have?)" >>"$log"
            fail=$((fail + 1))
        }
    fi
    cat "$log"
    grep '^skip ' "$log" >>"$times/skips"
    line=$(grep -E '^[0-9]+ passed, [0-9]+ failed' "$log" | tail -1)
    rm -f "$log"
    if [ -z "$line" ]; then
        echo "FAIL $name: ended without a summary line (exit $rc; crashed?)"
        fail=$((fail + 1))
        continue
    fi
    set -- $line
    pass=$((pass + $1)) fail=$((fail + $3))
    [ "$#" -ge 6 ] && skip=$((skip + $5))
    # a crash or sanitizer report after the summary still fails
    if [ "$rc" != 0 ] && [ "$3" = 0 ]; then
        echo "FAIL $name: exit status $rc although no case failed"
        fail=$((fail + 1))
    fi
done
if [ "$ran" = 0 ]; then
    echo "FAIL: no test matched '${only}' (tests are named test_<module>)"
    fail=$((fail + 1))
fi
# a tier that names a suite there is not must not pass quietly either
if [ -n "$tier" ] && [ -z "$only" ]; then
    for s in $(sed 's/#.*//' "$tier" | awk 'NF { print $1 }'); do
        [ -e "$here/$s" ] || [ -e "$build/tests/$s" ] ||
            { echo "FAIL: tests/$RS_TIER.tier names $s, which is no suite"; fail=$((fail + 1)); }
    done
fi
[ -z "$left_out" ] || echo "not in the $RS_TIER tier (tests/$RS_TIER.tier; they run in make test):$left_out"
# the tables: every suite by time, then the slowest cases
if [ -s "$times/suites" ]; then
    echo "suites by time (seconds, cases):"
    sort -rn "$times/suites" | awk '{ printf "  %8.1f s  %-26s %4d\n", $1, $2, $3 }'
    echo "slowest 15 cases:"
    sort -rn "$times/cases" | head -15 | awk '{ printf "  %8.2f s  %s\n", $1, $2 }'
    [ -z "${RS_TIMES:-}" ] || { sort -rn "$times/suites" >"$RS_TIMES.suites"; sort -rn "$times/cases" >"$RS_TIMES.cases"; }
fi
# what did not run, and why (docs/testing.md, "Skips"): "missing install"
# fails under CI=true, so on CI this lists the machine's reasons alone
if [ -s "$times/skips" ]; then
    echo "skipped cases, by reason:"
    awk -v prefix="  " -f "$here/skips.awk" "$times/skips"
fi
echo "tests took $(( $(date +%s) - start )) s"
echo "$pass passed, $fail failed, $skip skipped"
[ "$fail" = 0 ]
