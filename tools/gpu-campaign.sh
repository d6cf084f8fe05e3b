#!/usr/bin/env bash
# tools/gpu-campaign.sh REPORTDIR [--quick]
#
# Everything worth measuring on a GPU machine lent for a few minutes, in one
# command with a deadline, without network, most valuable first: the
# device, the smoke scene, the renderer's golden frames (PSNR), capture
# (async vs sequential) at three sizes, replay-to-video speed per stage,
# per-pass timings, the fp16 stress looks, movie upload, one full demo to
# .mp4, one demo per encoder (software, NVENC H.264/HEVC/AV1, --hw auto).  Each step may use a share of the budget
# (what an earlier step leaves over goes on to the later ones), so a slow
# step cannot starve the rest; a render cut by its time limit still
# reports its speed over the frames it did.
# docs/benchmarks.md ("On a real GPU") says how to run it and what it gave.
#
#   tools/gpu-campaign.sh "$OUT"              on the GPU machine, from the repo root
#   tools/gpu-campaign.sh /tmp/rep --quick    the dry run: small sizes, few frames
#                                             (under 2 minutes on a 2-core llvmpipe)
#
# The ringside it runs: $RINGSIDE, else .gpu-bundle/run, else build/ringside.
# Demos: $RINGSIDE_DEMOS, else demos/.  Golden frames: tests/golden/.
# Environment:
#   CAMPAIGN_BUDGET_S     whole-run deadline in seconds (default 520); steps
#                         that no longer fit are skipped and said so
#   CAMPAIGN_REF          folder of reference frames from an earlier run
#                         (<stage>_<tick>.y4m) to compare the golden frames
#                         with too; default .gpu-bundle/ref if it exists
#   CAMPAIGN_SAVE_FRAMES  folder to copy this run's golden frames into (to
#                         make such a reference on llvmpipe)
#   CAMPAIGN_CAPTURE_SINK bench capture's sink: mp4 (default), y4m or null
#
# REPORTDIR gets at most 8 files: summary.txt (read this first), golden.csv,
# capture.csv, stages.csv, passes.csv, fp16.csv, encoders.csv, log.txt.
# Exit status: 0 when the campaign ran (failed steps are in the report),
# 1 when it could not run at all (no ringside, REPORTDIR not writable),
# 2 bad usage.
# The whole script is one { } block, read before it runs: a copy replaced
# while a campaign runs (a new bundle, an edit) cannot change it midway.
{
set -u
export LC_ALL=C

usage() {
    echo "usage: tools/gpu-campaign.sh REPORTDIR [--quick]   (--help: what it does)" >&2
    exit 2
}
die() {
    echo "gpu-campaign: $*" >&2
    exit 1
}

report="" quick=0
for a in "$@"; do
    case "$a" in
    --quick) quick=1 ;;
    -h | --help)
        sed -n '2,35p' "$0" | sed 's/^# \{0,1\}//'
        exit 0
        ;;
    -*) echo "gpu-campaign: unknown option '$a'" >&2; usage ;;
    *) [ -z "$report" ] || usage; report=$a ;;
    esac
done
[ -n "$report" ] || usage

here=$(cd "$(dirname "$0")" && pwd)
BUDGET=${CAMPAIGN_BUDGET_S:-520}
case "$BUDGET" in '' | *[!0-9]*) die "CAMPAIGN_BUDGET_S='$BUDGET': expected whole seconds" ;; esac
RESERVE=6 # seconds kept for the last lines of the report

for tool in timeout od awk; do
    command -v "$tool" >/dev/null 2>&1 || die "needs '$tool' (coreutils, awk)"
done

# ---- what to run, and on what ----
if [ -n "${RINGSIDE:-}" ]; then
    RS=$RINGSIDE
elif [ -x .gpu-bundle/run ]; then
    RS=.gpu-bundle/run
elif [ -x build/ringside ]; then
    RS=build/ringside
else
    die "no ringside: set RINGSIDE, or make .gpu-bundle (tools/gpu-bundle.sh .gpu-bundle) or build/ringside (make)"
