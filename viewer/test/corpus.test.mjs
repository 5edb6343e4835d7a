// The JS decoder against keyanim's C++ decoder on format-3 files of every corpus clip, encoded
// here by the CLI: every frame (keyanim decode), quarter frames over a stretch (decode
// --inbetweens 3), and single positions and times (keyanim sample --json) all equal, bit for
// bit; world positions (sample --world) agree within 1e-9 of the skeleton size.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { decodeKanim, nodeLabel } from 'keyanim-three/decoder/kanim.js';
import { samplePose } from 'keyanim-three/decoder/sample.js';
import { parseBvh } from '../src/bvh.js';
import { worldPositions, measuredPoints, measuredSettings, skeletonSize, largestDistance } from 'keyanim-three/decoder/pose.js';
import { corpusDir, keyanimCli, exists, bvhFilesBelow } from './paths.mjs';

const clips = bvhFilesBelow(corpusDir);
const skip = !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}` : clips.length === 0 ? `no corpus at ${corpusDir}` : false;
const cli = (...args) => execFileSync(keyanimCli, args, { maxBuffer: 1 << 30, encoding: 'utf8' });

function expectRowsEqual(clip, rows, positionOfRow, label) {
  const got = new Float32Array(clip.channelCount);
  for (let r = 0; r < rows.frameCount; ++r) {
    samplePose(clip, positionOfRow(r), got);
    for (let c = 0; c < clip.channelCount; ++c) {
      const want = Math.fround(rows.frames[r * clip.channelCount + c]);
      if (!Object.is(got[c], want)) assert.fail(`${label}: row ${r} (position ${positionOfRow(r)}), channel ${c}: JS ${got[c]} != C++ ${want}`);
    }
  }
}

// `keyanim sample --json` channel values in frame-column order.
function cliChannels(clip, json) {
  const byName = new Map(json.joints.map((j) => [j.name, j]));
  const out = [];
  clip.nodes.forEach((n, i) => n.channels.forEach((t) => out.push(byName.get(nodeLabel(clip.nodes, i))[['Xposition', 'Yposition', 'Zposition', 'Xrotation', 'Yrotation', 'Zrotation'][t]])));
  return out;
}

// Every corpus clip encoded once, at the default tolerance, into a scratch directory.
let dir;
before(() => {
  if (skip) return;
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-corpus-'));
  cli('encode', corpusDir, '-o', dir, '-q');
});
after(() => dir && fs.rmSync(dir, { recursive: true, force: true }));

test('corpus clips: JS decoder = C++ decoder, bit for bit', { skip }, () => {
  let checked = 0;
  for (const bvh of clips) {
    const file = path.join(dir, path.relative(corpusDir, bvh)).replace(/\.bvh$/, '.kanim');
    const label = path.relative(corpusDir, bvh);
    const clip = decodeKanim(fs.readFileSync(file));
    assert.equal(clip.version.major, 3, label);
    const F = clip.frameCount;
    expectRowsEqual(clip, parseBvh(cli('decode', file, '-o', '-')), (r) => r, `${label} (every frame)`);
    const a = Math.floor(F / 2), b = Math.min(F - 1, a + 30);
    expectRowsEqual(clip, parseBvh(cli('decode', file, '-o', '-', '--inbetweens', '3', '--frames', `${a}:${b}`)), (r) => a + r / 4, `${label} (quarter frames ${a}-${b})`);

    const size = skeletonSize(clip.nodes);
    // Positions inside the clip: `keyanim sample` refuses others (a 2-frame clip has no 7/3).
    for (const x of [0.37, F / 3 + 0.123, F - 1.5, Math.max(0, F - 1 - 1e-7), 7 / 3].filter((p) => p >= 0 && p <= F - 1)) {
      const json = JSON.parse(cli('sample', file, '--frame', String(x), '--json'));
      const want = cliChannels(clip, json), got = Array.from(samplePose(clip, x));
      for (let c = 0; c < got.length; ++c) if (!Object.is(got[c], want[c])) assert.fail(`${label} frame ${x}, channel ${c}: JS ${got[c]} != C++ ${want[c]}`);
      const world = JSON.parse(cli('sample', file, '--frame', String(x), '--world', '--json'));
      const p = worldPositions(clip.nodes, got);
      world.joints.forEach((j, i) => {
        assert.equal(j.name, nodeLabel(clip.nodes, i));
        const d = Math.hypot(p[3 * i] - j.position[0], p[3 * i + 1] - j.position[1], p[3 * i + 2] - j.position[2]);
        if (d > 1e-9 * size) assert.fail(`${label} frame ${x}, node ${j.name}: world position off by ${d} (size ${size})`);
      });
    }
    if (clip.frameTime > 0) {
      const s = (F - 1) * clip.frameTime * 0.61;
      const want = cliChannels(clip, JSON.parse(cli('sample', file, '--time', String(s), '--json')));
      assert.deepEqual(Array.from(samplePose(clip, s / clip.frameTime)), want, `${label} time ${s}`);
    }
    ++checked;
  }
  assert.equal(checked, clips.length);
});

// The viewer's BVH reader and forward kinematics over every frame of every corpus clip, on the
// points the encoder measures (joints, End Sites and shell points at the distance in its notes,
// under each reading of position channels it lists), give the error it wrote in its notes.
test('corpus clips: original against decoded in JS = the encoder\'s max_error', { skip }, () => {
  for (const bvh of clips) {
    const label = path.relative(corpusDir, bvh);
    const clip = decodeKanim(fs.readFileSync(path.join(dir, label).replace(/\.bvh$/, '.kanim')));
    const original = parseBvh(fs.readFileSync(bvh, 'latin1'));
    assert.equal(original.frameCount, clip.frameCount, label);
    let worst = 0;
    const values = new Float32Array(clip.channelCount), n = original.channelCount;
    assert.match(clip.notes, /^shell_units=.*$/m, label);
    const { shell, readings } = measuredSettings(clip.notes, skeletonSize(clip.nodes));
    for (let f = 0; f < clip.frameCount; ++f) {
      for (const reading of readings) {
        const a = measuredPoints(clip.nodes, samplePose(clip, f, values), shell, reading);
        const b = measuredPoints(original.nodes, original.frames.subarray(f * n, (f + 1) * n), shell, reading);
        worst = Math.max(worst, largestDistance(a, b, 4).distance);
      }
    }
    const reported = Number(/^max_error=(.*)$/m.exec(clip.notes)[1]);  // printed with 6 digits
    assert.ok(Math.abs(worst - reported) <= 1e-5 * reported + 1e-12, `${label}: JS ${worst}, encoder ${reported}`);
  }
});
