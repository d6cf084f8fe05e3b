#!/usr/bin/env node
// Browser test of the `ringside serve` dashboard (service/dashboard.html).
//
//   node tests/service/dashboard.mjs --url http://127.0.0.1:PORT --replay FILE.rsr \
//        --shot OUT.png [--timeout S] [--size WxH] [--format webm|mp4] [--chromium PATH]
//        [--phone-shot PHONE.png] [--token TOKEN --form-shot FORM.png [--quota-token TOKEN2]] [--live [--live-shot LIVE.png]]
//
// Opens the page in headless Chromium, uploads the replay, waits for the job's
// row to reach data-state="done" (failing fast on "failed"/"cancelled"), checks
// the row's <progress> moved, clicks "watch", waits for the <video> to load its
// metadata (videoWidth > 0, duration > 0), saves a full-page screenshot and
// prints one result line.  The form's encoder fields (codec, CRF, preset,
// sound) must reach the job.  At 1280x800, and at 390x844 (a phone; its
// screenshot PHONE.png with --phone-shot), nothing may scroll sideways (the
// page's and the table's scrollWidth <= clientWidth) and every action of the
// job's row must lie inside the window.  Exit 0 on success, 1 on any failure (with the reason),
// 2 on bad usage.
//
// Without --token the daemon must need no token: the page must never show the
// token form, and the player plays the plain /jobs/N/video URL.  With --token
// (a valid token of a daemon that needs one) the page must first show the
// token form instead of the job list; a made-up token must be refused with
// the server's message under the form (screenshot FORM.png); TOKEN must bring
// the list; then the upload as above, the video from a blob: URL, the hashes
// download; a reload must keep the token, and "forget token" bring the form back.
// With --quota-token (a token whose quota any upload passes, of another name)
// that token must then see an empty list (not TOKEN's job) and the upload's
// 429 message must show as the upload's error.
//
// The job list must come by push: once the page has opened GET /jobs/events,
// it must not poll GET /jobs while the job renders.  With --live (an mp4
// job, quality standard, on a daemon that splits it with a 2 s first
// segment), "watch live" must show while the job runs, and the player must
// play the live stream (hls.js, with the token when there is one) past its
// first 2 s piece before the job is done (screenshot LIVE.png then); when the
// job is done the finished video must take over at the second the live
// stream had reached, and "watch" then plays it.
//
// Needs playwright-core (cd tests/service && npm ci) and a Chromium binary
// (default /usr/bin/chromium, Debian's; or $CHROMIUM / --chromium).  The default
// format is webm (VP9): every Chromium build plays it, while H.264 mp4 needs a
// build with proprietary codecs (Debian's has them; Playwright's own does not).

import fs from 'node:fs';
import path from 'node:path';

const USAGE = 'usage: node tests/service/dashboard.mjs --url URL --replay FILE --shot OUT.png ' +
  '[--timeout S] [--size WxH] [--format webm|mp4] [--chromium PATH] [--phone-shot PHONE.png] ' +
  '[--token TOKEN --form-shot FORM.png [--quota-token TOKEN2]] [--live [--live-shot LIVE.png]]';

function parseArgs(argv) {
  const o = { timeout: 120, size: '320x180', format: 'webm', chromium: process.env.CHROMIUM || '/usr/bin/chromium' };
  const keys = new Set(['url', 'replay', 'shot', 'timeout', 'size', 'format', 'chromium', 'token', 'form-shot', 'quota-token', 'phone-shot', 'live-shot']);
  for (let i = 0; i < argv.length; i++) {
    let a = argv[i], v;
    if (a === '-h' || a === '--help') { console.log(USAGE); process.exit(0); }
    if (a === '--live') { o.live = true; continue; }
    if (!a.startsWith('--')) usage(`unexpected argument '${a}'`);
    a = a.slice(2);
    const eq = a.indexOf('=');
    if (eq >= 0) { v = a.slice(eq + 1); a = a.slice(0, eq); } else v = argv[++i];
    if (!keys.has(a)) usage(`unknown option --${a}`);
    if (v === undefined) usage(`--${a} needs a value`);
    o[a] = v;
  }
  for (const k of ['url', 'replay', 'shot']) if (!o[k]) usage(`--${k} is required`);
  if (!o.token !== !o['form-shot']) usage('--token and --form-shot go together');
  if (o['quota-token'] && !o.token) usage('--quota-token needs --token');
  if (o.live && o.format !== 'mp4') usage('--live needs --format mp4 (the live stream is H.264)');
  o.timeout = Number(o.timeout);
  if (!(o.timeout > 0)) usage('--timeout must be a positive number of seconds');
  if (!/^\d+x\d+$/.test(o.size)) usage('--size must be WxH');
  o.url = o.url.replace(/\/+$/, '');
  return o;
}
function usage(msg) { console.error(`dashboard: ${msg}\n${USAGE}`); process.exit(2); }