fi
[ -x "$RS" ] || die "RINGSIDE='$RS' is not an executable file"
case "$RS" in /*) ;; *) RS=$PWD/$RS ;; esac

if [ -n "${RINGSIDE_DEMOS:-}" ]; then
    DEMOS=$RINGSIDE_DEMOS
elif [ -d demos ]; then
    DEMOS=demos
else
    DEMOS=$here/../share/ringside/demos # the bundle's copy of this script: OUTDIR/tools
fi
GOLDEN=tests/golden
REF=${CAMPAIGN_REF:-}
[ -z "$REF" ] && [ -d .gpu-bundle/ref ] && REF=.gpu-bundle/ref
SINK=${CAMPAIGN_CAPTURE_SINK:-mp4}
STAGES=""
for d in stages "${RINGSIDE_DATA:-/nonexistent}/stages" "$(dirname "$RS")/share/ringside/stages"; do
    if [ -f "$d/dojo.stage" ]; then STAGES=$d; break; fi
done

mkdir -p "$report" 2>/dev/null || die "cannot make REPORTDIR '$report'"
probe=$report/.probe.$$
(: >"$probe") 2>/dev/null || die "REPORTDIR '$report' is not writable"
rm -f "$probe"
SUM=$report/summary.txt LOG=$report/log.txt
for f in summary.txt log.txt golden.csv capture.csv stages.csv passes.csv fp16.csv encoders.csv; do
    rm -f "$report/$f"
done
: >"$SUM"
: >"$LOG"

tmp=$(mktemp -d "${TMPDIR:-/tmp}/gpu-campaign-XXXXXX") || die "cannot make a temporary folder"
current="start"
# shellcheck disable=SC2317 # called by the traps
cleanup() { rm -rf "$tmp"; }
# shellcheck disable=SC2317
on_signal() {
    say ""
    say "INTERRUPTED by a signal during '$current' after ${SECONDS} s; everything above was measured."
    cleanup
    exit 1
}
trap cleanup EXIT
trap on_signal INT TERM

# ---- report helpers ----
say() { printf '%s\n' "$*" >>"$SUM"; }
log() { printf '[%4ds] %s\n' "$SECONDS" "$*" >>"$LOG"; }
LOG_CAP=$((4 * 1024 * 1024))
# The first 40 and last 20 lines of a command's output, while log.txt is
# under its cap (then only the command lines).
log_output() {
    local f=$1 what=$2 n
    [ -s "$f" ] || return 0
    [ "$(wc -c <"$LOG")" -lt "$LOG_CAP" ] || return 0
    n=$(wc -l <"$f")
    printf '  --- %s (%s lines)\n' "$what" "$n" >>"$LOG"
    if [ "$n" -le 60 ]; then
        cut -c1-400 "$f" | sed 's/^/  | /'
    else
        head -n 40 "$f" | cut -c1-400 | sed 's/^/  | /'
        printf '  | ... %d lines left out ...\n' $((n - 60))
        tail -n 20 "$f" | cut -c1-400 | sed 's/^/  | /'
    fi >>"$LOG"
}
now() { printf '%s' "${EPOCHREALTIME:-$(date +%s.%N)}"; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }'; }
# seconds left: to the campaign's deadline, or to the running step's
# share of the budget (so that no step can starve the ones after it)
STEP_END=0
left() {
    local l=$((BUDGET - SECONDS - RESERVE))
    [ "$STEP_END" -le 0 ] || [ $((STEP_END - SECONDS)) -ge "$l" ] || l=$((STEP_END - SECONDS))
    echo "$l"
}
# a fair share of what the step has left for each of N items still to run
share() { local l; l=$(left); echo $((l / ($1 > 0 ? $1 : 1))); }

# run_timed MIN LIMIT OUT ERR CMD...: CMD with a timeout of LIMIT seconds
# (at least MIN), cut to what the deadline leaves; not started when that
# is under MIN.
# Sets RC (124: timed out, 125: not started) and WALL (seconds).
RC=0 WALL=0 SKIP_WHY=""
run_timed() {
    local min=$1 limit=$2 out=$3 err=$4 l t0
    shift 4
    l=$(left)
    [ "$limit" -ge "$min" ] || limit=$min
    [ "$limit" -le "$l" ] || limit=$l
    if [ "$limit" -lt "$min" ]; then
        RC=125 WALL=0
        if [ $((BUDGET - SECONDS - RESERVE)) -lt "$min" ]; then
            SKIP_WHY="the campaign's deadline is near"
        else
            SKIP_WHY="the step's share of the budget is used up"
        fi
        log "not started ($SKIP_WHY: ${l} s left, needs ${min}): $*"
        : >"$out"; : >"$err"
        return
    fi
    log "\$ $* (timeout ${limit} s)"
    t0=$(now)
    # fd 3: render's --progress-fd, so a run cut short still says how far it got
    # (in a subshell whose stderr is dropped: bash's "Killed" notice when -k fires)
    (
        timeout -k 5 "$limit" "$@" >"$out" 2>"$err" 3>"$tmp/progress"
        exit $?
    ) 2>/dev/null
    RC=$?
    WALL=$(since "$t0")
    [ "$RC" -ne 137 ] || RC=124
    log "  exit $RC, ${WALL} s$([ "$RC" -eq 124 ] && echo ", TIMED OUT after ${limit} s")"
    log_output "$out" stdout
    log_output "$err" stderr
}
rc_word() {
    case "$1" in
    0) echo ok ;;
    124) echo timeout ;;
    125) echo skipped ;;
    *) echo "failed($1)" ;;
    esac
}
first_error() { # the last line of an error output, for one-line reports and CSV cells
    local m
    [ "$RC" -ne 125 ] || { echo "not started: $SKIP_WHY"; return; }
    m=$(grep -v '^$' "$1" | tail -n 1 | cut -c1-200 | tr ',' ';')
    echo "${m:-no message}"
}

# Step bookkeeping: every step ends up in the final table.
STEP_LINES=()
STEP_T0=0 STEP_NAME=""
step_begin() { # NAME MIN_SECONDS SHARE_PERCENT: 1 (skip) when fewer seconds are left
    STEP_NAME=$1 current=$1
    STEP_T0=$SECONDS STEP_END=0
    STEP_END=$((BUDGET * $3 / 100))
    [ "$STEP_END" -ge "$2" ] || STEP_END=$2
    STEP_END=$((SECONDS + STEP_END))
    say ""
    say "== $1"
    if [ "$(left)" -lt "$2" ]; then
        say "SKIPPED: the deadline is near ($(left) s usable of the ${BUDGET} s budget, ${RESERVE} s kept for the report; this step needs about $2 s)"
        STEP_LINES+=("$(printf '%-22s skipped (deadline)' "$1")")
        log "step $1 skipped: deadline"
        return 1
    fi
    log "step $1"
    return 0
}
step_end() { # VERDICT
    STEP_LINES+=("$(printf '%-22s %-40s %4d s' "$STEP_NAME" "$1" $((SECONDS - STEP_T0)))")
    STEP_END=0
}

# frames and fps from render's last line ("wrote X: N frames ... in S s, F fps")
render_frames() { sed -n 's/.*wrote .*: \([0-9][0-9]*\) frames .*/\1/p' "$1" | tail -n 1; }
render_fps() { sed -n 's/.*wrote .* s, \([0-9.][0-9.]*\) fps.*/\1/p' "$1" | tail -n 1; }
xrt() { awk -v f="$1" -v s="$2" 'BEGIN { if (f > 0 && s > 0) printf "%.2f", f / 60 / s; else printf "-" }'; }
ticks_of() { "$RS" replay info "$1" 2>/dev/null | sed -n 's/^duration *\([0-9][0-9]*\) ticks.*/\1/p'; }

