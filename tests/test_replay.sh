#!/bin/sh
# End-to-end: record / replay info / replay verify through the real binary,
# determinism across runs and across -O0 / -O2 builds, bad replay files.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
BIN_DIR=$(dirname "$RS_BIN")

t_record_is_reproducible() {
    "$RS_BIN" record --ai --quiet --seed 77 --stage temple -o a.rsr 2>/dev/null || return 1
    "$RS_BIN" record --ai --quiet --seed 77 --stage temple -o b.rsr 2>/dev/null || return 1
    cmp a.rsr b.rsr || { echo "two recordings with the same seed differ"; return 1; }
    "$RS_BIN" record --ai --quiet --seed 78 --stage temple -o c.rsr 2>/dev/null || return 1
    ! cmp -s a.rsr c.rsr || { echo "different seeds, same file"; return 1; }
}

t_demos_are_current() {
    # the bundled demos are exactly what 'make demo-replays' makes now
    for d in dojo:1 harbor:7 temple:23 shallows:31 snowfield:37 mistvale:41 plaza:43 quarry:47; do
        stage=${d%%:*} seed=${d##*:}
        "$RS_BIN" record --ai --quiet --stage "$stage" --seed "$seed" -o "$stage.rsr" 2>/dev/null || return 1
        cmp "$stage.rsr" "$SRC/demos/$stage.rsr" ||
            { echo "demos/$stage.rsr is stale: run 'make demo-replays' and commit"; return 1; }
        "$RS_BIN" replay verify --progress off "$SRC/demos/$stage.rsr" 2>v.txt || { cat v.txt; return 1; }
        grep -q "ok: .* checkpoints and the final hash match" v.txt || { cat v.txt; return 1; }
    done
}

t_info() {
    "$RS_BIN" record --ai --quiet --seed 3 --stage harbor -o m.rsr 2>/dev/null || return 1
    "$RS_BIN" replay info m.rsr >i.txt || return 1
    for k in "stage        1 (harbor)" "seed         3" "players      P1 cpu, P2 cpu" "format       version 3" \
        "game         version 1 (this build: 1)" \
        "every 60 ticks"; do
        grep -q "$k" i.txt || { echo "info lacks '$k'"; cat i.txt; return 1; }
    done
    grep -Eq "^winner       (P[12]|draw), rounds [0-9]-[0-9]" i.txt || { cat i.txt; return 1; }
    grep -Eq "^duration     [0-9]+ ticks, [0-9]+:[0-9]{2}\.[0-9]{2}" i.txt || { cat i.txt; return 1; }
}

t_seconds_exact() {
    "$RS_BIN" record --ai --quiet --seconds 200 --seed 4 -o s.rsr 2>/dev/null || return 1
    "$RS_BIN" replay info s.rsr | grep -q "^duration     12000 ticks, 3:20.00" || return 1
    [ "$(wc -c <s.rsr)" -lt 16384 ] || { echo "more than 16 KiB for 200 s"; return 1; }
}

t_hashes_same_at_O0_O2_and_in_ringside() {
    for o in O0 O2; do
        [ -x "$BIN_DIR/tests/simhash-$o" ] || { echo "missing $BIN_DIR/tests/simhash-$o"; return 1; }
    done
    for d in dojo harbor temple shallows snowfield mistvale plaza quarry; do
        "$BIN_DIR/tests/simhash-O0" "$SRC/demos/$d.rsr" >o0.txt || { echo "O0 build fails $d"; return 1; }
        "$BIN_DIR/tests/simhash-O2" "$SRC/demos/$d.rsr" >o2.txt || { echo "O2 build fails $d"; return 1; }
        "$RS_BIN" replay verify --quiet -y --hashes r.txt "$SRC/demos/$d.rsr" 2>/dev/null || return 1
        cmp o0.txt o2.txt || { echo "$d: -O0 and -O2 hashes differ"; return 1; }
        cmp o0.txt r.txt || { echo "$d: ringside and simhash hashes differ"; return 1; }
        ticks=$("$RS_BIN" replay info "$SRC/demos/$d.rsr" | sed -n 's/^duration *\([0-9]*\) ticks.*/\1/p')
        [ "$(wc -l <r.txt)" = "$ticks" ] || { echo "$d: want one hash per tick"; return 1; }
    done
}

t_hashes_same_with_clang() {
    [ -x "$BIN_DIR/tests/simhash-clang" ] || t_skip_install "no $BIN_DIR/tests/simhash-clang: clang not installed (tools/deps.sh test installs it)"
    for d in dojo harbor temple shallows snowfield mistvale plaza quarry; do
        "$BIN_DIR/tests/simhash-clang" "$SRC/demos/$d.rsr" >c.txt || { echo "clang build fails $d"; return 1; }
        "$BIN_DIR/tests/simhash-O2" "$SRC/demos/$d.rsr" >g.txt || return 1
        cmp c.txt g.txt || { echo "$d: clang and gcc hashes differ"; return 1; }
    done
}

t_header_tampering_is_reported() {
    # a replay whose inputs verify but whose header claims another winner
    "$BIN_DIR/tests/simhash-O2" --winner 0 "$SRC/demos/dojo.rsr" lie.rsr || return 1
    expect_fail 1 "lie.rsr: the header says winner 0.*but the simulation gives winner" \
        "$RS_BIN" replay verify --quiet lie.rsr || return 1
    # a CPU player relabelled human (byte 30), the CRC made right again:
    # format 3's hashes carry the kinds, so verify, a render and an upload
    # all refuse it and say what was done
    python3 -c "
import sys, zlib
b = bytearray(open(sys.argv[1], 'rb').read())
b[30] = 0
b[-4:] = zlib.crc32(bytes(b[:-4])).to_bytes(4, 'little')
open(sys.argv[2], 'wb').write(bytes(b))" "$SRC/demos/dojo.rsr" human.rsr || return 1
    "$RS_BIN" replay info human.rsr | grep -q "P1 human, P2 cpu" || return 1
    expect_fail 1 "human.rsr: the header's player kinds \\(bytes 30-31\\) are not the ones it was recorded with \\(P1 cpu, P2 cpu\\): the header was altered" \
        "$RS_BIN" replay verify --quiet human.rsr || return 1
    expect_fail 1 "human.rsr: the header's player kinds \\(P1 human, P2 cpu, bytes 30-31\\) are not the ones it was recorded with" \
        "$RS_BIN" render human.rsr --ticks 0:61 --size 160x90 -o h.y4m || return 1
}

t_flipped_bit_reports_tick() {
    "$BIN_DIR/tests/simhash-O2" --flip 1234 6 "$SRC/demos/dojo.rsr" bad.rsr || return 1
    expect_fail 1 "bad.rsr: desync at tick 1260: .*last matching checkpoint: tick 1200; the inputs diverge in ticks 1201..1260" \
        "$RS_BIN" replay verify --quiet bad.rsr || return 1
    [ "$(wc -l <err.txt)" = 1 ] || { cat err.txt; return 1; }
}

t_final_hash_alone_damaged() {
    # the state at tick 180 matched its checkpoint: only the recorded final
    # hash (the 8 bytes before the CRC) is wrong, and the message says so
    "$RS_BIN" record --ai --quiet --seconds 3 --seed 5 -o f.rsr 2>/dev/null || return 1
    python3 -c "
import sys, zlib
b = bytearray(open('f.rsr', 'rb').read())
b[len(b) - 12] ^= 1
b[-4:] = (zlib.crc32(bytes(b[:-4])) & 0xffffffff).to_bytes(4, 'little')
open('fbad.rsr', 'wb').write(b)" || return 1
    expect_fail 1 "fbad.rsr: the final hash at tick 180 is .*though the checkpoint at tick 180 matched: the recorded final hash is damaged" \
        "$RS_BIN" replay verify --quiet fbad.rsr || return 1
    ! grep -q "diverge" err.txt || { cat err.txt; return 1; }
}

t_bad_files() {
    cp "$SRC/demos/dojo.rsr" good.rsr
    head -c 100 good.rsr >trunc.rsr
    expect_fail 1 "trunc.rsr: checksum mismatch at byte 96" "$RS_BIN" replay verify trunc.rsr || return 1
    : >empty.rsr
    expect_fail 1 "empty.rsr: not a ringside replay: expected \"RSRP\" at byte 0" "$RS_BIN" replay info empty.rsr || return 1
    printf 'RSRP\004\000' >v4.rsr
    expect_fail 1 "v4.rsr: format version 4 at byte 4 is not supported \\(this build reads 1 to 3\\)" \
        "$RS_BIN" replay info v4.rsr || return 1
    # one flipped bit in the middle: the checksum catches it
    size=$(wc -c <good.rsr)
    dd if=good.rsr of=flip.rsr bs=1 count=$((size / 2)) 2>/dev/null
    printf '\377' >>flip.rsr
    dd if=good.rsr bs=1 skip=$((size / 2 + 1)) 2>/dev/null >>flip.rsr
    expect_fail 1 "flip.rsr: checksum mismatch" "$RS_BIN" replay verify flip.rsr || return 1
    expect_fail 1 "nope.rsr: cannot open" "$RS_BIN" replay verify nope.rsr || return 1
    mkdir dir.rsr
    expect_fail 1 "dir.rsr: read error" "$RS_BIN" replay info dir.rsr || return 1
    for f in err.txt; do [ "$(wc -l <$f)" = 1 ] || { cat $f; return 1; }; done
}

# Format 1 (no game version) is still read: the demos as they were before
# format 3 verify, and are the same match as today's demos.
t_format1_verifies() {
    "$RS_BIN" replay verify --quiet --hashes v1.txt "$SRC/tests/golden/dojo-format1.rsr" 2>v.txt || { cat v.txt; return 1; }
    "$RS_BIN" replay verify --quiet --hashes v2.txt "$SRC/demos/dojo.rsr" 2>/dev/null || return 1
    cmp v1.txt v2.txt || { echo "format 1 and 2 dojo differ"; return 1; }
    "$RS_BIN" replay info "$SRC/tests/golden/dojo-format1.rsr" >i.txt || return 1
    grep -q "^game         none recorded (format 1: taken as this build's, 1)" i.txt || { cat i.txt; return 1; }
    "$BIN_DIR/tests/simhash-O2" --game-version 0 "$SRC/demos/dojo.rsr" back.rsr || return 1
    cmp back.rsr "$SRC/tests/golden/dojo-format1.rsr" || { echo "format 3 -> 1 is not the old file"; return 1; }
}

# Three failures, three messages: another game version, damage, desync.
t_game_version_told_apart() {
    "$BIN_DIR/tests/simhash-O2" --game-version 9 "$SRC/demos/dojo.rsr" other.rsr || return 1
    expect_fail 1 "^ringside replay: other.rsr: recorded by another version of the game \\(replay: 9, this build: 1\\)$" \
        "$RS_BIN" replay verify --quiet other.rsr || return 1
    "$RS_BIN" replay info other.rsr | grep -q "^game         version 9 (this build: 1; verify refuses it)" || return 1
    "$BIN_DIR/tests/simhash-O2" --flip 1234 6 other.rsr both.rsr || return 1
    expect_fail 1 "both.rsr: recorded by another version of the game" "$RS_BIN" replay verify --quiet both.rsr || return 1
}

t_usage() {
    expect_fail 2 "--ai is required" "$RS_BIN" record -o x.rsr || return 1
    expect_fail 2 "-o FILE is required" "$RS_BIN" record --ai || return 1
    expect_fail 2 "unknown stage" "$RS_BIN" record --ai --stage moon -o x.rsr || return 1
    expect_fail 2 "--level '9'" "$RS_BIN" record --ai --level 9 -o x.rsr || return 1
    expect_fail 2 "unknown subcommand 'play'" "$RS_BIN" replay play x.rsr || return 1
    expect_fail 2 "needs exactly one FILE" "$RS_BIN" replay verify || return 1
    [ ! -e x.rsr ] || return 1
}

t_disk_full_keeps_nothing() {
    ( trap '' XFSZ; export ASAN_OPTIONS=detect_leaks=0; ulimit -f 1; exec "$RS_BIN" record --ai --quiet --seconds 120 -o full.rsr ) >out.txt 2>err.txt
    rc=$?
    [ $rc = 1 ] || { echo "exit $rc"; cat err.txt; return 1; }
    grep -q "full.rsr: write failed: File too large" err.txt || { cat err.txt; return 1; }
    [ ! -e full.rsr ] && [ ! -e full.rsr.part ] || { echo "a partial file was left"; ls; return 1; }
}

t_bench_sim_short() {
    "$RS_BIN" bench sim --hours 1 --quiet --csv b.csv >b.txt 2>&1 || { cat b.txt; return 1; }
    grep -q "verify: all 3600 checkpoints and the final hash match" b.txt || { cat b.txt; return 1; }
    [ "$(wc -l <b.csv)" = 2 ] || return 1
}

t_run final_hash_alone_damaged record_is_reproducible demos_are_current info seconds_exact hashes_same_at_O0_O2_and_in_ringside \
    hashes_same_with_clang header_tampering_is_reported flipped_bit_reports_tick bad_files format1_verifies game_version_told_apart usage disk_full_keeps_nothing bench_sim_short
t_done