class Fail extends Error {}
const fail = (msg) => { throw new Fail(msg); };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// the page's state as the test sees it
const visible = (page, sel) => page.locator(sel).isVisible();
// each of these steps takes well under a second when it works
const STEP_MS = 15_000;
async function waitFor(page, what, cond, ctx, detail) {
  const end = Date.now() + STEP_MS;
  for (;;) {
    ctx.checkPageErrors();
    ctx.checkTime(`waiting for ${what}`);
    if (Date.now() > end) fail(`${what}: not within ${STEP_MS / 1000} s${detail ? ` (${detail()})` : ''}`);
    if (await cond()) return;
    await sleep(100);
  }
}
const randomToken = () => 'rs_' + Array.from({ length: 43 }, () =>
  'ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789-_'[Math.floor(Math.random() * 64)]).join('');

// the token form, as a first visit to a daemon that needs a token meets it
async function tokenForm(page, opt, ctx) {
  await waitFor(page, 'the token form', () => visible(page, '#token-section'), ctx);
  for (const sel of ['#upload-section', '#jobs-section', '#player-section', '#token-forget']) {
    if (await visible(page, sel)) fail(`${sel} shows beside the token form`);
  }
  if (await page.getAttribute('#token-input', 'type') !== 'password') fail('#token-input is not a password field');
  // a made-up token: refused, with the server's message, and not kept
  await page.fill('#token-input', randomToken());
  await page.click('#token-save');
  await waitFor(page, 'the refusal of a made-up token',
    async () => /unknown token/.test(await page.textContent('#token-error')), ctx);
  if (!(await visible(page, '#token-section')) || await visible(page, '#jobs-section')) {
    fail('a made-up token took the token form away');
  }
  if (await page.evaluate(() => localStorage.getItem('ringside.token')) !== null) fail('the refused token was kept');
  fs.mkdirSync(path.dirname(path.resolve(opt['form-shot'])), { recursive: true });
  await page.screenshot({ path: opt['form-shot'], fullPage: true });
  // the right one: the list comes, the token is kept
  await page.fill('#token-input', opt.token);
  await page.click('#token-save');
  await waitFor(page, 'the job list after saving the token',
    async () => await visible(page, '#jobs-section') && !(await visible(page, '#token-section')), ctx);
  if (!(await visible(page, '#token-forget'))) fail('no visible "forget token" with a token stored');
  if (await page.evaluate(() => localStorage.getItem('ringside.token')) !== opt.token) fail('the token was not stored');
}

// reload keeps the token (the job's row comes back), "forget token" brings the form back
async function reloadAndForget(page, id, ctx) {
  await page.reload({ waitUntil: 'load' });
  await waitFor(page, `job ${id}'s row after a reload`,
    () => page.locator(`#jobs tr[data-job-id="${id}"]`).isVisible(), ctx);
  if (await visible(page, '#token-section')) fail('the token form shows after a reload');
  await page.click('#token-forget');
  await waitFor(page, 'the token form after "forget token"', () => visible(page, '#token-section'), ctx);
  if (await page.locator('#jobs tr').count() !== 0) fail('the job list stays after "forget token"');
  if (await visible(page, '#token-forget')) fail('"forget token" still shows with no token');
  if (await page.evaluate(() => localStorage.getItem('ringside.token')) !== null) fail('"forget token" left the token stored');
}

