# Shell side of the test harness, for end-to-end tests of the real binary.
#   . tests/lib.sh
#   t_foo() { ...; return 1 on failure after echoing why; t_skip_env or
#             t_skip_install "why" to skip (below); }
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

# A case that cannot run here says why, and which kind of reason it is
# (docs/testing.md, "Skips"):
#   t_skip_env WHY       the machine or the run: no mount namespaces, a GPU
#                        device node, no server given, a machine too busy to
#                        time; nothing an install could change
#   t_skip_install WHY   a tool or library that tools/deps.sh installs is
#                        missing: under CI=true the case FAILS, so a CI
#                        machine cannot pass with an install step missing
# The reason goes on the verdict line ("skip SUITE/CASE (KIND: WHY) (N s)"),
# which tests/run.sh and .ci/run list at the end.
T_SKIP_ENV=77 T_SKIP_INSTALL=78
t_skip_as() { # CODE KIND WHY...
    code=$1 kind=$2
    shift 2
    echo "    skip ($kind): $*" >&2
    [ -z "${T_CASE_DIR:-}" ] || printf '%s: %s\n' "$kind" "$*" >"$T_CASE_DIR.skip"
    exit "$code"
}
t_skip_env() { t_skip_as "$T_SKIP_ENV" environment "$@"; }
t_skip_install() { t_skip_as "$T_SKIP_INSTALL" "missing install" "$@"; }

# T_CASES="a b": run only the cases of those exact names (tests/run.sh's tiers)
t_run() {
    for name in "$@"; do
        if [ -n "${T_CASES:-}" ]; then
            case " $T_CASES " in *" $name "*) ;; *) continue ;; esac
        fi
        dir="$T_TMP/$name"
        mkdir -p "$dir"
        T_CASE_DIR=$dir
        t0=$(date +%s%N)
        ( cd "$dir" && "t_$name" ) >"$dir.log" 2>&1
        rc=$?
        # each verdict line ends with the case's wall time (tests/run.sh sums them)
        secs=$(awk -v a="$t0" -v b="$(date +%s%N)" 'BEGIN { printf "%.2f", (b - a) / 1e9 }')
        why=$(head -n 1 "$dir.skip" 2>/dev/null)
        case $rc in
        "$T_SKIP_ENV" | "$T_SKIP_INSTALL") [ -n "$why" ] || why="no reason given" ;;
        esac
        if [ "$rc" = "$T_SKIP_INSTALL" ] && [ "${CI:-}" = true ]; then
            t_failed=$((t_failed + 1))
            echo "FAIL $T_SUITE/$name (CI=true, and a $why) ($secs s)"
            sed 's/^/    /' "$dir.log" | tail -15
            continue
        fi
        case $rc in
        0) t_pass=$((t_pass + 1)); echo "ok   $T_SUITE/$name ($secs s)" ;;
        "$T_SKIP_ENV" | "$T_SKIP_INSTALL") t_skipped=$((t_skipped + 1)); echo "skip $T_SUITE/$name ($why) ($secs s)" ;;
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
