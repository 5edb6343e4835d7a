// The viewer in a real browser: Debian's chromium, headless, driven by puppeteer-core. The page
// loads a corpus clip (format 5: quaternion nodes) with no console error; sampleWorld agrees
// with `keyanim sample --world --json` within 1e-4 of the skeleton size, at frames and
// in-betweens; the curve panel shows a quaternion node's rotation channels as `keyanim decode`
// writes them (Euler angles, continuous); a screenshot of the 3D view shows both skeletons
// (pixels of each colour). The same for a page from `keyanim view`.
// A BVH opened alone plays; a Bandai-like walker stays in the picture (through the page's own
// camera); a z-up file is shown upright.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { pathToFileURL } from 'node:url';
import { decodeKanim } from 'keyanim-three/decoder/kanim.js';
import { parseBvh } from '../src/bvh.js';
import { skeletonSize } from 'keyanim-three/decoder/pose.js';
import { decodePng } from './png.mjs';
import { bandaiLikeBvh } from './bandai-like.mjs';
import { corpusDir, keyanimCli, viewerPage, sourceDir, exists } from './paths.mjs';

const chromium = process.env.KEYANIM_CHROMIUM || '/usr/bin/chromium';
// A corpus clip (CMU 02_01, a walk); without the corpus, the same take shipped in data/.
const corpusClip = path.join(corpusDir, 'cmu/BvhToDeepMimic__02_01.bvh');
const clipBvh = exists(corpusClip) ? corpusClip : path.join(sourceDir, 'data/cmu_02_01_walk.bvh');
const skip = !exists(chromium) ? `no chromium at ${chromium}` : !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}`
  : !exists(viewerPage) ? `no built viewer page at ${viewerPage}` : false;
const FLAGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync',
  '--enable-unsafe-swiftshader'];  // WebGL in software: chromium warns that the implicit fallback is going away

let browser, dir, kanim, clip;
const cli = (...args) => execFileSync(keyanimCli, args, { encoding: 'utf8' });

before(async () => {
  if (skip) return;
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-browser-'));
  kanim = path.join(dir, 'clip.kanim');
  cli('encode', clipBvh, '-o', kanim, '-q');
  clip = decodeKanim(fs.readFileSync(kanim));
  const { default: puppeteer } = await import('puppeteer-core');
  browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: [...FLAGS, `--user-data-dir=${path.join(dir, 'profile')}`] });
});
after(async () => {
  await browser?.close();
  if (dir) fs.rmSync(dir, { recursive: true, force: true });
});

// Opens a page; collects console errors and uncaught exceptions.
async function open(url) {
  const page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  const problems = [];
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console error: ${m.text()}`); });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => problems.push(`request failed: ${r.url()}`));
  await page.goto(url, { waitUntil: 'load' });
  await page.waitForFunction(() => window.keyanim !== undefined);
  return { page, problems };
}

// Pixels of a screenshot for which is(r, g, b) holds.
function count(png, is) {
  let n = 0;
  for (let i = 0; i < png.data.length; i += png.channels) if (is(png.data[i], png.data[i + 1], png.data[i + 2])) ++n;
  return n;
}
// Lit and shaded, the figures' colours vary: orange is red over green over blue, blue the reverse.
const isBackground = (r, g, b) => r === 0x1c && g === 0x1f && b === 0x26;
const isOrange = (r, g, b) => r > g + 25 && g > b + 15 && r > 90;
const isBlue = (r, g, b) => b > r + 50 && b > g + 10;

// withDecoded false: a BVH shown alone, drawn in the original's colour and nothing orange.
async function expectSkeletonsDrawn(page, withOriginal, shotPath, withDecoded = true) {
  const view = await page.$('#view');
  const png = decodePng(Buffer.from(await view.screenshot(shotPath ? { path: shotPath } : {})));
  const pixels = png.width * png.height, background = count(png, isBackground);
  assert.ok(background > pixels * 0.3 && background < pixels * 0.995, `background ${background} of ${pixels} pixels: the view is blank or not drawn`);
  const orange = count(png, isOrange), blue = count(png, isBlue);
  if (withDecoded) assert.ok(orange > 300, `${orange} orange pixels: no decoded skeleton in the screenshot`);
  else assert.ok(orange < 20, `${orange} orange pixels without a clip`);
  if (withOriginal) assert.ok(blue > 100, `${blue} blue pixels: no original skeleton in the screenshot`);
  else assert.ok(blue < 20, `${blue} blue pixels without an original`);
}

