// The JS decoder against keyanim's C++ decoder on every corpus clip, encoded here by the CLI in
// format 3 (--rotations euler) and at its default (format 5: quaternion nodes): every frame
// (keyanim decode), quarter frames over a stretch (decode --inbetweens 3), and single positions
// and times (keyanim sample --json) all equal, bit for bit in format 3; in format 5 the same but
// for a quaternion node's rotation channels, Euler angles of its rotation (sampleChannels, each
// frame's nearest the one before), within 1e-9 degrees (decode) or a binary32 ulp (sample).
// World positions (sample --world) agree within 1e-9 of the skeleton size (1e-6 with quaternion
// nodes, whose rotation keyanim's runtime computes in binary32).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { decodeKanim, nodeLabel } from 'keyanim-three/decoder/kanim.js';
import { samplePose, sampleChannels } from 'keyanim-three/decoder/sample.js';
import { expectChannels } from './channels.mjs';
import { parseBvh } from '../src/bvh.js';
import { worldPositions, measuredPoints, measuredSettings, skeletonSize, largestDistance } from 'keyanim-three/decoder/pose.js';
import { corpusDir, keyanimCli, exists, bvhFilesBelow } from './paths.mjs';

const clips = bvhFilesBelow(corpusDir);
const skip = !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}` : clips.length === 0 ? `no corpus at ${corpusDir}` : false;
const cli = (...args) => execFileSync(keyanimCli, args, { maxBuffer: 1 << 30, encoding: 'utf8' });

// The rows of a BVH the CLI decoded: the channels of each row's position, continuous from the
// first row (Appendix B).
function expectRowsEqual(clip, rows, positionOfRow, label) {
  let previous = null;
  for (let r = 0; r < rows.frameCount; ++r) {
    const got = sampleChannels(clip, positionOfRow(r), undefined, previous);
    expectChannels(clip, got, rows.frames.subarray(r * clip.channelCount, (r + 1) * clip.channelCount), `${label}: row ${r} (position ${positionOfRow(r)})`, 'binary64');
    previous = got;
  }
}

// `keyanim sample --json` channel values in frame-column order.
function cliChannels(clip, json) {
  const byName = new Map(json.joints.map((j) => [j.name, j]));
  const out = [];
  clip.nodes.forEach((n, i) => n.channels.forEach((t) => out.push(byName.get(nodeLabel(clip.nodes, i))[['Xposition', 'Yposition', 'Zposition', 'Xrotation', 'Yrotation', 'Zrotation'][t]])));
  return out;
}

// Every corpus clip encoded at the default tolerance into a scratch directory, twice: in format 3
// (--rotations euler) and at the CLI's default (format 5, or 3 for a clip without a joint it
// stores as a quaternion node).
let dir;
const FORMATS = { 3: ['--rotations', 'euler'], 5: [] };
const encoded = (format, bvh) => path.join(dir, String(format), path.relative(corpusDir, bvh)).replace(/\.bvh$/, '.kanim');
before(() => {
  if (skip) return;
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-corpus-'));
  for (const [format, args] of Object.entries(FORMATS)) cli('encode', corpusDir, '-o', path.join(dir, format), '-q', ...args);
});
after(() => dir && fs.rmSync(dir, { recursive: true, force: true }));

for (const format of Object.keys(FORMATS)) test(`corpus clips in format ${format}: JS decoder = C++ decoder${format === '3' ? ', bit for bit' : ''}`, { skip }, () => {
  let checked = 0, quaternionClips = 0;
  for (const bvh of clips) {
    const file = encoded(format, bvh);
    const label = path.relative(corpusDir, bvh);
    const clip = decodeKanim(fs.readFileSync(file));
    if (format === '3') assert.equal(clip.version.major, 3, label);
    else assert.equal(clip.version.major, clip.quatNodes.length > 0 ? 5 : 3, label);
    if (clip.quatNodes.length > 0) ++quaternionClips;
    const F = clip.frameCount;
    expectRowsEqual(clip, parseBvh(cli('decode', file, '-o', '-')), (r) => r, `${label} (every frame)`);
    const a = Math.floor(F / 2), b = Math.min(F - 1, a + 30);
    expectRowsEqual(clip, parseBvh(cli('decode', file, '-o', '-', '--inbetweens', '3', '--frames', `${a}:${b}`)), (r) => a + r / 4, `${label} (quarter frames ${a}-${b})`);

    const size = skeletonSize(clip.nodes);
    // keyanim's runtime makes a quaternion node's rotation in binary32 (spec 4.7), this decoder
    // in binary64: world positions of format 5 agree to binary32's precision, not binary64's.
    const worldBound = clip.quatNodes.length > 0 ? 1e-6 : 1e-9;
    // Positions inside the clip: `keyanim sample` refuses others (a 2-frame clip has no 7/3).
    for (const x of [0.37, F / 3 + 0.123, F - 1.5, Math.max(0, F - 1 - 1e-7), 7 / 3].filter((p) => p >= 0 && p <= F - 1)) {
      const json = JSON.parse(cli('sample', file, '--frame', String(x), '--json'));
      expectChannels(clip, sampleChannels(clip, x), cliChannels(clip, json), `${label} frame ${x}`, 'binary32');
      const world = JSON.parse(cli('sample', file, '--frame', String(x), '--world', '--json'));
      const p = worldPositions(clip.nodes, samplePose(clip, x));  // from the stored values
      world.joints.forEach((j, i) => {
        assert.equal(j.name, nodeLabel(clip.nodes, i));
        const d = Math.hypot(p[3 * i] - j.position[0], p[3 * i + 1] - j.position[1], p[3 * i + 2] - j.position[2]);
        if (d > worldBound * size) assert.fail(`${label} frame ${x}, node ${j.name}: world position off by ${d} (size ${size})`);
      });
    }
    if (clip.frameTime > 0) {
      const s = (F - 1) * clip.frameTime * 0.61;
      const want = cliChannels(clip, JSON.parse(cli('sample', file, '--time', String(s), '--json')));
      expectChannels(clip, sampleChannels(clip, s / clip.frameTime), want, `${label} time ${s}`, 'binary32');
      if (format === '3') assert.deepEqual(Array.from(samplePose(clip, s / clip.frameTime)), want, `${label} time ${s}`);
    }
    ++checked;
  }
  assert.equal(checked, clips.length);
  if (format === '5') assert.ok(quaternionClips >= clips.length / 2, `only ${quaternionClips} of ${clips.length} clips have quaternion nodes`);
});

// The viewer's BVH reader and forward kinematics over every frame of every corpus clip, on the
// points the encoder measures (joints, End Sites and shell points at the distance in its notes,
// under each reading of position channels it lists), give the error it wrote in its notes (in
// format 5, forward kinematics of the stored values: a quaternion node's rotation from its x, y, z).
for (const format of Object.keys(FORMATS)) test(`corpus clips in format ${format}: original against decoded in JS = the encoder's max_error`, { skip }, () => {
  for (const bvh of clips) {
    const label = path.relative(corpusDir, bvh);
    const clip = decodeKanim(fs.readFileSync(encoded(format, bvh)));
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
