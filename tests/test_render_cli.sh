#!/bin/sh
# End-to-end: the renderer's options through the real binary (--passes,
# --ticks, --stage-file, --mask, --hdr-format) and their errors.
here=$(cd "$(dirname "$0")" && pwd)
. "$here/lib.sh"
SRC=$(cd "$here/.." && pwd)
SIZES="--render-size 320x180 --size 160x90"

short_replay() { # 300 ticks on the dojo
    "$RS_BIN" record --ai --quiet --seconds 5 --seed 21 -o short.rsr 2>/dev/null
}

t_passes_summary_and_frames() {
    short_replay || return 1
    "$RS_BIN" render short.rsr --ticks 100:110 $SIZES -q --passes -o a.y4m 2>p.txt || { cat p.txt; return 1; }
    for pass in shadow_map silhouette_mips shadow_mask mask_filter scene sky lens bloom_blur sun_visibility flare tonemap hud total; do
        grep -q "^$pass " p.txt || { echo "no '$pass' row"; cat p.txt; return 1; }
    done
    grep -q "passes (stage dojo, 320x180, the scene at 240x135, 10 frames" p.txt || { cat p.txt; return 1; }
    # dojo's sun is on screen: every pass ran all 10 frames
    awk '$1 == "scene" && ($2 != 10 || $3 != 0) { exit 1 }' p.txt || { cat p.txt; return 1; }
    # per frame
    "$RS_BIN" render short.rsr --ticks 100:104 $SIZES -q --passes=frames -o b.y4m 2>f.txt || { cat f.txt; return 1; }
    [ "$(grep -c '^frame [0-9]*: shadow_map ' f.txt)" = 4 ] || { cat f.txt; return 1; }
    # the sunless look skips its passes, every frame, and says so
    "$RS_BIN" render short.rsr --ticks 100:104 $SIZES -q --passes=frames --stage-file "$SRC/stages/sunless.stage" \
        -o c.y4m 2>s.txt || { cat s.txt; return 1; }
    [ "$(grep -c 'skipped: shadow_map silhouette silhouette_mips z_prepass shadow_mask mask_filter fog_map lspsm_map holes water_sim water_reflect snow_map snow_light snow_light_blur buildings water_under water_surface snow_surface lspsm_focus sun_visibility flare bloom_bright bloom_blur fxaa$' s.txt)" = 4 ] ||
        { cat s.txt; return 1; }
    awk '$1 == "shadow_map" && ($2 != 0 || $3 != 4) { exit 1 }' s.txt || { cat s.txt; return 1; }
    expect_fail 2 "--passes='often': expected summary or frames" "$RS_BIN" render short.rsr --passes=often -o d.y4m || return 1
    # play prints the same table
    "$RS_BIN" play --headless --replay short.rsr --size 160x90 --passes --quiet 2>q.txt || { cat q.txt; return 1; }
    grep -q "passes (stage dojo, 160x90, the scene at 120x68, 300 frames" q.txt || { cat q.txt; return 1; }
    grep -q "^tonemap  *300  *0 " q.txt || { cat q.txt; return 1; }
    expect_fail 2 "--passes='often'" "$RS_BIN" play --headless --replay short.rsr --passes=often
}

t_ticks_match_a_full_render() {
    short_replay || return 1
    "$RS_BIN" render short.rsr $SIZES -q --hashes all.txt -o all.y4m || return 1
    "$RS_BIN" render short.rsr $SIZES -q --ticks 200:205 --hashes part.txt -o part.y4m || return 1
    [ "$(wc -l <part.txt)" = 5 ] || { cat part.txt; return 1; }
    # the same pictures as frames 200..204 of the whole replay, numbered 200..204
    [ "$(sed -n '201,205p' all.txt)" = "$(cat part.txt)" ] ||
        { echo "--ticks frames differ from the full render:"; sed -n '201,205p' all.txt; cat part.txt; return 1; }
    # image sequences are numbered by tick too
    mkdir seq && "$RS_BIN" render short.rsr $SIZES -q --ticks 298:300 -o seq/f%04d.png || return 1
    [ "$(ls seq | tr '\n' ' ')" = "f0298.png f0299.png " ] || { ls seq; return 1; }
}