async function expectWorldAgrees(page) {
  const size = skeletonSize(clip.nodes), F = clip.frameCount;
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), F);
  for (const x of [0, 1, 0.5, 2.25, F / 3 + 0.37, F - 1.5, F - 1]) {
    const got = await page.evaluate((p) => window.keyanim.sampleWorld(p), x);
    const want = JSON.parse(cli('sample', kanim, '--frame', String(x), '--world', '--json')).joints;
    assert.equal(got.length, want.length);
    want.forEach((j, i) => {
      const d = Math.hypot(got[i][0] - j.position[0], got[i][1] - j.position[1], got[i][2] - j.position[2]);
      if (!(d <= 1e-4 * size)) assert.fail(`frame ${x}, node ${i} (${j.name}): ${got[i]} vs ${j.position}, off by ${d} (skeleton size ${size})`);
    });
  }
}

test('the page loads a corpus clip through window.keyanim.load, with no console error', { skip }, async () => {
  const { page, problems } = await open(pathToFileURL(viewerPage).href);
  const bytes = fs.readFileSync(kanim).toString('base64');
  await page.evaluate((b) => window.keyanim.load(Uint8Array.from(atob(b), (c) => c.charCodeAt(0)).buffer, 'clip.kanim'), bytes);
  await expectWorldAgrees(page);
  // The curve panel on a quaternion node's rotation channels: the angles of keyanim decode.
  assert.ok(clip.quatNodes.length > 0, 'the CLI wrote quaternion nodes');
  const decoded = parseBvh(cli('decode', kanim, '-o', '-')), C = clip.channelCount;
  for (const q of [clip.quatNodes[0], clip.quatNodes[clip.quatNodes.length - 1]]) {
    for (let k = 0; k < 3; ++k) {
      const c = q.column + k;
      const got = await page.evaluate((ch, n) => Array.from({ length: n }, (_, f) => window.keyanim.curveAt(ch, f)), c, clip.frameCount);
      got.forEach((v, f) => { if (!(Math.abs(v - decoded.frames[f * C + c]) <= 1e-9)) assert.fail(`curve of channel ${c} at frame ${f}: ${v}, keyanim decode ${decoded.frames[f * C + c]}`); });
      const between = await page.evaluate((ch) => window.keyanim.curveAt(ch, 10.5), c);
      assert.ok(Math.abs(between - (got[10] + got[11]) / 2) < 5, `an in-between angle ${between} near its frames' (${got[10]}, ${got[11]})`);
    }
  }
  await page.evaluate((x) => window.keyanim.show(x), clip.frameCount / 2 + 0.5);
  await expectSkeletonsDrawn(page, false);
  assert.match(await page.$eval('#facts', (e) => e.textContent), new RegExp(`frames${clip.frameCount}`));
  assert.deepEqual(problems, []);
  await page.close();
});

