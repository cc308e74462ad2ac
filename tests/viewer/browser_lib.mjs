// Helpers for the viewer's browser tests: start any server command that
// prints "viewer: http://HOST:PORT/" (tonus-viewer-fixture, tonusd), drive
// Debian's chromium with puppeteer-core (host/viewer/web/node_modules; never
// a downloaded browser), and measure what the page shows.
//
//   import * as lib from './browser_lib.mjs';
//   const { args, command } = lib.parseArgs(process.argv.slice(2));
//   const puppeteer = await lib.loadPuppeteer();
//   const server = await lib.startServer(command);
//   const browser = await lib.launchBrowser(puppeteer);
//   const page = await lib.openViewer(browser, server.url);
//   ...
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { createRequire } from 'node:module';

const here = path.dirname(fileURLToPath(import.meta.url));
export const SOURCE_DIR = path.resolve(here, '..', '..');
export const WEB_DIR = path.join(SOURCE_DIR, 'host', 'viewer', 'web');
export const CHROMIUM = process.env.TONUS_CHROMIUM || '/usr/bin/chromium';
export const VIEWER_LINE = /^viewer: (https?:\/\/\S+)\s*$/m;
// As the machine notes say: headless, no sandbox (root), no GPU (SwiftShader
// renders WebGL), and nothing that reaches for the network.
export const CHROMIUM_ARGS = [
  '--headless=new', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
  '--disable-background-networking', '--disable-component-update', '--disable-sync',
  '--disable-dev-shm-usage', '--mute-audio', '--hide-scrollbars',
];

export class TestFailure extends Error {}

export function fail(message) {
  throw new TestFailure(message);
}

export function check(condition, message) {
  if (!condition) fail(message);
}

export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

// "--artifacts DIR [--timeout S] [--scenario NAME] [--port-option NAME] -- command args..."
// -> {args, command}. Each of these options takes the next argument as its
// value, even one that starts with "--" (--port-option --viewer-port).
const VALUE_OPTIONS = new Set(['--artifacts', '--timeout', '--scenario', '--port-option']);
const USAGE = 'usage: --artifacts DIR [--timeout S] [--scenario NAME] [--port-option NAME] -- command args...';

export function parseArgs(argv) {
  const split = argv.indexOf('--');
  const own = split >= 0 ? argv.slice(0, split) : argv;
  const command = split >= 0 ? argv.slice(split + 1) : [];
  const args = { artifacts: path.join(os.tmpdir(), 'tonus-viewer-browser'), timeoutS: 60 };
  for (let i = 0; i < own.length; i++) {
    const key = own[i];
    if (!VALUE_OPTIONS.has(key)) fail(`unexpected argument ${key} (${USAGE})`);
    const value = own[++i];
    if (value === undefined) fail(`${key} needs a value (${USAGE})`);
    if (key === '--artifacts') args.artifacts = path.resolve(value);
    else if (key === '--timeout') args.timeoutS = Number(value);
    else args[key.slice(2)] = value;
  }
  if (!(args.timeoutS > 0)) fail(`--timeout must be a number of seconds (${USAGE})`);
  if (command.length === 0) fail('no server command after "--" (e.g. -- build/release/bin/tonus-viewer-fixture --port 0)');
  fs.mkdirSync(args.artifacts, { recursive: true });
  return { args, command };
}

// puppeteer-core from host/viewer/web/node_modules (or TONUS_VIEWER_NODE_MODULES).
export async function loadPuppeteer() {
  const modules = process.env.TONUS_VIEWER_NODE_MODULES || path.join(WEB_DIR, 'node_modules');
  const require = createRequire(path.join(modules, '..', 'package.json'));
  let entry;
  try {
    entry = require.resolve('puppeteer-core');
  } catch {
    fail(`puppeteer-core is not installed in ${modules}: run scripts/install-deps.sh (npm ci in host/viewer/web)`);
  }
  const module = await import(pathToFileURL(entry).href);
  return module.default ?? module;
}

export function checkChromium() {
  try {
    fs.accessSync(CHROMIUM, fs.constants.X_OK);
  } catch {
    fail(`chromium not found at ${CHROMIUM}: run scripts/install-deps.sh (Debian package chromium)`);
  }
}

