// keyanim-three in a web page, as a web developer uses it: the packed package installed in a
// fresh folder with three, served over HTTP, imported by a page through an import map (no
// bundler), in Debian's chromium (headless, puppeteer-core). The page loads a corpus clip with
// KanimLoader.loadAsync and plays it with an AnimationMixer and a SkeletonHelper: the clock
// moves the bones, the bones agree with `keyanim sample --world --json` within the clip's
// tolerance, a damaged file and a missing one reach onError (the decoder's status for the
// first), and the console stays free of errors.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import http from 'node:http';
import { execFileSync } from 'node:child_process';
import { pack, installFresh } from './packed.mjs';
import { corpusDir, keyanimCli, sourceDir, exists } from './paths.mjs';

const chromium = process.env.KEYANIM_CHROMIUM || '/usr/bin/chromium';
const corpusClip = path.join(corpusDir, 'cmu/BvhToDeepMimic__02_01.bvh');
const clipBvh = exists(corpusClip) ? corpusClip : path.join(sourceDir, 'data/cmu_02_01_walk.bvh');
const skip = !exists(chromium) ? `no chromium at ${chromium}` : !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}` : false;
const FLAGS = ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run', '--disable-background-networking',
  '--disable-component-update', '--disable-sync', '--enable-unsafe-swiftshader'];
const cli = (...args) => execFileSync(keyanimCli, args, { encoding: 'utf8' });

// The page: what README's three.js section shows, plus window.test for the test to drive.
const PAGE = `<!doctype html>
<html><head><meta charset="utf-8"><title>keyanim-three</title>
<script type="importmap">
{ "imports": {
  "three": "./node_modules/three/build/three.module.js",
  "keyanim-three": "./node_modules/keyanim-three/src/index.js",
  "fzstd": "./node_modules/fzstd/esm/index.mjs" } }
</script></head>
<body style="margin:0"><canvas id="view" width="640" height="480"></canvas>
<script type="module">
import * as THREE from 'three';
import { KanimLoader } from 'keyanim-three';

const renderer = new THREE.WebGLRenderer({ canvas: document.getElementById('view') });
const scene = new THREE.Scene();
const camera = new THREE.PerspectiveCamera(45, 640 / 480, 0.1, 1000);
camera.position.set(0, 20, 80);

const { skeleton, root, clip, kanim } = await new KanimLoader().loadAsync('clip.kanim');
scene.add(root, new THREE.SkeletonHelper(root));
const mixer = new THREE.AnimationMixer(root);
const action = mixer.clipAction(clip);
action.play();
const clock = new THREE.Clock();
renderer.setAnimationLoop(() => { mixer.update(clock.getDelta()); renderer.render(scene, camera); });

