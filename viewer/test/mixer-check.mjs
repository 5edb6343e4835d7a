// What the three.js loader tests share: encode a BVH with the CLI, play a loaded clip in an
// AnimationMixer, and check it against the CLI: every bone's world position (getWorldPosition
// after mixer.setTime and updateMatrixWorld) at whole and fractional frames equals `keyanim
// sample --frame F --world --json` within the clip's tolerance (`keyanim info --json`:
// guarantee.tolerance_units), and so at every quarter frame of the first 40 (channels from
// `keyanim decode --inbetweens 3`: a BVH of Euler angles, read with its own nodes; forward
// kinematics by pose.js), with keys at the source
// frames and at a caller's rate; the bones have the BVH's names and hierarchy (the viewer's BVH
// reader on the original), End Sites as leaf bones.
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import * as THREE from 'three';
import { KanimLoader, worldPositions } from 'keyanim-three';
import { parseBvh } from '../src/bvh.js';
import { keyanimCli } from './paths.mjs';

export const cli = (...args) => execFileSync(keyanimCli, args, { encoding: 'utf8', maxBuffer: 1 << 28 });

// A scratch directory for the encoded clips, made on first use (the test file removes it at the end).
let dir;
const scratch = () => (dir ??= fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-three-')));
export function removeScratch() { if (dir) fs.rmSync(dir, { recursive: true, force: true }); }

// Encodes a BVH at the CLI's defaults; returns the .kanim path and its info --json.
export function encode(bvh) {
  const out = path.join(scratch(), `${path.basename(bvh, '.bvh')}.kanim`);
  cli('encode', bvh, '-o', out, '-q', '-f');
  return { file: out, info: JSON.parse(cli('info', out, '--json')) };
}

// Plays the loaded clip in a mixer; at(x) poses the bones at frame position x.
export function player(result) {
  const mixer = new THREE.AnimationMixer(result.root);
  const action = mixer.clipAction(result.clip);
  action.setLoop(THREE.LoopOnce, 1);
  action.clampWhenFinished = true;  // the last frame holds instead of jumping back to the start
  action.play();
  const frameTime = result.kanim.frameTime;
  return {
    mixer,
    // reset(): a LoopOnce action that reached the end is paused, and setTime would not move it.
    at(x) { action.reset(); mixer.setTime(x * frameTime); result.root.updateMatrixWorld(true); },
  };
}

// The largest distance between the bones' world positions and the CLI's at frame position x.
export function worstAgainstCli(result, file, x) {
  const joints = JSON.parse(cli('sample', file, '--frame', String(x), '--world', '--json')).joints;
  const bones = result.skeleton.bones, v = new THREE.Vector3();
  assert.deepEqual(bones.map((b) => b.name), joints.map((j) => j.name), 'bones in the order and with the names of sample --json');
  let worst = { distance: 0, name: '' };
  joints.forEach((j, i) => {
    const d = bones[i].getWorldPosition(v).distanceTo(new THREE.Vector3(...j.position));
    if (d > worst.distance) worst = { distance: d, name: j.name };
  });
  return worst;
}

// The hierarchy against the original BVH read by the viewer's own reader.
function expectHierarchy(result, bvh) {
  const original = parseBvh(fs.readFileSync(bvh, 'latin1'));
  const bones = result.skeleton.bones;
  assert.equal(bones.length, original.nodes.length);
  const severalRoots = original.nodes.filter((n) => n.parent < 0).length > 1;
  original.nodes.forEach((n, i) => {
    if (n.name !== '') assert.equal(bones[i].name, n.name, `node ${i}`);
    const parent = n.parent >= 0 ? bones[n.parent] : severalRoots ? result.root : null;
    assert.equal(bones[i].parent, parent, `parent of ${bones[i].name}`);
    if (n.endSite) assert.equal(bones[i].children.length, 0, `End Site ${bones[i].name} is a leaf`);
    assert.ok(bones[i].isBone);
  });
}

export function checkClip(bvh) {
  const { file, info } = encode(bvh);
  const tolerance = info.guarantee.tolerance_units;
  assert.ok(tolerance > 0, 'info --json gives the clip\'s tolerance');
  const F = info.frames, fps = 1 / info.frame_time;
  const report = [];
  // Keys at the source frames, and at a caller's rate that is no divisor of the source's.
  for (const rate of [null, fps > 40 ? 50 : 24]) {
    const loader = new KanimLoader().setFrameRate(rate);
    const result = loader.parse(fs.readFileSync(file), path.basename(file, '.kanim'));
    assert.ok(result.skeleton instanceof THREE.Skeleton && result.clip instanceof THREE.AnimationClip);
    assert.ok(Math.abs(result.clip.duration - (F - 1) * info.frame_time) < 1e-9);
    assert.equal(result.clip.userData.keyanim.budgetMet, true);
    expectHierarchy(result, bvh);
    const play = player(result);
    const kinds = result.clip.tracks.map((t) => t.ValueTypeName);
    assert.ok(kinds.includes('quaternion'));
    const positions = [];
    for (let f = 0; f < 8; ++f) positions.push(Math.round((f * (F - 1)) / 7));  // whole frames, first to last
    // In between; `keyanim sample` takes positions inside the clip only (0 .. F-1), so a short
    // clip keeps those it has.
    for (const x of [0.5, 1.25, F / 3 + 0.37, F / 2 - 0.81, F - 1.5, F - 1 - 1e-3]) if (x >= 0 && x <= F - 1) positions.push(x);
    if (rate) for (const k of [1, 3, 7]) positions.push(Math.min(F - 1, k / rate / info.frame_time));  // the rate's keys
    let worst = { distance: 0 };
    for (const x of positions) {
      play.at(x);
      const w = worstAgainstCli(result, file, x);
      if (w.distance > tolerance) assert.fail(`${bvh} (keys at ${rate ?? 'the source'} fps) frame ${x}: ${w.name} is ${w.distance} from the CLI's, above the clip's tolerance ${tolerance}`);
      if (w.distance > worst.distance) worst = { ...w, x };
    }
    // Densely: every quarter frame of the first 40 frames (where the corpus clips start from a
    // rest pose and snap into the motion), channel values from the CLI (decode --inbetweens 3),
    // forward kinematics by the viewer's pose.js.
    const last = Math.min(F - 1, 40);
    const quarter = parseBvh(cli('decode', file, '-o', '-', '--inbetweens', '3', '--frames', `0:${last}`));
    for (let r = 0; r < quarter.frameCount; ++r) {
      play.at(r / 4);
      // The decoded BVH's channels are Euler angles (spec Appendix B), also a quaternion node's:
      // read with the BVH's nodes, not the clip's (whose values are stored x, y, z).
      const want = worldPositions(quarter.nodes, quarter.frames.subarray(r * quarter.channelCount, (r + 1) * quarter.channelCount));
      const v = new THREE.Vector3();
      result.skeleton.bones.forEach((b, i) => {
        const d = b.getWorldPosition(v).distanceTo(new THREE.Vector3().fromArray(want, 3 * i));
        if (d > tolerance) assert.fail(`${bvh} (keys at ${rate ?? 'the source'} fps) frame ${r / 4}: ${b.name} is ${d} from decode --inbetweens, above ${tolerance}`);
        if (d > worst.distance) worst = { distance: d, name: b.name, x: r / 4 };
      });
    }
    // The mixer plays: advancing its clock by half the clip moves the bones there.
    play.at(0);
    play.mixer.update(((F - 1) / 2) * info.frame_time);
    result.root.updateMatrixWorld(true);
    const w = worstAgainstCli(result, file, (F - 1) / 2);
    assert.ok(w.distance <= tolerance, `after mixer.update to the middle: ${w.name} off by ${w.distance}`);
    report.push(`${rate ?? 'source'} fps: ${result.clip.userData.keyanim.keyTimes} key times for ${F} frames, worst ${worst.distance.toPrecision(3)} at ${worst.name} frame ${worst.x} (tolerance ${tolerance})`);
  }
  return report;
}
