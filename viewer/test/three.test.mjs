// keyanim-three's KanimLoader under node with three.js, on the clips of data/ and a BVH with
// two roots (the corpus clips: three_corpus.test.mjs): an AnimationMixer plays each clip and
// its bones agree with the CLI (mixer-check.mjs says how); without the keys the loader adds,
// three.js's in-betweens leave the tolerance; several roots come under a Group; a damaged file
// throws the decoder's error; bad options are refused; a bank's clip gives its own file's tracks.
// Version 5 (the CLI's default, and the v5 test vectors): a quaternion node's bone takes the
// rotation the decoder makes of its stored x, y, z (spec 4.7), and its track stays in one
// hemisphere.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import os from 'node:os';
import { execFileSync } from 'node:child_process';
import * as THREE from 'three';
import { KanimLoader, KanimError, decodeKanim, openBank, decodeBankClip, samplePose, worldPositions } from 'keyanim-three';
import { localRotation } from 'keyanim-three/decoder/rotation.js';
import { encode, player, worstAgainstCli, checkClip, removeScratch } from './mixer-check.mjs';
import { keyanimCli, sourceDir, vectorsDir, exists } from './paths.mjs';

const noCli = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;
const DATA_CLIPS = ['data/cmu_02_01_walk.bvh', 'data/cmu_131_03_hop.bvh'];
const MULTI_ROOT = 'fuzz/corpus/bvh/fixture_multi_root.bvh';
after(removeScratch);

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

