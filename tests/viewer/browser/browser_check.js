// Drives the viewer's page in headless Chromium over the DevTools protocol
// (puppeteer-core, pinned in package-lock.json, against Debian's
// /usr/bin/chromium) and writes what the page showed as JSON for
// viewer_browser_test.cc to check against the bus or the log.
//
//   node browser_check.js live  URL OUT.json   samples of window.viewerState
//   node browser_check.js scrub URL OUT.json   seek to 15 s with the slider, then play
//   node browser_check.js operator URL OUT.json  press hold once ARMED
'use strict';

const fs = require('fs');
const os = require('os');
const path = require('path');
const puppeteer = require('puppeteer-core');

const [mode, url, outPath] = process.argv.slice(2);
const CHROMIUM = process.env.STEWART_CHROMIUM || '/usr/bin/chromium';

function sleep(ms) { return new Promise((resolve) => setTimeout(resolve, ms)); }

async function waitFor(page, predicate, arg, timeoutMs, what) {
  try {
    await page.waitForFunction(predicate, { timeout: timeoutMs, polling: 50 }, arg);
  } catch (e) {
    const state = await page.evaluate(() => JSON.stringify(window.viewerState)).catch(() => '?');
    throw new Error(`timed out waiting for ${what}; viewerState = ${state}`);
  }
}

async function live(page, result) {
  await waitFor(page, () => window.viewerState.renderedFrames > 0 && window.viewerState.q, null, 20000,
                'a rendered frame');
  // Samples of what the page rendered, each after a newer state was drawn
  // (software WebGL on a loaded machine draws a few frames per second): each
  // must be a state the stack sent, and they must move on.
  for (let k = 0; k < 5; k++) {
    const sample = await page.evaluate(() => ({
      utime_us: window.viewerState.utime_us, q: window.viewerState.q,
      renderedFrames: window.viewerState.renderedFrames, frames: window.viewerState.frames }));
    result.samples.push(sample);
    // A newer frame may redraw the same state (a heartbeat changed): wait
    // for a newer state, which a running stack sends within well under 10 s.
    await waitFor(page, (u) => window.viewerState.utime_us > u, sample.utime_us, 10000,
                  'a newer state rendered');
  }
  result.operator = await page.evaluate(() => window.viewerState.operator);
  result.buttons_hidden = await page.$eval('#operator-buttons', (e) => e.hidden);
}

async function scrub(page, result) {
  await waitFor(page, () => window.viewerState.mode === 'log' && window.viewerState.playback, null, 20000,
                'the log to load');
  // The user's gesture: the slider to 15 s.
  await page.$eval('#slider', (slider) => {
    slider.value = '15';
    slider.dispatchEvent(new Event('input', { bubbles: true }));
  });
  await waitFor(page, () => window.viewerState.playback && Math.abs(window.viewerState.playback.t_s - 15) < 1e-6,
                null, 10000, 'the seek to 15 s');
  result.at_15 = await page.evaluate(() => ({ ...window.viewerState }));
  // Bad input on a second connection: an error reply, the viewer keeps serving.
  result.malformed_reply = await page.evaluate(() => new Promise((resolve) => {
    const ws = new WebSocket(`ws://${location.host}/ws`);
    ws.onopen = () => ws.send('{"type": "seek", "t_s": "soon"');
    ws.onmessage = (e) => { const m = JSON.parse(e.data); if (m.type === 'error') { resolve(m.message); ws.close(); } };
    setTimeout(() => resolve(null), 5000);
  }));
  await page.select('#rate', '2');
  await page.click('#play');
  await sleep(1500);
  result.after_play = await page.evaluate(() => ({ ...window.viewerState }));
}

async function operator(page, result) {
  await waitFor(page, () => window.viewerState.supervisor === 'ARMED', null, 30000, 'the supervisor ARMED');
  result.buttons_hidden = await page.$eval('#operator-buttons', (e) => e.hidden);
  await page.click('button[data-command="hold"]');
  await waitFor(page, () => window.viewerState.supervisor === 'HOLD', null, 10000, 'HOLD after the button');
  await waitFor(page, () => document.getElementById('operator-reply').textContent !== '', null, 10000,
                'the supervisor\'s reply');
  result.reply = await page.$eval('#operator-reply', (e) => e.textContent);
  result.supervisor = await page.evaluate(() => window.viewerState.supervisor);
  // The viewer also shows the command as it saw it on the operator channel.
  await waitFor(page, () => document.getElementById('supervisor-detail').textContent
    .includes('last operator command: hold'), null, 10000, 'the hold on the operator channel');
  result.last_operator_command = await page.$eval('#supervisor-detail', (e) => e.textContent);
}

async function main() {
  const result = { mode, console_errors: [], page_errors: [], samples: [] };
  const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'stewart-viewer-chromium-'));
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    userDataDir: profile,
    // Root on CI has no sandbox; WebGL in software (no GPU on the machine).
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--window-size=1280,800'],
  });
  try {
    const page = await browser.newPage();
    await page.setViewport({ width: 1280, height: 800 });
    page.on('console', (m) => { if (m.type() === 'error') result.console_errors.push(m.text()); });
    page.on('pageerror', (e) => result.page_errors.push(String(e)));
    await page.goto(url, { waitUntil: 'load', timeout: 20000 });
    if (mode === 'live') await live(page, result);
    else if (mode === 'scrub') await scrub(page, result);
    else if (mode === 'operator') await operator(page, result);
    else throw new Error(`unknown mode ${mode}`);
    if (process.env.STEWART_VIEWER_SCREENSHOT) {
      await page.screenshot({ path: process.env.STEWART_VIEWER_SCREENSHOT });
    }
  } finally {
    await browser.close();
    fs.rmSync(profile, { recursive: true, force: true });
  }
  fs.writeFileSync(outPath, JSON.stringify(result, null, 1));
}

main().catch((e) => {
  console.error(`browser_check: ${e.message}`);
  process.exit(1);
});