# PSNR of a Y4M frame against a reference: a binary PPM (converted to
# BT.709 limited 4:2:0 exactly as capture/cap_cpu.c does, in double) or
# another Y4M.  Prints: psnr_y psnr_cb psnr_cr psnr_all luma_off24_pct max_dy
y4m_psnr() {
    awk '
    function rnd(v,  r) { r = int(v); if (v - r >= 0.5) r++; return r < 0 ? 0 : r > 255 ? 255 : r }
    function psnr(se, n) { return se > 0 ? sprintf("%.2f", 10 * log(65025 / (se / n)) / log(10)) : "inf" }
    function bail(m) { print "error: " m; err = 1; exit 1 }
    # the byte after a Y4M stream header line and its FRAME line; w, h out
    function y4m(buf, n,  q, s, i) {
        q = 0; while (q < n && buf[q] != 10) q++
        s = ""; for (i = 0; i < q && i < 200; i++) s = s sprintf("%c", buf[i])
        if (s !~ /^YUV4MPEG2 /) bail("not a Y4M stream")
        split(s, t, " "); W = 0; H = 0
        for (i in t) { if (t[i] ~ /^W/) W = substr(t[i], 2) + 0; if (t[i] ~ /^H/) H = substr(t[i], 2) + 0 }
        q++; while (q < n && buf[q] != 10) q++
        return q + 1
    }
    FNR == 1 { f++; n = 0 }
    f == 1 { for (i = 1; i <= NF; i++) a[n++] = $i + 0; na = n; next }
    f == 2 { for (i = 1; i <= NF; i++) b[n++] = $i + 0; nb = n; next }
    END {
        if (err) exit 1
        q = y4m(b, nb); w = W; h = H; cw = int(w / 2); ch = int(h / 2)
        if (nb - q < w * h + 2 * cw * ch) bail("the frame is short")
        if (a[0] == 80 && a[1] == 54) { # P6 W H 255, one white space, RGB
            p = 2; k = 0
            while (k < 3 && p < na) {
                while (a[p] == 32 || a[p] == 10 || a[p] == 13 || a[p] == 9) p++
                if (a[p] == 35) { while (p < na && a[p] != 10) p++; continue }
                v = 0; while (a[p] >= 48 && a[p] <= 57) { v = v * 10 + a[p] - 48; p++ }
                hv[k++] = v
            }
            p++
            if (hv[0] != w || hv[1] != h) bail("reference is " hv[0] "x" hv[1] ", frame " w "x" h)
            if (hv[2] != 255 || na - p < w * h * 3) bail("reference PPM not 8-bit or short")
            for (y = 0; y < h; y++) for (x = 0; x < w; x++) {
                o = p + 3 * (y * w + x)
                ry[y * w + x] = rnd(16 + 219 * ((0.2126 * a[o] + 0.7152 * a[o + 1] + 0.0722 * a[o + 2]) / 255.0))
            }
            for (y = 0; y < ch; y++) for (x = 0; x < cw; x++) {
                r = 0; g = 0; bl = 0
                for (k = 0; k < 4; k++) {
                    o = p + 3 * ((2 * y + int(k / 2)) * w + 2 * x + k % 2)
                    r += a[o]; g += a[o + 1]; bl += a[o + 2]
                }
                r /= 4 * 255.0; g /= 4 * 255.0; bl /= 4 * 255.0
                l = 0.2126 * r + 0.7152 * g + 0.0722 * bl
                rb[y * cw + x] = rnd(128 + 224 * (bl - l) / 1.8556)
                rr[y * cw + x] = rnd(128 + 224 * (r - l) / 1.5748)
            }
        } else {
            p = y4m(a, na)
            if (W != w || H != h) bail("reference is " W "x" H ", frame " w "x" h)
            if (na - p < w * h + 2 * cw * ch) bail("the reference frame is short")
            for (i = 0; i < w * h; i++) ry[i] = a[p + i]
            for (i = 0; i < cw * ch; i++) { rb[i] = a[p + w * h + i]; rr[i] = a[p + w * h + cw * ch + i] }
        }
        sy = 0; off = 0; mx = 0; sb = 0; sr = 0
        for (i = 0; i < w * h; i++) {
            d = ry[i] - b[q + i]; if (d < 0) d = -d
            sy += d * d; if (d > 24) off++; if (d > mx) mx = d
        }
        for (i = 0; i < cw * ch; i++) {
            d = rb[i] - b[q + w * h + i]; sb += d * d
            d = rr[i] - b[q + w * h + cw * ch + i]; sr += d * d
        }
        printf "%s %s %s %s %.3f %d\n", psnr(sy, w * h), psnr(sb, cw * ch), psnr(sr, cw * ch), \
            psnr(sy + sb + sr, w * h + 2 * cw * ch), 100 * off / (w * h), mx
    }' <(od -An -v -tu1 "$1") <(od -An -v -tu1 "$2")
}

# The middle band of a Y4M frame the way test_render's stress test reads
# it (rows h/3 .. 2h/3 from the bottom): mean of R, G and B (0..255, BT.709
# limited inverted; exact up to rounding, as R, G, B are linear in Y, Cb,
# Cr and the band's rows pair up), and the band's luma min and max.
y4m_band() {
    od -An -v -tu1 "$1" | awk '
    function c8(v) { v *= 255; return v < 0 ? 0 : v > 255 ? 255 : v }
    { for (i = 1; i <= NF; i++) b[n++] = $i + 0 }
    END {
        q = 0; while (q < n && b[q] != 10) q++
        s = ""; for (i = 0; i < q && i < 200; i++) s = s sprintf("%c", b[i])
        split(s, t, " ")
        for (i in t) { if (t[i] ~ /^W/) w = substr(t[i], 2) + 0; if (t[i] ~ /^H/) h = substr(t[i], 2) + 0 }
        q++; while (q < n && b[q] != 10) q++; q++
        cw = int(w / 2); qb = q + w * h; qr = qb + cw * int(h / 2)
        if (!w || !h || n - qr < cw * int(h / 2)) { print "- - -"; exit }
        sum = 0; c = 0; lo = 255; hi = 0
        for (yb = int(h / 3); yb < int(2 * h / 3); yb++) for (x = 0; x < w; x++) {
            y = h - 1 - yb; v = b[q + y * w + x]; if (v < lo) lo = v; if (v > hi) hi = v
            k = int(y / 2) * cw + int(x / 2)
            l = (v - 16) / 219; pb = (b[qb + k] - 128) / 224; pr = (b[qr + k] - 128) / 224
            r = l + 1.5748 * pr; bl = l + 1.8556 * pb; g = (l - 0.2126 * r - 0.0722 * bl) / 0.7152
            sum += c8(r) + c8(g) + c8(bl); c += 3
        }
        printf "%.1f %d %d\n", sum / c, lo, hi
    }'
}

