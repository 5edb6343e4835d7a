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

// Issue 23: hostile BVH text. A chain as deep as the CLI encodes must not overflow the stack
// (the reader once recursed per joint), and a frame count must be a whole number of frames.
const chain = (n, frames = 'Frames: 2') => {
  const out = ['HIERARCHY'];
  for (let i = 0; i < n; ++i) out.push(`${i ? 'JOINT' : 'ROOT'} j${i}`, '{', 'OFFSET 0 1 0', 'CHANNELS 1 Zrotation');
  out.push('End Site', '{', 'OFFSET 0 1 0', '}');
  for (let i = 0; i < n; ++i) out.push('}');
  out.push('MOTION', frames, 'Frame Time: 0.1', Array(n).fill('1').join(' '), Array(n).fill('2').join(' '));
  return out.join('\n') + '\n';
};

test('an 8000-joint chain reads without overflowing the stack', () => {
  const b = parseBvh(chain(8000));
  assert.equal(b.nodes.length, 8001);
  assert.equal(b.nodes[7999].parent, 7998);
  assert.equal(b.nodes[8000].endSite, true);
  assert.equal(b.channelCount, 8000);
  assert.equal(b.frameCount, 2);
});

test('Frames: must be a whole, non-negative number', () => {
  for (const bad of ['Frames: -3', 'Frames: 2.5', 'Frames: 1e30']) {
    assert.throws(() => parseBvh(chain(2, bad)), /^Error|BvhError/, bad);
    assert.throws(() => parseBvh(chain(2, bad)), (e) => e.name === 'BvhError' && /frame count/.test(e.message), bad);
  }
  assert.equal(parseBvh(chain(2, 'Frames: 2')).frameCount, 2);
});
