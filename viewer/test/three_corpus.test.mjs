// keyanim-three's KanimLoader under node with three.js on three corpus clips (CMU, Bandai and
// one other) encoded by the CLI at its defaults: an AnimationMixer plays each clip and its bones
// agree with the CLI within the clip's tolerance (mixer-check.mjs says how). Skipped without the
// corpus (three.test.mjs runs the same check on the clips of data/).
import { test, after } from 'node:test';
import path from 'node:path';
import { checkClip, removeScratch } from './mixer-check.mjs';
import { corpusDir, keyanimCli, exists } from './paths.mjs';

const CORPUS_CLIPS = ['cmu/BvhToDeepMimic__02_01.bvh', 'bandai/dataset-1_kick_normal_001.bvh', 'misc/makehuman__walk1.bvh'];
const skip = !exists(keyanimCli) ? `no keyanim CLI at ${keyanimCli}`
  : CORPUS_CLIPS.every((c) => exists(path.join(corpusDir, c))) ? false : `no corpus at ${corpusDir}`;
after(removeScratch);

test('corpus clips (CMU, Bandai, other): bones through an AnimationMixer = sample --world', { skip }, (t) => {
  for (const clip of CORPUS_CLIPS) for (const line of checkClip(path.join(corpusDir, clip))) t.diagnostic(`${clip}: ${line}`);
});
