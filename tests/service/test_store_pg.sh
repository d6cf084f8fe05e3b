#!/bin/sh
# The queue contract (tests/test_svc_store.c) on a real PostgreSQL server:
# starts a throwaway one on loopback (tests/pg.sh), runs the store test's
# pg_ cases against it and requires every one to pass, not skip.
#   RS_BIN=build/ringside sh tests/service/test_store_pg.sh
here=$(cd "$(dirname "$0")/.." && pwd)
: "${RS_BIN:=$(dirname "$here")/build/ringside}"
. "$here/lib.sh"
. "$here/pg.sh"
# killed (a run's time limit): still leave through lib.sh's EXIT cleanup
trap 'exit 143' TERM INT HUP

t_store_contract() {
    bin=$(dirname "$RS_BIN")/tests/test_svc_store
    if [ ! -x "$bin" ]; then
        echo "$bin is missing: make $(basename "$(dirname "$RS_BIN")")/tests/test_svc_store"
        return 1
    fi
    # outside T_TMP: the server runs as postgres, and T_TMP is private to us
    pgdir=$(mktemp -d "${TMPDIR:-/tmp}/ringside-pg-XXXXXX") || return 1
    trap pg_stop EXIT
    trap 'exit 143' TERM INT HUP
    pg_start "$pgdir"
    rc=$?
    [ "$rc" = 77 ] && t_skip_install "PostgreSQL is not installed (tools/deps.sh service installs it)"
    [ "$rc" = 0 ] || return 1
    RINGSIDE_TEST_PG=$PG_URI "$bin" pg_ >out.txt 2>&1
    rc=$?
    cat out.txt
    [ "$rc" = 0 ] || { echo "test_svc_store pg_ cases failed (exit $rc)"; return 1; }
    if grep -q '^skip ' out.txt; then
        echo "pg_ cases skipped although a server was running"
        return 1
    fi
    grep -q '^ok .*/pg_roundtrip ' out.txt || { echo "pg_roundtrip did not run"; return 1; }
    return 0
}

t_run store_contract
t_done
