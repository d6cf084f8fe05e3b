# The skipped cases of a test run, one line per reason:
#   awk -v prefix=':::   test ' -f tests/skips.awk LOG...
# reads the verdict lines "skip SUITE/CASE (KIND: WHY) (N s)" (tests/lib.sh,
# tests/t.c) and prints "PREFIX SUITE/CASE[ and N more]: KIND: WHY" in the
# order the reasons first appeared.  Prints nothing when nothing skipped.
/^skip / {
    r = $0
    sub(/^skip [^ ]* \(/, "", r)
    sub(/\) \([0-9.]+ s\)$/, "", r)
    if (!(r in cnt)) { order[k++] = r; first[r] = $2 }
    cnt[r]++
}
END {
    for (i = 0; i < k; i++) {
        r = order[i]
        printf "%s%s%s: %s\n", prefix, first[r], (cnt[r] > 1 ? " and " (cnt[r] - 1) " more" : ""), r
    }
}
