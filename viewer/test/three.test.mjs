// keyanim-three's KanimLoader under node with three.js, on the clips of data/ and a BVH with
// two roots (the corpus clips: three_corpus.test.mjs): an AnimationMixer plays each clip and
// its bones agree with the CLI (mixer-check.mjs says how); without the keys the loader adds,
// three.js's in-betweens leave the tolerance; several roots come under a Group; a damaged file
// throws the decoder's error; bad options are refused; a bank's clip gives its own file's tracks.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import os from 'node:os';
import { execFileSync } from 'node:child_process';
import { KanimLoader, KanimError, decodeKanim, openBank, decodeBankClip } from 'keyanim-three';
import { encode, player, worstAgainstCli, checkClip, removeScratch } from './mixer-check.mjs';
import { keyanimCli, sourceDir, exists } from './paths.mjs';

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
