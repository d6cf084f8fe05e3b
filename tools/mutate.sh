#!/usr/bin/env bash
# tools/mutate.sh: the mutation check (docs/testing.md, "Mutation check").
#
# A test suite that passes is worth something only if it fails when the
# code is wrong.  This plants small bugs from a list (tools/mutations.txt:
# a bound off by one, a check removed, a comparison flipped, a wrong
# constant, a lookalike accepted, an error return dropped), one at a time,
# and runs each one's covering tests: the mutation is KILLED when one of
# them fails, SURVIVED when they all pass.
#
# The checkout it is run from is never touched: the tree at HEAD (with
# --worktree, the files as they are now) is copied into a scratch folder
# and built there once; every covering command then runs once unmutated
# (the baseline: it must pass and run at least one case, or a mutation
# could be "killed" by a test that fails anyway, or "survive" a case name
# that matches nothing); then for each mutation the file is edited, make
# rebuilds what the tests need, they run, and the file is put back.
#
#   tools/mutate.sh                    every mutation of the list
#   tools/mutate.sh -m 'rp-|svc-'      only ids matching the extended regex
#   tools/mutate.sh --list             the list, nothing built or run
#
# stdout: one line a mutation (KILLED, SURVIVED or DID NOT BUILD), then
# "N killed, N survived of N".  stderr: progress, as it goes.
# Exit status: 0 every mutation killed; 1 one survived or did not build;
# 2 bad usage, a stale list, a covering test failing or running nothing
# unmutated, or the unmutated tree not building.
#
# The whole script is one { } block, read before it runs: a run takes
# minutes, and a checkout switched or an edit made meanwhile must not
# change it midway (bash reads a script as it goes).
{
set -u
export LC_ALL=C

usage() {
    cat <<'EOF'
usage: tools/mutate.sh [options]

Plants each mutation of the list in a scratch copy of the tree, rebuilds,
runs its covering tests and says whether they caught it (KILLED) or not
(SURVIVED).  The list's format is described at its top.

  -m, --match ERE     only the mutations whose id matches ERE (grep -E)
  -l, --list          print the mutations (id, file, covering tests) and exit
  -k, --keep-going    a mutation that does not build is reported as
                      "DID NOT BUILD" and the run goes on (default: stop),
                      and a covering test that fails unmutated skips its
                      mutations instead of stopping the run
  -f, --file FILE     the list (default: tools/mutations.txt of the tree
                      copied; with --list, of this checkout)
      --worktree      copy the working tree's files (tracked ones as they are
                      now, and untracked ones git does not ignore) instead of
                      HEAD: for trying a new test or mutation before committing
      --no-baseline   skip the unmutated run of the covering tests
      --timeout S     limit for one covering command, in seconds (default
                      900); one that runs out kills its mutation (a hang)
      --keep          leave the scratch folder (tree, build, logs) and say where
  -j N                make's jobs (default 2)
  -h, --help          this text

The scratch folder is made under $TMPDIR (default /tmp).  Everything runs
under nice.  Exit status: 0 all killed, 1 some survived or did not build,
2 usage, a stale list or a broken baseline.
EOF
}

say() { printf '%s\n' "$*" >&2; }
die() { say "mutate: $*"; exit 2; }

match="" list_only=0 keep_going=0 list_file="" worktree=0 baseline=1 timeout_s=900 keep=0 jobs=2
while [ $# -gt 0 ]; do
    case $1 in
    -m | --match) [ $# -ge 2 ] || die "$1 needs a pattern"; match=$2; shift ;;
    --match=*) match=${1#*=} ;;
    -l | --list) list_only=1 ;;
    -k | --keep-going) keep_going=1 ;;
    -f | --file) [ $# -ge 2 ] || die "$1 needs a file"; list_file=$2; shift ;;
    --file=*) list_file=${1#*=} ;;
    --worktree) worktree=1 ;;
    --no-baseline) baseline=0 ;;
    --timeout) [ $# -ge 2 ] || die "$1 needs seconds"; timeout_s=$2; shift ;;
    --timeout=*) timeout_s=${1#*=} ;;
    --keep) keep=1 ;;
    -j) [ $# -ge 2 ] || die "-j needs a number"; jobs=$2; shift ;;
    -j[0-9]*) jobs=${1#-j} ;;
    -h | --help) usage; exit 0 ;;
    *) say "mutate: unknown option '$1'"; usage >&2; exit 2 ;;
    esac
    shift
