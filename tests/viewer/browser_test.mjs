#!/usr/bin/env node
// The live viewer in a real browser (Debian's chromium, puppeteer-core),
// against any server command that prints "viewer: http://HOST:PORT/":
//
//   node tests/viewer/browser_test.mjs --artifacts DIR -- build/release/bin/tonus-viewer-fixture --port 0
//
// Checks: the page connects and draws frames; the stiffness gauges change
// over a few seconds; "throw ball" makes an object appear in the next frames;
// the 3D view is not blank and moves (two screenshots a second apart differ);
// killing the server brings up the "not reachable" overlay; and, when the
// command takes --port, a server started again on that port is reconnected
// to and the scene rebuilt (--port-option NAME for another option's name).
// Screenshots go to the artifacts folder.
//
// --scenario no-three: the page is served without three.js (a web root with
// no node_modules) and must say how to install it rather than stay blank.
// --scenario playback: the server replays (tonus-viewer-fixture --playback):
// the timeline plays, pauses and seeks.
import path from 'node:path';
import * as lib from './browser_lib.mjs';

const BACKGROUND = [0x15, 0x18, 0x1d]; // the page's clear colour (css/viewer.css, scene3d.js)

let parsed;
try {
  parsed = lib.parseArgs(process.argv.slice(2));
} catch (error) {
  console.error(`browser_test: ${error.message}`);
  process.exit(2);
}
const { args, command } = parsed;
const artifact = (name) => path.join(args.artifacts, name);

let puppeteer;
let server;
let browser;
let page;
const ctx = {};

async function collectDetails() {
  if (page) {
    console.log(`     page state: ${JSON.stringify(await lib.viewerState(page).catch(() => 'unavailable'))}`);
    if (page.tonusErrors.length) console.log(`     page errors: ${page.tonusErrors.join(' | ')}`);
    if (page.tonusConsole.length) console.log(`     console errors: ${page.tonusConsole.slice(0, 5).join(' | ')}`);
    await page.screenshot({ path: artifact('failure.png') }).catch(() => {});
    console.log(`     screenshot: ${artifact('failure.png')}`);
  }
  if (server) console.log(`     server output:\n${server.output().replace(/^/gm, '       ')}`);
}

async function cleanup() {
  if (browser) await browser.close();
  if (server && !server.exited) await server.stop('SIGTERM');
}

// Hard stop, whatever hangs.
const watchdog = setTimeout(async () => {
  console.log(`FAIL the whole test took longer than ${args.timeoutS} s`);
  await collectDetails().catch(() => {});
  await cleanup().catch(() => {});
  console.log('0 passed, 1 failed');
  process.exit(1);
}, args.timeoutS * 1000);

const setup = [
  ['puppeteer-core and chromium are installed', async () => {
    puppeteer = await lib.loadPuppeteer();
    lib.checkChromium();
  }],
  ['the server starts and prints its viewer line', async () => {
    server = await lib.startServer(command);
    console.log(`     ${server.url}`);
  }],
  ['chromium opens the page', async () => {
    browser = await lib.launchBrowser(puppeteer);
    page = await lib.openViewer(browser, server.url);
  }],
];

