// spec Appendix C: on every committed test vector, the decoder's skeleton and values equal the
// expected ones of the vector's .json, bit for bit. A v4_X vector is the runtime profile
// (spec 9) of v3_X, the same clip bit for bit: until its own v4_X.json exists it is checked
// against v3_X.json, and its keys against those v3_X decodes to.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { decodeKanim, CHANNEL_TYPES } from 'keyanim-three/decoder/kanim.js';
import { samplePose } from 'keyanim-three/decoder/sample.js';
import { vectorsDir } from './paths.mjs';

const vectors = fs.readdirSync(vectorsDir).filter((f) => f.endsWith('.kanim')).sort();
const inDir = (name) => path.join(vectorsDir, name);
// v4_archive is an archive file of version 4.0 (Runtime clear), the clip of v3_rules; every
// other v4_* vector is of the runtime profile, the clip of the v3 vector of its name.
const isRuntime = (file) => file.startsWith('v4_') && file !== 'v4_archive.kanim';
const runtimeVectors = vectors.filter(isRuntime);
const archiveTwin = (file) => (file === 'v4_archive.kanim' ? 'v3_rules.kanim' : file.replace(/^v4_/, 'v3_'));

// The expected values of a vector, and the format version they are of ('4.0' for a v4 vector
// checked against its v3 twin's file).
function expected(file) {
  const own = inDir(file.replace(/\.kanim$/, '.json'));
  if (fs.existsSync(own) || !file.startsWith('v4_')) return { want: JSON.parse(fs.readFileSync(own, 'utf8')) };
  const twin = inDir(archiveTwin(file).replace(/\.kanim$/, '.json'));
  return { want: JSON.parse(fs.readFileSync(twin, 'utf8')), version: '4.0' };
}

test('the test vectors are there', () => {
  assert.ok(vectors.length >= 13, `only ${vectors.length} vectors in ${vectorsDir}`);
  for (const v of ['v1_', 'v2_', 'v3_', 'v4_']) assert.ok(vectors.some((f) => f.startsWith(v)), `no ${v}* vector`);
});

for (const file of vectors) {
  test(`${file}: skeleton, clip fields and every expected value, bit for bit`, () => {
    const clip = decodeKanim(fs.readFileSync(inDir(file)));
    const { want, version } = expected(file);
    assert.equal(`${clip.version.major}.${clip.version.minor}`, version ?? want.format_version);
    assert.equal(clip.profile, isRuntime(file) ? 'runtime' : 'archive');
    assert.equal(clip.frameCount, want.frame_count);
    assert.equal(clip.frameTime, want.frame_time);
    assert.equal(clip.tangentRule, want.tangent_rule);
    assert.equal(clip.notes, want.notes);
    assert.deepEqual(clip.nodes.map((n) => ({ name: n.name, parent: n.parent, end_site: n.endSite, offset: n.offset, channels: n.channels.map((t) => CHANNEL_TYPES[t]) })), want.nodes);
    assert.ok(want.samples.length > 0);
    for (const s of want.samples) {
      const got = Array.from(samplePose(clip, s.position));
      assert.equal(got.length, s.values.length);
      for (let c = 0; c < got.length; ++c) {
        // Object.is: bit for bit for binary32 values held in doubles, -0 distinct from +0
        if (!Object.is(got[c], s.values[c])) assert.fail(`position ${s.position}, channel ${c}: ${got[c]} != expected ${s.values[c]}`);
      }
    }
  });
}

test('the six runtime vectors are there, each with its v3 twin', () => {
  for (const n of ['blocks', 'long', 'predict', 'rules', 'single', 'uniform']) assert.ok(runtimeVectors.includes(`v4_${n}.kanim`), `no v4_${n}.kanim`);
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
  });
}
