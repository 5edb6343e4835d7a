// spec Appendix C: on every committed test vector, the decoder's skeleton and values equal the
// expected ones of the vector's .json, bit for bit. A v4_X vector is the runtime profile
// (spec 9) of v3_X, the same clip bit for bit: until its own v4_X.json exists it is checked
// against v3_X.json, and its keys against those v3_X decodes to; so is v5_X_runtime against
// v5_X. Version 5 (spec 4.7): the quaternion nodes and their references as the .json lists
// them, and each quaternion node's rotation from its stored x, y, z within 2e-6 of the
// expected one (q or -q); the BVH channel values (Appendix B) are Euler angles of that rotation.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { decodeKanim, CHANNEL_TYPES } from 'keyanim-three/decoder/kanim.js';
import { openBank, decodeBankClip } from 'keyanim-three/decoder/bank.js';
import { samplePose, sampleChannels } from 'keyanim-three/decoder/sample.js';
import { localRotation, axisQuaternion, hamilton, rotationAxes, storedRotation, referenceRotation, eulerFromQuaternion } from 'keyanim-three/decoder/rotation.js';
import { vectorsDir } from './paths.mjs';

const vectors = fs.readdirSync(vectorsDir).filter((f) => f.endsWith('.kanim')).sort();
const inDir = (name) => path.join(vectorsDir, name);
// v4_archive is an archive file of version 4.0 (Runtime clear), the clip of v3_rules; every
// other v4_* vector is of the runtime profile, the clip of the v3 vector of its name; v5_X_runtime
// is the runtime profile of v5_X.
const isRuntime = (file) => (file.startsWith('v4_') && file !== 'v4_archive.kanim') || /^v5_.*_runtime\.kanim$/.test(file);
const runtimeVectors = vectors.filter(isRuntime);
const archiveTwin = (file) => (file === 'v4_archive.kanim' ? 'v3_rules.kanim' : file.startsWith('v5_') ? file.replace(/_runtime\.kanim$/, '.kanim') : file.replace(/^v4_/, 'v3_'));

// The expected values of a vector, and the format version they are of ('4.0' for a v4 vector
// checked against its v3 twin's file).
function expected(file) {
  const own = inDir(file.replace(/\.kanim$/, '.json'));
  if (fs.existsSync(own) || !isRuntime(file) && file !== 'v4_archive.kanim') return { want: JSON.parse(fs.readFileSync(own, 'utf8')) };
  const twin = inDir(archiveTwin(file).replace(/\.kanim$/, '.json'));
  return { want: JSON.parse(fs.readFileSync(twin, 'utf8')), version: file.startsWith('v4_') ? '4.0' : undefined };
}

// Rotations q and -q are the same: the distance between two quaternions up to sign.
const quatDistance = (a, b) => Math.min(Math.hypot(...a.map((v, k) => v - b[k])), Math.hypot(...a.map((v, k) => v + b[k])));
const eulerRotation = (axes, angles) => axes.reduce((q, axis, k) => hamilton(q, axisQuaternion(axis, angles[k])), [0, 0, 0, 1]);

test('the test vectors are there', () => {
  assert.ok(vectors.length >= 13, `only ${vectors.length} vectors in ${vectorsDir}`);
  for (const v of ['v1_', 'v2_', 'v3_', 'v4_', 'v5_']) assert.ok(vectors.some((f) => f.startsWith(v)), `no ${v}* vector`);
  for (const v of ['v5_quat', 'v5_blocks', 'v5_quat_runtime', 'v5_blocks_runtime']) assert.ok(vectors.includes(`${v}.kanim`), `no ${v}.kanim`);
});