// another token over its quota: its own (empty) list, the 429 as the upload's error
async function overQuota(page, opt, ctx) {
  await page.fill('#token-input', opt['quota-token']);
  await page.click('#token-save');
  await waitFor(page, 'the job list of the quota token', () => visible(page, '#jobs-section'), ctx);
  await waitFor(page, 'the empty list note', () => visible(page, '#empty'), ctx);
  if (await page.locator('#jobs tr').count() !== 0) fail('the quota token sees another token\'s jobs');
  await page.setInputFiles('#upload-file', opt.replay);
  await page.selectOption('#upload-size', opt.size);
  await page.selectOption('#upload-format', opt.format);
  await page.click('#upload-button');
  let st = '';
  await waitFor(page, 'the 429 under the upload', async () => {
    st = await page.textContent('#upload-status');
    if (/queued as job/.test(st)) fail('an upload over the quota was queued');
    return /^HTTP 429: .*quota/.test(st);
  }, ctx, () => `the upload says '${st}'`);
}

// the hashes link with a token: fetched with the header, saved from a blob: URL
async function downloadHashes(page, id) {
  const [dl] = await Promise.all([
    page.waitForEvent('download', { timeout: 10_000 }),
    page.click(`#jobs tr[data-job-id="${id}"] a.download-hashes`),
  ]);
  const file = await dl.path();
  const text = fs.readFileSync(file, 'utf8');
  if (dl.suggestedFilename() !== `job-${id}.hashes.txt` || !/^0 [0-9a-f]{16}\n/.test(text)) {
    fail(`the hashes download of job ${id} is ${dl.suggestedFilename()}: ${text.slice(0, 120)}`);
  }
}

// nothing scrolls sideways, and every action of the row shown is inside the window
async function layoutFits(page, rowSel, what) {
  const m = await page.evaluate((sel) => {
    const de = document.documentElement, wrap = document.querySelector('.table-wrap');
    const tr = document.querySelector(sel);
    const out = [];
    for (const el of tr ? tr.querySelectorAll('td.actions > button, td.actions > a, td.actions summary') : []) {
      if (el.hidden || el.closest('[hidden]')) continue;
      const b = el.getBoundingClientRect();
      if (b.width === 0) continue;
      if (b.left < 0 || b.right > window.innerWidth + 0.5) out.push(`${el.textContent.trim()} at ${Math.round(b.left)}..${Math.round(b.right)}`);
    }
    return { page: [de.scrollWidth, de.clientWidth], table: wrap ? [wrap.scrollWidth, wrap.clientWidth] : null,
      outside: out, width: window.innerWidth, row: !!tr };
  }, rowSel);
  if (!m.row) fail(`${what}: the job's row is gone`);
  if (m.page[0] > m.page[1]) fail(`${what}: the page scrolls sideways (scrollWidth ${m.page[0]} > clientWidth ${m.page[1]})`);
  if (m.table && m.table[0] > m.table[1]) fail(`${what}: the jobs table scrolls sideways (scrollWidth ${m.table[0]} > clientWidth ${m.table[1]})`);
  if (m.outside.length) fail(`${what}: actions outside the ${m.width} px window: ${m.outside.join(', ')}`);
  return m;
}

// while the job runs: "watch live" once it shows, then the player's time
// past the first piece (2 s) with the row still running
async function watchLive(page, rowSel, live) {
  if (!live.clicked) {
    const btn = page.locator(`${rowSel} button.watch`);
    if (!(await btn.isVisible()) || (await btn.textContent()) !== 'watch live') return;
    live.tClick = Date.now();
    await btn.click();
    live.clicked = true;
  }
  const st = await page.evaluate((sel) => {
    const v = document.getElementById('player'), cap = document.getElementById('player-caption');
    return { t: v.currentTime, caption: cap.textContent, error: cap.classList.contains('error'),
      running: (document.querySelector(sel) || {}).dataset?.state === 'running' };
  }, rowSel);
  live.time = st.t;
  live.caption = st.caption;
  if (st.error) fail(`the live player says: ${st.caption}`);
  if (st.t > 2.2 && st.running) {
    live.played = true;
    live.tPlayed = Date.now();
    if (live.shot) await page.screenshot({ path: live.shot, fullPage: true });
  }
}