// Starts `command` and waits for its "viewer: URL" line. The server's output
// is kept (server.output()) and echoed on failure.
export function startServer(command, { timeoutMs = 15000, env = process.env } = {}) {
  return new Promise((resolve, reject) => {
    const child = spawn(command[0], command.slice(1), { stdio: ['ignore', 'pipe', 'pipe'], env });
    let output = '';
    let settled = false;
    const server = {
      process: child,
      command,
      url: null,
      exited: false,
      output: () => output,
      async stop(signal = 'SIGTERM', waitMs = 5000) {
        if (server.exited) return child.exitCode;
        const done = new Promise((r) => child.once('exit', () => r(child.exitCode)));
        child.kill(signal);
        const code = await Promise.race([done, sleep(waitMs).then(() => 'timeout')]);
        if (code === 'timeout') {
          child.kill('SIGKILL');
          await done;
          return 'killed after timeout';
        }
        return code;
      },
    };
    const timer = setTimeout(() => {
      if (settled) return;
      settled = true;
      child.kill('SIGKILL');
      reject(new TestFailure(`${command.join(' ')} printed no "viewer: http://..." line within ${timeoutMs} ms\n${output}`));
    }, timeoutMs);
    const onData = (chunk) => {
      output += chunk.toString();
      const match = VIEWER_LINE.exec(output);
      if (match && !settled) {
        settled = true;
        clearTimeout(timer);
        server.url = match[1];
        resolve(server);
      }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', (chunk) => { output += chunk.toString(); });
    child.on('error', (error) => {
      if (settled) return;
      settled = true;
      clearTimeout(timer);
      reject(new TestFailure(`cannot start ${command[0]}: ${error.message}`));
    });
    child.on('exit', (code, signal) => {
      server.exited = true;
      if (settled) return;
      settled = true;
      clearTimeout(timer);
      reject(new TestFailure(`${command.join(' ')} exited (${signal ?? code}) before printing its viewer line\n${output}`));
    });
  });
}

// The same command on the port of `url` (replacing the value of its port
// option: `--port N`, `--viewer-port N` or the one named), to bring a server
// back where the page expects it; null when the command has none.
export function commandOnSamePort(command, url, options = ['--port', '--viewer-port']) {
  const i = command.findIndex((arg) => options.includes(arg));
  if (i < 0 || i + 1 >= command.length) return null;
  const copy = [...command];
  copy[i + 1] = new URL(url).port;
  return copy;
}

// Chromium with a fresh profile folder (removed on close).
export async function launchBrowser(puppeteer, { width = 1280, height = 720 } = {}) {
  checkChromium();
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), 'tonus-chromium-'));
  const browser = await puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    userDataDir,
    args: [...CHROMIUM_ARGS, `--window-size=${width},${height}`],
    defaultViewport: { width, height },
    timeout: 20000,
  });
  const close = browser.close.bind(browser);
  browser.close = async () => {
    try {
      await close();
    } finally {
      fs.rmSync(userDataDir, { recursive: true, force: true });
    }
  };
  return browser;
}

// Opens the page; collects its uncaught errors and console errors.
export async function openViewer(browser, url) {
  const page = await browser.newPage();
  page.tonusErrors = [];
  page.tonusConsole = [];
  page.on('pageerror', (error) => page.tonusErrors.push(String(error && error.message ? error.message : error)));
  page.on('console', (message) => {
    if (message.type() === 'error') page.tonusConsole.push(message.text());
  });
  await page.goto(url, { waitUntil: 'load', timeout: 15000 });
  return page;
}

// Waits until `fn(...args)` is truthy in the page; fails naming `what`.
export async function waitFor(page, what, fn, { timeoutMs = 5000, args = [] } = {}) {
  try {
    return await page.waitForFunction(fn, { timeout: timeoutMs, polling: 50 }, ...args);
  } catch (error) {
    const state = await viewerState(page).catch(() => ({}));
    fail(`timed out after ${timeoutMs} ms waiting for ${what}; page state: ${JSON.stringify(state)}`);
  }
  return null;
}

