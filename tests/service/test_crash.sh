#!/bin/sh
# Crash bookkeeping (issue 21, item 6): daemons killed with SIGKILL at
# random moments charge no attempt and leave no file behind; a render that
# always fails still ends in the dead letter; retention and DELETE remove
# finished jobs' files.
. "$(dirname "$0")/../lib.sh"
. "$(dirname "$0")/svc_lib.sh"

# the hidden, partial and work files left in data directory D: one a line
crash_leftovers() { # D
    { ls -A "$1/work" 2>/dev/null | sed "s|^|$1/work/|"; ls -A "$1/videos" | grep '^\.' | sed "s|^|$1/videos/|"
      find "$1" -name '*.part'; } | sort -u
}

# Starts a daemon on d, lets it run for a while, SIGKILLs it; KILLS times,
# the moments drawn from awk's generator with SEED (the same run each time)
crash_kill_run() { # KILLS SEED [serve options...]
    kills=$1 seed=$2
    shift 2
    for delay in $(awk -v n="$kills" -v s="$seed" 'BEGIN { srand(s); for (i = 0; i < n; i++) printf "%.1f ", 1 + 4 * rand() }'); do
        svc_start d $SVC_FAST "$@" || return 1
        sleep "$delay"
        kill -KILL "$SVC_PID"
        wait "$SVC_PID" 2>/dev/null
        echo "killed the daemon after $delay s"
    done
}

t_random_kills_charge_nothing_and_leave_nothing() {
    svc_replays r 8 3 || return 1
    svc_start d $SVC_FAST --workers 2 || return 1
    ids=""
    for k in 1 2 3 4 5 6 7 8; do ids="$ids $(svc_submit r/r$k.rsr)" || return 1; done
    svc_stop
    crash_kill_run 4 21 --workers 2 --max-attempts 1 || return 1
    svc_start d $SVC_FAST --workers 2 --max-attempts 1 || return 1
    bad=0
    for id in $ids; do
        svc_wait_state "$id" done 120 || bad=1
        a=$(svc_field "$id" attempts)
        [ "$a" = 1 ] || { echo "job $id: attempts $a, want 1 (a daemon crash charged it)"; bad=1; }
    done
    grep "re-queued\|lost its daemon" d.log
    left=$(crash_leftovers d)
    [ -z "$left" ] || { echo "leftover files after the last restart:"; echo "$left"; bad=1; }
    svc_stop
    [ -z "$(crash_leftovers d)" ] || { echo "leftovers after the drain:"; crash_leftovers d; bad=1; }
    return $bad
}

t_run ${T_ONLY:-random_kills_charge_nothing_and_leave_nothing}
t_done
