#!/bin/sh
# End-to-end: the real build/ringside binary, as a user runs it.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)

t_help() {
    "$RS_BIN" --help >h.txt || return 1
    for w in info smoke shaders bench RINGSIDE_DATA "exit status"; do
        grep -q "$w" h.txt || { echo "--help lacks $w"; return 1; }
    done
    for c in info smoke shaders; do
        "$RS_BIN" $c --help | grep -q "usage: ringside $c" || { echo "$c --help"; return 1; }
    done
    "$RS_BIN" help smoke | grep -q "usage: ringside smoke" || return 1
    "$RS_BIN" --version | grep -Eq '^ringside [0-9]+\.[0-9]+\.[0-9]+$' || return 1
}

t_usage_errors() {
    expect_fail 2 "unknown command 'frobnicate'" "$RS_BIN" frobnicate || return 1
    expect_fail 2 "see 'ringside info --help'" "$RS_BIN" info --bogus || return 1
    expect_fail 2 "expected WIDTHxHEIGHT" "$RS_BIN" smoke --size 12by9 || return 1
    expect_fail 2 "at least 16" "$RS_BIN" smoke --size 8x8 -o x.png || return 1
    expect_fail 2 "unknown image extension" "$RS_BIN" smoke -o x.jpg || return 1
    expect_fail 2 "unknown backend 'dx12'" "$RS_BIN" info --backend dx12 || return 1
    expect_fail 2 "unexpected argument 'extra'" "$RS_BIN" shaders extra || return 1
    expect_fail 2 "unknown image extension" "$RS_BIN" smoke -o x.pgm || return 1
    [ ! -e x.png ] || { echo "x.png written on a usage error"; return 1; }
}

info_reports_core() { # backend [wrapper command...]
    b=$1
    shift
    "$@" "$RS_BIN" info --backend "$b" >i.txt 2>e.txt || { cat e.txt; return 1; }
    grep -q "^backend *$b " i.txt || { echo "backend line"; cat i.txt; return 1; }
    ver=$(sed -n 's/^context *\([0-9]*\)\.\([0-9]*\) core.*/\1\2/p' i.txt)
    [ -n "$ver" ] && [ "$ver" -ge 33 ] || { echo "not a core >= 3.3 context"; cat i.txt; return 1; }
    for k in vendor renderer version glsl "max texture" "float targets" fences "timer queries" "buffer storage"; do
        grep -q "^$k " i.txt || { echo "info lacks '$k'"; return 1; }
    done
}

# headless backends need no display at all
t_info_egl() { info_reports_core egl env -u DISPLAY -u WAYLAND_DISPLAY; }
t_info_osmesa() { info_reports_core osmesa env -u DISPLAY -u WAYLAND_DISPLAY; }

t_info_glfw_xvfb() {
    if [ -n "${DISPLAY:-}" ]; then info_reports_core glfw; return; fi
    command -v xvfb-run >/dev/null || t_skip_install "no DISPLAY and xvfb-run not installed"
    info_reports_core glfw xvfb-run -a
}

t_info_glfw_no_display() {
    env -u DISPLAY -u WAYLAND_DISPLAY "$RS_BIN" info --backend glfw >out.txt 2>err.txt
    rc=$?
    [ $rc = 1 ] || { echo "exit $rc, want 1"; return 1; }
    [ "$(wc -l <err.txt)" = 1 ] || { echo "want one line:"; cat err.txt; return 1; }
    grep -q "glfw: cannot open a window" err.txt || { cat err.txt; return 1; }
}

t_info_falls_back() {
    __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent __EGL_VENDOR_LIBRARY_DIRS=/nonexistent \
        "$RS_BIN" info >i.txt 2>e.txt || { cat e.txt; return 1; }
    grep -q "^backend *osmesa" i.txt || { echo "did not fall back"; cat i.txt; return 1; }
    grep -q "egl unavailable, using osmesa" e.txt || { echo "no note on stderr"; return 1; }
}