test('a page from `keyanim view --against` plays the clip with its original overlaid', { skip }, async () => {
  const html = path.join(dir, 'view.html');
  assert.equal(cli('view', kanim, '--against', clipBvh, '-o', html, '--no-open').trim(), html);
  const { page, problems } = await open(pathToFileURL(html).href);
  await expectWorldAgrees(page);
  // The largest distance over the clip is the error the encoder measured (its notes say it).
  const comparison = await page.evaluate(() => window.keyanim.comparison);
  const reported = Number(/max_error=([0-9.eE+-]+)/.exec(clip.notes)?.[1]);
  assert.ok(comparison && Math.abs(comparison.distance - reported) <= 1e-6 * skeletonSize(clip.nodes), `page: ${JSON.stringify(comparison)}, encoder: ${reported}`);
  await page.evaluate(() => { document.getElementById('rate').value = '60'; window.keyanim.show(40.5); });
  assert.match(await page.$eval('#compare-frame', (e) => e.textContent), /at .+ of the skeleton size/);
  await expectSkeletonsDrawn(page, true, process.env.KEYANIM_SCREENSHOT);
  // Playing moves the slider.
  const slider = () => page.$eval('#slider', (e) => Number(e.value));
  const before = await slider();
  await page.click('#play');
  await page.waitForFunction((x) => Number(document.getElementById('slider').value) !== x, { timeout: 5000 }, before);
  assert.equal(await page.$eval('#play', (e) => e.textContent), 'Pause');
  await page.click('#play');
  assert.deepEqual(problems, []);
  await page.close();
});

test('the file picker opens a clip and its original; a damaged file is reported in the page', { skip }, async () => {
  const { page, problems } = await open(pathToFileURL(viewerPage).href);
  const input = await page.$('#open');
  await input.uploadFile(clipBvh, kanim);  // in either order: the clip is opened first
  await page.waitForFunction(() => window.keyanim.comparison !== null, { timeout: 10000 });
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), clip.frameCount);
  assert.match(await page.$eval('#facts', (e) => e.textContent), /original/);
  await expectSkeletonsDrawn(page, true);

  const damaged = path.join(dir, 'damaged.kanim');
  const bytes = fs.readFileSync(kanim);
  bytes[bytes.length - 1] ^= 1;
  fs.writeFileSync(damaged, bytes);
  await input.uploadFile(damaged);
  await page.waitForFunction(() => document.getElementById('message').className === 'error');
  assert.match(await page.$eval('#message', (e) => e.textContent), /^damaged\.kanim: checksum, offset \d+ \(0x[0-9a-f]+\): checksum_mismatch: /);
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), clip.frameCount, 'the clip shown before stays');
  assert.deepEqual(problems, []);
  await page.close();
});

// Issue 28, items 10 and 2: a BVH opened alone is played (not "No clip loaded"), and the camera
// keeps a Bandai-like walker (a ROOT that stays at the origin, Hips walking 800 units) in the
// picture at every frame, following it or framing the whole clip; the clip's .kanim opened
// next is compared with it.
test('a BVH alone plays; a Bandai-like walker stays in the picture; its .kanim then compares', { skip }, async () => {
  const bvhPath = path.join(dir, 'bandai_like.bvh'), kanimPath = path.join(dir, 'bandai_like.kanim');
  fs.writeFileSync(bvhPath, bandaiLikeBvh());
  cli('encode', bvhPath, '-o', kanimPath, '-q');
  const { page, problems } = await open(pathToFileURL(viewerPage).href);
  const input = await page.$('#open');
  await input.uploadFile(bvhPath);
  await page.waitForFunction(() => document.body.classList.contains('loaded'), { timeout: 10000 });
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), 195);
  assert.match(await page.$eval('#message', (e) => e.textContent), /^bandai_like\.bvh: 195 frames; playing the BVH alone: open its \.kanim too to compare/);
  assert.match(await page.$eval('#facts', (e) => e.textContent), /formatBVH \(no \.kanim loaded\)frames195/);
  assert.equal(await page.$eval('#empty', (e) => getComputedStyle(e).display), 'none', '"No clip loaded" is hidden');
  await expectSkeletonsDrawn(page, true, undefined, false);
  // No bone from the placeholder joint_Root to Hips: 17 nodes, 16 links, 15 drawn.
  assert.deepEqual(await page.evaluate(() => [window.keyanim.nodeNames.length, window.keyanim.app.view.figures.original.bones.length]), [17, 15]);

  // In the picture at every tenth frame: following (the default: placeholders may leave), then
  // with following off (every node, joint_Root too).
  const expectInView = async (label, withPlaceholders) => {
    for (let x = 0; x < 195; x += 10) {
      const nodes = await page.evaluate((p) => window.keyanim.inView(p), x);
      const lost = nodes.filter((n) => (withPlaceholders || !n.placeholder) && !n.ndc.every((v) => Math.abs(v) <= 1));
      assert.deepEqual(lost, [], `${label}, frame ${x}`);
    }
  };
  await expectInView('following', false);
  await page.click('#follow');
  await expectInView('whole clip', true);
  await page.click('#follow');

  // Playing moves the slider.
  const slider = () => page.$eval('#slider', (e) => Number(e.value));
  await page.evaluate(() => window.keyanim.show(0));
  await page.click('#play');
  await page.waitForFunction(() => Number(document.getElementById('slider').value) > 0, { timeout: 5000 });
  await page.click('#play');
  assert.ok(await slider() > 0);

  // The .kanim opened next: decoded and compared with the BVH already open.
  await input.uploadFile(kanimPath);
  await page.waitForFunction(() => window.keyanim.comparison !== null, { timeout: 10000 });
  await expectInView('the .kanim, following', false);
  await expectSkeletonsDrawn(page, true);
  assert.deepEqual(problems, []);
  await page.close();
});

