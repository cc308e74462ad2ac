// The README's screenshot of the live viewer: tonusd --demo on free ports,
// Debian's chromium through puppeteer-core (as the browser tests drive it),
// a ball thrown at the chest, then the whole page after a few seconds.
//   node scripts/viewer-screenshot.mjs [OUT.png] [BUILD_DIR]
// Needs the release build and scripts/install-deps.sh (chromium, npm ci).
import path from 'node:path';
import * as lib from '../tests/viewer/browser_lib.mjs';

const out = path.resolve(process.argv[2] || path.join(lib.SOURCE_DIR, 'docs', 'images', 'viewer.png'));
const build = path.resolve(process.argv[3] || path.join(lib.SOURCE_DIR, 'build', 'release'));
const tonusd = path.join(build, 'bin', 'tonusd');

const puppeteer = await lib.loadPuppeteer();
const server = await lib.startServer([tonusd, '--demo', '--seconds', '30', '--no-realtime', '--listen-port', '0',
  '--control-port', '0', '--viewer-port', '0']);
const browser = await lib.launchBrowser(puppeteer);
try {
  const page = await lib.openViewer(browser, server.url);
  await lib.sleep(3000);
  const [button] = await page.$$('xpath/.//button[contains(., "throw ball")]');
  lib.check(button, 'no "throw ball" button on the page');
  await button.click();
  await lib.sleep(350);  // the ball in flight, on its way to the chest
  await page.screenshot({ path: out });
  console.log(`wrote ${out}`);
} finally {
  await browser.close();
  await server.stop();
}