t_ticks_errors() {
    short_replay || return 1
    expect_fail 2 "--ticks '5:3': the end must be after the start" "$RS_BIN" render short.rsr --ticks 5:3 -o x.y4m || return 1
    expect_fail 2 "--ticks '7': expected A:B" "$RS_BIN" render short.rsr --ticks 7 -o x.y4m || return 1
    expect_fail 2 "--ticks start" "$RS_BIN" render short.rsr --ticks x:9 -o x.y4m || return 1
    expect_fail 2 "short.rsr: --ticks 300: starts past the replay's end \(300 ticks\)" \
        "$RS_BIN" render short.rsr --ticks 300:310 -o x.y4m || return 1
    [ ! -e x.y4m ] || { echo "output written on error"; return 1; }
    # an end past the replay is clamped with a note; A: runs to the end; both the same frames
    "$RS_BIN" render short.rsr --ticks 290:999999 --size 160x90 -q --hashes a.txt -o a.y4m 2>note.txt || { cat note.txt; return 1; }
    grep -q "^ringside render: --ticks 290:999999: the replay ends at tick 300, so ticks 290:300 are drawn$" note.txt ||
        { cat note.txt; return 1; }
    "$RS_BIN" render short.rsr --ticks 290: --size 160x90 -q --hashes b.txt -o b.y4m 2>note.txt || { cat note.txt; return 1; }
    [ ! -s note.txt ] || { cat note.txt; return 1; }
    [ "$(wc -l <a.txt)" = 10 ] && cmp a.txt b.txt || { echo "290:999999 and 290: differ"; cat a.txt b.txt; return 1; }
}

# --size and --render-size hold each side to its bounds on its own: the
# first value past either end of either side is refused before any work
t_size_sides_bounded() {
    for s in 15x90 160x15 8193x90 160x8193 160x 160x90x2; do
        expect_fail 2 "^ringside render: --size '$s': expected WIDTHxHEIGHT, each from 16 to 8192" \
            "$RS_BIN" render short.rsr --size "$s" -o x.y4m || return 1
    done
    for s in 0x90 160x0 8193x90 160x8193; do
        expect_fail 2 "^ringside render: --render-size '$s': expected WIDTHxHEIGHT, each from 1 to 8192" \
            "$RS_BIN" render short.rsr --render-size "$s" -o x.y4m || return 1
    done
    [ ! -e x.y4m ] || { echo "output written on error"; return 1; }
}

t_bad_stage_files() {
    short_replay || return 1
    printf 'name = bad\ngame = dojo\nsunn = yes\n' >bad.stage
    expect_fail 1 "bad.stage:3: unknown key 'sunn' \(did you mean 'sun'\?\)" \
        "$RS_BIN" render short.rsr --stage-file bad.stage $SIZES -o x.y4m || return 1
    printf 'name = bad\ngame = dojo\n\nbloom = lots\n' >bad.stage
    expect_fail 1 "bad.stage:4: bloom: expected a number" "$RS_BIN" render short.rsr --stage-file bad.stage $SIZES -o x.y4m || return 1
    printf 'name = bad\ngame = dojo\nenvironment = nothere.hdr\n' >bad.stage
    expect_fail 1 "stage 'bad': environment: .*nothere.hdr: cannot open" \
        "$RS_BIN" render short.rsr --stage-file bad.stage $SIZES -o x.y4m || return 1
    expect_fail 1 "nope.stage: cannot open" "$RS_BIN" render short.rsr --stage-file nope.stage $SIZES -o x.y4m || return 1
    [ ! -e x.y4m ] && [ ! -e x.y4m.part ] || { echo "output written on error"; return 1; }
    # a file that was there before a failed render is left alone
    echo keep >x.y4m
    "$RS_BIN" render short.rsr --stage-file bad.stage $SIZES -o x.y4m 2>/dev/null && return 1
    [ "$(cat x.y4m)" = keep ] || { echo "existing output clobbered"; return 1; }
}

