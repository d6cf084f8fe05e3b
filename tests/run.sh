#!/bin/sh
# Runs every test binary in BUILD/tests and every tests/test_*.sh, and sums
# their "N passed, N failed, N skipped" lines into one final line.
#   tests/run.sh BUILD [NAME]    NAME: run only tests/test_NAME*
#   RS_SUITE=service tests/run.sh BUILD   the service's end-to-end tests
#                                         (tests/service/test_*.sh: make test-service)
set -u
# One X server for the whole run, so the GLFW backend is tested too; tests
# that need "no display" unset DISPLAY themselves.
if [ -z "${DISPLAY:-}" ] && [ -z "${RS_IN_XVFB:-}" ] && command -v xvfb-run >/dev/null 2>&1; then
    RS_IN_XVFB=1 exec xvfb-run -a -s "-screen 0 1280x1024x24 -nolisten tcp" sh "$0" "$@"
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
trap 'rm -rf "$RINGSIDE_CACHE"' EXIT
# Diff images of failed golden tests land here.
export RS_TEST_OUT="$(cd "$build" && pwd)/test-output"
mkdir -p "$RS_TEST_OUT"

pass=0 fail=0 skip=0 ran=0
start=$(date +%s)
if [ -n "${RS_SUITE:-}" ]; then
    set -- "$here/$RS_SUITE"/test_*.sh
else
    set -- "$build"/tests/test_* "$here"/test_*.sh
fi
for t in "$@"; do
    [ -e "$t" ] || continue
    name=$(basename "$t" .sh)
    case "$name" in *.d|*.o) continue ;; esac
    [ -z "$only" ] || case "$name" in test_"$only"*) ;; *) continue ;; esac
    echo "== $name"
    log=$(mktemp)
    ran=$((ran + 1))
    # a hang must fail the run, not stall CI: 20 minutes per test program
    if [ "${t%.sh}" != "$t" ]; then timeout -k 10 1200 sh "$t" >"$log" 2>&1; else timeout -k 10 1200 "$t" >"$log" 2>&1; fi
    rc=$?
    [ "$rc" = 124 ] && echo "FAIL $name: timed out after 20 minutes" >>"$log"
    cat "$log"
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
echo "tests took $(( $(date +%s) - start )) s"
echo "$pass passed, $fail failed, $skip skipped"
[ "$fail" = 0 ]