async function main() {
  const opt = parseArgs(process.argv.slice(2));
  if (!fs.existsSync(opt.replay)) fail(`replay ${opt.replay} not found`);
  if (!fs.existsSync(opt.chromium)) fail(`no Chromium at ${opt.chromium} (use --chromium PATH or $CHROMIUM)`);

  let chromium;
  try {
    ({ chromium } = await import('playwright-core'));
  } catch (e) {
    fail(`cannot load playwright-core (${e.code || e.message}); run: cd tests/service && npm ci`);
  }

  const t0 = Date.now();
  const deadline = t0 + opt.timeout * 1000;
  const left = () => deadline - Date.now();
  const checkTime = (what) => { if (left() <= 0) fail(`timed out after ${opt.timeout} s ${what}`); };

  const browser = await chromium.launch({
    executablePath: opt.chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-dev-shm-usage', '--disable-gpu', '--mute-audio',
      '--autoplay-policy=no-user-gesture-required'],
  });
  const pageErrors = [];
  try {
    const page = await browser.newPage({ viewport: { width: 1280, height: 800 }, acceptDownloads: true });
    page.setDefaultTimeout(Math.max(1000, Math.min(30_000, left())));
    page.on('pageerror', (e) => pageErrors.push(String(e && e.message || e)));
    // the requests the page makes: the list must come by push while the job renders
    const asked = [];
    page.on('request', (r) => {
      const u = new URL(r.url());
      if (r.method() === 'GET' && (u.pathname === '/jobs' || u.pathname === '/jobs/events')) asked.push({ t: Date.now(), path: u.pathname });
    });

    const checkPageErrors = () => { if (pageErrors.length) fail(`JavaScript error in the page: ${pageErrors[0]}`); };
    const ctx = { checkPageErrors, checkTime };

    // 1. open the page
    let resp;
    try {
      resp = await page.goto(opt.url + '/', { waitUntil: 'load', timeout: Math.min(15_000, left()) });
    } catch (e) {
      fail(`cannot open ${opt.url}/: ${e.message.split('\n')[0]}`);
    }
    if (!resp || !resp.ok()) fail(`GET ${opt.url}/ answered ${resp ? resp.status() : 'nothing'}`);
    for (const sel of ['#upload-file', '#upload-size', '#upload-format', '#upload-quality', '#upload-codec', '#upload-crf',
      '#upload-preset', '#upload-audio', '#upload-button', '#upload-status', '#jobs', '#player',
      '#token-section', '#token-input', '#token-save', '#token-error', '#token-forget']) {
      if (await page.locator(sel).count() !== 1) fail(`page has no single ${sel}`);
    }
    if (opt.token) await tokenForm(page, opt, ctx);

    // 2. fill in the form: the size menu offers the server's default, selected, and nothing over its max_size
    const health = await (await page.request.get(opt.url + '/healthz')).json();
    await waitFor(page, 'the size menu built from /healthz', () => page.$eval('#upload-size',
      (s, def) => s.value === def && Array.from(s.options).some((o) => o.value === def && /default/.test(o.textContent)),
      health.default_size), ctx);
    const [mw, mh] = health.max_size.split('x').map(Number);
    for (const v of await page.$$eval('#upload-size option', (os) => os.map((o) => o.value))) {
      const [w, h] = v.split('x').map(Number);
      if (w > mw || h > mh) fail(`the size menu offers ${v}, over max_size ${health.max_size}`);
    }
    // the quality menu: the server's default selected
    await waitFor(page, 'the quality menu set from /healthz', () => page.$eval('#upload-quality',
      (s, def) => s.value === def, health.default_quality), ctx);
    await page.setInputFiles('#upload-file', opt.replay);
    // draft renders fast; a live watch needs a job that takes a while after its first piece
    const quality = opt.live ? 'standard' : 'draft';
    for (const [sel, val] of [['#upload-size', opt.size], ['#upload-format', opt.format], ['#upload-quality', quality]]) {
      const vals = await page.$$eval(`${sel} option`, (os) => os.map((o) => o.value));
      if (!vals.includes(val)) fail(`${sel} has no option '${val}' (has ${vals.join(', ')})`);
      await page.selectOption(sel, val);
    }
    // the encoder's fields: what the form sends must be what the job gets
    const enc = opt.format === 'webm' ? { codec: 'vp9', crf: '40', preset: '8' } : { codec: 'h264', crf: '30', preset: 'superfast' };
    await page.selectOption('#upload-codec', enc.codec);
    await page.fill('#upload-crf', enc.crf);
    await page.fill('#upload-preset', enc.preset);
    const presets = await page.$$eval('#upload-presets option', (os) => os.map((o) => o.value));
    if (!presets.includes(enc.preset)) fail(`the preset suggestions (${presets.join(', ')}) leave out ${enc.preset}`);
    if (!(await page.isChecked('#upload-audio'))) fail('the sound box is not checked by default');
    const formats = await page.$$eval('#upload-format option', (os) => os.map((o) => o.value));
    if (!formats.includes('mkv')) fail(`the format menu offers ${formats.join(', ')}: no mkv`);
    const high = await page.$eval('#upload-quality option[value="high"]', (o) => o.textContent);
    if (!/2×2/.test(high)) fail(`the high quality option says '${high}', not 2×2`);
    if (opt.format === 'mp4') {
      const can = await page.evaluate(() => document.createElement('video').canPlayType('video/mp4; codecs="avc1.640028"'));
      if (!can) fail('this Chromium cannot play H.264 mp4; use --format webm');
    }
    // record loadedmetadata on the player before anything can load into it
    await page.evaluate(() => {
      const v = document.getElementById('player');
      window.__rsMeta = 0;
      v.addEventListener('loadedmetadata', () => { window.__rsMeta++; });
    });


    // 3. upload, read the job id
    const tUpload = Date.now();
    await page.click('#upload-button');
    let id = null;
    for (;;) {
      checkPageErrors();
      checkTime('waiting for the upload to be accepted');
      const st = await page.$eval('#upload-status', (el) => ({ text: el.textContent.trim(), error: el.classList.contains('error') }));
      const m = /queued as job (\d+)/.exec(st.text);
      if (m) { id = Number(m[1]); break; }
      if (st.error) fail(`upload refused: ${st.text}`);
      await sleep(100);
    }
    const job = await (await page.request.get(`${opt.url}/jobs/${id}`, opt.token ? { headers: { Authorization: `Bearer ${opt.token}` } } : {})).json();
    if (job.quality !== quality) fail(`the job was queued with quality ${job.quality}, not the '${quality}' the form asked for`);
    if (job.codec !== enc.codec || !job.encode.includes(`crf=${enc.crf}`) || !job.encode.includes(`preset=${enc.preset}`)) {
      fail(`the job was queued with codec ${job.codec}, encode '${job.encode}': not the form's ${JSON.stringify(enc)}`);
    }

    // 4. wait for the row to be done, watching its progress bar
    const rowSel = `#jobs tr[data-job-id="${id}"]`;
    let samples = 0, increases = 0, last = null, lastState = null, sawRow = false;
    const live = { clicked: false, played: false, time: 0, caption: '', tClick: 0, tPlayed: 0, shot: opt['live-shot'] };
    for (;;) {
      checkPageErrors();
      if (left() <= 0) {
        fail(`timed out after ${opt.timeout} s waiting for job ${id} to finish (state ${lastState || 'no row'}, ` +
          `progress ${last ? `${last.value}/${last.max}` : '-'})`);
      }
      const row = await page.evaluate((sel) => {
        const tr = document.querySelector(sel);
        if (!tr) return null;
        const bar = tr.querySelector('progress');
        const err = tr.querySelector('td.err');
        return {
          state: tr.dataset.state || '',
          value: bar ? (bar.hasAttribute('value') ? bar.value : null) : undefined,
          max: bar ? bar.max : undefined,
          error: err ? err.textContent.trim() : '',
          text: tr.innerText.replace(/\s+/g, ' ').trim(),
        };
      }, rowSel);
      if (!row) {
        if (!sawRow && Date.now() - tUpload > 10_000) fail(`job ${id} has no row in #jobs after 10 s`);
        await sleep(200);
        continue;
      }
      sawRow = true;
      if (row.value === undefined) fail(`job ${id}'s row has no <progress>`);
      lastState = row.state;
      if (row.value !== null) {
        samples++;
        if (last && last.value !== null && row.value > last.value) increases++;
      }
      last = row;
      if (row.state === 'failed' || row.state === 'cancelled') {
        fail(`job ${id} ${row.state}: ${row.error || '(no error text)'} [row: ${row.text}]`);
      }
      if (opt.live && row.state === 'running' && !live.played) await watchLive(page, rowSel, live);
      if (row.state === 'done') {
        if (opt.live && !live.played) {
          fail(`job ${id} was done before its live stream played past its first piece (${live.clicked ? `clicked "watch live", ` +
            `currentTime ${live.time}, caption '${live.caption}'` : '"watch live" never showed'})`);
        }
        if (!(row.max > 0 && row.value === row.max) && increases === 0) {
          fail(`job ${id} is done but its progress bar never moved (value ${row.value}, max ${row.max})`);
        }
        break;
      }
      await sleep(250);
    }
    const tDone = Date.now();
    // pushed, not polled: after the event stream opened, at most one list poll (one in flight as it opened)
    const opened = asked.find((a) => a.path === '/jobs/events');
    if (!opened) fail('the page never opened GET /jobs/events');
    const polls = asked.filter((a) => a.path === '/jobs' && a.t > opened.t && a.t >= tUpload && a.t <= tDone).length;
    if (polls > 1) fail(`the page polled GET /jobs ${polls} times while job ${id} rendered, with its event stream open`);

    // the live player takes the finished video by itself, at the second it had reached
    if (opt.live) {
      let st = null;
      await waitFor(page, 'the finished video to take over from the live stream', async () => {
        st = await page.evaluate(() => ({ cap: document.getElementById('player-caption').textContent,
          t: document.getElementById('player').currentTime, d: document.getElementById('player').duration }));
        return /· \d+\.\d\d s$/.test(st.cap);
      }, ctx, () => `caption '${st && st.cap}'`);
      if (!(st.t >= 2) || Math.abs(st.d - job.length_s) > 0.1) {
        fail(`the finished video took over at ${st.t} s of ${st.d} s: not where the live stream was (past 2.2 s) in the ${job.length_s} s video`);
      }
    }

    // 5. watch it (the finished video)
    await page.evaluate(() => { window.__rsMeta = 0; });
    await page.click(`${rowSel} button.watch`);
    let meta = null;
    for (;;) {
      checkPageErrors();
      checkTime(`waiting for job ${id}'s video to load`);
      meta = await page.evaluate(() => {
        const v = document.getElementById('player');
        const cap = document.getElementById('player-caption');
        return { fired: window.__rsMeta, w: v.videoWidth, h: v.videoHeight, d: v.duration, src: v.currentSrc,
          err: v.error ? `code ${v.error.code} ${v.error.message || ''}`.trim() : null,
          capErr: cap.classList.contains('error') ? cap.textContent : null };
      });
      if (meta.err) fail(`the player cannot load ${meta.src}: ${meta.err}`);
      if (meta.capErr) fail(`the player says: ${meta.capErr}`);
      if (meta.fired > 0 && meta.w > 0 && meta.d > 0) break;
      await sleep(100);
    }
    if (opt.token) {
      if (!meta.src.startsWith('blob:')) fail(`with a token the player loaded ${meta.src}, not a blob: URL`);
      await downloadHashes(page, id);
    } else {
      if (!/\/jobs\/\d+\/video$/.test(new URL(meta.src).pathname)) fail(`the player loaded ${meta.src}, not /jobs/${id}/video`);
      if (await visible(page, '#token-section') || await visible(page, '#token-forget')) {
        fail('the token form or "forget token" shows on a daemon that needs no token');
      }
    }

    // 6. what the row shows of the job: poster, match, output, render time, the log
    await waitFor(page, `job ${id}'s poster thumbnail`, () => page.$eval(`${rowSel} img.poster`,
      (im) => !im.hidden && im.complete && im.naturalWidth > 0), ctx);
    const row = await page.$eval(rowSel, (tr) => ({
      poster: [tr.querySelector('img.poster').naturalWidth, tr.querySelector('img.poster').naturalHeight].join('x'),
      posterSrc: tr.querySelector('img.poster').src,
      match: tr.querySelector('.match').textContent, output: tr.querySelector('td.output').textContent,
    }));
    if (row.poster !== opt.size) fail(`the poster is ${row.poster}, not the video's ${opt.size}`);
    if (opt.token && !row.posterSrc.startsWith('blob:')) fail(`with a token the poster came from ${row.posterSrc}`);
    if (!/^temple · cpu vs cpu · /.test(row.match)) fail(`match cell: '${row.match}'`);
    if (!row.output.includes(opt.size) || !row.output.includes(opt.format + '/' + (opt.format === 'webm' ? 'vp9' : 'h264')) ||
        !/ kB| MB/.test(row.output) || (quality === 'draft') !== / · draft · /.test(row.output)) fail(`output cell: '${row.output}'`);
    await page.click(`${rowSel} details.log summary`);
    await waitFor(page, `job ${id}'s log`, () => page.$eval(`${rowSel} + tr.log-row pre`,
      (pre) => /== (segment 0 \(ticks [0-9-]+\): )?render, attempt 1, process \d+: exit status 0/.test(pre.textContent) &&
        /ringside render: wrote /.test(pre.textContent)), ctx);

    // 7. screenshot (the table from its first column: opening the log scrolled it)
    await page.$eval('.table-wrap', (w) => { w.scrollLeft = 0; });
    fs.mkdirSync(path.dirname(path.resolve(opt.shot)), { recursive: true });
    await page.screenshot({ path: opt.shot, fullPage: true });
    await layoutFits(page, rowSel, 'at 1280x800');
    if (opt['phone-shot']) {
      await page.setViewportSize({ width: 390, height: 844 });
      await sleep(300);
      await layoutFits(page, rowSel, 'at 390x844');
      fs.mkdirSync(path.dirname(path.resolve(opt['phone-shot'])), { recursive: true });
      await page.screenshot({ path: opt['phone-shot'], fullPage: true });
      await page.setViewportSize({ width: 1280, height: 800 });
    }
    checkPageErrors();
    if (!opt.token) {
      // 8. delete the finished job: a confirm, then the row and its files go
      page.once('dialog', (d) => d.accept());
      await page.click(`${rowSel} button.delete`);
      await waitFor(page, `job ${id}'s row to go after delete`, async () => await page.locator(rowSel).count() === 0, ctx);
      const gone = await page.request.get(`${opt.url}/jobs/${id}/poster`);
      if (gone.status() !== 404) fail(`the deleted job's poster answers ${gone.status()}`);
    }
    if (opt.token) await reloadAndForget(page, id, ctx);
    if (opt['quota-token']) await overQuota(page, opt, ctx);
    checkPageErrors();

    const secs = ((tDone - tUpload) / 1000).toFixed(1);
    const dur = Number.isFinite(meta.d) ? meta.d.toFixed(2) : String(meta.d);
    if (opt.live) {
      console.log(`dashboard live: "watch live" clicked ${((live.tClick - tUpload) / 1000).toFixed(1)} s after the upload, ` +
        `played past ${live.time.toFixed(2)} s at ${((live.tPlayed - tUpload) / 1000).toFixed(1)} s, the job done at ${secs} s`);
    }
    console.log(`dashboard ok${opt.token ? ' with a token' : ''}: job ${id} done in ${secs} s ` +
      `(total ${((Date.now() - t0) / 1000).toFixed(1)} s), ` +
      `video ${meta.w}x${meta.h} ${opt.format} from ${meta.src.split(':')[0]}:, duration ${dur} s, ` +
      `progress ${samples} samples ${increases} rises, shot ${opt.shot}${opt['phone-shot'] ? ` and ${opt['phone-shot']}` : ''}` +
      `${opt.token ? ` and ${opt['form-shot']}` : ''}`);
  } finally {
    await browser.close().catch(() => {});
  }
}

main().then(() => process.exit(0), (e) => {
  console.error(`dashboard FAILED: ${e instanceof Fail ? e.message : (e && e.stack) || e}`);
  process.exit(1);
});
