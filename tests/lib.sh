# Shell side of the test harness, for end-to-end tests of the real binary.
#   . tests/lib.sh
#   t_foo() { ...; return 1 on failure after echoing why; t_skip_case "why" to skip; }
#   t_run foo
#   t_done
# T_CASES="foo bar" runs only those cases (tests/run.sh's ASan tier).
# RS_BIN is the binary under test (tests/run.sh sets it).
set -u
: "${RS_BIN:=$(cd "$(dirname "$0")/.." && pwd)/build/ringside}"
T_SUITE=$(basename "$0" .sh)
t_pass=0 t_failed=0 t_skipped=0
T_TMP=$(mktemp -d "${TMPDIR:-/tmp}/ringside-e2e-XXXXXX")
trap 'rm -rf "$T_TMP"' EXIT

t_skip_case() { echo "    skip: $*" >&2; exit 77; }

# T_CASES="a b": run only the cases of those exact names (tests/run.sh's tiers)
t_run() {
    for name in "$@"; do
        if [ -n "${T_CASES:-}" ]; then
            case " $T_CASES " in *" $name "*) ;; *) continue ;; esac
        fi
        dir="$T_TMP/$name"
        mkdir -p "$dir"
        t0=$(date +%s%N)
        ( cd "$dir" && "t_$name" ) >"$dir.log" 2>&1
        rc=$?
        # each verdict line ends with the case's wall time (tests/run.sh sums them)
        secs=$(awk -v a="$t0" -v b="$(date +%s%N)" 'BEGIN { printf "%.2f", (b - a) / 1e9 }')
        case $rc in
        0) t_pass=$((t_pass + 1)); echo "ok   $T_SUITE/$name ($secs s)" ;;
        77) t_skipped=$((t_skipped + 1)); echo "skip $T_SUITE/$name ($secs s)"; sed 's/^/    /' "$dir.log" | tail -3 ;;
        *) t_failed=$((t_failed + 1)); echo "FAIL $T_SUITE/$name ($secs s)"; sed 's/^/    /' "$dir.log" | tail -15 ;;
        esac
    done
}

t_done() {
    echo "$t_pass passed, $t_failed failed, $t_skipped skipped"
    [ "$t_failed" = 0 ]
}

# expect_fail CODE PATTERN CMD...: CMD exits with CODE and prints PATTERN (grep -E) on stderr
expect_fail() {
    want=$1 pat=$2
    shift 2
    "$@" >out.txt 2>err.txt
    rc=$?
    if [ "$rc" != "$want" ]; then echo "exit $rc, want $want: $*"; cat err.txt; return 1; fi
    if ! grep -Eq -- "$pat" err.txt; then echo "stderr lacks /$pat/: $*"; cat err.txt; return 1; fi
    return 0
}