// The clip against a vector's .json: fields, skeleton, every sample's stored values bit for bit;
// in version 5 the quaternion nodes, each sample's rotations (2e-6, q or -q) and its channels
// as BVH has them (Appendix B: Euler angles of those rotations, continuous).
function expectClip(clip, want) {
  assert.equal(clip.frameCount, want.frame_count);
  assert.equal(clip.frameTime, want.frame_time);
  assert.equal(clip.tangentRule, want.tangent_rule);
  assert.equal(clip.notes, want.notes);
  assert.deepEqual(clip.nodes.map((n) => ({ name: n.name, parent: n.parent, end_site: n.endSite, offset: n.offset, channels: n.channels.map((t) => CHANNEL_TYPES[t]) })), want.nodes);
  assert.ok(want.samples.length > 0);
  const v5 = clip.version.major >= 5;
  assert.deepEqual(clip.quatNodes.map((q) => ({ node: q.node, reference: q.reference })), want.quat_nodes ?? []);
  clip.quatNodes.forEach((q) => assert.equal(clip.nodes[q.node].quaternion, q));
  let previous = null;
  for (const s of want.samples) {
    const got = Array.from(samplePose(clip, s.position));
    assert.equal(got.length, s.values.length);
    for (let c = 0; c < got.length; ++c) {
      // Object.is: bit for bit for binary32 values held in doubles, -0 distinct from +0
      if (!Object.is(got[c], s.values[c])) assert.fail(`position ${s.position}, channel ${c}: ${got[c]} != expected ${s.values[c]}`);
    }
    if (!v5) continue;
    // Spec 4.7: each quaternion node's rotation, within 2e-6 (q or -q).
    assert.equal(s.rotations.length, clip.quatNodes.length);
    const channels = sampleChannels(clip, s.position, undefined, previous);
    clip.quatNodes.forEach((q, k) => {
      const node = clip.nodes[q.node], rotation = localRotation(node, got);
      const d = quatDistance(rotation, s.rotations[k]);
      if (!(d <= 2e-6)) assert.fail(`position ${s.position}, quaternion node ${q.node}: rotation ${rotation} is ${d} from expected ${s.rotations[k]}`);
      // Appendix B: its channel values are Euler angles of that rotation, near the previous sample's.
      const angles = Array.from(channels.subarray(q.column, q.column + 3));
      const e = quatDistance(eulerRotation(rotationAxes(node), angles), rotation);
      if (!(e <= 1e-12)) assert.fail(`position ${s.position}, quaternion node ${q.node}: Euler angles ${angles} are ${e} from its rotation`);
      if (previous) angles.forEach((a, i) => { if (!(Math.abs(a - previous[q.column + i]) <= 180)) assert.fail(`position ${s.position}, node ${q.node}: angle ${a} jumps from ${previous[q.column + i]}`); });
    });
    previous = channels;
  }
}

for (const file of vectors) {
  test(`${file}: skeleton, clip fields and every expected value, bit for bit`, () => {
    const clip = decodeKanim(fs.readFileSync(inDir(file)));
    const { want, version } = expected(file);
    assert.equal(`${clip.version.major}.${clip.version.minor}`, version ?? want.format_version);
    assert.equal(clip.profile, isRuntime(file) ? 'runtime' : 'archive');
    expectClip(clip, want);
  });
}

// The bank vectors (spec Appendix C): each clip, named after its vector, decodes to that
// vector's expected values; in b41_damaged, clip v3_uniform fails its checksum.
const banks = fs.readdirSync(vectorsDir).filter((f) => f.endsWith('.kbank')).sort();
test('the bank vectors are there', () => {
  for (const b of ['b41_archive', 'b41_dictionary', 'b41_runtime', 'b41_damaged', 'b50_archive', 'b50_runtime']) assert.ok(banks.includes(`${b}.kbank`), `no ${b}.kbank`);
});
for (const file of banks) {
  test(`${file}: every clip is its vector's clip`, () => {
    const bank = openBank(fs.readFileSync(inDir(file)));
    assert.equal(`${bank.version.major}.${bank.version.minor}`, file.startsWith('b50_') ? '5.0' : '4.1');
    assert.equal(bank.profile, file.endsWith('_runtime.kbank') ? 'runtime' : 'archive');
    assert.ok(bank.clips.length >= 4);
    for (const c of bank.clips) {
      if (file === 'b41_damaged.kbank' && c.name === 'v3_uniform') {
        assert.throws(() => decodeBankClip(bank, c.index), (e) => e.status === 'checksum_mismatch');
        continue;
      }
      const clip = decodeBankClip(bank, c.index);
      assert.equal(clip.profile, bank.profile, c.name);
      if (c.name.startsWith('v5_')) assert.equal(clip.version.major, 5, c.name);
      expectClip(clip, JSON.parse(fs.readFileSync(inDir(`${c.name}.json`), 'utf8')));
    }
  });
}

test('the runtime vectors are there, each with its archive twin', () => {
  for (const n of ['blocks', 'long', 'predict', 'rules', 'single', 'uniform']) assert.ok(runtimeVectors.includes(`v4_${n}.kanim`), `no v4_${n}.kanim`);
  for (const n of ['quat', 'blocks']) assert.ok(runtimeVectors.includes(`v5_${n}_runtime.kanim`), `no v5_${n}_runtime.kanim`);
  for (const f of runtimeVectors) assert.ok(vectors.includes(archiveTwin(f)), `no ${archiveTwin(f)}`);
});

