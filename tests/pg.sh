# A throwaway PostgreSQL server on loopback for the service tests.
#   . tests/pg.sh
#   pg_start DIR || exit $?     # 77: PostgreSQL is not installed (a skip)
#   ... "$PG_URI" ...           # postgresql://postgres@127.0.0.1:PORT/ringside
#   pg_psql SQL                 # a statement's rows (unaligned, no header)
#   pg_stop                     # stops the server and removes DIR
# DIR must not exist yet or be empty; the server owns it (as the postgres
# user when we run as root: initdb refuses root).  Trust authentication,
# listening on 127.0.0.1 only, its socket inside DIR: nothing outside this
# machine can reach it, and nothing of the system's own clusters is used.

pg_bindir() {
    # Debian keeps each major version apart; take the newest
    for d in $(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V -r); do
        [ -x "$d/initdb" ] && { echo "$d"; return 0; }
    done
    d=$(command -v initdb 2>/dev/null) && { dirname "$d"; return 0; }
    return 1
}

# PG_LISTEN: the address the server listens on (default 127.0.0.1; any
# other is trusted for its whole subnet: a test's private network).
# PG_WRAP: a command every server and client command runs under ("ip
# netns exec NS": the server inside a test's network namespace).

# pg_as CMD...: CMD as the server's owner, from a directory it can read
pg_as() {
    if [ "$(id -u)" != 0 ]; then
        (cd "$PG_DIR" && ${PG_WRAP:-} "$@")
    elif command -v runuser >/dev/null 2>&1; then
        (cd "$PG_DIR" && ${PG_WRAP:-} runuser -u postgres -- "$@")
    else
        (cd "$PG_DIR" && ${PG_WRAP:-} su postgres -s /bin/sh -c 'exec "$0" "$@"' "$@")
    fi
}

pg_start() {
    PG_URI= PG_PORT=
    if ! PG_BIN=$(pg_bindir); then
        echo "pg.sh: no PostgreSQL server here (initdb not found): run tools/deps.sh service (Debian: postgresql)" >&2
        return 77
    fi
    if [ "$(id -u)" = 0 ] && ! id postgres >/dev/null 2>&1; then
        echo "pg.sh: running as root, and there is no postgres user to run the server as" >&2
        return 77
    fi
    case $1 in
    *[[:space:]]*) echo "pg.sh: '$1': the server's directory may not contain spaces" >&2; return 1 ;;
    esac
    # pg_stop removes the directory: refuse one that holds someone else's files
    if [ -n "$(ls -A "$1" 2>/dev/null)" ]; then
        echo "pg.sh: $1 is not empty" >&2
        return 1
    fi
    PG_DIR=$1
    mkdir -p "$PG_DIR" || return 1
    [ "$(id -u)" = 0 ] && chown postgres "$PG_DIR"
    if ! pg_as test -w "$PG_DIR"; then
        echo "pg.sh: $PG_DIR is not writable by the server's user (a private parent directory?)" >&2
        return 1
    fi
    if ! pg_as "$PG_BIN/initdb" -D "$PG_DIR/data" -U postgres -A trust -E UTF8 --locale=C --no-sync \
        >"$PG_DIR/initdb.log" 2>&1; then
        echo "pg.sh: initdb failed:" >&2
        tail -5 "$PG_DIR/initdb.log" >&2
        return 1
    fi
    pg_host=${PG_LISTEN:-127.0.0.1}
    [ "$pg_host" = 127.0.0.1 ] || echo "host all all samenet trust" >>"$PG_DIR/data/pg_hba.conf"
    # A random port; if another program holds it the server cannot bind
    # and we try the next one (the bind itself is the only reliable check).
    tries=0
    while [ "$tries" -lt 8 ]; do
        tries=$((tries + 1))
        PG_PORT=$((20000 + $(od -An -N2 -tu2 /dev/urandom | tr -d ' ') % 40000))
        if pg_as "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -l "$PG_DIR/server.log" -w -t 60 \
            -o "-h $pg_host -p $PG_PORT -k $PG_DIR -c fsync=off -c full_page_writes=off" start >/dev/null 2>&1; then
            if ${PG_WRAP:-} "$PG_BIN/createdb" -h "$pg_host" -p "$PG_PORT" -U postgres ringside >>"$PG_DIR/server.log" 2>&1; then
                PG_URI="postgresql://postgres@$pg_host:$PG_PORT/ringside"
                export PG_URI PG_PORT PG_DIR
                return 0
            fi
            echo "pg.sh: createdb failed:" >&2
            tail -5 "$PG_DIR/server.log" >&2
            pg_stop
            return 1
        fi
        grep -q 'could not bind\|already in use' "$PG_DIR/server.log" 2>/dev/null || break
    done
    echo "pg.sh: the server did not start:" >&2
    tail -5 "$PG_DIR/server.log" >&2
    return 1
}

# pg_psql SQL: the result's rows, unaligned, no header
pg_psql() {
    ${PG_WRAP:-} psql -X -q -A -t -h "${PG_LISTEN:-127.0.0.1}" -p "$PG_PORT" -U postgres -d ringside -c "$1"
}

pg_stop() {
    [ -n "${PG_DIR:-}" ] || return 0
    if [ -f "$PG_DIR/data/postmaster.pid" ]; then
        # signals, not the network: outside any namespace (which may be gone)
        PG_WRAP= pg_as "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m fast -w -t 30 stop >/dev/null 2>&1 ||
            PG_WRAP= pg_as "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m immediate -w stop >/dev/null 2>&1
    fi
    rm -rf "$PG_DIR"
    PG_DIR= PG_URI=
}