const live = [
  ['the page connects, builds the scene and draws frames', async () => {
    await lib.waitFor(page, 'the connection, the scene and 10 frames drawn',
      () => window.tonusViewer?.connected && window.tonusViewer.sceneBuilds >= 1 && window.tonusViewer.framesShown >= 10,
      { timeoutMs: 8000 });
    const state = await lib.viewerState(page);
    lib.check(state.webgl, `the 3D view did not start (WebGL): ${state.fatal}`);
    lib.check(state.overlay === 'false', 'the "not reachable" overlay is still up while connected');
    lib.check(page.tonusErrors.length === 0, `the page threw: ${page.tonusErrors.join(' | ')}`);
  }],
  ['the stiffness gauges change over a few seconds', async () => {
    const before = await lib.gaugeValues(page);
    lib.check(before.length > 0, 'no stiffness gauges (.gauge) on the page');
    lib.check(before.every((g) => g.value !== ''), `a gauge has no value: ${JSON.stringify(before)}`);
    await lib.waitFor(page, 'a gauge to change',
      (initial) => [...document.querySelectorAll('.gauge')].some((g, i) => g.dataset.value !== initial[i]),
      { timeoutMs: 4000, args: [before.map((g) => g.value)] });
    const after = await lib.gaugeValues(page);
    console.log(`     ${before.map((g, i) => `${g.group} ${g.value} -> ${after[i].value}`).join(', ')}`);
  }],
  ['"throw ball" makes an object appear in the next frames', async () => {
    const objectsBefore = await page.evaluate(() => window.tonusViewer.lastFrame.objects.length);
    await page.select('#gift-bone', 'Chest');
    await page.click('#throw-ball');
    await lib.waitFor(page, 'a reply to POST /gifts',
      () => window.tonusViewer.lastReply?.path === '/gifts', { timeoutMs: 3000 });
    const reply = await page.evaluate(() => window.tonusViewer.lastReply);
    lib.check(reply.status === 202, `POST /gifts was answered ${JSON.stringify(reply)}`);
    await lib.waitFor(page, 'a ball in the frames and in the 3D view',
      (n) => window.tonusViewer.lastFrame.objects.some((o) => o.kind === 'ball') &&
        window.tonusViewer.lastFrame.objects.length > n && window.tonusViewer.objectsShown > 0,
      { timeoutMs: 3000, args: [objectsBefore] });
    const status = await page.$eval('#request-status', (el) => el.textContent);
    lib.check(status.includes('202'), `the status line does not show the reply: "${status}"`);
  }],
  ['the 3D view is not blank, and moves', async () => {
    await lib.sleep(300); // the ball in flight
    const first = await lib.canvasShot(page, artifact('viewer.png'));
    await lib.sleep(1000);
    const second = await lib.canvasShot(page, artifact('viewer-1s-later.png'));
    const stats = await lib.pixelStats(page, first, { background: BACKGROUND, other: second });
    console.log(`     ${stats.width}x${stats.height}: ${(100 * stats.nonBackground).toFixed(1)} % not background, ` +
      `${(100 * stats.differing).toFixed(2)} % changed in 1 s; ${artifact('viewer.png')}`);
    lib.check(stats.nonBackground > 0.02, `the canvas is nearly blank: ${(100 * stats.nonBackground).toFixed(2)} % drawn`);
    lib.check(stats.differing > 0.001, `two screenshots a second apart are the same (${stats.differing})`);
  }],
  ['pausing the view freezes it while frames keep arriving', async () => {
    await page.click('#pause-view');
    await lib.waitFor(page, 'the view paused', () => window.tonusViewer.paused === true);
    await lib.sleep(100);
    const shown = await page.evaluate(() => [window.tonusViewer.framesShown, window.tonusViewer.framesReceived]);
    await lib.sleep(500);
    const later = await page.evaluate(() => [window.tonusViewer.framesShown, window.tonusViewer.framesReceived]);
    lib.check(later[0] === shown[0], `frames were drawn while paused (${shown[0]} -> ${later[0]})`);
    lib.check(later[1] > shown[1], 'no frames arrived while paused (the connection should stay)');
    await page.click('#pause-view');
    await lib.waitFor(page, 'drawing to resume', (n) => window.tonusViewer.framesShown > n, { args: [later[0]] });
  }],
  ['when the server dies, the "not reachable" overlay appears', async () => {
    ctx.url = server.url;
    ctx.builds = await page.evaluate(() => window.tonusViewer.sceneBuilds);
    await server.stop('SIGKILL');
    await lib.waitFor(page, 'the overlay',
      () => document.getElementById('overlay').dataset.visible === 'true' && !window.tonusViewer.connected,
      { timeoutMs: 4000 });
    const text = await page.$eval('#overlay', (el) => el.innerText);
    lib.check(/not reachable/.test(text) && /retrying/.test(text), `the overlay says "${text}"`);
    await page.screenshot({ path: artifact('overlay.png') });
    console.log(`     "${text.replace(/\s+/g, ' ').trim()}"; ${artifact('overlay.png')}`);
  }],
  ['a server back on the same port is reconnected to and the scene rebuilt', async () => {
    const again = lib.commandOnSamePort(command, ctx.url, args['port-option'] ? [args['port-option']] : undefined);
    if (!again) {
      console.log('     (the command has no --port or --viewer-port to reuse: not checked)');
      return;
    }
    server = await lib.startServer(again);
    await lib.waitFor(page, 'a reconnection with the scene rebuilt and frames drawn',
      (builds) => window.tonusViewer.connected && window.tonusViewer.sceneBuilds > builds &&
        document.getElementById('overlay').dataset.visible === 'false',
      { timeoutMs: 6000, args: [ctx.builds] });
    const n = await page.evaluate(() => window.tonusViewer.framesShown);
    await lib.waitFor(page, 'frames after reconnecting', (k) => window.tonusViewer.framesShown > k + 3, { args: [n] });
    lib.check(page.tonusErrors.length === 0, `the page threw: ${page.tonusErrors.join(' | ')}`);
  }],
];

