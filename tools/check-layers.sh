#!/bin/sh
# Fails when a lower layer includes a higher one (docs/architecture.md,
# "Layers").  Every `#include "..."` of every C/C++ source outside tests/ is
# resolved against its file's folder and checked against the table below.
#
#   tools/check-layers.sh [ROOT]     (make check-layers; make test runs it)
#
# Three kinds of rule:
#   1. a folder may include only the folders its row names (and itself);
#   2. a private header (*_local.h) only from its own folder, or from the
#      folders named for it in LOCAL_OK;
#   3. the render core (runtime/render) names no stage effect: nothing in it
#      includes runtime/fx/ (effects reach the core through the r_fx.h table).
# Prints one line per violation, "file:line: includes X (rule)", and exits 1.
set -eu
root=${1:-.}
cd "$root"

# folder            what it may include besides itself (lowest layer first)
rules='
runtime/util
runtime/gl          runtime/util
runtime/game        runtime/util
runtime/platform    runtime/util runtime/gl
runtime/replay      runtime/util runtime/game
runtime/audio       runtime/util runtime/game runtime/replay
runtime             runtime/util runtime/gl runtime/platform runtime/game runtime/replay runtime/audio
runtime/render      runtime/util runtime/gl runtime/platform runtime/game runtime/replay
runtime/fx          runtime/util runtime/gl runtime/platform runtime/game runtime/replay runtime/render
capture             runtime/util runtime/gl runtime/platform runtime/game runtime/replay runtime/render runtime/audio
player              runtime/util runtime/gl runtime/platform runtime/game runtime/replay runtime/render runtime/audio
service             runtime/util runtime/gl runtime/platform runtime/game runtime/replay runtime/render capture runtime/audio
cmd                 runtime runtime/util runtime/gl runtime/platform runtime/game runtime/replay runtime/render runtime/fx capture player service runtime/audio
'
# private header            folders besides its own that may include it (none
# today: the effects see the render core through r_fx_core.h, not r_local.h)
LOCAL_OK='
'

if git rev-parse --show-toplevel >/dev/null 2>&1 && [ "$(git rev-parse --show-toplevel)" = "$(pwd -P)" ]; then
    files=$(git ls-files -co --exclude-standard '*.c' '*.h' '*.cpp' | grep -v '^tests/' || true)
else # a copy without git (tests/test_layers.sh plants violations in one)
    files=$(find . -path ./tests -prune -o -path './build*' -prune -o -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' \) -print |
        sed 's@^\./@@' | sort)
fi
[ -n "$files" ] || { echo "check-layers: no sources found under $(pwd)" >&2; exit 2; }

# file:line:folder-of-file:included-path, the included path resolved and
# normalised (no "..", no ".")
edges=$(for f in $files; do
    awk -v f="$f" '
        match($0, /^[ \t]*#[ \t]*include[ \t]*"[^"]+"/) {
            s = substr($0, RSTART, RLENGTH); sub(/^[^"]*"/, "", s); sub(/"$/, "", s)
            d = f; sub(/\/[^\/]*$/, "", d); if (d == f) d = "."
            n = split(d "/" s, p, "/"); k = 0
            for (i = 1; i <= n; i++) {
                if (p[i] == "." || p[i] == "") continue
                if (p[i] == "..") { if (k > 0) k--; continue }
                q[++k] = p[i]
            }
            out = q[1]; for (i = 2; i <= k; i++) out = out "/" q[i]
            print f ":" FNR ":" d ":" out
        }' "$f"
done)

bad=0
report() { echo "$1"; bad=$((bad + 1)); }

allowed_for() { # folder -> its row's allowed folders, or "?" when it has no row
    printf '%s\n' "$rules" | awk -v d="$1" '$1 == d { $1 = ""; print; found = 1 } END { if (!found) print "?" }'
}

IFS_SAVE=$IFS
for e in $edges; do
    IFS=:
    set -- $e
    IFS=$IFS_SAVE
    file=$1 line=$2 from=$3 inc=$4
    to=$(dirname "$inc")
    [ -f "$inc" ] || continue # a system header found through -I, or generated
    case "$inc" in
    */*_local.h)
        if [ "$to" != "$from" ]; then
            ok=$(printf '%s\n' "$LOCAL_OK" | awk -v h="$inc" -v d="$from" '$1 == h { for (i = 2; i <= NF; i++) if ($i == d) print "y" }')
            [ -n "$ok" ] || report "$file:$line: includes $inc (a private header of $to)"
        fi
        ;;
    esac
    [ "$to" = "$from" ] && continue
    if [ "$from" = runtime/render ] && [ "$to" = runtime/fx ]; then
        report "$file:$line: includes $inc (the render core names no effect; effects plug in through r_fx.h)"
        continue
    fi
    allow=$(allowed_for "$from")
    if [ "$allow" = "?" ]; then
        report "$file:$line: $from has no row in tools/check-layers.sh (add one: which layers may it include?)"
        continue
    fi
    case " $allow " in
    *" $to "*) ;;
    *) report "$file:$line: includes $inc ($from may include only:${allow:- nothing outside itself})" ;;
    esac
done

if [ $bad -gt 0 ]; then
    echo "check-layers: $bad include(s) break the layering (docs/architecture.md, Layers)" >&2
    exit 1
fi
echo "check-layers: $(printf '%s\n' "$edges" | grep -c .) includes in $(printf '%s\n' $files | grep -c .) files follow the layers"
