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
// --scenario vrm: the server serves a VRM avatar (--vrm, make_vrm.mjs's): it
// loads, its normalized bones carry the pose sent (computed here from the
// scene's rest poses and the frame), its bones point where the capsules do,
// and its screenshot differs from the capsules-only one.
// --scenario vrm-corrupt: a .vrm the page cannot read: it says so and the
// capsules carry on.
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
    // tonusd --demo's band swells once over the demo (--seconds 120 here): its
    // co-contraction crosses the stiffness's dead zone about 6.5 s after start,
    // which a page that loads in half a second has to wait for.
    await lib.waitFor(page, 'a gauge to change',
      (initial) => [...document.querySelectorAll('.gauge')].some((g, i) => g.dataset.value !== initial[i]),
      { timeoutMs: 15000, args: [before.map((g) => g.value)] });
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
    // The first paused frames may still carry the step the replay made as the
    // pause arrived (one frame on, seen under load): judge the position after.
    await lib.sleep(200);
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

// --- the VRM avatar (make_vrm.mjs's models) --------------------------------
// Rotations as 3x3 matrices (row-major), independent of the page's
// quaternion arithmetic (js/vrm_pose.js).
function matrixOf([x, y, z, w]) {
  const n = Math.hypot(x, y, z, w);
  [x, y, z, w] = [x / n, y / n, z / n, w / n];
  return [
    [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
    [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
    [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
  ];
}
const mmul = (a, b) => a.map((row) => [0, 1, 2].map((j) => row[0] * b[0][j] + row[1] * b[1][j] + row[2] * b[2][j]));
const mt = (a) => [0, 1, 2].map((i) => [0, 1, 2].map((j) => a[j][i]));
// The angle of the rotation taking a to b (radians).
const angleBetween = (a, b) => {
  const m = mmul(mt(a), b);
  return Math.acos(Math.min(1, Math.max(-1, (m[0][0] + m[1][1] + m[2][2] - 1) / 2)));
};
// tonus (x forward, y left, z up) -> VRM 1.0 (x left, y up, z forward), and
// VRM 1.0 -> a VRM 0.x model's frame (half a turn about Y).
const TONUS_TO_VRM = [[0, 1, 0], [0, 0, 1], [1, 0, 0]];
const VRM1_TO_VRM0 = [[-1, 0, 0], [0, 1, 0], [0, 0, -1]];
const vrmName = (name) => ({ LeftThumbProximal: 'leftThumbMetacarpal', RightThumbProximal: 'rightThumbMetacarpal',
  LeftThumbIntermediate: 'leftThumbProximal', RightThumbIntermediate: 'rightThumbProximal' })[name] ??
  name[0].toLowerCase() + name.slice(1);
const direction = (a, b) => {
  const d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
  const n = Math.hypot(...d);
  return d.map((c) => c / n);
};
const degrees = (r) => (r * 180) / Math.PI;
// tonus's world -> three.js's (the page's world group: (x, y, z) -> (x, z, -y)).
const toThree = (p) => [p[0], p[2], -p[1]];

const MODEL_HIPS_Y = 0.85; // make_vrm.mjs's hips height
const SEGMENTS = [
  ['Hips', 'Spine'], ['Spine', 'Chest'],
  ['LeftUpperArm', 'LeftLowerArm'], ['LeftLowerArm', 'LeftHand'],
  ['RightUpperArm', 'RightLowerArm'], ['RightLowerArm', 'RightHand'],
  ['LeftUpperLeg', 'LeftLowerLeg'], ['LeftLowerLeg', 'LeftFoot'],
  ['RightUpperLeg', 'RightLowerLeg'], ['RightLowerLeg', 'RightFoot'],
];

const vrmScenario = [
  ['the page connects and draws frames', async () => {
    await lib.waitFor(page, 'the connection, the scene and 5 frames drawn',
      () => window.tonusViewer?.connected && window.tonusViewer.framesShown >= 5, { timeoutMs: 8000 });
    const scene = await page.evaluate(() => window.tonusViewer.scene);
    lib.check(scene.vrm && scene.vrm.url === '/avatar.vrm', `the scene announces no VRM: ${JSON.stringify(scene.vrm)}`);
  }],
  ['the page reports the VRM avatar loaded', async () => {
    await lib.waitFor(page, 'the VRM avatar loaded (or failed)',
      () => ['loaded', 'failed'].includes(window.tonusViewer.vrm.state), { timeoutMs: 20000 });
    const vrm = await page.evaluate(() => ({ ...window.tonusViewer.vrm, capsules: window.tonusViewer.capsulesShown }));
    const line = await page.$eval('#vrm-status', (el) => ({ text: el.textContent, hidden: el.hidden, state: el.dataset.state }));
    lib.check(vrm.state === 'loaded', `the VRM did not load: ${vrm.message}`);
    lib.check(!line.hidden && line.state === 'loaded' && /driven by simulation B/.test(line.text), `the status line: ${JSON.stringify(line)}`);
    lib.check(!vrm.capsules, 'the capsules still show over the loaded VRM (they step aside by default)');
    console.log(`     "${line.text}"`);
  }],
  ['the driven bones match the pose sent (rotations and directions)', async () => {
    await page.click('#pause-view');
    await lib.waitFor(page, 'the view paused', () => window.tonusViewer.paused === true);
    await lib.sleep(200);
    const got = await page.evaluate(() => {
      const v = window.tonusViewer;
      const names = v.scene.bones.map((b) => b.name);
      const vrmName = (n) => n[0].toLowerCase() + n.slice(1);
      return {
        scene: v.scene,
        frame: v.shownFrame,
        vrm: v.vrm,
        local: Object.fromEntries(names.map((n) => [n, v.vrm.normalizedLocal(vrmName(n))])),
        raw: Object.fromEntries(names.map((n) => [n, v.vrm.rawWorldPosition(vrmName(n))])),
      };
    });
    lib.check(got.vrm.applied && got.vrm.applied.tick === got.frame.tick,
      `the VRM was posed from tick ${got.vrm.applied?.tick}, the view shows ${got.frame.tick}`);
    const vrm0 = got.vrm.version === '0';
    const bones = got.scene.bones;
    // Expected: each bone's world rotation from rest, in the VRM frame, relative to its parent's.
    const worldFromRest = bones.map((b, i) =>
      mmul(mmul(TONUS_TO_VRM, mmul(matrixOf(got.frame.avatar[i].slice(3, 7)), mt(matrixOf(b.rest.slice(3, 7))))), mt(TONUS_TO_VRM)));
    let worst = { angle: 0, bone: 'none' };
    let moved = 0;
    for (let i = 0; i < bones.length; i++) {
      const shown = got.local[bones[i].name];
      lib.check(shown, `the model has no normalized ${vrmName(bones[i].name)}`);
      let expected = bones[i].parent >= 0 ? mmul(mt(worldFromRest[bones[i].parent]), worldFromRest[i]) : worldFromRest[i];
      if (vrm0) expected = mmul(mmul(VRM1_TO_VRM0, expected), VRM1_TO_VRM0);
      const angle = angleBetween(expected, matrixOf(shown));
      if (angle > worst.angle) worst = { angle, bone: bones[i].name };
      if (angleBetween(expected, matrixOf([0, 0, 0, 1])) > 0.05) moved++;
    }
    console.log(`     ${bones.length} bones, ${moved} away from rest; largest rotation error ${degrees(worst.angle).toFixed(4)} deg (${worst.bone})`);
    lib.check(moved >= 4, `only ${moved} bones are away from their rest: the pose check would prove little`);
    lib.check(worst.angle < 1e-3, `${worst.bone}'s normalized rotation is ${degrees(worst.angle)} deg from the pose sent`);
    // The model's bones as drawn point where the capsules' do.
    const index = Object.fromEntries(bones.map((b, i) => [b.name, i]));
    let worstDir = { angle: 0, segment: 'none' };
    for (const [a, b] of SEGMENTS) {
      const want = direction(toThree(got.frame.avatar[index[a]]), toThree(got.frame.avatar[index[b]]));
      const have = direction(got.raw[a], got.raw[b]);
      const angle = Math.acos(Math.min(1, want[0] * have[0] + want[1] * have[1] + want[2] * have[2]));
      if (angle > worstDir.angle) worstDir = { angle, segment: `${a}-${b}` };
    }
    console.log(`     bone directions: largest difference ${degrees(worstDir.angle).toFixed(4)} deg (${worstDir.segment})`);
    lib.check(worstDir.angle < (0.5 * Math.PI) / 180, `${worstDir.segment} points ${degrees(worstDir.angle)} deg away from the capsules`);
    // The root: the model's hips height moves with tonus's, scaled by the hips heights.
    const hips = bones.findIndex((b) => b.parent < 0);
    const ground = got.scene.ground_z_m;
    const scale = MODEL_HIPS_Y / (bones[hips].rest[2] - ground);
    const wantY = ground + MODEL_HIPS_Y + scale * (got.frame.avatar[hips][2] - bones[hips].rest[2]);
    lib.check(Math.abs(got.raw.Hips[1] - wantY) < 1e-4, `the model's hips are at ${got.raw.Hips[1]} m, expected ${wantY}`);
  }],
  ['a screenshot of the VRM differs from the capsules-only one', async () => {
    const withVrm = await lib.canvasShot(page, artifact('vrm.png'));
    await page.click('#show-capsules');
    await page.click('#show-vrm');
    await lib.waitFor(page, 'capsules on, VRM off', () => window.tonusViewer.capsulesShown && !window.tonusViewer.vrm.visible);
    await lib.sleep(200);
    const capsules = await lib.canvasShot(page, artifact('capsules.png'));
    const stats = await lib.pixelStats(page, withVrm, { background: BACKGROUND, other: capsules });
    console.log(`     VRM ${(100 * stats.nonBackground).toFixed(1)} % drawn; ${(100 * stats.differing).toFixed(1)} % of pixels ` +
      `differ from the capsules; ${artifact('vrm.png')}, ${artifact('capsules.png')}`);
    lib.check(stats.nonBackground > 0.02, `the VRM view is nearly blank (${stats.nonBackground})`);
    lib.check(stats.differing > 0.01, `the VRM and capsule screenshots hardly differ (${stats.differing})`);
    await page.click('#show-vrm');
    await page.click('#pause-view');
    await lib.waitFor(page, 'drawing to resume', () => !window.tonusViewer.paused);
    const n = await page.evaluate(() => window.tonusViewer.framesShown);
    await lib.waitFor(page, 'frames after resuming', (k) => window.tonusViewer.framesShown > k + 3, { args: [n] });
    await lib.canvasShot(page, artifact('vrm-and-capsules.png'));
    lib.check(page.tonusErrors.length === 0, `the page threw: ${page.tonusErrors.join(' | ')}`);
  }],
];

// A .vrm the page cannot use: it says so and the capsules carry on.
const vrmCorrupt = [
  ['the page says the VRM cannot be used and falls back to the capsules', async () => {
    await lib.waitFor(page, 'the VRM to fail', () => window.tonusViewer?.vrm.state === 'failed', { timeoutMs: 15000 });
    const line = await page.$eval('#vrm-status', (el) => ({ text: el.textContent, hidden: el.hidden }));
    lib.check(!line.hidden && /could not be used/.test(line.text) && /showing the capsules/.test(line.text),
      `the status line: ${JSON.stringify(line)}`);
    lib.check(await page.evaluate(() => window.tonusViewer.capsulesShown), 'the capsules are not shown');
    lib.check(await page.$eval('#vrm-toggle', (el) => el.hidden), 'the VRM checkbox is offered for a VRM that failed');
    console.log(`     "${line.text}"`);
  }],
  ['the capsules still render and frames keep coming', async () => {
    const n = await page.evaluate(() => window.tonusViewer.framesShown);
    await lib.waitFor(page, 'more frames drawn', (k) => window.tonusViewer.framesShown > k + 10, { args: [n], timeoutMs: 5000 });
    const first = await lib.canvasShot(page, artifact('vrm-corrupt.png'));
    await lib.sleep(800);
    const second = await lib.canvasShot(page, artifact('vrm-corrupt-later.png'));
    const stats = await lib.pixelStats(page, first, { background: BACKGROUND, other: second });
    console.log(`     ${(100 * stats.nonBackground).toFixed(1)} % drawn, ${(100 * stats.differing).toFixed(2)} % changed; ${artifact('vrm-corrupt.png')}`);
    lib.check(stats.nonBackground > 0.02, `the canvas is nearly blank: ${stats.nonBackground}`);
    lib.check(stats.differing > 0.001, 'the view does not move');
    lib.check(page.tonusErrors.length === 0, `the page threw: ${page.tonusErrors.join(' | ')}`);
  }],
];

const scenarios = { live, 'no-three': noThree, playback, vrm: vrmScenario, 'vrm-corrupt': vrmCorrupt };
const scenario = args.scenario ?? 'live';
if (!scenarios[scenario]) {
  console.error(`browser_test: unknown --scenario ${scenario} (${Object.keys(scenarios).join(', ')})`);
  process.exit(2);
}
const code = await lib.runSteps(`viewer browser test (${scenario})`, [...setup, ...scenarios[scenario]],
  { cleanup, onFailure: collectDetails });
clearTimeout(watchdog);
process.exit(code);