const noThree = [
  ['without three.js the page says how to install it', async () => {
    await lib.waitFor(page, 'the three.js message',
      () => document.getElementById('fatal') && !document.getElementById('fatal').hidden, { timeoutMs: 8000 });
    const text = await page.$eval('#fatal', (el) => el.innerText);
    await page.screenshot({ path: artifact('no-three.png') });
    lib.check(text.includes('three.js is not installed: run scripts/install-deps.sh'), `the page says "${text}"`);
    const overlay = await page.$eval('#overlay', (el) => el.dataset.visible);
    lib.check(overlay === 'false', 'the overlay hides the message');
    console.log(`     "${text.split('\n')[0]}"; ${artifact('no-three.png')}`);
  }],
];

// --scenario playback: the server replays a recording (frames carry
// "playback"): the timeline shows, and its buttons and slider drive it.
const playback = [
  ['the timeline shows while frames carry playback', async () => {
    await lib.waitFor(page, 'the timeline', () => window.tonusViewer?.framesShown >= 3 &&
      !document.getElementById('timeline').hidden, { timeoutMs: 8000 });
    const frame = await page.evaluate(() => window.tonusViewer.lastFrame.playback);
    lib.check(frame && frame.duration_s > 0, `frame.playback is ${JSON.stringify(frame)}`);
    const max = await page.$eval('#seek', (el) => Number(el.max));
    lib.check(Math.abs(max - frame.duration_s) < 1e-6, `the seek slider's max is ${max}, the duration ${frame.duration_s}`);
  }],
  ['pause and play go to the server', async () => {
    await lib.waitFor(page, 'playing', () => window.tonusViewer.lastFrame.playback.playing === true);
    await page.click('#play-toggle');
    await lib.waitFor(page, 'paused frames', () => window.tonusViewer.lastFrame.playback.playing === false);
    const at = await page.evaluate(() => window.tonusViewer.lastFrame.playback.position_s);
    await lib.sleep(400);
    const still = await page.evaluate(() => window.tonusViewer.lastFrame.playback.position_s);
    lib.check(still === at, `the position moved while paused (${at} -> ${still})`);
    lib.check((await page.$eval('#play-toggle', (el) => el.textContent)) === 'play', 'the button does not offer play');
    await page.click('#play-toggle');
    await lib.waitFor(page, 'playing again', () => window.tonusViewer.lastFrame.playback.playing === true);
  }],
  ['the seek slider moves the recording', async () => {
    await page.$eval('#seek', (el) => {
      el.value = String(Number(el.max) * 0.75);
      el.dispatchEvent(new Event('change', { bubbles: true }));
    });
    await lib.waitFor(page, 'the position near 75 %', () => {
      const p = window.tonusViewer.lastFrame.playback;
      return Math.abs(p.position_s - 0.75 * p.duration_s) < 1.0;
    });
    const time = await page.$eval('#playback-time', (el) => el.textContent);
    console.log(`     timeline: ${time}`);
    await page.screenshot({ path: artifact('playback.png') });
  }],
];

const scenarios = { live, 'no-three': noThree, playback };
const scenario = args.scenario ?? 'live';
if (!scenarios[scenario]) {
  console.error(`browser_test: unknown --scenario ${scenario} (${Object.keys(scenarios).join(', ')})`);
  process.exit(2);
}
const code = await lib.runSteps(`viewer browser test (${scenario})`, [...setup, ...scenarios[scenario]],
  { cleanup, onFailure: collectDetails });
clearTimeout(watchdog);
process.exit(code);
