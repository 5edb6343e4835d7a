// The viewer's framing and up axis on corpus files (skipped without the corpus): Bandai's walk,
// whose ROOT joint_Root stays at the origin, and MakeHuman's z-up files. The checks are
// framing-check.mjs's, as framing.test.mjs uses them on data/ and a Bandai-like fixture.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { parseBvh } from '../src/bvh.js';
import { detectUpAxis } from '../src/upaxis.js';
import { poses, expectFramed } from './framing-check.mjs';
import { corpusDir, exists } from './paths.mjs';

const bandaiWalk = path.join(corpusDir, 'bandai/dataset-1_walk_normal_001.bvh');
test("the corpus's Bandai walk: joint_Root alone is a placeholder, every joint framed", { skip: exists(bandaiWalk) ? false : `no corpus at ${corpusDir}` }, () => {
  const bvh = parseBvh(fs.readFileSync(bandaiWalk, 'utf8'));
  const e = expectFramed(bvh, poses(bvh), 'Bandai walk');
  assert.deepEqual(bvh.nodes.map((n, i) => e.placeholders[i] ? n.name : null).filter(Boolean), ['joint_Root']);
});

test("up axis on the corpus: MakeHuman's files are z-up, Bandai's and CMU's y-up", { skip: exists(corpusDir) ? false : `no corpus at ${corpusDir}` }, () => {
  const want = { 'misc/makehuman__zombieWalk1.bvh': 'z', 'misc/makehuman__tpose.bvh': 'z', 'bandai/dataset-1_walk_normal_001.bvh': 'y', 'cmu/BvhToDeepMimic__02_01.bvh': 'y' };
  for (const [file, axis] of Object.entries(want)) {
    const got = detectUpAxis(parseBvh(fs.readFileSync(path.join(corpusDir, file), 'utf8')).nodes);
    assert.deepEqual([got.axis, got.ambiguous], [axis, false], file);
  }
});