// A budget the keys cannot meet: the refinement stops at 64 key times per source frame and says so.
test('an unreachable tolerance: key times bounded, budgetMet false', { skip: noCli }, () => {
  const { file, info } = encode(path.join(sourceDir, DATA_CLIPS[0]));
  const { keyanim } = new KanimLoader().setTolerance(1e-12).parse(fs.readFileSync(file)).clip.userData;
  assert.equal(keyanim.budgetMet, false);
  assert.ok(keyanim.keyTimes > 8 * info.frames && keyanim.keyTimes <= 64 * info.frames, `${keyanim.keyTimes} key times for ${info.frames} frames`);
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

// Spec 4.7 through three.js, on the v5 vectors (archive and runtime profile): every key of a
// bone's rotation track at a source frame is the decoder's rotation of its node there (a
// quaternion node's from its stored x, y, z), q or -q within binary32 rounding, and neighbouring
// keys are in one hemisphere; that rotation is the .json's expected one where it lists the
// frame. Played by a mixer over the first 240 frames, the bones' local rotations and world
// positions are the decoder's (pose.js). (Later, binary32 key times put the mixer 1e-4 frame
// off a key: the keys themselves are checked there.)
const quatNear = (a, b) => Math.min(Math.hypot(...a.map((v, k) => v - b[k])), Math.hypot(...a.map((v, k) => v + b[k])));
for (const name of ['v5_quat', 'v5_blocks', 'v5_quat_runtime', 'v5_blocks_runtime']) {
  test(`${name}.kanim: the loader's bones take the decoder's rotations`, () => {
    const result = new KanimLoader().parse(fs.readFileSync(path.join(vectorsDir, `${name}.kanim`)));
    const { kanim, skeleton, clip } = result;
    assert.ok(kanim.quatNodes.length > 0);
    const json = path.join(vectorsDir, `${name.replace(/_runtime$/, '')}.json`);
    const expected = exists(json) ? new Map(JSON.parse(fs.readFileSync(json, 'utf8')).samples.map((s) => [s.position, s.rotations])) : new Map();
    const trackOf = new Map(clip.tracks.map((t) => [t.name, t]));
    let keysChecked = 0, jsonChecked = 0;
    kanim.nodes.forEach((node, i) => {
      if (!node.channels.some((t) => t >= 3)) return;
      const track = trackOf.get(`${skeleton.bones[i].name}.quaternion`);
      assert.ok(track, `node ${i} has a rotation track`);
      for (let k = 0; k < track.times.length; ++k) {
        const key = Array.from(track.values.subarray(4 * k, 4 * k + 4));
        if (k > 0 && key.reduce((s, v, c) => s + v * track.values[4 * (k - 1) + c], 0) < 0) assert.fail(`${track.name}: key ${k} in the other hemisphere`);
        const x = track.times[k] / kanim.frameTime, f = Math.round(x);
        if (Math.abs(x - f) > 1e-3) continue;  // an added key between source frames
        const values = samplePose(kanim, f), rotation = localRotation(node, values);
        if (!(quatNear(key, rotation) <= 1e-6)) assert.fail(`${track.name} key ${k} (frame ${f}): ${key}, the decoder's ${rotation}`);
        ++keysChecked;
        const q = kanim.quatNodes.findIndex((n) => n.node === i), rotations = expected.get(f);
        if (q < 0 || !rotations) continue;
        if (!(quatNear(key, rotations[q]) <= 2e-6)) assert.fail(`${track.name} key ${k} (frame ${f}): ${key}, the .json's ${rotations[q]}`);
        ++jsonChecked;
      }
    });
    assert.ok(keysChecked >= kanim.frameCount, `${keysChecked} keys checked`);
    if (expected.size > 0) assert.ok(jsonChecked > 0, 'frames of the .json checked');

    const play = player(result), v = new THREE.Vector3();
    for (let f = 0; f < Math.min(kanim.frameCount, 240); ++f) {
      play.at(f);
      const values = samplePose(kanim, f), want = worldPositions(kanim.nodes, values);
      kanim.nodes.forEach((node, i) => {
        if (!node.channels.some((t) => t >= 3)) return;
        const got = skeleton.bones[i].quaternion.toArray(), rotation = localRotation(node, values);
        if (!(quatNear(got, rotation) <= 1e-6)) assert.fail(`frame ${f}, node ${i}: bone ${got}, decoder ${rotation}`);
      });
      const bound = 1e-6 * (1 + Math.max(...want.map(Math.abs)));  // binary32 keys and times
      skeleton.bones.forEach((b, i) => {
        const d = b.getWorldPosition(v).distanceTo(new THREE.Vector3().fromArray(want, 3 * i));
        if (!(d <= bound)) assert.fail(`frame ${f}, node ${i}: world position off by ${d}`);
      });
    }
  });
}

// A rotation track stays in one hemisphere: a quaternion node (identity reference) whose stored z
// goes from 0.99 to -0.99 in one frame turns from 164 degrees about z to -164, quaternions of
// opposite sides; with no key added between (tolerance Infinity) the second key is flipped.
test('a quaternion node\'s track keys stay in one hemisphere', () => {
  const kanim = decodeKanim(fs.readFileSync(path.join(vectorsDir, 'v5_quat.kanim')));
  const q = kanim.quatNodes.find((n) => n.reference.every((v) => v === 0));
  [0, 0, 0.99].forEach((first, k) => Object.assign(kanim.channels[q.column + k], {
    interp: 1, keyCount: 2, keyFrames: Int32Array.from([0, 1]), values: Float32Array.from([first, k === 2 ? -0.99 : 0]),
  }));
  const { clip, skeleton } = new KanimLoader().setTolerance(Infinity).fromClip(kanim);
  const track = clip.tracks.find((t) => t.name === `${skeleton.bones[q.node].name}.quaternion`);
  const key = (k) => Array.from(track.values.subarray(4 * k, 4 * k + 4));
  const w = Math.sqrt(1 - 0.99 * 0.99);
  assert.ok(Math.hypot(...key(0).map((v, c) => v - [0, 0, 0.99, w][c])) < 1e-6, `key 0: ${key(0)}`);
  assert.ok(Math.hypot(...key(1).map((v, c) => v - [0, 0, 0.99, -w][c])) < 1e-6, `key 1, flipped: ${key(1)}`);
});

test('setFrameRate and setTolerance reject what is not a number > 0', () => {
  const loader = new KanimLoader();
  for (const bad of [0, -1, NaN, Infinity, '30']) assert.throws(() => loader.setFrameRate(bad), RangeError);
  for (const bad of [0, -1, NaN]) assert.throws(() => loader.setTolerance(bad), RangeError);
  assert.equal(loader.setFrameRate(null).frameRate, null);
});

// A bank's clip through fromClip: the same tracks as its own file through parse.
test('a bank clip (dictionary bank) through fromClip = its unpacked file through parse', { skip: noCli }, (t) => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-three-bank-'));
  t.after(() => fs.rmSync(dir, { recursive: true, force: true }));
  const bank = path.join(dir, 'b.kbank');
  execFileSync(keyanimCli, ['pack', ...DATA_CLIPS.map((c) => path.join(sourceDir, c)), '-o', bank, '--dictionary', 'on', '-q']);
  execFileSync(keyanimCli, ['unpack', bank, '-o', path.join(dir, 'out'), '-q']);
  const opened = openBank(fs.readFileSync(bank));
  assert.equal(opened.clips.length, 2);
  for (const c of opened.clips) {
    const fromBank = new KanimLoader().fromClip(decodeBankClip(opened, c.index), c.name);
    const fromFile = new KanimLoader().parse(fs.readFileSync(path.join(dir, 'out', `${c.name}.kanim`)), c.name);
    assert.equal(fromBank.skeleton.bones.length, fromFile.skeleton.bones.length);
    assert.deepEqual(fromBank.clip.tracks.map((k) => [k.name, Array.from(k.times), Array.from(k.values)]),
      fromFile.clip.tracks.map((k) => [k.name, Array.from(k.times), Array.from(k.values)]), c.name);
  }
});