// A summary of window.tonusViewer and the overlay, for messages.
export function viewerState(page) {
  return page.evaluate(() => {
    const v = window.tonusViewer;
    const overlay = document.getElementById('overlay');
    const fatal = document.getElementById('fatal');
    return {
      connected: v?.connected,
      framesReceived: v?.framesReceived,
      framesShown: v?.framesShown,
      sceneBuilds: v?.sceneBuilds,
      objectsShown: v?.objectsShown,
      webgl: v?.webgl,
      overlay: overlay?.dataset.visible,
      overlayText: overlay?.innerText,
      fatal: fatal && !fatal.hidden ? fatal.innerText : null,
    };
  });
}

export function gaugeValues(page) {
  return page.$$eval('.gauge', (rows) => rows.map((r) => ({ group: r.dataset.group, value: r.dataset.value })));
}

// A PNG of the 3D view's canvas, also written to `file`.
export async function canvasShot(page, file) {
  const canvas = await page.$('#view canvas');
  check(canvas, 'the page has no 3D canvas (#view canvas)');
  const png = await canvas.screenshot({ type: 'png' });
  fs.writeFileSync(file, png);
  return Buffer.from(png);
}

// Decodes PNGs in the page (the browser's own decoder) and compares pixels:
// the share of pixels farther than `tolerance` (sum of |dR|+|dG|+|dB|) from
// `background` [r, g, b], and when `other` is given, the share that differ
// between the two images.
export function pixelStats(page, png, { background, other = null, tolerance = 30 } = {}) {
  return page.evaluate(async (a, b, bg, tol) => {
    async function pixels(base64) {
      const blob = await (await fetch(`data:image/png;base64,${base64}`)).blob();
      const bitmap = await createImageBitmap(blob);
      const canvas = new OffscreenCanvas(bitmap.width, bitmap.height);
      const ctx = canvas.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      return ctx.getImageData(0, 0, bitmap.width, bitmap.height);
    }
    const first = await pixels(a);
    const n = first.width * first.height;
    let away = 0;
    const d = first.data;
    for (let i = 0; i < n; i++) {
      const k = 4 * i;
      if (Math.abs(d[k] - bg[0]) + Math.abs(d[k + 1] - bg[1]) + Math.abs(d[k + 2] - bg[2]) > tol) away++;
    }
    const result = { width: first.width, height: first.height, nonBackground: away / n };
    if (b) {
      const second = await pixels(b);
      if (second.width !== first.width || second.height !== first.height) {
        result.differing = 1;
      } else {
        let differ = 0;
        const e = second.data;
        for (let i = 0; i < n; i++) {
          const k = 4 * i;
          if (Math.abs(d[k] - e[k]) + Math.abs(d[k + 1] - e[k + 1]) + Math.abs(d[k + 2] - e[k + 2]) > tol) differ++;
        }
        result.differing = differ / n;
      }
    }
    return result;
  }, png.toString('base64'), other ? other.toString('base64') : null, background, tolerance);
}

// Runs named steps, timing each; a failing step ends the run. Prints the
// plain "N passed, N failed" closing line and returns the exit code.
export async function runSteps(title, steps, { cleanup = async () => {}, onFailure = async () => {} } = {}) {
  const started = Date.now();
  let passed = 0;
  let failed = 0;
  for (const [name, fn] of steps) {
    const t0 = Date.now();
    try {
      await fn();
      passed++;
      console.log(`ok   ${name} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
    } catch (error) {
      failed++;
      console.log(`FAIL ${name} (${((Date.now() - t0) / 1000).toFixed(1)} s)`);
      console.log(`     ${error instanceof TestFailure ? error.message : error.stack || error}`.replace(/\n/g, '\n     '));
      await onFailure(error).catch((e) => console.log(`     (while collecting details: ${e.message})`));
      break;
    }
  }
  const skipped = steps.length - passed - failed;
  await cleanup().catch((e) => console.log(`cleanup: ${e.message}`));
  console.log(`${title}: ${((Date.now() - started) / 1000).toFixed(1)} s`);
  console.log(`${passed} passed, ${failed} failed${skipped ? `, ${skipped} skipped` : ''}`);
  return failed === 0 && skipped === 0 ? 0 : 1;
}
