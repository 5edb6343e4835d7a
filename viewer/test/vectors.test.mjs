// spec Appendix C: on every committed test vector, the decoder's skeleton and values equal the
// expected ones of the vector's .json, bit for bit.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { decodeKanim, CHANNEL_TYPES } from 'keyanim-three/decoder/kanim.js';
import { samplePose } from 'keyanim-three/decoder/sample.js';
import { vectorsDir } from './paths.mjs';

const vectors = fs.readdirSync(vectorsDir).filter((f) => f.endsWith('.kanim')).sort();

test('the test vectors are there', () => {
  assert.ok(vectors.length >= 13, `only ${vectors.length} vectors in ${vectorsDir}`);
  for (const v of ['v1_', 'v2_', 'v3_']) assert.ok(vectors.some((f) => f.startsWith(v)), `no ${v}* vector`);
});

for (const file of vectors) {
  test(`${file}: skeleton, clip fields and every expected value, bit for bit`, () => {
    const clip = decodeKanim(fs.readFileSync(path.join(vectorsDir, file)));
    const want = JSON.parse(fs.readFileSync(path.join(vectorsDir, file.replace(/\.kanim$/, '.json')), 'utf8'));
    assert.equal(`${clip.version.major}.${clip.version.minor}`, want.format_version);
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