const world = () => skeleton.bones.map((b) => b.getWorldPosition(new THREE.Vector3()).toArray());
window.test = {
  names: skeleton.bones.map((b) => b.name),
  frameTime: kanim.frameTime,
  playing: () => ({ time: action.time, world: world() }),
  // Scrubbing: once, held at the end (looping, the clip's end time is its start again).
  at(x) {
    renderer.setAnimationLoop(null);
    action.setLoop(THREE.LoopOnce, 1);
    action.clampWhenFinished = true;
    action.reset();
    mixer.setTime(x * kanim.frameTime);
    root.updateMatrixWorld(true);
    return world();
  },
  failure(url) {
    return new Promise((resolve) => new KanimLoader().load(url, () => resolve(null), undefined,
      (e) => resolve({ status: e.status ?? null, where: e.where ?? null, offset: e.offset ?? null, message: String(e.message) })));
  },
};
</script></body></html>
`;

const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.kanim': 'application/octet-stream' };

// A static server over root (following node_modules' links); 404 for anything missing.
function serve(root) {
  const server = http.createServer((req, res) => {
    const file = path.join(root, decodeURIComponent(new URL(req.url, 'http://x').pathname));
    if (!file.startsWith(root) || !exists(file) || !fs.statSync(file).isFile()) { res.writeHead(404).end(); return; }
    res.writeHead(200, { 'Content-Type': TYPES[path.extname(file)] ?? 'application/octet-stream' }).end(fs.readFileSync(file));
  });
  return new Promise((resolve) => server.listen(0, '127.0.0.1', () => resolve(server)));
}

let dir, app, server, browser, kanim, info;
before(async () => {
  if (skip) return;
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-three-page-'));
  app = installFresh(dir, pack(dir).tarball);
  kanim = path.join(app, 'clip.kanim');
  cli('encode', clipBvh, '-o', kanim, '-q');
  info = JSON.parse(cli('info', kanim, '--json'));
  const damaged = fs.readFileSync(kanim);
  damaged[damaged.length - 1] ^= 1;
  fs.writeFileSync(path.join(app, 'damaged.kanim'), damaged);
  fs.writeFileSync(path.join(app, 'index.html'), PAGE);
  server = await serve(app);
  const { default: puppeteer } = await import('puppeteer-core');
  browser = await puppeteer.launch({ executablePath: chromium, headless: true, args: [...FLAGS, `--user-data-dir=${path.join(dir, 'profile')}`] });
});
after(async () => {
  await browser?.close();
  server?.close();
  if (dir) fs.rmSync(dir, { recursive: true, force: true });
});

test('a page importing the packed package plays a clip, with no console error', { skip }, async () => {
  const page = await browser.newPage();
  const problems = [];
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console error: ${m.text()}`); });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  await page.goto(`http://127.0.0.1:${server.address().port}/index.html`, { waitUntil: 'load' });
  await page.waitForFunction(() => window.test !== undefined, { timeout: 20000 });

  // Playing: the mixer's clock advances and the bones move with it.
  const first = await page.evaluate(() => window.test.playing());
  await page.waitForFunction((t) => window.test.playing().time > t + 0.2, { timeout: 10000 }, first.time);
  const later = await page.evaluate(() => window.test.playing());
  assert.notDeepEqual(later.world, first.world, 'the bones moved while playing');

  // Where the bones are, against the CLI, at whole and fractional frames.
  const names = await page.evaluate(() => window.test.names);
  const tolerance = info.guarantee.tolerance_units, F = info.frames;
  for (const x of [0, 1, 0.5, 2.25, F / 3 + 0.37, F - 1.5, F - 1]) {
    const got = await page.evaluate((p) => window.test.at(p), x);
    const want = JSON.parse(cli('sample', kanim, '--frame', String(x), '--world', '--json')).joints;
    assert.deepEqual(names, want.map((j) => j.name));
    want.forEach((j, i) => {
      const d = Math.hypot(got[i][0] - j.position[0], got[i][1] - j.position[1], got[i][2] - j.position[2]);
      if (!(d <= tolerance)) assert.fail(`frame ${x}, ${j.name}: ${got[i]} vs ${j.position}, off by ${d} (tolerance ${tolerance})`);
    });
  }

  // Failures reach onError: the decoder's error for a damaged file, the HTTP one for a missing file.
  const damaged = await page.evaluate(() => window.test.failure('damaged.kanim'));
  assert.equal(damaged?.status, 'checksum_mismatch');
  assert.equal(damaged.where, 'checksum');
  assert.match(damaged.message, /^damaged\.kanim: checksum, offset \d+ \(0x[0-9a-f]+\): checksum_mismatch: /);
  const missing = await page.evaluate(() => window.test.failure('missing.kanim'));
  assert.ok(missing && missing.status === null && /404/.test(missing.message), JSON.stringify(missing));
  // The browser itself logs the missing file's 404 as a console error: that one is expected.
  const notFound = 'console error: Failed to load resource: the server responded with a status of 404 (Not Found)';
  assert.ok(problems.includes(notFound), JSON.stringify(problems));
  assert.deepEqual(problems.filter((p) => p !== notFound), []);
  await page.close();
});
