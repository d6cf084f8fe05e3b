#!/bin/sh
# make check-layers (tools/check-layers.sh): the tree as it is follows the
# layers, and each kind of violation planted in a copy is caught and named.
. "$(dirname "$0")/lib.sh"
ROOT=$(cd "$(dirname "$0")/.." && pwd)
CHECK=$ROOT/tools/check-layers.sh

t_tree_follows_layers() {
    "$CHECK" "$ROOT"
}

# Copy the sources (no build folders, no tests) into ./src, plant LINE at the
# top of FILE, and expect the check to fail with exactly one line naming
# FILE:1 and WHY.  An included file that does not exist is taken for a
# system header, so a planted include names a real file.
plant() { # FILE LINE WHY
    rm -rf src && mkdir src || return 1
    (cd "$ROOT" && find runtime capture player service cmd -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' \) \
        -exec cp --parents {} "$OLDPWD/src" \;) || return 1
    [ -f "src/$1" ] || { echo "no $1 to plant into"; return 1; }
    { echo "$2"; cat "src/$1"; } >"src/$1.new" && mv "src/$1.new" "src/$1"
    "$CHECK" src >out.txt 2>err.txt
    rc=$?
    [ $rc = 1 ] || { echo "exit $rc, want 1 for '$2' in $1"; cat out.txt err.txt; return 1; }
    grep -q "^$1:1: includes .*$3" out.txt || { echo "no line naming $1:1 and '$3':"; cat out.txt; return 1; }
    [ "$(wc -l <out.txt)" = 1 ] || { echo "more than the planted violation:"; cat out.txt; return 1; }
}

t_engine_includes_capture() { plant runtime/game/g_game.c '#include "../../capture/cap.h"' 'runtime/game may include only'; }
t_engine_includes_cmd() { plant runtime/loop.c '#include "../cmd/cli.h"' 'runtime may include only'; }
t_util_includes_render() { plant runtime/util/rs_err.c '#include "../render/r_graph.h"' 'runtime/util may include only'; }
t_capture_includes_player() { plant capture/cap.c '#include "../player/mv.h"' 'capture may include only'; }
t_service_includes_cmd() { plant service/svc_json.c '#include "../cmd/cli.h"' 'service may include only'; }
t_private_header() { plant cmd/main.c '#include "../runtime/platform/plat_local.h"' 'a private header of runtime/platform'; }
t_effects_see_the_core_contract() { plant runtime/fx/fx_fog.c '#include "../render/r_local.h"' 'a private header of runtime/render'; }
t_core_names_effect() {
    fx=$(cd "$ROOT" && ls runtime/fx/*.h 2>/dev/null | head -1)
    [ -n "$fx" ] || t_skip_env "no runtime/fx/*.h in this tree"
    plant runtime/render/r_graph.c "#include \"../fx/$(basename "$fx")\"" 'the render core names no effect'
}

# tools/check-length.sh: the tree's functions and service files are within
# their sizes, and a long function or a long service file planted in a copy
# is named
LENGTH=$ROOT/tools/check-length.sh
copy_src() {
    rm -rf src && mkdir src || return 1
    (cd "$ROOT" && find runtime capture player service cmd -type f \( -name '*.c' -o -name '*.h' \) \
        -exec cp --parents {} "$OLDPWD/src" \;)
}
t_tree_within_sizes() { "$LENGTH" "$ROOT"; }
t_long_function_named() {
    copy_src || return 1
    { printf 'static int planted(void)\n{\n'; i=0; while [ $i -lt 150 ]; do echo '    ;'; i=$((i + 1)); done; printf '}\n'; } \
        >>src/cmd/cli.c
    "$LENGTH" src >out.txt && { echo "a 152-line function passed"; return 1; }
    grep -q '^cmd/cli.c:[0-9]*: static int planted(void) is 152 lines' out.txt || { cat out.txt; return 1; }
    [ "$(wc -l <out.txt)" = 1 ] || { cat out.txt; return 1; }
}
t_long_service_file_named() {
    copy_src || return 1
    i=0; while [ $i -lt 800 ]; do echo; i=$((i + 1)); done >>src/service/svc_log.c
    "$LENGTH" src >out.txt && { echo "an 840-line service file passed"; return 1; }
    grep -q '^service/svc_log.c: [0-9]* lines' out.txt || { cat out.txt; return 1; }
}

t_run tree_within_sizes long_function_named long_service_file_named tree_follows_layers engine_includes_capture engine_includes_cmd util_includes_render capture_includes_player \
    service_includes_cmd private_header effects_see_the_core_contract core_names_effect
t_done
