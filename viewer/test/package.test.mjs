// keyanim-three as a user installs it: `npm pack` (offline) gives a tarball with the package's
// sources and README and nothing else; `npm install` of it in a fresh folder, with three,
// gives a package (a copy, not a link to this tree) whose `import { KanimLoader } from
// 'keyanim-three'` works under node: spec test vectors (3.0 with zstd sections, 5.0 with
// quaternion nodes) parse to the skeleton and clip the workspace's decoder reads from them.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { decodeKanim, nodeLabel } from 'keyanim-three/decoder/kanim.js';
import { pack, installFresh, packageDir } from './packed.mjs';
import { vectorsDir } from './paths.mjs';

const VECTORS = [path.join(vectorsDir, 'v3_long.kanim'), path.join(vectorsDir, 'v5_quat.kanim')];  // zstd sections: fzstd is installed and works
let dir, packed, app;
before(() => {
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-three-pack-'));
  packed = pack(dir);
  app = installFresh(dir, packed.tarball);
});
after(() => dir && fs.rmSync(dir, { recursive: true, force: true }));

test('npm pack: the sources, package.json and README, nothing else', () => {
  const files = packed.files;
  for (const f of ['package.json', 'README.md', 'src/index.js', 'src/three/loader.js', 'src/decoder/kanim.js', 'src/decoder/zstd.js'])
    assert.ok(files.includes(f), `${f} is in the tarball: ${files.join(', ')}`);
  assert.deepEqual(files.filter((f) => !/^(package\.json|README\.md|src\/.*\.js)$/.test(f)), []);
});

test('installed in a fresh folder: import { KanimLoader } from \'keyanim-three\' parses a clip', () => {
  const installed = path.join(app, 'node_modules/keyanim-three');
  assert.ok(!fs.lstatSync(installed).isSymbolicLink(), 'installed from the tarball, not linked');
  const script = path.join(app, 'parse.mjs');
  fs.writeFileSync(script, `
import fs from 'node:fs';
import * as THREE from 'three';
import { KanimLoader } from 'keyanim-three';
const { skeleton, root, clip, kanim } = new KanimLoader().parse(fs.readFileSync(process.argv[2]));
const mixer = new THREE.AnimationMixer(root);
mixer.clipAction(clip).play();
mixer.setTime(clip.duration / 2);
console.log(JSON.stringify({ bones: skeleton.bones.map((b) => b.name), isBone: root.isBone === true,
  duration: clip.duration, tracks: clip.tracks.length, frames: kanim.frameCount, quatNodes: kanim.quatNodes.length }));
`);
  for (const vector of VECTORS) {
    const out = JSON.parse(execFileSync(process.execPath, [script, vector], { cwd: app, encoding: 'utf8' }));
    const clip = decodeKanim(fs.readFileSync(vector));
    assert.deepEqual(out.bones, clip.nodes.map((_, i) => nodeLabel(clip.nodes, i)));
    assert.equal(out.frames, clip.frameCount);
    assert.equal(out.quatNodes, clip.quatNodes.length);
    assert.ok(Math.abs(out.duration - (clip.frameCount - 1) * clip.frameTime) < 1e-9);
    const rotated = clip.nodes.filter((n) => n.channels.some((t) => t >= 3)).length;
    const moved = clip.nodes.filter((n) => n.channels.some((t) => t < 3)).length;
    assert.equal(out.tracks, rotated + moved);
  }
  // What was installed is this tree's package, file for file.
  for (const f of packed.files) assert.ok(fs.readFileSync(path.join(installed, f)).equals(fs.readFileSync(path.join(packageDir, f))), f);
});
