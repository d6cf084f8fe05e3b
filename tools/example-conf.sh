#!/bin/sh
# Writes the example ringside.conf from the settings table in `ringside
# serve --help` (the table in service/svc_config.c): every setting with its
# help line and its default, commented out, so the file changes nothing
# until a line is uncommented (make install puts it in share/doc/ringside
# and the unit's config path points at where an operator copies it).
#
#   tools/example-conf.sh BIN > ringside.conf.example
set -eu

[ $# = 1 ] || { echo "usage: tools/example-conf.sh BIN" >&2; exit 2; }
bin=$1

cat <<EOF
# ringside serve settings (ringside $("$bin" version | sed 's/^ringside //')): 'name = value' lines, # comments.
# Every setting is here with its default, commented out; uncomment what you
# change.  Options on the command line (--name VALUE) override this file;
# 'ringside serve --config FILE --print-config' prints what is in effect.
# man ringside.conf; docs/service.md.
EOF
"$bin" serve --help | awk '
/^Settings/ { on = 1; next }
on && /^$/ { exit }
on {
    # "  name  default  help": the default has no spaces, "(see text)" aside
    name = $1
    rest = $0
    sub(/^ +[^ ]+ +/, "", rest)
    if (rest ~ /^\(see text\)/) { def = ""; sub(/^\(see text\) +/, "", rest) }
    else { def = rest; sub(/ .*/, "", def); sub(/^[^ ]+ +/, "", rest) }
    # the help, wrapped at 76 columns
    print ""
    n = split(rest, w, " ")
    line = "#"
    for (i = 1; i <= n; i++) {
        if (length(line) + 1 + length(w[i]) > 76) { print line; line = "#" }
        line = line " " w[i]
    }
    print line
    print "#" name " =" (def != "" ? " " def : "")
}'