# ---- sizes and lengths: the campaign, and its dry run ----
if [ "$quick" -eq 1 ]; then
    MODE="quick (dry-run sizes: small frames, few ticks)"
    CAP_CASES="512x288:256x144:10 512x288:512x288:10 768x432:384x216:10" # drawn:written:frames
    CAP_RUNS=1
    SPEED_ARGS=(--ticks 0:30 --render-size 640x360 --size 320x180)
    FULL_ARGS=(--ticks 0:60 --render-size 640x360 --size 320x180)
    PASS_TICKS=120:130 PASS_SIZE=(--render-size 640x360 --size 320x180)
    FP16_SIZE=(--render-size 320x180 --size 320x180)
    FP16_FORMATS="rgba16f" # the plumbing; the GPU run does both formats
    ENC_ARGS=(--ticks 0:30 --render-size 640x360 --size 320x180)
    UPLOAD_ARGS=(--frames 20 --runs 1 --size 640x384)
    SMOKE_ARGS=(--size 320x180)
else
    MODE="full"
    # enough frames for a pipelined encoder: at 120 frames libx264's open,
    # look-ahead and flush dominate a run (async 188 fps at 120 frames, 649
    # at 600 on an H200); one run each, so the sequential rows (6-70 fps)
    # fit the step's share
    CAP_CASES="1280x720:640x360:600 1920x1080:1920x1080:200 3840x2160:1920x1080:120"
    CAP_RUNS=1
    SPEED_ARGS=()
    FULL_ARGS=()
    PASS_TICKS=1200:1320 PASS_SIZE=()
    FP16_SIZE=(--render-size 1280x720 --size 320x180)
    FP16_FORMATS="rgba16f r11g11b10f"
    ENC_ARGS=()
    UPLOAD_ARGS=()
    SMOKE_ARGS=()
fi

# ==== 0. the binary starts (the bundle unpacks itself on its first run) ====
current=startup
log "campaign: $MODE, budget ${BUDGET} s, ringside $RS, demos $DEMOS, golden $GOLDEN, reference ${REF:-none}"
run_timed 1 120 "$tmp/o" "$tmp/e" "$RS" version
START_RC=$RC START_WALL=$WALL
START_VERSION=$(head -n 1 "$tmp/o")

# ==== 1. the device ====
current=info
run_timed 1 60 "$tmp/info" "$tmp/info.err" "$RS" info
INFO_RC=$RC
vendor=$(sed -n 's/^vendor  *//p' "$tmp/info" | head -n 1)
renderer=$(sed -n 's/^renderer  *//p' "$tmp/info" | head -n 1)
if [ "$INFO_RC" -ne 0 ] || [ -z "$renderer" ]; then
    say "GL device: UNKNOWN -- 'ringside info' failed ($(rc_word "$INFO_RC")): $(first_error "$tmp/info.err")"
    IS_GPU=unknown
else
    say "GL device: $renderer (vendor $vendor)"
    case "$renderer" in
    *llvmpipe* | *softpipe* | *swrast* | *"Software Rasterizer"*)
        say "*** NOT a GPU run: '$renderer' is Mesa's software rasteriser: this is a dry run of the campaign ***"
        IS_GPU=no
        ;;
    *) IS_GPU=yes ;;
    esac
fi
say "ringside GPU campaign, $(date -u '+%Y-%m-%d %H:%M UTC'), mode $MODE, budget ${BUDGET} s"
say "binary: $RS ($START_VERSION; first start $(rc_word "$START_RC") in ${START_WALL} s, bundle unpacking included)"
say "host: $(uname -srm), $(nproc 2>/dev/null || echo '?') CPUs ($(sed -n 's/^model name[^:]*: //p' /proc/cpuinfo 2>/dev/null | head -n 1))"
if command -v nvidia-smi >/dev/null 2>&1; then
    timeout 15 nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv,noheader >"$tmp/smi" 2>&1
    say "nvidia-smi: $(head -n 1 "$tmp/smi")"
fi
say ""
say "== info"
if [ -s "$tmp/info" ]; then sed 's/^/  /' "$tmp/info" >>"$SUM"; else say "  (no output)"; fi
STEP_LINES+=("$(printf '%-22s %-40s %4d s' info "$(rc_word "$INFO_RC") ($IS_GPU GPU)" "$SECONDS")")

# ==== 2. the smoke scene (exact on any conforming rasteriser) ====
if step_begin smoke 5 3; then
    run_timed 3 "$(left)" "$tmp/o" "$tmp/e" "$RS" smoke -o "$tmp/smoke.ppm" "${SMOKE_ARGS[@]}"
    say "smoke: $(rc_word "$RC") in ${WALL} s: $(first_error "$tmp/e")"
    step_end "$(rc_word "$RC")"
fi

