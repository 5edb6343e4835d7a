// keyanim-three's KanimLoader under node with three.js on three corpus clips (CMU, Bandai and
// one other) encoded by the CLI at its defaults: an AnimationMixer plays each clip and its bones
// agree with the CLI within the clip's tolerance (mixer-check.mjs says how). Skipped without the
// corpus (three.test.mjs runs the same check on the clips of data/). And every corpus clip at
// every fifth of a frame against the JS decoder's forward kinematics (samplePose and pose.js,
// which viewer_corpus shows equal to the CLI's).
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import * as THREE from 'three';
import { KanimLoader, samplePose, worldPositions } from 'keyanim-three';
import { checkClip, removeScratch, player, cli } from './mixer-check.mjs';
import { corpusDir, keyanimCli, exists, bvhFilesBelow } from './paths.mjs';

const CORPUS_CLIPS = ['cmu/BvhToDeepMimic__02_01.bvh', 'bandai/dataset-1_kick_normal_001.bvh', 'misc/makehuman__walk1.bvh'];
const skip = !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}`
  : CORPUS_CLIPS.every((c) => exists(path.join(corpusDir, c))) ? false : `no corpus at ${corpusDir}`;
after(removeScratch);

test('corpus clips (CMU, Bandai, other): bones through an AnimationMixer = sample --world', { skip }, (t) => {
  for (const clip of CORPUS_CLIPS) for (const line of checkClip(path.join(corpusDir, clip))) t.diagnostic(`${clip}: ${line}`);
});

test('every corpus clip: bones within the tolerance at every fifth of a frame', { skip }, (t) => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-three-corpus-'));
  try {
    cli('encode', corpusDir, '-o', dir, '-q');
    const clips = bvhFilesBelow(corpusDir);
    assert.ok(clips.length >= 40);
    const v = new THREE.Vector3();
    for (const bvh of clips) {
      const label = path.relative(corpusDir, bvh), file = path.join(dir, label).replace(/\.bvh$/, '.kanim');
      const tolerance = JSON.parse(cli('info', file, '--json')).guarantee.tolerance_units;
      const result = new KanimLoader().parse(fs.readFileSync(file));
      const play = player(result), { kanim } = result;
      let worst = 0;
      for (let k = 0; k <= 5 * (kanim.frameCount - 1); ++k) {
        play.at(k / 5);
        const want = worldPositions(kanim.nodes, samplePose(kanim, k / 5));
        result.skeleton.bones.forEach((b, i) => {
          const d = b.getWorldPosition(v).distanceTo(new THREE.Vector3().fromArray(want, 3 * i));
          if (d > tolerance) assert.fail(`${label} frame ${k / 5}: ${b.name} off by ${d}, above the tolerance ${tolerance}`);
          worst = Math.max(worst, d);
        });
      }
      t.diagnostic(`${label}: ${kanim.frameCount} frames, ${result.clip.userData.keyanim.keyTimes} key times, worst ${(worst / tolerance).toFixed(3)} of the tolerance`);
    }
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
});
