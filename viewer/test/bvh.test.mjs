// The viewer's BVH reader against keyanim's: on the BVH fixtures of fuzz/corpus/bvh (line
// endings, tabs, several roots, names with spaces, damaged files), both accept the same files
// with the same frame and channel counts, and reject the same files on the same line.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { parseBvh } from '../src/bvh.js';
import { sourceDir, keyanimCli, exists } from './paths.mjs';

const dir = path.join(sourceDir, 'fuzz/corpus/bvh');
const skip = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;

test('BVH fixtures: the same verdicts as keyanim info', { skip }, () => {
  const files = fs.readdirSync(dir).filter((f) => f.endsWith('.bvh')).sort();
  assert.ok(files.length >= 20);
  let rejected = 0;
  for (const f of files) {
    const r = spawnSync(keyanimCli, ['info', path.join(dir, f), '--json'], { encoding: 'utf8' });
    let js;
    try { const b = parseBvh(fs.readFileSync(path.join(dir, f), 'utf8')); js = `${b.frameCount} frames, ${b.channelCount} channels`; } catch (e) { js = `error on line ${e.message.split(':')[0]}`; }
    let cpp;
    if (r.status === 0) { const j = JSON.parse(r.stdout); cpp = `${j.frames} frames, ${j.channels} channels`; } else { cpp = `error on line ${/\.bvh:(\d+):/.exec(r.stderr)?.[1]}`; ++rejected; }
    assert.equal(js, cpp, f);
  }
  assert.ok(rejected >= 5, `only ${rejected} fixtures rejected`);
});