done
case $timeout_s in '' | *[!0-9]* | 0) die "--timeout '$timeout_s': expected a whole number of seconds" ;; esac
case $jobs in '' | *[!0-9]* | 0) die "-j '$jobs': expected a whole number" ;; esac
if [ -n "$match" ]; then
    echo x | grep -Eq -- "$match" 2>/dev/null
    [ $? -le 1 ] || die "--match '$match': not an extended regular expression"
fi
[ -z "$list_file" ] || [ -f "$list_file" ] || die "--file $list_file: no such file"
[ -z "$list_file" ] || list_file=$(cd "$(dirname "$list_file")" && pwd)/$(basename "$list_file")

root=$(cd "$(dirname "$0")/.." && pwd)
git -C "$root" rev-parse --git-dir >/dev/null 2>&1 || die "$root is not a git checkout"

# --- the list --------------------------------------------------------------
# Parsed into parallel arrays, one entry a mutation; from, to and test may
# take several lines (from and to are joined with newlines, tests run in turn).
ids=() files=() froms=() tos=() tests=() whys=() lines=()

parse_list() { # FILE
    local f=$1 n=0 line key val in_block=0
    local id="" file="" from="" to="" test="" why="" has_from=0 has_to=0 at=0
    end_block() {
        [ "$in_block" = 1 ] || return 0
        local miss=""
        [ -n "$id" ] || miss="$miss id"
        [ -n "$file" ] || miss="$miss file"
        [ "$has_from" = 1 ] || miss="$miss from"
        [ "$has_to" = 1 ] || miss="$miss to"
        [ -n "$test" ] || miss="$miss test"
        # shellcheck disable=SC2016 # the quotes are text, inside double quotes
        [ -z "$miss" ] || die "$f:$at: the mutation${id:+ '$id'} lacks:$miss"
        case $id in *[!A-Za-z0-9_.-]*) die "$f:$at: id '$id': use letters, digits, '.', '_' and '-'" ;; esac
        [ -n "$from" ] || die "$f:$at: '$id': from is empty"
        [ "$from" != "$to" ] || die "$f:$at: '$id': to is the same text as from"
        local k
        for k in "${ids[@]}"; do [ "$k" != "$id" ] || die "$f:$at: id '$id' is used twice"; done
        ids+=("$id") files+=("$file") froms+=("$from") tos+=("$to") tests+=("$test") whys+=("$why") lines+=("$at")
        id="" file="" from="" to="" test="" why="" has_from=0 has_to=0 in_block=0
    }
    while IFS= read -r line || [ -n "$line" ]; do
        n=$((n + 1))
        case $line in
        '#'*) continue ;;
        '') end_block; continue ;;
        esac
        case $line in
        *:*) key=${line%%:*} val=${line#*:} ;;
        *) die "$f:$n: expected 'key: value', got: $line" ;;
        esac
        val=${val# } # one space after the colon is the separator; the rest is literal
        [ "$in_block" = 1 ] || { in_block=1; at=$n; }
        case $key in
        id) id=$val ;;
        file) file=$val ;;
        from) if [ "$has_from" = 1 ]; then from="$from"$'\n'"$val"; else from=$val has_from=1; fi ;;
        to) if [ "$has_to" = 1 ]; then to="$to"$'\n'"$val"; else to=$val has_to=1; fi ;;
        test) test="${test:+$test$'\n'}$val" ;;
        why) why=$val ;;
        *) die "$f:$n: unknown key '$key' (id, file, from, to, test, why)" ;;
        esac
    done <"$f"
    end_block
}

