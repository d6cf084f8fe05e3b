#!/bin/sh
# The dashboard in a real browser: headless Chromium (Debian's), driven by
# playwright-core (tests/service/dashboard.mjs), uploads a replay, watches
# the progress bar reach done and plays the video, with the form's encoder
# options, and checks that nothing scrolls sideways at 1280x800 and 390x844
# (the phone screenshot): once on a loopback daemon
# that needs no token, once on one that does (the token form, a refused
# token, the job watched live while it renders, through hls.js with the
# token, then the video from a blob: URL, reload, "forget token", a 429).
# Both times the list must come by push (GET /jobs/events).  Screenshots
# land in $RS_TEST_OUT/dashboard*.png.
here=$(cd "$(dirname "$0")/.." && pwd)
: "${RS_BIN:=$(dirname "$here")/build/ringside}"
. "$here/lib.sh"
. "$here/service/svc_lib.sh"
trap 'exit 143' TERM INT HUP

# node, Chromium and playwright-core, or the case is skipped (sets chromium)
need_browser() {
    command -v node >/dev/null 2>&1 || t_skip_install "node is not installed (the browser test runs playwright-core on Node.js)"
    chromium=$(command -v chromium) || t_skip_install "chromium is not installed (tools/deps.sh service installs it)"
    if [ ! -d "$here/service/node_modules/playwright-core" ]; then
        (cd "$here/service" && npm ci --no-audit --no-fund --loglevel=error) >npm.log 2>&1 ||
            { cat npm.log; echo "npm ci failed (the npm registry must be reachable)"; return 1; }
    fi
}

t_upload_progress_and_watch() {
    need_browser || return 1
    "$RS_BIN" record --ai --quiet --seconds 5 --seed 12 --stage temple -o match.rsr || return 1
    svc_start d $SVC_FAST --render-size 320x180 --max-size 640x360 || return 1
    shot=${RS_TEST_OUT:-.}/dashboard.png phone=${RS_TEST_OUT:-.}/dashboard-phone.png
    node "$here/service/dashboard.mjs" --url "$SVC_URL" --replay match.rsr --size 320x180 --format webm \
        --shot "$shot" --phone-shot "$phone" --chromium "$chromium" --timeout 120 || { tail -20 d.log; return 1; }
    [ -s "$shot" ] && [ -s "$phone" ] || { echo "no screenshots"; return 1; }
    svc_stop
}

t_token_form_list_and_watch() {
    need_browser || return 1
    # 12 s at the standard quality, one worker, a 2 s first segment: the
    # job renders for a while after its first piece, which is watched live
    "$RS_BIN" record --ai --quiet --seconds 12 --seed 12 --stage temple -o match.rsr || return 1
    tok=$("$RS_BIN" serve token add alice --data d 2>add.err) || { cat add.err; return 1; }
    # any upload of more than 1 s of game passes this one's quota
    quota=$("$RS_BIN" serve token add bob --seconds-per-hour 1 --data d 2>add.err) || { cat add.err; return 1; }
    svc_start d $SVC_FAST --render-size 320x180 --max-size 640x360 --workers 1 --first-segment-seconds 2 || return 1
    grep -q "API tokens required" d.log || { cat d.log; return 1; }
    out=${RS_TEST_OUT:-.}
    node "$here/service/dashboard.mjs" --url "$SVC_URL" --replay match.rsr --size 320x180 --format mp4 --live --live-shot "$out/dashboard-live.png" \
        --token "$tok" --quota-token "$quota" --form-shot "$out/dashboard-token-form.png" --shot "$out/dashboard-token-list.png" \
        --chromium "$chromium" --timeout 120 >node.log 2>&1 || { tail -8 d.log; cat node.log; return 1; }
    cp node.log "$out/dashboard-token.txt"
    [ -s "$out/dashboard-token-form.png" ] && [ -s "$out/dashboard-token-list.png" ] && [ -s "$out/dashboard-live.png" ] ||
        { echo "no screenshots"; return 1; }
    svc_stop
}

t_run upload_progress_and_watch
t_run token_form_list_and_watch
t_done
