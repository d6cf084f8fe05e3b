#!/bin/sh
# tools/gpu-campaign.sh: usage, the refusals that mean "could not run at
# all", and a run with a budget too short for most steps: it must still
# end in time with a report that names the device first and every step,
# skipped ones included (docs/benchmarks.md, "On a real GPU").  The full
# --quick dry run takes about 70 s here, so it is not run in make test.
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=tests/lib.sh
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
C=$SRC/tools/gpu-campaign.sh
export RINGSIDE_CACHE=off

t_usage() {
    expect_fail 2 "usage: tools/gpu-campaign.sh REPORTDIR" "$C" || return 1
    expect_fail 2 "unknown option '--nope'" "$C" rep --nope || return 1
    expect_fail 2 "usage:" "$C" a b || return 1
    "$C" --help >help.txt 2>&1 || { cat help.txt; return 1; }
    grep -q "CAMPAIGN_BUDGET_S" help.txt || { echo "--help does not describe CAMPAIGN_BUDGET_S"; return 1; }
}

t_cannot_run() {
    RINGSIDE=/nonexistent/ringside expect_fail 1 "not an executable" "$C" rep || return 1
    # no $RINGSIDE, no .gpu-bundle/run, no build/ringside in this folder
    expect_fail 1 "no ringside" "$C" rep || return 1
    : >file
    RINGSIDE=$RS_BIN expect_fail 1 "cannot make REPORTDIR" "$C" file/rep || return 1
    RINGSIDE=$RS_BIN CAMPAIGN_BUDGET_S=soon expect_fail 1 "expected whole seconds" "$C" rep || return 1
}

t_deadline_skips_cleanly() {
    rep=$T_TMP/rep log=$PWD
    t0=$(date +%s)
    # from the source tree (demos/, tests/golden/), as on the GPU machine
    (cd "$SRC" && RINGSIDE=$RS_BIN CAMPAIGN_BUDGET_S=25 "$C" "$rep" --quick) >"$log/out.txt" 2>"$log/err.txt"
    rc=$? t=$(($(date +%s) - t0))
    [ "$rc" = 0 ] || { echo "exit $rc"; cat err.txt; return 1; }
    [ "$t" -le 35 ] || { echo "a 25 s budget took $t s"; return 1; }
    n=0
    for f in "$rep"/* "$rep"/.[!.]*; do
        [ -e "$f" ] || continue
        n=$((n + 1))
        case "$(basename "$f")" in *[!A-Za-z0-9._-]*) echo "bad file name: $f"; return 1 ;; esac
        [ -f "$f" ] || { echo "not a plain file: $f"; return 1; }
    done
    if [ "$n" -lt 7 ] || [ "$n" -gt 8 ]; then echo "$n files in the report"; ls -la "$rep"; return 1; fi
    head -n 1 "$rep/summary.txt" | grep -q "^GL device: .*llvmpipe" || { head -3 "$rep/summary.txt"; return 1; }
    sed -n 2p "$rep/summary.txt" | grep -q "NOT a GPU run" || { head -3 "$rep/summary.txt"; return 1; }
    grep -q "SKIPPED: the deadline is near" "$rep/summary.txt" || { echo "nothing skipped in 25 s"; cat "$rep/summary.txt"; return 1; }
    for s in info smoke golden capture stages passes full-mp4 fp16 encoders upload; do
        sed -n '/^== steps/,$p' "$rep/summary.txt" | grep -q "^  $s " ||
            { echo "step $s missing from the table"; cat "$rep/summary.txt"; return 1; }
    done
    head -n 1 "$rep/golden.csv" | grep -q "^stage,tick," || { cat "$rep/golden.csv"; return 1; }
}

t_run usage cannot_run deadline_skips_cleanly
t_done
