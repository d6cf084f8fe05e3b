#!/bin/sh
# Fails when a function or a file of the project's C code outgrows what a
# reader can hold (docs/architecture.md, "Sizes"): a function body over 150
# lines anywhere outside tests/, or a file of service/ over 800 lines.
#
#   tools/check-length.sh [ROOT]     (make check-layers runs it too)
#
# A function is what clang-format's layout makes of it: a line that begins
# with "{" opens a body, the next line that is just "}" closes it, and its
# name is the line before the "{".  Prints one line per violation,
# "file:line: NAME is N lines (at most 150)", and exits 1.
set -eu
root=${1:-.}
cd "$root"
files=$(find runtime capture player service cmd -name '*.c' 2>/dev/null | sort)
[ -n "$files" ] || { echo "check-length: no C files under $root" >&2; exit 2; }
# shellcheck disable=SC2086
out=$(awk -v max=150 '
    FNR == 1 { start = 0 }
    /^\{/ { start = FNR; name = prev }
    /^\}/ && start { n = FNR - start + 1; if (n > max) printf "%s:%d: %s is %d lines (at most %d)\n", FILENAME, start, name, n, max; start = 0 }
    !/^[{}]/ { prev = $0 }
' $files
for f in service/*.c; do
    n=$(wc -l <"$f")
    [ "$n" -le 800 ] || echo "$f: $n lines (a file of service/ has at most 800)"
done)
if [ -n "$out" ]; then
    printf '%s\n' "$out"
    exit 1
fi
echo "check-length: $(echo "$files" | wc -l) files, no function over 150 lines, no service file over 800"
