// A screenshot of a page written by `keyanim view`, at a frame position, for documentation
// (docs/viewer.png). Uses Debian's chromium through puppeteer-core, like the browser tests.
// Usage: node screenshot.mjs PAGE.html OUT.png [FRAME] [CURVE_CHANNEL]
import puppeteer from 'puppeteer-core';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [pagePath, out, frame = '0', channel] = process.argv.slice(2);
if (!out) throw new Error('usage: node screenshot.mjs PAGE.html OUT.png [FRAME] [CURVE_CHANNEL]');
const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-shot-'));
const browser = await puppeteer.launch({
  executablePath: process.env.KEYANIM_CHROMIUM || '/usr/bin/chromium', headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
    '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader', `--user-data-dir=${profile}`],
});
try {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  await page.goto(pathToFileURL(path.resolve(pagePath)).href, { waitUntil: 'load' });
  await page.evaluate((x, c) => {
    if (c !== undefined) { const s = document.getElementById('curve-channel'); s.value = c; s.dispatchEvent(new Event('change')); }
    window.keyanim.show(Number(x));
  }, frame, channel);
  await page.screenshot({ path: out });
} finally {
  await browser.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