# ==== 3. golden frames ====
# tests/test_render.c draws render_<stage>_<tick>.ppm at 320x180 into an
# RGBA8 framebuffer: the state at tick T (prev = T-1), interpolation 1,
# the stage's own file, IBL cache off; shallows, snowfield and mistvale
# after the 120 ticks before T (30 for plaza).  render's frame numbered
# T-1 draws the same two states (it steps once, then draws); drawn and
# written at 320x180 with no scaling, converted on the CPU (sequential
# capture), so the only loss is the exact 4:2:0 conversion, which the
# comparison applies to the golden too.  What differs: render warms the
# effects' history up from tick 0 (their own rule), the test from T-120.
G=$report/golden.csv
echo "stage,tick,render_ticks,status,wall_s,psnr_y,psnr_cb,psnr_cr,psnr_all,luma_off24_pct,max_dy,verdict,ref_psnr_y,ref_psnr_all,ref_max_dy,ref_identical" >"$G"
if step_begin golden 10 8; then
    say "Each golden frame drawn again by this binary, 320x180 (docs/testing.md); PSNR per plane after BT.709"
    say "4:2:0 conversion of the golden (exact, as capture does it); verdict = the test's tolerance read on luma"
    say "(PSNR >= 30 dB and <= 1% of pixels more than 24 off)."
    [ -z "$REF" ] || say "ref_* columns: against the frames in $REF (an earlier run, e.g. llvmpipe), same recipe."
    ng=0 nbad=0 nskip=0
    [ -n "${CAMPAIGN_SAVE_FRAMES:-}" ] && mkdir -p "$CAMPAIGN_SAVE_FRAMES"
    printf '  %-10s %5s %8s %8s %8s %8s %7s %5s  %s\n' stage tick "Y dB" "Cb dB" "Cr dB" "all dB" ">24 %" maxd verdict >>"$SUM"
    for g in "$GOLDEN"/render_*_*.ppm; do
        [ -f "$g" ] || continue
        b=$(basename "$g" .ppm); b=${b#render_}
        st=${b%_*} tick=${b##*_}
        demo=$DEMOS/$st.rsr
        if [ ! -f "$demo" ] || [ "$tick" -lt 1 ]; then
            echo "$st,$tick,,no-demo,,,,,,,,,,,," >>"$G"
            continue
        fi
        dims=$(head -c 40 "$g" | tr -c '0-9P' ' ' | awk '{ print $2 "x" $3 }')
        fr=$tmp/g_${st}_$tick.y4m
        # the goldens are drawn with every knob at full: --quality high gives those knobs (the size is given)
        run_timed 5 "$(left)" "$tmp/o" "$tmp/e" "$RS" render "$demo" --ticks $((tick - 1)):"$tick" --quality high --render-size "$dims" \
            --size "$dims" --capture sequential --downscale cpu --quiet -y -o "$fr"
        if [ "$RC" -ne 0 ]; then
            [ "$RC" -eq 125 ] && nskip=$((nskip + 1)) || nbad=$((nbad + 1))
            echo "$st,$tick,$((tick - 1)):$tick,$(rc_word "$RC"),$WALL,,,,,,,,,,," >>"$G"
            printf '  %-10s %5s  %s: %s\n' "$st" "$tick" "$(rc_word "$RC")" "$(first_error "$tmp/e")" >>"$SUM"
            continue
        fi
        read -r py pb pr pa off mx <<<"$(y4m_psnr "$g" "$fr" 2>&1 | tail -n 1)"
        if [ "$py" = "error:" ]; then
            nbad=$((nbad + 1))
            echo "$st,$tick,$((tick - 1)):$tick,compare-failed,$WALL,,,,,,,,,,," >>"$G"
            printf '  %-10s %5s  comparison failed: %s %s %s %s\n' "$st" "$tick" "$pb" "$pr" "$pa" "$off" >>"$SUM"
            continue
        fi
        verdict=$(awk -v p="$py" -v o="$off" 'BEGIN { print ((p == "inf" || p + 0 >= 30) && o + 0 <= 1) ? "within" : "OUTSIDE" }')
        [ "$verdict" = within ] || nbad=$((nbad + 1))
        ng=$((ng + 1))
        rpy="" rpa="" rmx="" rid=""
        if [ -n "$REF" ] && [ -f "$REF/${st}_$tick.y4m" ]; then
            if cmp -s "$REF/${st}_$tick.y4m" "$fr"; then rid=yes; else rid=no; fi
            read -r rpy _ _ rpa _ rmx <<<"$(y4m_psnr "$REF/${st}_$tick.y4m" "$fr" 2>&1 | tail -n 1)"
            [ "$rpy" != "error:" ] || rpy="" rpa="" rmx=""
        fi
        [ -z "${CAMPAIGN_SAVE_FRAMES:-}" ] || cp "$fr" "$CAMPAIGN_SAVE_FRAMES/${st}_$tick.y4m"
        echo "$st,$tick,$((tick - 1)):$tick,ok,$WALL,$py,$pb,$pr,$pa,$off,$mx,$verdict,$rpy,$rpa,$rmx,$rid" >>"$G"
        printf '  %-10s %5s %8s %8s %8s %8s %7s %5s  %s%s\n' "$st" "$tick" "$py" "$pb" "$pr" "$pa" "$off" "$mx" \
            "$verdict" "$([ -n "$rid" ] && echo "; vs ref: Y $rpy dB, identical $rid")" >>"$SUM"
    done
    say "What a difference means: the goldens are llvmpipe's pictures and are not exact across drivers"
    say "(docs/testing.md).  On a GPU, 35-60 dB with a few pixels off is expected rasteriser, texture"
    say "filtering and fp16 rounding difference at edges and highlights, inside the tolerance.  Under 30 dB,"
    say "or more than 1% of pixels far off, means a real difference: a missing fighter, a wrong camera,"
    say "shadow or effect, an overflow to Inf/NaN the clamps should stop (docs/accuracy.md), or a history"
    say "that depends on the driver (denormals, docs/effects.md).  Compare with the llvmpipe dry run's"
    say "numbers (docs/benchmarks.md, or the ref_ columns): what llvmpipe already loses is not the GPU's."
    step_end "$ng compared, $nbad outside/failed, $nskip skipped"
fi

# ==== 4. capture: async vs sequential at three sizes ====
C=$report/capture.csv
if step_begin capture 15 26; then
    say "bench capture, $CAP_RUNS runs per configuration (medians), sink $SINK (docs/capture.md)."
    # bench capture reads $RINGSIDE_DATA/demos/dojo.rsr; a data folder
    # without demos/ (not the bundle's: it has them) is lent one
    data=${RINGSIDE_DATA:-}
    [ -n "$data" ] || [ ! -d "$(dirname "$RS")/share/ringside/shaders" ] || data=$(dirname "$RS")/share/ringside
    if [ -n "$data" ] && [ ! -f "$data/demos/dojo.rsr" ] && [ -f "$DEMOS/dojo.rsr" ]; then
        mkdir -p "$tmp/data"
        abs=$(cd "$data" && pwd)
        for d in "$abs"/*; do ln -s "$d" "$tmp/data/$(basename "$d")"; done
        ln -s "$(cd "$DEMOS" && pwd)" "$tmp/data/demos"
        data=$tmp/data
        log "RINGSIDE_DATA=$data for bench capture ($abs has no demos/; demos from $DEMOS)"
    fi
    ratios=""
    hdr=0 todo=3
    for c in $CAP_CASES; do
        IFS=: read -r src dst frames <<<"$c"
        run_timed 10 "$(share "$todo")" "$tmp/o" "$tmp/e" \
            env ${data:+RINGSIDE_DATA="$data"} "$RS" bench capture \
            --frames "$frames" --runs "$CAP_RUNS" --render-size "$src" --size "$dst" --sink "$SINK" \
            --csv "$tmp/cap.csv" --chart "" --quiet -y
        if [ "$RC" -ne 0 ] || [ ! -s "$tmp/cap.csv" ]; then
            say "$src -> $dst: $(rc_word "$RC") after ${WALL} s: $(first_error "$tmp/e")"
            ratios="$ratios $src->$dst:$(rc_word "$RC")"
            rm -f "$tmp/cap.csv"
            todo=$((todo - 1))
            continue
        fi
        if [ "$hdr" -eq 0 ]; then echo "case,$(head -n 1 "$tmp/cap.csv")" >"$C"; hdr=1; fi
        tail -n +2 "$tmp/cap.csv" | sed "s/^/$src->$dst,/" >>"$C"
        r=$(awk -F, '$1 == "sequential" { s = $2 } $1 == "async pbo2 q120" { a = $2 } $1 ~ /^async/ && $2 > best { best = $2; bn = $1 }
            END { if (s > 0) printf "%.2f %.2f %s", a / s, best / s, bn; else print "- - -" }' "$tmp/cap.csv")
        read -r rd rb bn <<<"$r"
        say ""
        say "$src -> $dst, $frames frames (${WALL} s): async (pbo 2, queue 120) / sequential = ${rd}x; best async ($bn) / sequential = ${rb}x"
        sed 's/^/  /' "$tmp/o" >>"$SUM"
        ratios="$ratios $src->$dst:${rd}x"
        rm -f "$tmp/cap.csv"
        todo=$((todo - 1))
    done
    step_end "async/seq$ratios"
fi

# ==== 5. replay-to-video speed per stage ====
S=$report/stages.csv
echo "kind,stage,ticks,video_s,output,args,status,wall_s,frames,fps,x_realtime,bytes,note" >"$S"
# What a render run gave (after run_timed): R_FRAMES R_FPS R_X (x real
# time) R_BYTES R_NOTE.  A run cut by its timeout still has a speed: the
# frames its --progress-fd said were done, over its wall time.
render_result() { # TICKS OUTFILE
    local done_
    R_FRAMES="" R_FPS="" R_X="-" R_BYTES="" R_NOTE=""
    [ ! -f "$2" ] || R_BYTES=$(wc -c <"$2")
    if [ "$RC" -eq 0 ]; then
        R_FRAMES=$(render_frames "$tmp/e") R_FPS=$(render_fps "$tmp/e")
        [ -n "$R_FRAMES" ] || R_FRAMES=$1
        R_X=$(xrt "$R_FRAMES" "$WALL")
    elif [ "$RC" -eq 124 ]; then
        done_=$(sed -n 's/^frames \([0-9][0-9]*\) .*/\1/p' "$tmp/progress" | tail -n 1)
        if [ -n "$done_" ] && [ "$done_" -gt 0 ]; then
            R_FRAMES=$done_ R_X=$(xrt "$done_" "$WALL")
            R_FPS=$(awk -v f="$done_" -v s="$WALL" 'BEGIN { printf "%.1f", f / s }')
            R_NOTE="cut by the time limit after $done_ of $1 frames: speed of the part done, start-up included"
        else
            R_X="<$(xrt "$1" "$WALL")"
            R_NOTE="cut by the time limit before the first frame"
        fi
    else
        R_NOTE=$(first_error "$tmp/e")
    fi
}
speed_row() { # KIND STAGE TICKS OUTPUT ARGS OUTFILE
    render_result "$3" "$6"
    echo "$1,$2,$3,$(awk -v t="$3" 'BEGIN { printf "%.2f", t / 60 }'),$4,$5,$(rc_word "$RC"),$WALL,$R_FRAMES,$R_FPS,$R_X,$R_BYTES,$R_NOTE" >>"$S"
    printf '  %-10s %6s ticks %-9s %-16s %7s s %8s fps  %7s x real time%s\n' "$2" "$3" "$4" "$(rc_word "$RC")" "$WALL" \
        "${R_FPS:--}" "$R_X" "${R_NOTE:+ ($R_NOTE)}" >>"$SUM"
}
# the ticks a run renders: the demo's length, or B-A of --ticks A:B
run_ticks() { # DEMO ARGS...
    local demo=$1 t
    shift
    while [ $# -gt 0 ]; do
        if [ "$1" = --ticks ]; then t=$2; echo $((${t#*:} - ${t%%:*})); return; fi
        shift
    done
    ticks_of "$demo"
}
if step_begin stages 10 28; then
    say "Each demo, default options unless listed, to /dev/null (render + GPU downscale + async capture, no"
    say "encoder); wall time of the whole command (start-up, shader compile, lighting prefilter included)."
    say "args: ${SPEED_ARGS[*]:-(defaults: 1280x720 drawn, 640x360 written)}"
    n=0 nok=0 todo=0
    for demo in "$DEMOS"/*.rsr; do
        [ ! -f "$demo" ] || todo=$((todo + $(run_ticks "$demo" "${SPEED_ARGS[@]}")))
    done
    for demo in "$DEMOS"/*.rsr; do
        [ -f "$demo" ] || continue
        st=$(basename "$demo" .rsr)
        t=$(run_ticks "$demo" "${SPEED_ARGS[@]}")
        # the step's time left shared by length: a demo twice as long may take twice as long
        run_timed 5 "$(awk -v l="$(left)" -v t="$t" -v all="$todo" 'BEGIN { print int(all > 0 ? l * t / all : l) }')" \
            "$tmp/o" "$tmp/e" "$RS" render "$demo" -o /dev/null --progress-fd 3 "${SPEED_ARGS[@]}"
        todo=$((todo - t))
        speed_row speed "$st" "${t:-0}" /dev/null "${SPEED_ARGS[*]}" /nonexistent
        n=$((n + 1))
        [ "$RC" -ne 0 ] || nok=$((nok + 1))
    done
    step_end "$nok of $n demos rendered"
fi

# ==== 6. per-pass timings ====
P=$report/passes.csv
echo "stage,ticks,pass,runs,skipped,gpu_ms,gpu_max_ms,cpu_ms" >"$P"
if step_begin passes 10 10; then
    say "render --passes --ticks $PASS_TICKS ${PASS_SIZE[*]:-(default sizes)} per stage (docs/renderer.md): ms per frame:"
    n=0 nok=0
    set -- "$DEMOS"/*.rsr
    todo=$#
    for demo in "$@"; do
        [ -f "$demo" ] || continue
        st=$(basename "$demo" .rsr)
        run_timed 5 "$(share "$todo")" "$tmp/o" "$tmp/e" "$RS" render "$demo" --passes --ticks "$PASS_TICKS" -o /dev/null \
            "${PASS_SIZE[@]}"
        todo=$((todo - 1))
        n=$((n + 1))
        if [ "$RC" -ne 0 ]; then
            say "  $st: $(rc_word "$RC") after ${WALL} s: $(first_error "$tmp/e")"
            continue
        fi
        nok=$((nok + 1))
        [ "$nok" -gt 1 ] || say "  ($(grep -m 1 '^passes' "$tmp/e" | cut -c1-160))"
        # the table is on stderr
        awk -v st="$st" -v tk="$PASS_TICKS" 'NF == 6 && $2 ~ /^[0-9]+$/ { printf "%s,%s,%s,%s,%s,%s,%s,%s\n", st, tk, $1, $2, $3, $4, $5, $6 }
            $1 == "total" { printf "%s,%s,total,,,%s,,%s\n", st, tk, $2, $3 }' "$tmp/e" >>"$P"
        awk -v st="$st" 'NF == 6 && $2 ~ /^[0-9]+$/ && $2 > 0 { ran = ran " " $1 "=" $4 }
            $1 == "total" { tot = $2; cpu = $3 }
            END { printf "  %-10s total %s ms (cpu %s):%s\n", st, tot, cpu, ran }' "$tmp/e" >>"$SUM"
    done
    step_end "$nok of $n stages"
fi

# ==== 7. fp16 stress looks ====
# test_render/stress_no_nan_or_inf's cases (docs/accuracy.md), as stage
# files on dojo@1200 (the sun on screen, every pass runs), in both HDR
# formats.  The test also reads the HDR, bloom, shadow and silhouette
# buffers back for NaN/Inf; the CLI shows only the picture, so here a case
# passes when it renders and its middle band has the level the light says,
# as in the test (black: mean RGB level < 8; white: > 150).
F=$report/fp16.csv
echo "case,hdr_format,status,wall_s,mean_rgb_middle,min_y,max_y,expect,verdict" >"$F"
# stress_stage NAME SUN SKY GAMMA SAT EXPOSURE BLOOM: dojo.stage with these
# (-1: keep); SKY sets sky, ground and the key and counter lights
stress_stage() {
    awk -v sun="$2" -v sky="$3" -v gam="$4" -v sat="$5" -v ex="$6" -v bl="$7" '
    { line = $0; sub(/#.*/, "", line); k = line; sub(/[ \t]*=.*/, "", k); gsub(/[ \t]/, "", k) }
    k == "sun_intensity" && sun >= 0 { next }
    (k == "sky_zenith" || k == "sky_horizon" || k == "ground") && sky >= 0 { next }
    (k == "key_light" || k == "counter_light") && sky >= 0 {
        v = line; sub(/^[^=]*=/, "", v); n = split(v, f, " "); f[7] = sky
        s = k " ="; for (i = 1; i <= n; i++) s = s " " f[i]; print s; next
    }
    k == "gamma" || k == "saturation" || k == "exposure" || k == "bloom" { next }
    { print }
    END {
        if (sun >= 0) print "sun_intensity = " sun
        if (sky >= 0) { print "sky_zenith = " sky " " sky " " sky; print "sky_horizon = " sky " " sky " " sky
                        print "ground = " sky " " sky " " sky }
        print "gamma = " gam; print "saturation = " sat; print "exposure = " ex; print "bloom = " bl
    }' "$STAGES/dojo.stage" >"$tmp/$1.stage"
}
if step_begin fp16 10 6; then
    if [ -z "$STAGES" ]; then
        say "no stages/dojo.stage found (cwd, \$RINGSIDE_DATA, the bundle): cannot make the stress looks"
        step_end "no stage files"
    else
        say "test_render/stress_no_nan_or_inf's looks on dojo@1200 (docs/accuracy.md) as stage files, ${FP16_SIZE[*]};"
        say "mean RGB level of the middle band (0..255) as the test reads it: black < 8, white > 150; and the band's"
        say "luma range (16 black .. 235 white).  The test also checks the HDR"
        say "buffers for NaN/Inf, which the CLI cannot read: a GPU may store Inf where llvmpipe clamps."
        # name sun sky gamma saturation exposure bloom expect
        cases="sun-65504:65504:-1:2.2:1:1:0.35:any sun-0:0:-1:2.2:1:1:0.35:any black-world:0:0:2.2:1:1:0.35:black
white-world-65504:65504:65504:2.2:1:1:10:white gamma-0.1:-1:-1:0.1:1:1:0.35:any gamma-10:-1:-1:10:1:1:0.35:any
saturation-0:-1:-1:2.2:0:1:0.35:any saturation-10:-1:-1:2.2:10:1:0.35:any exposure-1000:-1:-1:2.2:1:1000:0.35:white
exposure-0.001:-1:-1:2.2:1:0.001:0.35:black"
        n=0 nok=0 nruns=$(($(echo $FP16_FORMATS | wc -w) * 10))
        for fmt in $FP16_FORMATS; do
            for c in $cases; do
                IFS=: read -r name sun sky gam sat ex bl expect <<<"$c"
                stress_stage "$name" "$sun" "$sky" "$gam" "$sat" "$ex" "$bl"
                fr=$tmp/fp16.y4m
                rm -f "$fr"
                run_timed 4 "$(share $((nruns - n)))" "$tmp/o" "$tmp/e" "$RS" render "$DEMOS/dojo.rsr" --ticks 1199:1200 --stage-file "$tmp/$name.stage" \
                    --hdr-format "$fmt" "${FP16_SIZE[@]}" --quiet -o "$fr"
                n=$((n + 1))
                if [ "$RC" -ne 0 ]; then
                    echo "$name,$fmt,$(rc_word "$RC"),$WALL,,,,$expect,FAIL" >>"$F"
                    printf '  %-18s %-10s %s: %s\n' "$name" "$fmt" "$(rc_word "$RC")" "$(first_error "$tmp/e")" >>"$SUM"
                    continue
                fi
                read -r mean lo hi <<<"$(y4m_band "$fr")"
                v=$(awk -v m="$mean" -v e="$expect" 'BEGIN { if (m == "-") print "FAIL"; else if (e == "black") print (m < 8 ? "ok" : "FAIL");
                    else if (e == "white") print (m > 150 ? "ok" : "FAIL"); else print "ok" }')
                [ "$v" != ok ] || nok=$((nok + 1))
                echo "$name,$fmt,ok,$WALL,$mean,$lo,$hi,$expect,$v" >>"$F"
                printf '  %-18s %-10s rgb mean %6s  Y %3s..%3s  expect %-5s %s\n' "$name" "$fmt" "$mean" "$lo" "$hi" "$expect" "$v" >>"$SUM"
            done
        done
        say "(bench accuracy has no fp16 table; its capture table needs OpenImageIO, which the bundle leaves out)"
        step_end "$nok of $n ok"
    fi
fi

# ==== 8. movie upload ====
if step_begin upload 8 4; then
    run_timed 5 "$(left)" "$tmp/o" "$tmp/e" "$RS" bench upload --quiet "${UPLOAD_ARGS[@]}"
    say "bench upload ${UPLOAD_ARGS[*]:-(defaults)} (docs/player.md): $(rc_word "$RC") in ${WALL} s"
    if [ "$RC" -eq 0 ]; then sed 's/^/  /' "$tmp/o" >>"$SUM"; else say "  $(first_error "$tmp/e")"; fi
    step_end "$(rc_word "$RC")"
fi

# ==== 9. one full demo to .mp4 ====
if step_begin full-mp4 10 10; then
    say "demos/dojo.rsr, default options, to .mp4 (H.264, libx264): the service's main job."
    say "args: ${FULL_ARGS[*]:-(defaults)}"
    demo=$DEMOS/dojo.rsr
    t=$(run_ticks "$demo" "${FULL_ARGS[@]}")
    run_timed 10 "$(left)" "$tmp/o" "$tmp/e" "$RS" render "$demo" -o "$tmp/dojo.mp4" --progress-fd 3 "${FULL_ARGS[@]}"
    speed_row full-mp4 dojo "${t:-0}" .mp4 "${FULL_ARGS[*]}" "$tmp/dojo.mp4"
    rm -f "$tmp/dojo.mp4"
    step_end "$(rc_word "$RC"), $R_X x real time"
fi

# ==== 10. one demo per encoder / output ====
E=$report/encoders.csv
echo "output,encoder,stage,ticks,args,status,wall_s,frames,fps,x_realtime,bytes,note" >"$E"
if step_begin encoders 10 8; then
    say "demos/temple.rsr (the shortest) per output, ${ENC_ARGS[*]:-default options}:"
    demo=$DEMOS/temple.rsr
    t=$(run_ticks "$demo" "${ENC_ARGS[@]}")
    n=0 nok=0 nhw=0 nhw_ok=0
    # ext:label:render options; NVENC asked for by name (--hw nvenc fails
    # plainly where there is none), the software encoders by --hw off
    specs=(mp4:libx264:--hw,off webm:libvpx-vp9:--hw,off y4m:ringside:
           mp4:h264_nvenc:--hw,nvenc,--codec,h264 mp4:hevc_nvenc:--hw,nvenc,--codec,hevc
           mp4:av1_nvenc:--hw,nvenc,--codec,av1 mp4:auto:--codec,hevc)
    for spec in "${specs[@]}"; do
        ext=${spec%%:*} rest=${spec#*:}
        enc=${rest%%:*} opts=${rest#*:}
        IFS=, read -r -a extra <<<"$opts"
        out=$tmp/enc.$ext
        rm -f "$out"
        run_timed 5 "$(share $((${#specs[@]} - n - nhw)))" "$tmp/o" "$tmp/e" "$RS" render "$demo" -o "$out" --progress-fd 3 \
            "${extra[@]}" "${ENC_ARGS[@]}"
        render_result "${t:-0}" "$out"
        used=$(sed -n 's/.*wrote .*; encoder \([^ ]*\)$/\1/p' "$tmp/e" | tail -n 1)
        echo ".$ext,$enc${used:+ ($used)},temple,${t:-},${extra[*]} ${ENC_ARGS[*]},$(rc_word "$RC"),$WALL,$R_FRAMES,$R_FPS,$R_X,$R_BYTES,$R_NOTE" >>"$E"
        printf '  .%-5s %-12s %-16s %-16s %7s s %8s fps %7s x real time %10s bytes%s\n' "$ext" "$enc" "${used:--}" "$(rc_word "$RC")" \
            "$WALL" "${R_FPS:--}" "$R_X" "${R_BYTES:--}" "${R_NOTE:+ ($R_NOTE)}" >>"$SUM"
        rm -f "$out"
        # NVENC is counted apart: on a machine without NVIDIA it fails by design
        case "$opts" in
        *nvenc*) nhw=$((nhw + 1)); [ "$RC" -ne 0 ] || nhw_ok=$((nhw_ok + 1)) ;;
        *) n=$((n + 1)); [ "$RC" -ne 0 ] || nok=$((nok + 1)) ;;
        esac
    done
    if [ -e /dev/nvidia0 ]; then hw="nvenc $nhw_ok/$nhw"; else hw="nvenc: no /dev/nvidia0"; fi
    step_end "$nok of $n outputs; $hw"
fi

# ==== the end ====
current=end
say ""
say "== steps ($MODE; ${SECONDS} s of the ${BUDGET} s budget)"
for l in "${STEP_LINES[@]}"; do say "  $l"; done
[ "$IS_GPU" = yes ] || say "  (NOT a GPU run: the numbers above are llvmpipe's, a dry run)"
say ""
files=""
for f in "$report"/*; do [ ! -f "$f" ] || files="$files $(basename "$f")"; done
say "files:$files"
log "campaign done in ${SECONDS} s"
echo "gpu-campaign: done in ${SECONDS} s; report in $report/summary.txt" >&2
exit 0
}