t_mask_cutouts() {
    short_replay || return 1
    mkdir cut && "$RS_BIN" render short.rsr --ticks 200:202 --mask $SIZES -q -o cut/f%04d.png || return 1
    [ -s cut/f0200.png ] && [ -s cut/f0201.png ] || { ls cut; return 1; }
    fmt=$(ffprobe -v error -show_entries stream=pix_fmt -of default=nw=1:nk=1 cut/f0200.png)
    [ "$fmt" = rgba ] || { echo "pix_fmt $fmt, want rgba"; return 1; }
    # the alpha is the fighters' mask: mostly 0 (background), some 255 (fighters), a few edges between
    ffmpeg -v error -i cut/f0200.png -vf alphaextract -f rawvideo -pix_fmt gray - 2>/dev/null | od -An -v -tu1 -w1 |
        awk '{ n++; if ($1 == 0) z++; else if ($1 == 255) f++ }
             END { printf "alpha: %d px, %d zero, %d full\n", n, z, f; exit !(n == 160 * 90 && z > n / 2 && f > n / 100 && f < n / 3) }' ||
        return 1
    expect_fail 2 "--mask writes RGBA images" "$RS_BIN" render short.rsr --mask -o m.y4m || return 1
    expect_fail 1 "--mask needs an alpha channel" "$RS_BIN" render short.rsr --mask --hdr-format r11g11b10f -o cut/m%02d.png || return 1
    expect_fail 2 "hdr" "$RS_BIN" render short.rsr --hdr-format rgb9e5 -o m.y4m
}

t_help_lists_the_options() {
    "$RS_BIN" render --help >h.txt || return 1
    for o in --stage-file --passes --mask --no-hud --hdr-format --ticks; do
        grep -q -- "$o" h.txt || { echo "render --help lacks $o"; return 1; }
    done
    "$RS_BIN" play --help >h.txt || return 1
    for o in --stage-file --passes --hdr-format; do
        grep -q -- "$o" h.txt || { echo "play --help lacks $o"; return 1; }
    done
}

