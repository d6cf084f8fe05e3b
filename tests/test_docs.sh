#!/bin/sh
# The docs against the code: README's command table against `ringside
# --help`, every manual page against the --help it was made from, and every
# usage line against its option list.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)

# the commands `ringside --help` lists (help and version are not jobs)
help_commands() {
    "$RS_BIN" --help | awk '/^commands:/ { on = 1; next } on && /^$/ { exit } on && $1 != "help" && $1 != "version" { print $1 }' |
        sort
}

# the commands README's table shows: "build/ringside CMD ..." lines in "## Commands"
readme_commands() {
    awk '/^## / { on = ($0 == "## Commands") } on && /^build\/ringside [a-z]/ { print $2 }' "${1:-$SRC/README.md}" | sort -u
}

t_readme_lists_every_command() {
    help_commands >h.txt
    readme_commands >r.txt
    [ -s h.txt ] && [ -s r.txt ] || { echo "no commands found"; return 1; }
    comm -23 h.txt r.txt >missing.txt
    comm -13 h.txt r.txt >extra.txt
    [ ! -s missing.txt ] || { echo "README's command table lacks: $(cat missing.txt)"; return 1; }
    [ ! -s extra.txt ] || { echo "README's command table has commands ringside --help does not: $(cat extra.txt)"; return 1; }
    # the check itself: a README without one row, or with a row too many, fails
    grep -v '^build/ringside shaders' "$SRC/README.md" >less.md
    readme_commands less.md | comm -23 h.txt - | grep -qx shaders || { echo "a missing row went unseen"; return 1; }
    sed 's/^build\/ringside shaders/build\/ringside tint/' "$SRC/README.md" >more.md
    readme_commands more.md | comm -13 h.txt - | grep -qx tint || { echo "an unknown row went unseen"; return 1; }
}

# the help a page was made from: ringside.1 <- --help, ringside-bench-capture.1 <- bench capture --help
own_help() {
    case $1 in
    ringside) "$RS_BIN" --help ;;
    *) "$RS_BIN" $(echo "${1#ringside-}" | tr - ' ') --help ;;
    esac
}
# the text a page is made from: its --help, then the top-level exit statuses
# (unless it has its own) and the pages around it (tools/man.sh)
page_help() { cat "$(dirname "$RS_BIN")/man/.text/$1.txt"; }

# words of a --help, as the page says them (SYNOPSIS has no "usage:", a
# section's name is its heading)
help_words() {
    sed -E '1s/^usage: //; s/^(examples|environment|files|exit status|see also)://' | tr -s ' \t' '\n\n' | grep -v '^$'
}

# words of a rendered page below NAME: indented lines only (headings, the
# header and the footer start at column 0), the NAME section left out
page_words() {
    GROFF_NO_SGR=1 MANWIDTH=250 man -l "$1" 2>/dev/null | col -bx |
        awk '/^NAME$/ { skip = 1; next } /^[A-Z]/ { skip = 0; next } !skip && /^ /' | tr -s ' \t' '\n\n' | grep -v '^$'
}

t_man_pages_match_help() {
    command -v man >/dev/null && command -v groff >/dev/null && command -v mandoc >/dev/null ||
        t_skip_install "man, groff or mandoc not installed (make man installs groff-base, man-db and mandoc)"
    make -s -C "$SRC" man BUILD="$(dirname "$RS_BIN")" >make.txt 2>&1 || { cat make.txt; return 1; }
    man=$(dirname "$RS_BIN")/man
    # a page for every command
    for c in $(help_commands); do
        [ -f "$man/ringside-$c.1" ] || { echo "no page ringside-$c.1"; return 1; }
    done
    n=0
    for f in "$man"/ringside*.1; do
        page=$(basename "$f" .1)
        warn=$(groff -man -Tutf8 -ww -z "$f" 2>&1)
        [ -z "$warn" ] || { echo "$page: groff: $warn"; return 1; }
        warn=$(mandoc -Tlint -W warning "$f" 2>&1)
        [ -z "$warn" ] || { echo "$page: mandoc -Tlint: $warn"; return 1; }
        # the page's text is its own --help first, word for word, then what man.sh adds
        own_help "$page" >own.txt
        page_help "$page" >text.txt
        [ "$(head -n "$(wc -l <own.txt)" text.txt)" = "$(cat own.txt)" ] || { echo "$page: not made from its --help"; return 1; }
        grep -q '^exit status:' text.txt && grep -q '^see also:' text.txt || { echo "$page: no exit status or see also"; return 1; }
        help_words <text.txt >help.txt
        page_words "$f" >page.txt
        cmp -s help.txt page.txt || { echo "$page.1 differs from its --help:"; diff help.txt page.txt | head -20; return 1; }
        n=$((n + 1))
    done
    [ "$n" -ge 13 ] || { echo "only $n pages"; return 1; }
    # the check itself: a page that lost a line of its help fails
    grep -v 'GPU downscale: box' "$man/ringside-render.1" >cut.1
    page_words cut.1 >page.txt
    "$RS_BIN" render --help | help_words >help.txt
    ! cmp -s help.txt page.txt || { echo "a line missing from the page went unseen"; return 1; }
    # ringside.conf(5): renders clean and has every setting
    warn=$(groff -man -Tutf8 -ww -z "$man/ringside.conf.5" 2>&1; mandoc -Tlint -W warning "$man/ringside.conf.5" 2>&1)
    [ -z "$warn" ] || { echo "ringside.conf.5: groff or mandoc: $warn"; return 1; }
    GROFF_NO_SGR=1 MANWIDTH=250 man -l "$man/ringside.conf.5" 2>/dev/null | col -bx >conf.txt
    for s in $("$RS_BIN" serve --print-config | sed 's/ = .*//'); do
        grep -Eq "^       $s( |$)" conf.txt || { echo "ringside.conf.5 lacks $s"; return 1; }
    done
}

