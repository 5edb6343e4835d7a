// keyanim-three's KanimLoader under node with three.js: on three corpus clips (CMU, Bandai and
// one other; without the corpus, the two clips of data/ and the corpus cases skipped) encoded
// by the CLI at its defaults, an AnimationMixer plays the clip, and every bone's world position
// (getWorldPosition after mixer.setTime and updateMatrixWorld) at whole and fractional frames
// equals `keyanim sample --frame F --world --json` within the clip's tolerance (`keyanim info
// --json`: guarantee.tolerance_units), and so at every quarter frame of the first 40 (channels
// from `keyanim decode --inbetweens 3`), with keys at the source frames and at a caller's rate.
// The bones have the BVH's names and hierarchy (the viewer's BVH reader on the original), End
// Sites as leaf bones; several roots come under a Group; a damaged file throws the decoder's error.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import * as THREE from 'three';
import { KanimLoader, KanimError, decodeKanim, worldPositions } from 'keyanim-three';
import { parseBvh } from '../src/bvh.js';
import { corpusDir, keyanimCli, sourceDir, exists } from './paths.mjs';

const noCli = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;
const CORPUS_CLIPS = ['cmu/BvhToDeepMimic__02_01.bvh', 'bandai/dataset-1_kick_normal_001.bvh', 'misc/makehuman__walk1.bvh'];
const corpusSkip = noCli || (exists(path.join(corpusDir, CORPUS_CLIPS[0])) ? false : `no corpus at ${corpusDir}`);
const DATA_CLIPS = ['data/cmu_02_01_walk.bvh', 'data/cmu_131_03_hop.bvh'];
const MULTI_ROOT = 'fuzz/corpus/bvh/fixture_multi_root.bvh';

const cli = (...args) => execFileSync(keyanimCli, args, { encoding: 'utf8', maxBuffer: 1 << 28 });
let dir;
before(() => { dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-three-')); });
after(() => dir && fs.rmSync(dir, { recursive: true, force: true }));

// Encodes a BVH at the CLI's defaults; returns the .kanim path and its info --json.
function encode(bvh) {
  const out = path.join(dir, `${path.basename(bvh, '.bvh')}.kanim`);
  cli('encode', bvh, '-o', out, '-q', '-f');
  return { file: out, info: JSON.parse(cli('info', out, '--json')) };
}

// Plays the loaded clip in a mixer; at(x) poses the bones at frame position x.
function player(result) {
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
function worstAgainstCli(result, file, x) {
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

function checkClip(bvh) {
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
    expectHierarchy(result, bvh);
    const play = player(result);
    const kinds = result.clip.tracks.map((t) => t.ValueTypeName);
    assert.ok(kinds.includes('quaternion'));
    const positions = [];
    for (let f = 0; f < 8; ++f) positions.push(Math.round((f * (F - 1)) / 7));  // whole frames, first to last
    positions.push(0.5, 1.25, F / 3 + 0.37, F / 2 - 0.81, F - 1.5, Math.max(0, F - 1 - 1e-3));  // in between
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
      const want = worldPositions(result.kanim.nodes, quarter.frames.subarray(r * quarter.channelCount, (r + 1) * quarter.channelCount));
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

test('corpus clips (CMU, Bandai, other): bones through an AnimationMixer = sample --world', { skip: corpusSkip }, (t) => {
  for (const clip of CORPUS_CLIPS) for (const line of checkClip(path.join(corpusDir, clip))) t.diagnostic(`${clip}: ${line}`);
});

test('data/ clips: bones through an AnimationMixer = sample --world', { skip: noCli }, (t) => {
  for (const clip of DATA_CLIPS) for (const line of checkClip(path.join(sourceDir, clip))) t.diagnostic(`${clip}: ${line}`);
});

// The check above can fail: with no keys added between the source frames, three.js's chords
// leave the curves by more than the tolerance (here in the first frames, the snap from the
// rest pose), and the whole frames still agree.
test('without the added keys, in-betweens leave the tolerance', { skip: noCli }, () => {
  const { file, info } = encode(path.join(sourceDir, DATA_CLIPS[0]));
  const result = new KanimLoader().setTolerance(Infinity).parse(fs.readFileSync(file));
  assert.equal(result.clip.userData.keyanim.keyTimes, info.frames);
  const play = player(result), tolerance = info.guarantee.tolerance_units;
  play.at(1);
  assert.ok(worstAgainstCli(result, file, 1).distance <= tolerance);
  play.at(0.5);
  const w = worstAgainstCli(result, file, 0.5);
  assert.ok(w.distance > 10 * tolerance, `frame 0.5: ${w.distance} (tolerance ${tolerance})`);
});

test('several roots: a Group holds them; positions as sample --world', { skip: noCli }, () => {
  checkClip(path.join(sourceDir, MULTI_ROOT));
  const { file } = encode(path.join(sourceDir, MULTI_ROOT));
  const { root, skeleton } = new KanimLoader().parse(fs.readFileSync(file));
  assert.ok(root.isGroup && !root.isBone);
  assert.deepEqual(root.children.map((b) => b.name), ['Body', 'Prop']);
  assert.equal(skeleton.bones.length, 5);
});

test('a damaged file: parse throws the decoder\'s error (status, where, offset)', { skip: noCli }, () => {
  const { file } = encode(path.join(sourceDir, DATA_CLIPS[0]));
  const good = fs.readFileSync(file);
  const cases = [
    [(b) => { b[b.length - 1] ^= 1; }, 'checksum_mismatch'],
    [(b) => { b[0] = 0; }, 'bad_signature'],
  ];
  for (const [damage, status] of cases) {
    const bytes = Buffer.from(good);
    damage(bytes);
    let want;
    try { decodeKanim(bytes); } catch (e) { want = e; }
    assert.equal(want?.status, status);
    assert.throws(() => new KanimLoader().parse(bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.length)), (e) => {
      assert.ok(e instanceof KanimError);
      assert.deepEqual([e.status, e.where, e.offset, e.message], [want.status, want.where, want.offset, want.message]);
      return true;
    });
  }
  const cut = good.subarray(0, 100);
  assert.throws(() => new KanimLoader().parse(cut), (e) => e.status === 'truncated' && /offset \d+/.test(e.message));
});

test('setFrameRate and setTolerance reject what is not a number > 0', () => {
  const loader = new KanimLoader();
  for (const bad of [0, -1, NaN, Infinity, '30']) assert.throws(() => loader.setFrameRate(bad), RangeError);
  for (const bad of [0, -1, NaN]) assert.throws(() => loader.setTolerance(bad), RangeError);
  assert.equal(loader.setFrameRate(null).frameRate, null);
});