# the indexes of the selected mutations
selected=()
select_mutations() {
    local i
    for i in "${!ids[@]}"; do
        if [ -z "$match" ] || printf '%s\n' "${ids[$i]}" | grep -Eq -- "$match"; then
            selected+=("$i")
        fi
    done
    [ ${#selected[@]} -gt 0 ] || die "no mutation id matches '$match' (tools/mutate.sh --list shows them)"
}

if [ "$list_only" = 1 ]; then
    parse_list "${list_file:-$root/tools/mutations.txt}"
    select_mutations
    for i in "${selected[@]}"; do
        printf '%-28s %s\n' "${ids[$i]}" "${files[$i]}"
        printf '%s\n' "${tests[$i]}" | sed 's/^/    test: /'
    done
    exit 0
fi

# --- the scratch copy -------------------------------------------------------
scratch=$(mktemp -d "${TMPDIR:-/tmp}/ringside-mutate-XXXXXX") || die "cannot make a scratch folder"
# searchable by others: the PostgreSQL cases start a server (as the postgres
# user) in a folder under the scratch's tmp (tests/pg.sh)
chmod 755 "$scratch"
src=$scratch/tree logs=$scratch/logs orig=$scratch/orig
mkdir -p "$src" "$logs" "$orig" "$scratch/cache"
# shellcheck disable=SC2317 # called by the EXIT trap
cleanup() {
    if [ "$keep" = 1 ]; then
        say "mutate: the scratch copy, its build and the logs stay in $scratch"
    else
        rm -rf "$scratch"
    fi
}
trap cleanup EXIT
trap 'say "mutate: interrupted"; [ -z "${cur_sid:-}" ] || end_session "$cur_sid"; exit 130' INT TERM

if [ "$worktree" = 1 ]; then
    what="the working tree of $root"
    (cd "$root" && git ls-files -z -c -o --exclude-standard |
        tar --null --ignore-failed-read -T - -cf - 2>/dev/null) | tar -xf - -C "$src" ||
        die "cannot copy the working tree"
else
    what="HEAD ($(git -C "$root" rev-parse --short HEAD)) of $root"
    git -C "$root" archive HEAD | tar -xf - -C "$src" || die "cannot copy HEAD"
fi
say "mutate: $what copied to $src"
parse_list "${list_file:-$src/tools/mutations.txt}"
select_mutations

# --- stale entries: each original text must be in its file exactly once ------
# count_or_replace MODE FILE: MODE count prints the occurrences of $MUT_FROM
# (taken literally, newlines included); MODE replace writes the file with the
# first one replaced by $MUT_TO to stdout
count_or_replace() {
    awk -v mode="$1" '
        { text = text $0 "\n" }
        END {
            from = ENVIRON["MUT_FROM"]; to = ENVIRON["MUT_TO"]
            n = 0; rest = text; out = ""
            while ((i = index(rest, from)) > 0) {
                n++
                if (n == 1) out = substr(rest, 1, i - 1) to
                else out = out substr(rest, 1, i - 1) from
                rest = substr(rest, i + length(from))
            }
            if (mode == "count") print n
            else printf "%s", out rest
        }' "$2"
}

stale=0
for i in "${selected[@]}"; do
    f=$src/${files[$i]}
    if [ ! -f "$f" ]; then
        say "mutate: ${ids[$i]}: ${files[$i]}: no such file (the list has gone stale)"
        stale=1
        continue
    fi
    n=$(MUT_FROM=${froms[$i]} count_or_replace count "$f")
    if [ "$n" != 1 ]; then
        if [ "$n" = 0 ]; then where="is not in the file"; else where="is there $n times, not once"; fi
        say "mutate: ${ids[$i]}: ${files[$i]}: the original text $where (the list has gone stale):"
        printf '%s\n' "${froms[$i]}" | sed 's/^/    /' >&2
        stale=1
    fi
done
[ "$stale" = 0 ] || die "fix the list (${list_file:-tools/mutations.txt}) before running it"

# --- building -----------------------------------------------------------------
# make targets for a covering command: the binary, and the test programs it names
targets_of() { # CMD...
    local t
    printf '%s\n' build/ringside
    printf '%s\n' "$@" | grep -oE 'build/tests/[A-Za-z0-9_.-]+' | sort -u
    # "tests/run.sh build NAME" runs build/tests/test_NAME* as well
    for t in $(printf '%s\n' "$@" | sed -n 's|.*tests/run\.sh  *build  *\([A-Za-z0-9_]*\).*|\1|p'); do
        (cd "$src" && ls tests/test_"$t"*.c 2>/dev/null) | sed 's|^tests/|build/tests/|; s|\.c$||'
    done
}

build() { # LOG TARGET...
    local log=$1
    shift
    (cd "$src" && nice -n 10 make -j"$jobs" "$@") >"$log" 2>&1
}

all_tests=()
for i in "${selected[@]}"; do all_tests+=("${tests[$i]}"); done
mapfile -t all_targets < <(targets_of "${all_tests[@]}" | sort -u)
say "mutate: building the unmutated tree (make -j$jobs all ${all_targets[*]})"
t0=$(date +%s)
build "$logs/build.log" all "${all_targets[@]}" || { tail -30 "$logs/build.log" >&2; die "the unmutated tree does not build"; }
say "mutate: built in $(($(date +%s) - t0)) s"

# --- running a covering command ----------------------------------------------
# the tests' temporary files go in the scratch folder too, so a test ended
# early leaves nothing behind once it is removed
export RS_BIN=$src/build/ringside RINGSIDE_CACHE=$scratch/cache RS_TEST_OUT=$src/build/test-output TMPDIR=$scratch/tmp
mkdir -p "$RS_TEST_OUT" "$TMPDIR"

# Each command runs in a session of its own: what it leaves behind (a
# daemon, or a nested timeout's process group, which the outer timeout
# cannot reach) is ended with it, by session, when it ends or runs out.
cur_sid=""
run_test() { # CMD LOG: the command's exit status (124/137: ran out of time)
    (cd "$src" && exec setsid nice -n 10 timeout -k 10 "$timeout_s" sh -c "$1") >"$2" 2>&1 &
    cur_sid=$! # not a group leader (no job control here), so setsid keeps the pid
    wait "$cur_sid"
    local rc=$?
    end_session "$cur_sid"
    cur_sid=""
    return "$rc"
}
end_session() { # SID: TERM first, so traps can tidy up, then KILL
    pgrep -s "$1" >/dev/null 2>&1 || return 0
    pkill -TERM -s "$1" 2>/dev/null
    sleep 1
    pkill -KILL -s "$1" 2>/dev/null
}

# cases the summary lines of a log say passed
passed_in() { awk '/^[0-9]+ passed, [0-9]+ failed/ { n += $1 } END { print n + 0 }' "$1"; }
skipped_in() { awk '/^[0-9]+ passed, [0-9]+ failed, [0-9]+ skipped/ { n += $5 } END { print n + 0 }' "$1"; }

broken=() # covering commands that fail (or run nothing) unmutated
if [ "$baseline" = 1 ]; then
    mapfile -t cmds < <(printf '%s\n' "${all_tests[@]}" | awk 'NF && !seen[$0]++')
    say "mutate: baseline: each of the ${#cmds[@]} covering commands on the unmutated build"
    k=0
    for c in "${cmds[@]}"; do
        k=$((k + 1))
        log=$logs/baseline-$k.log
        t0=$(date +%s)
        run_test "$c" "$log"
        rc=$?
        secs=$(($(date +%s) - t0))
        p=$(passed_in "$log") s=$(skipped_in "$log")
        if [ "$rc" != 0 ] || [ "$p" = 0 ]; then
            if [ "$rc" != 0 ]; then why="exit $rc"; else why="no case passed (a case name the suite does not have, or all skipped)"; fi
            say "  FAIL $(printf '%4d' "$secs") s  $c: $why"
            tail -15 "$log" | sed 's/^/      /' >&2
            broken+=("$c")
        else
            note=""
            [ "$s" = 0 ] || note=" ($s cases skipped)"
            say "  ok   $(printf '%4d' "$secs") s  $c$note"
        fi
    done
    if [ ${#broken[@]} -gt 0 ] && [ "$keep_going" = 0 ]; then
        die "${#broken[@]} covering commands fail without any mutation: fix them first (or --keep-going skips their mutations)"
    fi
fi

# --- the mutations --------------------------------------------------------------
killed=0 survived=0 unbuilt=0 skipped=0 total=${#selected[@]} k=0
survivors=()
start=$(date +%s)
for i in "${selected[@]}"; do
    k=$((k + 1))
    id=${ids[$i]} file=${files[$i]}
    mapfile -t cmds < <(printf '%s\n' "${tests[$i]}")
    tag=$(printf '[%2d/%d] %s' "$k" "$total" "$id")
    skip_it=0
    for c in "${cmds[@]}"; do
        for b in "${broken[@]}"; do [ "$c" != "$b" ] || skip_it=1; done
    done
    if [ "$skip_it" = 1 ]; then
        say "$tag: not run: a covering test fails unmutated"
        printf 'NOT RUN        %s  (a covering test fails without the mutation)\n' "$id"
        skipped=$((skipped + 1))
        continue
    fi
    cp "$src/$file" "$orig/$id"
    MUT_FROM=${froms[$i]} MUT_TO=${tos[$i]} count_or_replace replace "$orig/$id" >"$src/$file"
    mapfile -t tg < <(targets_of "${cmds[@]}")
    t0=$(date +%s)
    if ! build "$logs/$id.build.log" "${tg[@]}"; then
        cp "$orig/$id" "$src/$file"
        say "$tag: $file: did not build ($logs/$id.build.log)"
        grep -m 5 -E 'error|Error' "$logs/$id.build.log" | sed 's/^/    /' >&2
        printf 'DID NOT BUILD  %s  (%s)\n' "$id" "$file"
        unbuilt=$((unbuilt + 1))
        [ "$keep_going" = 1 ] || die "$id does not build: fix its replacement (or --keep-going reports it and goes on)"
        continue
    fi
    tb=$(($(date +%s) - t0))
    verdict=SURVIVED by="" t0=$(date +%s)
    n=0
    for c in "${cmds[@]}"; do
        n=$((n + 1))
        run_test "$c" "$logs/$id.test$n.log"
        rc=$?
        if [ "$rc" != 0 ]; then
            verdict=KILLED by=$c
            [ "$rc" = 124 ] || [ "$rc" = 137 ] && by="$c (timed out after $timeout_s s)"
            break
        fi
    done
    tt=$(($(date +%s) - t0))
    # the file as it was; make rebuilds it with the next mutation's build
    cp "$orig/$id" "$src/$file"
    cmp -s "$orig/$id" "$src/$file" || die "$id: could not put $file back"
    say "$tag: $file: built in $tb s, tested in $tt s: $verdict"
    if [ "$verdict" = KILLED ]; then
        killed=$((killed + 1))
        printf 'KILLED         %s  by: %s\n' "$id" "$by"
    else
        survived=$((survived + 1))
        survivors+=("$id")
        printf 'SURVIVED       %s  (%s; tests: %s)\n' "$id" "$file" "$(printf '%s; ' "${cmds[@]}" | sed 's/; $//')"
    fi
done

extra=""
[ "$unbuilt" = 0 ] || extra="$extra, $unbuilt did not build"
[ "$skipped" = 0 ] || extra="$extra, $skipped not run"
say "mutate: $total mutations in $(($(date +%s) - start)) s${survivors[0]+; survived: ${survivors[*]}}"
echo "$killed killed, $survived survived of $total${extra:+ ($extra)}" | sed 's/(, /(/'
[ "$survived" = 0 ] && [ "$unbuilt" = 0 ] && [ "$skipped" = 0 ]
exit
}