// Item 9: a z-up file is detected and shown upright: its joints span the screen's height.
test('a z-up BVH is shown upright (up: auto detects z; y lays it down)', { skip }, async () => {
  const zPath = path.join(dir, 'bandai_like_z.bvh');
  fs.writeFileSync(zPath, bandaiLikeBvh('z'));
  const { page, problems } = await open(pathToFileURL(viewerPage).href);
  await page.evaluate((text) => window.keyanim.loadOriginal(text, 'bandai_like_z.bvh'), fs.readFileSync(zPath, 'utf8'));
  assert.equal(await page.evaluate(() => window.keyanim.up), 'z');
  assert.match(await page.$eval('#up', (e) => e.options[0].textContent), /^auto \(z\)$/);
  // Upright: the head is above the feet on the screen (NDC y), by more than it is beside them.
  const names = await page.evaluate(() => window.keyanim.nodeNames);
  const head = names.indexOf('Head'), foot = names.indexOf('LeftLeg');
  const rise = async () => { const n = await page.evaluate(() => window.keyanim.inView(0)); return n[head].ndc[1] - n[foot].ndc[1]; };
  const upright = await rise();
  assert.ok(upright > 0.2, `head ${upright} above the knee on screen with up z`);
  await page.select('#up', 'y');
  const lying = await rise();
  assert.ok(Math.abs(lying) < upright / 3, `lying down with up y: ${lying} (upright: ${upright})`);
  assert.deepEqual(problems, []);
  await page.close();
});

