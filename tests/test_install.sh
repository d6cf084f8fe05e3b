#!/bin/sh
# What a system package ships: `make install` to a temporary prefix, file by
# file, the installed binary running from there, `make uninstall` leaving
# nothing; the systemd unit; the bash completion, sourced in bash and asked
# as bash asks it; the example config; serve's default data directory.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
BUILD_DIR=$(dirname "$RS_BIN")

install_to() { # PREFIX [make variables...]
    p=$1
    shift
    make -s -C "$SRC" install BUILD="$BUILD_DIR" PREFIX="$p" "$@" >install.txt 2>&1 || { cat install.txt; return 1; }
}

t_install_and_uninstall() {
    install_to "$PWD/prefix" || return 1
    p=$PWD/prefix
    for f in bin/ringside share/ringside/service/dashboard.html share/ringside/shaders/smoke.frag \
        share/ringside/stages/dojo.stage share/man/man1/ringside.1 share/man/man5/ringside.conf.5 \
        share/bash-completion/completions/ringside lib/systemd/system/ringside.service \
        share/doc/ringside/README.md share/doc/ringside/docs/service.md share/doc/ringside/ringside.conf.example \
        etc/ringside/ringside.conf; do
        [ -s "$p/$f" ] || { echo "not installed: $f"; return 1; }
    done
    [ -x "$p/bin/ringside" ] || { echo "bin/ringside is not executable"; return 1; }
    # the dashboard's live player beside its page, when make web fetched it
    hls=$SRC/service/web/node_modules/hls.js/dist/hls.min.js
    if [ -f "$hls" ]; then
        cmp -s "$hls" "$p/share/ringside/service/hls.min.js" || { echo "not installed: share/ringside/service/hls.min.js"; return 1; }
    fi
    # every demo, shader, stage and doc; a page for every command
    for d in $(cd "$SRC" && echo demos/*.rsr shaders/* stages/*.stage); do
        cmp -s "$SRC/$d" "$p/share/ringside/$d" || { echo "not installed: share/ringside/$d"; return 1; }
    done
    for d in "$SRC"/docs/*.md; do
        [ -f "$p/share/doc/ringside/docs/$(basename "$d")" ] || { echo "not installed: $d"; return 1; }
    done
    for c in $("$RS_BIN" --help | awk '/^commands:/ { on = 1; next } on && /^$/ { exit } on { print $1 }'); do
        case $c in help | version) continue ;; esac
        [ -s "$p/share/man/man1/ringside-$c.1" ] || { echo "no manual page ringside-$c.1"; return 1; }
    done
    # the unit names the installed binary and config, nothing left to fill in
    grep -qx "ExecStart=$p/bin/ringside serve --config $p/etc/ringside/ringside.conf" \
        "$p/lib/systemd/system/ringside.service" || { grep ExecStart "$p/lib/systemd/system/ringside.service"; return 1; }
    ! grep -q "@[A-Z]*@" "$p/lib/systemd/system/ringside.service" || { echo "unit has @...@ left"; return 1; }
    # the installed binary finds its shaders, stages and demos there, and its pages
    env -u RINGSIDE_DATA "$p/bin/ringside" shaders --quiet >o.txt 2>&1 || { cat o.txt; return 1; }
    grep -q "0 failed" o.txt || { cat o.txt; return 1; }
    env -u RINGSIDE_DATA "$p/bin/ringside" smoke --size 32x32 -o i.png 2>/dev/null || return 1
    env -u RINGSIDE_DATA "$p/bin/ringside" render "$p/share/ringside/demos/temple.rsr" --ticks 60:62 \
        --size 64x36 --render-size 128x72 -q -o r.y4m >o.txt 2>&1 || { cat o.txt; return 1; }
    # and OpenImageIO's plugin in lib/ringside (image sequences), when this build has one
    if [ -f "$(dirname "$RS_BIN")/ringside-oiio.so" ]; then
        [ -s "$p/lib/ringside/ringside-oiio.so" ] || { echo "not installed: lib/ringside/ringside-oiio.so"; return 1; }
        mkdir seq && env -u RINGSIDE_OIIO_PLUGIN "$p/bin/ringside" render "$p/share/ringside/demos/temple.rsr" \
            --ticks 60:62 --size 64x36 --render-size 64x36 -q -o seq/f%02d.png >o.txt 2>&1 || { cat o.txt; return 1; }
        [ -s seq/f61.png ] || { echo "no PNG frames from the installed binary:"; ls seq; return 1; } # frames by tick
    fi
    if command -v man >/dev/null; then
        MANPATH="$p/share/man" man -w ringside-render | grep -qx "$p/share/man/man1/ringside-render.1" || return 1
    fi
    # the installed config is the example: the daemon reads it as its defaults
    "$p/bin/ringside" serve --config "$p/etc/ringside/ringside.conf" --print-config >a.txt || return 1
    "$p/bin/ringside" serve --print-config >b.txt || return 1
    cmp -s a.txt b.txt || { diff a.txt b.txt; return 1; }
    # an operator's config survives a second install and the uninstall
    echo "workers = 4" >>"$p/etc/ringside/ringside.conf"
    install_to "$p" || return 1
    grep -qx "workers = 4" "$p/etc/ringside/ringside.conf" || { echo "install overwrote the config"; return 1; }
    make -s -C "$SRC" uninstall PREFIX="$p" >un.txt 2>&1 || { cat un.txt; return 1; }
    grep -q "has settings: left as it is" un.txt || { cat un.txt; return 1; }
    find "$p" -type f >left.txt
    [ "$(cat left.txt)" = "$p/etc/ringside/ringside.conf" ] || { echo "left after uninstall:"; cat left.txt; return 1; }
    # untouched, it goes too
    rm -rf "$p"
    install_to "$p" || return 1
    make -s -C "$SRC" uninstall PREFIX="$p" >un.txt 2>&1 || { cat un.txt; return 1; }
    find "$p" -type f >left.txt
    [ ! -s left.txt ] || { echo "left after uninstall:"; cat left.txt; return 1; }
    # DESTDIR: staged for a package, the paths inside still name PREFIX
    install_to /usr DESTDIR="$PWD/stage" || return 1
    grep -qx "ExecStart=/usr/bin/ringside serve --config /etc/ringside/ringside.conf" \
        stage/usr/lib/systemd/system/ringside.service || { grep ExecStart stage/usr/lib/systemd/system/ringside.service; return 1; }
    [ -s stage/etc/ringside/ringside.conf ] && [ -x stage/usr/bin/ringside ] || { find stage -maxdepth 3; return 1; }
}

t_unit_file() {
    u=$SRC/dist/ringside.service
    # the unit keys the service relies on, and the two that must stay off (why: in the file)
    for k in DynamicUser=yes StateDirectory=ringside KillMode=mixed ProtectSystem=strict ProtectHome=yes \
        PrivateTmp=yes NoNewPrivileges=yes SystemCallFilter=@system-service PrivateDevices=no \
        MemoryDenyWriteExecute=no; do
        grep -qx "$k" "$u" || { echo "unit lacks $k"; return 1; }
    done
    grep -q '^RestrictAddressFamilies=.*AF_INET6' "$u" || { echo "unit lacks RestrictAddressFamilies"; return 1; }
    # stop: the daemon's grace (30 s) + 10 s for a render that ignores SIGTERM
    t=$(sed -n 's/^TimeoutStopSec=//p' "$u")
    [ "${t:-0}" -gt 40 ] || { echo "TimeoutStopSec=$t is not above grace + 10 s"; return 1; }
    command -v systemd-analyze >/dev/null || t_skip_install "keys checked; systemd-analyze not installed (tools/deps.sh test installs systemd)"
    install_to "$PWD/prefix" || return 1
    MANPATH="$PWD/prefix/share/man" systemd-analyze verify "$PWD/prefix/lib/systemd/system/ringside.service" \
        >v.txt 2>&1 || { cat v.txt; return 1; }
    # verify only warns about a key it cannot parse: a warning is a failure here
    [ ! -s v.txt ] || { cat v.txt; return 1; }
}

# complete WORDS...: what the installed completion offers for the last word
complete_words() {
    bash -c '. "$1"; shift; COMP_WORDS=("$@"); COMP_CWORD=$(($# - 1)); _ringside; printf "%s\n" "${COMPREPLY[@]}"' \
        sh "$COMPL" "$@" | sort
}

want() { # WHAT EXPECTED...: COMPREPLY (sorted) is exactly EXPECTED
    what=$1
    shift
    printf '%s\n' "$@" | sort >want.txt
    cmp -s want.txt got.txt || { echo "completing '$what': want $(tr '\n' ' ' <want.txt), got $(tr '\n' ' ' <got.txt)"; return 1; }
}

t_bash_completion() {
    command -v bash >/dev/null || t_skip_install "no bash"
    make -s -C "$SRC" man BUILD="$BUILD_DIR" >m.txt 2>&1 || { cat m.txt; return 1; }
    COMPL=$BUILD_DIR/dist/ringside.bash
    bash -n "$COMPL" || return 1
    complete_words ringside re >got.txt && want "ringside re" record render replay || return 1
    complete_words ringside render demo.rsr --capt >got.txt && want "render --capt" --capture || return 1
    complete_words ringside render demo.rsr --capture "" >got.txt && want "render --capture" async sequential || return 1
    complete_words ringside render x --hdr-format r >got.txt && want "render --hdr-format" r11g11b10f rgba16f || return 1
    complete_words ringside render x --quality "" >got.txt && want "render --quality" draft high reference standard || return 1
    # file names after -o and for the replay; nothing to guess after --size
    touch out.mp4 other.y4m fight.rsr
    complete_words ringside render fight.rsr -o o >got.txt && want "render -o" other.y4m out.mp4 || return 1
    complete_words ringside render f >got.txt && want "render REPLAY" fight.rsr || return 1
    complete_words ringside render x --size "" >got.txt && want "render --size" || return 1
    # subcommands and their own options
    complete_words ringside bench "" >got.txt && want "bench" platform sim capture accuracy upload encode audio quality || return 1
    complete_words ringside bench capture --si >got.txt && want "bench capture --si" --sink --size || return 1
    complete_words ringside bench capture --sink "" >got.txt && want "bench capture --sink" mp4 y4m null || return 1
    complete_words ringside replay v >got.txt && want "replay" verify || return 1
    complete_words ringside replay "" >got.txt && want "replay" info verify sound events || return 1
    complete_words ringside play --mu >got.txt && want "play --mu" --mute || return 1
    # serve: its settings are options; token's own
    complete_words ringside serve --ret >got.txt && want "serve --ret" --retention || return 1
    complete_words ringside serve token add bob --op >got.txt && want "serve token --op" --operator || return 1
    complete_words ringside help ren >got.txt && want "help" render || return 1
}

t_example_config() {
    make -s -C "$SRC" man BUILD="$BUILD_DIR" >m.txt 2>&1 || { cat m.txt; return 1; }
    ex=$BUILD_DIR/dist/ringside.conf.example
    # every setting, commented out, with its default
    "$RS_BIN" serve --print-config >defaults.txt || return 1
    for s in $(sed 's/ = .*//' defaults.txt); do
        grep -Eq "^#$s =" "$ex" || { echo "example lacks $s"; return 1; }
    done
    grep -qx '#workers = 1' "$ex" && grep -qx '#max_upload = 1M' "$ex" || { grep -E '^#(workers|max_upload)' "$ex"; return 1; }
    # uncommented, every line is a valid setting that gives the defaults
    sed 's/^#\([a-z_]* =\)/\1/' "$ex" >all.conf
    "$RS_BIN" serve --config all.conf --print-config >got.txt || return 1
    cmp -s defaults.txt got.txt || { diff defaults.txt got.txt; return 1; }
}

t_serve_data_directory() {
    # systemd's StateDirectory, then XDG, then ~/.local/state; never ./ringside-data
    env STATE_DIRECTORY="$PWD/st" XDG_STATE_HOME="$PWD/xdg" "$RS_BIN" serve --print-config >a.txt || return 1
    grep -qx "data = $PWD/st" a.txt && grep -qx "queue = sqlite:$PWD/st/queue.db" a.txt || { cat a.txt; return 1; }
    env -u STATE_DIRECTORY XDG_STATE_HOME="$PWD/xdg" "$RS_BIN" serve --print-config >b.txt || return 1
    grep -qx "data = $PWD/xdg/ringside" b.txt || { cat b.txt; return 1; }
    env -u STATE_DIRECTORY -u XDG_STATE_HOME HOME="$PWD/home" "$RS_BIN" serve --print-config >c.txt || return 1
    grep -qx "data = $PWD/home/.local/state/ringside" c.txt || { cat c.txt; return 1; }
    expect_fail 2 "data: no default .*give --data DIR" env -u STATE_DIRECTORY -u XDG_STATE_HOME -u HOME \
        "$RS_BIN" serve --print-config || return 1
}

t_run install_and_uninstall unit_file bash_completion example_config serve_data_directory
t_done