# options_of: "usage" or "list" options of one help text (stdin), one a line.
# usage: the usage block (to the first blank line) without the lines that
# send to another page ("(see bench capture --help)") and without notes in
# parentheses; list: the first column of the option lines ("  --opt ARG  text")
# and serve's settings table (each is --name, with dashes for underscores)
options_of() {
    awk -v want="$1" '
    # usage: one option a line; list: the spellings of one option line
    # together ("-y --overwrite"), so either on the usage line counts
    function scan(s,    k, w, i, line) {
        gsub(/\([^)]*\)/, " ", s)
        gsub(/[][|=,\/]/, " ", s)
        k = split(s, w, " ")
        line = ""
        for (i = 1; i <= k; i++)
            if (w[i] ~ /^--?[a-zA-Z][a-z0-9-]*$/ && w[i] !~ /^--[A-Z]/) {
                if (want == "usage") print w[i]
                else line = line (line == "" ? "" : " ") w[i]
            }
        if (line != "") print line
    }
    NR == 1 { usage = 1 }
    usage && /^$/ { usage = 0; next }
    usage && /--SETTING/ { any_setting = 1 }
    usage { if (want == "usage" && $0 !~ /--help\)/) scan($0); next }
    /^Settings/ { settings = 1; next }
    settings && /^$/ { settings = 0 }
    # "[--SETTING VALUE ...]" on the usage line stands for all of them
    settings { if (want == "list" || any_setting) { s = $1; gsub(/_/, "-", s); print "--" s }; next }
    want == "list" && /^  ?  ?-/ { s = $0; sub(/^ +/, "", s); sub(/  .*/, "", s); scan(s) }' | sort -u
}

check_usage() { # CMD...: prints what differs; fails then
    "$RS_BIN" "$@" --help >h.txt || return 1
    options_of usage <h.txt >u.txt
    options_of list <h.txt >l.txt
    [ -s l.txt ] || return 0 # no options at all (replay info has none of its own)
    drift=0
    tr ' ' '\n' <l.txt | sort -u >lw.txt
    for o in $(comm -23 u.txt lw.txt); do echo "ringside $*: $o is on the usage line but not in the option list"; drift=1; done
    while read -r spellings; do
        found=0
        for o in $spellings; do grep -qx -- "$o" u.txt && found=1; done
        [ "$found" = 1 ] || { echo "ringside $*: $spellings is in the option list but not on the usage line"; drift=1; }
    done <l.txt
    return $drift
}

t_usage_lines_match_option_lists() {
    bad=0
    for c in $(help_commands); do
        check_usage "$c" || bad=1
    done
    for c in "bench capture" "bench accuracy" "bench upload" "bench encode" "bench audio" "bench quality" "replay sound" "replay events" "serve token"; do
        check_usage $c || bad=1
    done
    [ "$bad" = 0 ] || return 1
    # the check itself, both ways
    printf 'usage: x [--alpha N] [-o OUT]\n\n  -o OUT     out\n  --beta     b\n' >fake.txt
    options_of usage <fake.txt | grep -qx -- --alpha && ! options_of list <fake.txt | grep -qx -- --alpha &&
        options_of list <fake.txt | grep -qx -- --beta && ! options_of usage <fake.txt | grep -qx -- --beta ||
        { echo "options_of does not tell usage from list"; return 1; }
}

t_run readme_lists_every_command man_pages_match_help usage_lines_match_option_lists
t_done
