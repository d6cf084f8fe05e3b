#!/bin/sh
# The test harness itself (docs/testing.md, "Skips"): a skip says which kind
# it is on its verdict line, a "missing install" skip fails under CI=true,
# and the run's skip list groups the reasons.  Through a small shell suite
# on tests/lib.sh and the C runner (tests/t.c, test_util's probe case).
. "$(dirname "$0")/lib.sh"
HERE=$(cd "$(dirname "$0")" && pwd)
BIN_DIR=$(dirname "$RS_BIN")

# a suite with one case of each kind
mk_suite() {
    cat >suite.sh <<EOS
. "$HERE/lib.sh"
T_SUITE=probe
t_fine() { return 0; }
t_no_device() { t_skip_env "no such device here"; }
t_no_tool() { t_skip_install "frob not installed (tools/deps.sh test)"; }
t_run fine no_device no_tool
t_done
EOS
}

t_shell_kinds_on_verdict_lines() {
    mk_suite
    env -u CI sh suite.sh >out.txt 2>err.txt || { echo "a suite of skips and a pass failed"; cat out.txt; return 1; }
    grep -qx 'skip probe/no_device (environment: no such device here) ([0-9.]* s)' out.txt &&
        grep -qx 'skip probe/no_tool (missing install: frob not installed (tools/deps.sh test)) ([0-9.]* s)' out.txt &&
        grep -qx '1 passed, 0 failed, 2 skipped' out.txt || { echo "verdicts:"; cat out.txt; return 1; }
}

t_shell_missing_install_fails_on_ci() {
    mk_suite
    CI=true sh suite.sh >out.txt 2>err.txt && { echo "CI=true passed with a missing install"; cat out.txt; return 1; }
    grep -q '^FAIL probe/no_tool (CI=true, and a missing install: frob not installed' out.txt &&
        grep -qx 'skip probe/no_device (environment: no such device here) ([0-9.]* s)' out.txt &&
        grep -qx '1 passed, 1 failed, 1 skipped' out.txt || { echo "verdicts:"; cat out.txt; return 1; }
}

t_c_kinds_and_ci() {
    u=$BIN_DIR/tests/test_util
    [ -x "$u" ] || { echo "no $u"; return 1; }
    env -u CI T_SKIP_PROBE=env "$u" =harness_skip_probe >e.txt 2>/dev/null || { cat e.txt; return 1; }
    grep -qx 'skip test_util/harness_skip_probe (environment: probe: the machine has no such thing) ([0-9.]* s)' e.txt ||
        { echo "env skip:"; cat e.txt; return 1; }
    env -u CI T_SKIP_PROBE=install "$u" =harness_skip_probe >i.txt 2>/dev/null || { cat i.txt; return 1; }
    grep -qx 'skip test_util/harness_skip_probe (missing install: probe: a tool is not installed) ([0-9.]* s)' i.txt ||
        { echo "install skip:"; cat i.txt; return 1; }
    CI=true T_SKIP_PROBE=install "$u" =harness_skip_probe >c.txt 2>/dev/null && { echo "CI=true passed:"; cat c.txt; return 1; }
    grep -q '^FAIL test_util/harness_skip_probe (CI=true, and a missing install: probe: a tool' c.txt &&
        grep -qx '0 passed, 1 failed, 0 skipped' c.txt || { echo "CI=true:"; cat c.txt; return 1; }
    CI=true T_SKIP_PROBE=env "$u" =harness_skip_probe >ce.txt 2>/dev/null || { echo "CI=true failed an environment skip"; cat ce.txt; return 1; }
}

t_skip_list_groups_reasons() {
    cat >log.txt <<'EOS'
ok   a/one (0.01 s)
skip a/two (environment: no server given) (0.00 s)
skip a/three (environment: no server given) (0.00 s)
skip b/four (missing install: x (y) not installed) (1.50 s)
skip a/five (environment: no server given) (0.00 s)
EOS
    awk -v prefix="  " -f "$HERE/skips.awk" log.txt >list.txt
    printf '  a/two and 2 more: environment: no server given\n  b/four: missing install: x (y) not installed\n' >want.txt
    cmp -s list.txt want.txt || { echo "list:"; cat list.txt; echo "want:"; cat want.txt; return 1; }
    printf 'ok   a/one (0.01 s)\n' >none.txt
    [ -z "$(awk -f "$HERE/skips.awk" none.txt)" ] || { echo "a list without skips"; return 1; }
}

t_run shell_kinds_on_verdict_lines shell_missing_install_fails_on_ci c_kinds_and_ci skip_list_groups_reasons
t_done