// Issue 25: a bank opened with the file picker lists its clips (name, frames, duration, as
// `keyanim list --json` has them); picking one in the list shows it, sampling as `keyanim sample
// BANK:NAME --world --json`; a damaged clip says why when picked (its name, checksum_mismatch),
// is marked in the list, and the clip shown before stays; the others still play.
test('a .kbank lists its clips; picking one shows it; a damaged one says why, the others play', { skip }, async () => {
  const input = path.join(dir, 'bank-in'), bank = path.join(dir, 'clips.kbank'), damaged = path.join(dir, 'damaged.kbank');
  fs.mkdirSync(path.join(input, 'again'), { recursive: true });
  for (const f of ['cmu_02_01_walk.bvh', 'cmu_131_03_hop.bvh']) fs.copyFileSync(path.join(sourceDir, 'data', f), path.join(input, f));
  fs.copyFileSync(path.join(sourceDir, 'data/cmu_02_01_walk.bvh'), path.join(input, 'again/walk.bvh'));
  cli('pack', input, '-o', bank, '--dictionary', 'on', '-q');
  const listed = JSON.parse(cli('list', bank, '--json')).clips;
  const bytes = fs.readFileSync(bank);
  const hop = listed.findIndex((c) => c.name === 'cmu_131_03_hop');
  const hopAt = Number(bytes.readBigUInt64LE(40 + 32 * 2 + 40 * hop));  // its clip-table Offset (spec 10.3)
  bytes[hopAt + 200] ^= 0x08;  // inside the member: its own CRC-32 finds it, the bank's index is intact
  fs.writeFileSync(damaged, bytes);

  const { page, problems } = await open(pathToFileURL(viewerPage).href);
  const expectSampled = async (file, name) => {
    for (const x of [0, 10.5, 100.25]) {
      const got = await page.evaluate((p) => window.keyanim.sampleWorld(p), x);
      const want = JSON.parse(cli('sample', `${file}:${name}`, '--frame', String(x), '--world', '--json')).joints;
      assert.equal(got.length, want.length);
      want.forEach((j, i) => {
        const d = Math.hypot(got[i][0] - j.position[0], got[i][1] - j.position[1], got[i][2] - j.position[2]);
        // keyanim's runtime makes a quaternion node's rotation in binary32 (spec 4.7), the page in binary64.
        if (!(d <= 1e-6 * 100)) assert.fail(`${name} frame ${x}, node ${j.name}: ${got[i]} vs ${j.position}`);
      });
    }
  };
  await (await page.$('#open')).uploadFile(bank);
  await page.waitForFunction(() => window.keyanim.bankClips.length > 0 && document.body.classList.contains('loaded'), { timeout: 10000 });
  assert.equal(await page.$eval('#bank', (e) => e.hidden), false);
  const options = await page.$$eval('#bank-clips option', (os) => os.map((o) => o.textContent));
  assert.deepEqual(options, listed.map((c) => `${c.name} · ${c.frames} frames · ${c.duration.toFixed(3)} s`));
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), listed[0].frames);
  await expectSampled(bank, listed[0].name);
  await page.select('#bank-clips', String(hop));
  assert.equal(await page.evaluate(() => window.keyanim.bankShown), hop);
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), listed[hop].frames);
  assert.match(await page.$eval('#message', (e) => e.textContent), new RegExp(`^clips\\.kbank:cmu_131_03_hop: ${listed[hop].frames} frames`));
  await expectSampled(bank, 'cmu_131_03_hop');
  await expectSkeletonsDrawn(page, false);

  // The damaged bank: opens; its damaged clip is refused when picked, the others play.
  await (await page.$('#open')).uploadFile(damaged);
  await page.waitForFunction(() => window.keyanim.bankShown === 0 && document.getElementById('message').textContent.startsWith('damaged.kbank'), { timeout: 10000 });
  const walkAgain = listed.findIndex((c) => c.name === 'again/walk');
  await page.select('#bank-clips', String(walkAgain));
  assert.equal(await page.evaluate(() => window.keyanim.bankShown), walkAgain);
  await page.select('#bank-clips', String(hop));
  const message = await page.$eval('#message', (e) => ({ text: e.textContent, error: e.className }));
  assert.equal(message.error, 'error');
  assert.match(message.text, /^damaged\.kbank:cmu_131_03_hop: clip "cmu_131_03_hop" \(#\d\): checksum, offset \d+ \(0x[0-9a-f]+\): checksum_mismatch: /);
  assert.equal(await page.evaluate(() => window.keyanim.bankShown), walkAgain, 'the clip shown before stays');
  assert.equal(await page.$eval('#bank-clips', (e) => e.value), String(walkAgain));
  assert.match(await page.$eval(`#bank-clips option:nth-child(${hop + 1})`, (e) => e.textContent), / · damaged$/);
  await expectSampled(damaged, 'again/walk');
  await page.select('#bank-clips', '0');
  assert.equal(await page.evaluate(() => window.keyanim.frameCount), listed[0].frames);
  // A .kanim opened next puts the bank's list away.
  await (await page.$('#open')).uploadFile(kanim);
  await page.waitForFunction(() => window.keyanim.bankClips.length === 0, { timeout: 10000 });
  assert.equal(await page.$eval('#bank', (e) => e.hidden), true);
  assert.deepEqual(problems, []);
  await page.close();
});