// Spec 9: converting the runtime profile back gives the same keys. The keys recovered from IMAG
// (9.3) equal those of CHAN, KTIM and KVAL, frame for frame and value for value.
for (const file of runtimeVectors) {
  test(`${file}: the same channels and keys as ${archiveTwin(file)}`, () => {
    const got = decodeKanim(fs.readFileSync(inDir(file))), want = decodeKanim(fs.readFileSync(inDir(archiveTwin(file))));
    assert.equal(got.channels.length, want.channels.length);
    got.channels.forEach((ch, c) => {
      const w = want.channels[c], label = `channel ${c}`;
      assert.deepEqual([ch.node, ch.type, ch.interp, ch.keyCount], [w.node, w.type, w.interp, w.keyCount], label);
      assert.ok(Object.is(ch.tension, w.tension), `${label}: tension`);
      assert.deepEqual(Array.from(ch.keyFrames), Array.from(w.keyFrames), `${label}: key frames`);
      ch.values.forEach((v, i) => { if (!Object.is(v, w.values[i])) assert.fail(`${label} key ${i}: ${v} != ${w.values[i]}`); });
    });
    assert.deepEqual([got.frameCount, got.frameTime, got.tangentRule, got.keyCount, got.notes], [want.frameCount, want.frameTime, want.tangentRule, want.keyCount, want.notes]);
    assert.deepEqual(got.quatNodes, want.quatNodes, 'the quaternion nodes and their references');
  });
}

// Spec 4.7 by hand, where the vectors do not reach: the reference from X, Y, Z; the product's
// order (r ⊗ s); beyond the unit ball, w = 0 and the product normalized. Appendix B: Euler
// angles nearest the previous ones, past ±180 degrees, and at gimbal lock.
test('spec 4.7 and Appendix B on hand-made values', () => {
  const close = (a, b, label) => assert.ok(quatDistance(a, b) <= 1e-15, `${label}: ${a} against ${b}`);
  assert.deepEqual(referenceRotation([0, 0, 16384]), [0, 0, 0.5, Math.sqrt(0.75)]);
  assert.deepEqual(referenceRotation([-32768, 0, 0]), [-1, 0, 0, 0]);
  const identity = referenceRotation([0, 0, 0]);
  close(storedRotation(identity, 0.6, 0, 0), [0.6, 0, 0, 0.8], 'w from x, y, z');
  close(storedRotation(identity, 0.8, 0.8, 0), [Math.SQRT1_2, Math.SQRT1_2, 0, 0], 'beyond the unit ball: w = 0, normalized');
  close(storedRotation(identity, 0, 1.5, 0), [0, 1, 0, 0], 'beyond the unit ball on an axis');
  // r: 90 degrees about z; s: 90 degrees about x. r s first turns about x, then about z.
  const z90 = axisQuaternion(2, 90), x90 = axisQuaternion(0, 90);
  const r = [0, 0, z90[2], z90[3]];
  close(storedRotation(r, x90[0], 0, 0), hamilton(z90, x90), 'q = r ⊗ s');
  assert.ok(quatDistance(storedRotation(r, x90[0], 0, 0), hamilton(x90, z90)) > 0.5, 'not s ⊗ r');
  // A node whose rotation channels are Z X Y, as a quaternion node, poses as its rotation.
  const node = { channels: [0, 5, 3, 4], firstChannel: 0, quaternion: { r } };
  close(localRotation(node, [7, x90[0], 0, 0]), hamilton(z90, x90), 'localRotation of a quaternion node');
  close(localRotation({ channels: [5, 3], firstChannel: 0 }, [90, 90]), hamilton(z90, x90), 'localRotation of Euler channels');

  // Euler angles about z from 0 to 720 degrees: each the nearest the one before, so they go on
  // past 180 (from the canonical set, in (-180, 180], at the start).
  let previous = null;
  for (let a = 0; a <= 720; a += 10) {
    const angles = eulerFromQuaternion(axisQuaternion(2, a), [2, 0, 1], previous);
    assert.ok(Math.abs(angles[0] - a) < 1e-9 && Math.abs(angles[1]) < 1e-9 && Math.abs(angles[2]) < 1e-9, `${a}: ${angles}`);
    previous = angles;
  }
  assert.ok(Math.abs(eulerFromQuaternion(axisQuaternion(2, 350), [2, 0, 1])[0] + 10) < 1e-9, 'without a previous set: (-180, 180]');
  // The middle angle past 90: the other set (a1 + 180, 180 - a2, a3 + 180) is the nearer.
  previous = [10, 80, 20];
  for (const a2 of [85, 89, 91, 95, 100]) {
    const want = [10, a2, 20], q = eulerRotation([0, 1, 2], want);
    const got = eulerFromQuaternion(q, [0, 1, 2], previous);
    assert.ok(got.every((v, k) => Math.abs(v - want[k]) < 1e-6), `middle ${a2}: ${got}`);
    previous = got;
  }
  // At gimbal lock the first angle stays where it was; the set still makes the rotation.
  const locked = eulerRotation([0, 1, 2], [30, 90, 40]), got = eulerFromQuaternion(locked, [0, 1, 2], [25, 88, 45]);
  assert.ok(Math.abs(got[0] - 25) < 1e-9 && Math.abs(got[1] - 90) < 1e-6, `${got}`);
  assert.ok(quatDistance(eulerRotation([0, 1, 2], got), locked) < 1e-12);
});