t_smoke_both_backends() {
    mkdir egl && "$RS_BIN" smoke --backend egl -o egl/a.png 2>e.txt || { cat e.txt; return 1; }
    "$RS_BIN" smoke --backend osmesa -o b.png 2>>e.txt || { cat e.txt; return 1; }
    grep -q "matches the reference exactly" e.txt || return 1
    cmp egl/a.png b.png || { echo "egl and osmesa pictures differ"; return 1; }
    [ "$(head -c 8 b.png | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || { echo "not a PNG"; return 1; }
    [ ! -e b.png.part ] || return 1
}

# a copy of the data dir with one shader changed
data_copy() { mkdir -p data && cp -r "$SRC/shaders" data/ && export RINGSIDE_DATA=$PWD/data; }

t_broken_shader_names_file_line() {
    data_copy
    printf '#version 330 core\nout vec4 c;\nvoid main() {\n    c = vec4(1.0) +;\n}\n' >data/shaders/smoke.frag
    expect_fail 1 "shaders/smoke.frag:4: " "$RS_BIN" smoke -o s.png || return 1
    [ "$(wc -l <err.txt)" = 1 ] || { echo "want one line:"; cat err.txt; return 1; }
    [ ! -e s.png ] && [ ! -e s.png.part ] || { echo "output left behind"; return 1; }
    "$RS_BIN" shaders >sh.txt 2>&1
    [ $? = 1 ] || { echo "shaders: want exit 1"; cat sh.txt; return 1; }
    grep -q "shaders/smoke.frag:4: error" sh.txt || { cat sh.txt; return 1; }
    grep -q "^ok .*smoke.vert" sh.txt || { cat sh.txt; return 1; }
}

t_shader_variants_all_compile() {
    "$RS_BIN" shaders >sh.txt 2>&1 || { cat sh.txt; return 1; }
    grep -q "^ok .*tonemap.frag \[GLOW+AA\]" sh.txt || { cat sh.txt; return 1; }
    grep -q "^ok .*blur.frag \[REACH=4+RGBE+GLOW+LEVEL2+FLARE\]" sh.txt || { cat sh.txt; return 1; }
    grep -q "compiles, 0 failed" sh.txt || { cat sh.txt; return 1; }
    # an error only the SILHOUETTE variant sees is still found
    data_copy
    sed 's/^#ifdef SILHOUETTE$/#ifdef SILHOUETTE\nint broken = ;/' "$SRC/shaders/light_depth.frag" >data/shaders/light_depth.frag
    grep -q "int broken" data/shaders/light_depth.frag || { echo "sed did not apply"; return 1; }
    "$RS_BIN" shaders >sh.txt 2>&1
    [ $? = 1 ] || { echo "shaders: want exit 1"; cat sh.txt; return 1; }
    grep -q "^ok .*light_depth.frag \[-\]" sh.txt || { cat sh.txt; return 1; }
    grep -q "^FAILED .*light_depth.frag \[SILHOUETTE\]" sh.txt || { cat sh.txt; return 1; }
    grep -q "shaders/light_depth.frag:[0-9]*: error" sh.txt || { cat sh.txt; return 1; }
}

# every variant as the Khronos reference compiler sees it: GLSL that llvmpipe
# tolerates and a stricter driver (NVIDIA's) would refuse fails here first
t_shaders_valid_for_glslang() {
    command -v glslangValidator >/dev/null 2>&1 || t_skip_install "glslangValidator not installed (glslang-tools; tools/deps.sh test)"
    mkdir emit
    "$RS_BIN" shaders --emit emit --quiet >sh.txt 2>&1 || { cat sh.txt; return 1; }
    grep -q "variants written to emit, 0 failed" sh.txt || { cat sh.txt; return 1; }
    n=0
    for f in emit/*; do
        glslangValidator "$f" >v.txt 2>&1 || { echo "$f:"; cat v.txt; return 1; }
        n=$((n + 1))
    done
    [ "$n" -ge 70 ] || { echo "only $n variants written"; ls emit; return 1; }
    # and an error in one variant only is found there
    data_copy
    sed 's/^#ifdef SILHOUETTE$/#ifdef SILHOUETTE\nint broken = ;/' "$SRC/shaders/light_depth.frag" >data/shaders/light_depth.frag
    rm -rf emit && mkdir emit
    "$RS_BIN" shaders --emit emit --quiet >sh.txt 2>&1 || { cat sh.txt; return 1; }
    glslangValidator emit/light_depth.default.frag >v.txt 2>&1 || { cat v.txt; return 1; }
    ! glslangValidator emit/light_depth.SILHOUETTE.frag >v.txt 2>&1 || { echo "the broken variant passed"; return 1; }
}

t_wrong_picture_is_caught() {
    data_copy
    sed 's/o_color = u_color;/o_color = u_color.bgra;/' "$SRC/shaders/smoke.frag" >data/shaders/smoke.frag
    expect_fail 1 "w.png: not written: .* pixels differ from the reference" "$RS_BIN" smoke --size 64x48 -o w.png || return 1
    [ ! -e w.png ] && [ ! -e w.png.part ] || { echo "a wrong picture was written"; return 1; }
}

t_missing_data_dir() {
    expect_fail 1 "RINGSIDE_DATA=/nonexistent: no shaders/" env RINGSIDE_DATA=/nonexistent "$RS_BIN" smoke -o x.png
}

t_bench_platform() {
    "$RS_BIN" bench platform --size 64x64 --frames 3 --runs 2 --csv b.csv >b.txt 2>&1 || { cat b.txt; return 1; }
    grep -q "^egl " b.txt && grep -q "^osmesa " b.txt && grep -q "^ratio osmesa/egl" b.txt || { cat b.txt; return 1; }
    [ "$(wc -l <b.csv)" = 3 ] || { cat b.csv; return 1; }
    expect_fail 2 "unknown benchmark 'gpu'" "$RS_BIN" bench gpu || return 1
}

# OpenImageIO is a plugin (runtime/util/rs_oiio.h): its ~260 libraries are
# not loaded until an image file is read or written; without the plugin an
# image sequence is refused before its first frame, saying where to put it,
# and a video still renders
t_oiio_loaded_when_used() {
    [ -f "$(dirname "$RS_BIN")/ringside-oiio.so" ] || t_skip_install "this build has no OpenImageIO plugin"
    if ldd "$RS_BIN" | grep OpenImageIO; then echo "ringside links OpenImageIO"; return 1; fi
    LD_DEBUG=files "$RS_BIN" render --help >/dev/null 2>ld.txt || return 1
    if grep -m1 "file=libOpenImageIO" ld.txt; then echo "render --help loaded OpenImageIO"; return 1; fi
    r="$SRC/demos/dojo.rsr --ticks 0:2 --size 64x36 --render-size 64x36 --quiet"
    # shellcheck disable=SC2086
    LD_DEBUG=files "$RS_BIN" render $r -o "f%02d.png" 2>ld.txt || { grep -v "^ *[0-9]*:" ld.txt; return 1; }
    [ -s f00.png ] && [ -s f01.png ] || { echo "no frames"; return 1; }
    grep -q "file=libOpenImageIO" ld.txt || { echo "an image sequence without OpenImageIO loaded?"; return 1; }
    # shellcheck disable=SC2086
    RINGSIDE_OIIO_PLUGIN=$PWD/none.so expect_fail 1 "g%02d.png: OpenImageIO: RINGSIDE_OIIO_PLUGIN=$PWD/none.so: no such file" \
        "$RS_BIN" render $r -o "g%02d.png" || return 1
    if ls g* 2>/dev/null; then echo "frames left"; return 1; fi
    # shellcheck disable=SC2086
    RINGSIDE_OIIO_PLUGIN=$PWD/none.so "$RS_BIN" render $r -o v.y4m || return 1
    # a file that is no plugin of ours
    cp "$RS_BIN" notaplugin.so
    # shellcheck disable=SC2086
    RINGSIDE_OIIO_PLUGIN=$PWD/notaplugin.so expect_fail 1 "OpenImageIO: RINGSIDE_OIIO_PLUGIN=$PWD/notaplugin.so: " \
        "$RS_BIN" render $r -o "h%02d.png" || return 1
}


# `ringside --help` names every subcommand: the words after "ringside CMD" on
# the usage lines of each command with subcommands
t_help_lists_every_subcommand() {
    "$RS_BIN" --help >top.txt || return 1
    for cmd in replay bench; do
        "$RS_BIN" $cmd --help >sub.txt || return 1
        subs=$(sed -n "s/^ *\(usage: \)\{0,1\}ringside $cmd \([a-z]*\).*/\2/p" sub.txt | sort -u)
        [ -n "$subs" ] || { echo "no subcommands read from '$cmd --help'"; return 1; }
        line=$(grep "^  $cmd " top.txt) || { echo "no '$cmd' in ringside --help"; return 1; }
        for w in $subs; do
            printf '%s\n' "$line" | grep -qw "$w" || { echo "ringside --help: '$cmd $w' missing from: $line"; return 1; }
        done
    done
}

# --loglevel, -q and -v: every command takes them anywhere on its line, and
# each level shows what it says and no more (README, "How much a command says")
t_loglevel_on_every_command() {
    "$RS_BIN" --help >top.txt
    for cmd in $(sed -n '/^commands:/,/^$/p' top.txt | awk '/^  [a-z]/ { print $1 }' | grep -v '^help$\|^version$') \
        "bench sim" "bench capture" "bench accuracy" "bench upload" "bench encode" "bench audio" "bench quality" \
        "replay verify" "serve token"; do
        # shellcheck disable=SC2086
        "$RS_BIN" $cmd --loglevel warning --help >h.txt 2>&1 || { echo "$cmd --loglevel warning --help failed"; cat h.txt; return 1; }
        grep -q -- "--loglevel LEVEL" h.txt || { echo "$cmd --help does not list --loglevel"; return 1; }
    done
    grep -q -- "--loglevel LEVEL" top.txt || return 1
    expect_fail 2 "--loglevel 'loud': expected quiet, error, warning, info or debug" \
        "$RS_BIN" render x.rsr -o x.y4m --loglevel loud || return 1
    "$RS_BIN" record --ai --seconds 1 --seed 3 -o m.rsr 2>rec.txt || return 1
    grep -q "ringside record: wrote m.rsr" rec.txt || { cat rec.txt; return 1; }
    "$RS_BIN" record --ai --seconds 1 --seed 3 -o m2.rsr -q 2>rec.txt || return 1
    [ ! -s rec.txt ] || { echo "record -q said:"; cat rec.txt; return 1; }
    r="render m.rsr --size 160x90 --ticks 0:30 -y"
    # shellcheck disable=SC2086
    "$RS_BIN" $r -o a.y4m 2>info.txt || return 1
    grep -q "ringside render: wrote a.y4m" info.txt || { cat info.txt; return 1; }
    ! grep -q "ringside render: GL: " info.txt || { echo "a debug line at info"; return 1; }
    for q in "-q" "--quiet" "--loglevel error" "--loglevel=warning" "--loglevel quiet"; do
        # shellcheck disable=SC2086
        "$RS_BIN" $r -o a.y4m $q 2>q.txt || return 1
        [ ! -s q.txt ] || { echo "render $q said:"; cat q.txt; return 1; }
    done
    # before the command too, and for a split render's segments
    # shellcheck disable=SC2086
    "$RS_BIN" -q $r -o a.mp4 --jobs 2 2>q.txt || return 1
    [ ! -s q.txt ] || { echo "render --jobs 2 -q said:"; cat q.txt; return 1; }
    # shellcheck disable=SC2086
    "$RS_BIN" $r -o a.y4m -v 2>v.txt || return 1
    grep -q "ringside render: GL: .*start-up [0-9.]* s" v.txt || { echo "no debug line with -v"; cat v.txt; return 1; }
    grep -q "ringside render: wrote a.y4m" v.txt || return 1
    # a warning: shown with -q (warning), not at error
    # shellcheck disable=SC2086
    "$RS_BIN" render m.rsr --size 160x90 -y -o a.y4m --ticks 0:9999 -q 2>w.txt || return 1
    grep -q "the replay ends at tick 60" w.txt && ! grep -q "wrote a.y4m" w.txt || { cat w.txt; return 1; }
    # shellcheck disable=SC2086
    "$RS_BIN" render m.rsr --size 160x90 -y -o a.y4m --ticks 0:9999 --loglevel error 2>w.txt || return 1
    [ ! -s w.txt ] || { cat w.txt; return 1; }
    # errors: shown with -q and at error, not with quiet; the status is the same
    "$RS_BIN" render nope.rsr -o a.y4m -q 2>e.txt
    [ $? = 1 ] && grep -q "nope.rsr: cannot open" e.txt || { cat e.txt; return 1; }
    "$RS_BIN" render nope.rsr -o a.y4m --loglevel quiet 2>e.txt
    [ $? = 1 ] && [ ! -s e.txt ] || { echo "quiet said:"; cat e.txt; return 1; }
    "$RS_BIN" replay verify m.rsr -q 2>e.txt && [ ! -s e.txt ] || { cat e.txt; return 1; }
    "$RS_BIN" replay verify m.rsr 2>e.txt && grep -q "m.rsr: ok" e.txt || { cat e.txt; return 1; }
    # after --, -q is the command's: here a replay named -q
    expect_fail 1 "ringside render: -q: cannot open" "$RS_BIN" render -o a.y4m -y -- -q || return 1
}

t_run help_lists_every_subcommand loglevel_on_every_command oiio_loaded_when_used help usage_errors shader_variants_all_compile shaders_valid_for_glslang info_egl info_osmesa info_glfw_xvfb info_glfw_no_display info_falls_back \
    smoke_both_backends broken_shader_names_file_line wrong_picture_is_caught missing_data_dir \
    bench_platform
t_done