# --quality sets the render size from the output size (unless --render-size says)
# and the renderer's knobs; --size alone works from 16x16 to 3840x2160.
# Standard draws the dojo's scene at the stage's 75% (standard_scene_pct).
t_quality_and_sizes() {
    short_replay || return 1
    for qs in "draft:160x90:160x90, the scene at 96x54" "standard:160x90:160x90, the scene at 120x68" "high:160x90:320x180" \
        "reference:160x90:640x360" "standard:1920x1080:1920x1080, the scene at 1440x810" "standard:16x16:16x16, the scene at 12x12" \
        "standard:3840x2160:3840x2160, the scene at 2880x1620"; do
        q=${qs%%:*} rest=${qs#*:}
        size=${rest%%:*} drawn=${rest#*:}
        "$RS_BIN" render short.rsr --ticks 100:101 --size "$size" --quality "$q" -o "q_$q.y4m" -y 2>q.txt ||
            { cat q.txt; return 1; }
        grep -q "frames $size (drawn at $drawn, quality $q)" q.txt || { echo "$qs:"; cat q.txt; return 1; }
    done
    # --render-size wins over the quality's scale; the knobs still apply
    # (draft's scene at 60% of the render size: other bytes)
    for q in draft standard; do
        "$RS_BIN" render short.rsr --ticks 100:102 --size 160x90 --render-size 320x180 --quality $q --passes \
            -o r_$q.y4m -y 2>r_$q.txt || { cat r_$q.txt; return 1; }
        drawn="320x180, the scene at 240x135"
        [ $q = standard ] || drawn="320x180, the scene at 192x108"
        grep -q "(drawn at $drawn, quality $q)" r_$q.txt || { cat r_$q.txt; return 1; }
    done
    ! cmp -s r_draft.y4m r_standard.y4m || { echo "--render-size: draft drew what standard drew"; return 1; }
    # a stage file's standard_scene_pct is standard's size; 100 (or none) draws 1:1
    sed 's/^standard_scene_pct.*//' "$SRC/stages/dojo.stage" >whole.stage
    printf 'standard_scene_pct = 50\n' >>half.stage && cat whole.stage >>half.stage
    for sq in whole:160x90 half:"160x90, the scene at 80x45"; do
        "$RS_BIN" render short.rsr --ticks 100:101 --size 160x90 --stage-file "${sq%%:*}.stage" -o s.y4m -y 2>s.txt ||
            { cat s.txt; return 1; }
        grep -q "(drawn at ${sq#*:}, quality standard)" s.txt || { echo "$sq:"; cat s.txt; return 1; }
    done
    grep -q "^fxaa  *0  *2 " r_standard.txt || { echo "standard runs FXAA"; cat r_standard.txt; return 1; }
    expect_fail 2 "--quality 'ultra': expected draft, standard, high or reference" "$RS_BIN" render short.rsr --quality ultra \
        -o x.y4m || return 1
    expect_fail 2 "^ringside render: --size '8x8': expected WIDTHxHEIGHT, each from 16 to 8192" "$RS_BIN" render short.rsr --size 8x8 -o x.y4m || return 1
    expect_fail 2 "^ringside render: --size '0x0': expected WIDTHxHEIGHT, each from 16 to 8192" "$RS_BIN" render short.rsr --size 0x0 -o x.y4m || return 1
    expect_fail 2 "larger than the render size" "$RS_BIN" render short.rsr --size 640x360 --render-size 320x180 \
        -o x.y4m || return 1
    # play: the same presets, a larger drawing averaged down to the frame
    "$RS_BIN" play --headless --replay short.rsr --seconds 1 --size 160x90 --quality high --mute --screenshot h.png \
        --quiet || return 1
    "$RS_BIN" play --headless --replay short.rsr --seconds 1 --size 160x90 --quality standard --mute --screenshot s.png \
        --quiet || return 1
    ! cmp -s h.png s.png || { echo "play --quality high drew what standard drew"; return 1; }
    expect_fail 2 "--quality 'ultra'" "$RS_BIN" play --headless --quality ultra || return 1
}

# in_pairs CMD ITEM...: `CMD ITEM N` for each ITEM, N counting from 1, two at
# a time in the background: its exit status goes to rc.N, its stderr to err.N.
# For renders that fail early: each is mostly its start-up, one busy thread,
# so two fill the two cores that one leaves half idle.
in_pairs() {
    cmd=$1
    shift
    n=0
    for item; do
        n=$((n + 1))
        ("$cmd" "$item" $n 2>"err.$n"; echo $? >"rc.$n") &
        [ $((n % 2)) = 1 ] || wait
    done
    wait
}

# An output that cannot be written fails the render and leaves nothing: an
# image sequence on a full filesystem (a 160 KiB tmpfs, all but about 8 KiB
# filled: less than one frame of any sequence, half of any video here),
# in a read-only folder and in a missing one, the video beside it for
# comparison.  What was there before stays as it was.
t_outputs_on_a_full_disk() {
    short_replay || return 1
    mkdir -p full && mount -t tmpfs -o size=160k tmpfs full 2>mount.err ||
        { t_skip_env "cannot mount a tmpfs here ($(head -c 120 mount.err))"; return 0; }
    echo keep >full/keep.txt
    head -c 148k /dev/zero >full/filler # about 8 KiB left; 20 frames at 320x180 are 13-17 KiB in any container
    for out in full/f%04d.png full/f%04d.exr full/f%04d.tif full/v.mp4 full/v.y4m full/v.webm full/v.mkv full/v.nut; do
        "$RS_BIN" render short.rsr --ticks 0:20 --size 320x180 -q -o "$out" 2>err.txt
        rc=$?
        left=$(ls -A full | grep -Ev '^(keep.txt|filler)$' | tr '\n' ' ')
        if [ $rc = 0 ] || [ -n "$left" ] || [ "$(cat full/keep.txt)" != keep ]; then
            echo "$out on a full disk: exit $rc, left: '$left'"; cat err.txt; umount full; return 1
        fi
        case $out in *%*) grep -q "^ringside render: full/f00[0-9][0-9]\.[a-z]*: cannot write frame [0-9]*: No space left on device" err.txt ||
            { echo "$out:"; cat err.txt; umount full; return 1; } ;; esac
    done
    # the stream: a full disk behind standard output is a write error on it
    "$RS_BIN" render short.rsr --ticks 0:20 --size 320x180 -q -o - >full/stream.y4m 2>err.txt
    rc=$?
    rm -f full/stream.y4m # the shell's file, not ours
    [ $rc = 1 ] && grep -q "^ringside render: standard output: .*No space left on device" err.txt ||
        { echo "-o - on a full disk: exit $rc"; cat err.txt; umount full; return 1; }
    # the join: segments made elsewhere, joined onto the full disk (12 KiB)
    for r in 0:30 30:60; do
        "$RS_BIN" render short.rsr --ticks "$r" --size 320x180 -q --segment fulljob -y -o "s${r%:*}.mp4" 2>err.txt ||
            { cat err.txt; umount full; return 1; }
    done
    "$RS_BIN" join --segment fulljob -q -o full/j.mp4 s0.mp4 s30.mp4 2>err.txt
    rc=$?
    left=$(ls -A full | grep -Ev '^(keep.txt|filler)$' | tr '\n' ' ')
    [ $rc = 1 ] && [ -z "$left" ] && grep -q "^ringside join: full/j.mp4: .*No space left on device" err.txt ||
        { echo "join on a full disk: exit $rc, left: '$left'"; cat err.txt; umount full; return 1; }
    # a side output that cannot be written takes the video with it (the
    # video N is vN.mp4)
    : >full/filler2
    head -c 200k /dev/zero >>full/filler2 2>/dev/null # now nothing is left
    with_side() { "$RS_BIN" render short.rsr --ticks 148:152 --size 160x90 -q -o "v$2.mp4" $1; } # the poster is tick 150
    set -- "--hashes full/h.txt" "--wav full/a.wav" "--poster full/p.png"
    in_pairs with_side "$@"
    n=0
    for side; do
        n=$((n + 1))
        [ "$(cat rc.$n)" != 0 ] || { echo "$side: exit 0"; umount full; return 1; }
        name=${side#* }
        [ ! -e v$n.mp4 ] && [ -z "$(ls -A full | grep -Ev '^(keep.txt|filler2?)$')" ] ||
            { echo "$side left: $(ls v$n.mp4 full 2>&1)"; umount full; return 1; }
        grep -q "^ringside render: $name: .*No space left on device" err.$n ||
            { echo "$side:"; cat err.$n; umount full; return 1; }
    done
    umount full
    # read-only for root too: a read-only mount, not a mode
    mkdir ro && mount -t tmpfs -o ro,size=16k tmpfs ro || { echo "cannot mount a read-only tmpfs"; return 1; }
    # the error names what the user wrote (the frame's name for a sequence) and the system's reason
    render_to() { "$RS_BIN" render short.rsr --ticks 0:4 --size 160x90 -q -o "$1"; }
    set -- ro/f%04d.png ro/f%04d.exr ro/f%04d.tif ro/x.mp4 ro/x.y4m ro/x.webm ro/x.mkv ro/x.nut \
        nowhere/f%04d.png nowhere/x.mp4 nowhere/x.webm nowhere/x.nut
    in_pairs render_to "$@"
    n=0
    for out; do
        n=$((n + 1))
        [ "$(cat rc.$n)" != 0 ] || { echo "$out: exit 0"; umount ro; return 1; }
        name=$(printf '%s' "$out" | sed 's/%04d/0000/')
        case $out in
        ro/*) want="^ringside render: $name: cannot \(create\|write frame 0\).*: Read-only file system" ;;
        *) want="^ringside render: $name: folder nowhere does not exist" ;;
        esac
        grep -q "$want" err.$n || { echo "$out: want '$want':"; cat err.$n; umount ro; return 1; }
    done
    [ -z "$(ls -A ro)" ] || { echo "left in ro: $(ls -A ro)"; umount ro; return 1; }
    # the side outputs, read-only or in no folder: the video goes with them
    rm -f v*.mp4
    set -- "--hashes ro/h.txt" "--wav ro/a.wav" "--poster ro/p.png" "--hashes nowhere/h.txt" "--wav nowhere/a.wav"
    in_pairs with_side "$@"
    n=0
    for side; do
        n=$((n + 1))
        [ "$(cat rc.$n)" != 0 ] || { echo "$side: exit 0"; umount ro; return 1; }
        name=${side#* }
        [ ! -e v$n.mp4 ] && [ -z "$(ls -A ro)" ] || { echo "$side left: $(ls v$n.mp4 ro 2>&1)"; umount ro; return 1; }
        grep -q "^ringside render: $name: .*\(Read-only file system\|folder nowhere does not exist\)" err.$n ||
            { echo "$side:"; cat err.$n; umount ro; return 1; }
    done
    umount ro
}

t_run outputs_on_a_full_disk passes_summary_and_frames quality_and_sizes size_sides_bounded ticks_match_a_full_render ticks_errors bad_stage_files mask_cutouts help_lists_the_options
t_done
