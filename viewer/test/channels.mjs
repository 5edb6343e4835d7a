// Comparing the JS decoder's BVH channel values (sampleChannels: spec Appendix B) with keyanim's
// (`keyanim decode`, `keyanim sample --json`): every channel bit for bit as binary32, except a
// quaternion node's rotation channels (version 5), which both compute as Euler angles of the
// node's rotation in binary64: within 1e-9 degrees where the CLI prints binary64 (decode), within
// one binary32 ulp where it prints the angle rounded to binary32 (sample --json).
import assert from 'node:assert/strict';

// The channels that hold a quaternion node's rotation (its stored x, y, z in the file).
export const quatColumns = (clip) => new Set(clip.quatNodes.flatMap((q) => [q.column, q.column + 1, q.column + 2]));

// The distance between two binary32 neighbours at |v|.
function ulp32(v) {
  const a = Math.abs(Math.fround(v));
  const next = new Float32Array([a]);
  new Uint32Array(next.buffer)[0] += 1;
  return next[0] - a;
}

// got: sampleChannels' values; want: the CLI's, in frame-column order. angles: 'binary64' or
// 'binary32' (how the CLI printed them).
export function expectChannels(clip, got, want, label, angles, quat = quatColumns(clip)) {
  assert.equal(got.length, want.length, label);
  for (let c = 0; c < got.length; ++c) {
    if (!quat.has(c)) {
      if (!Object.is(Math.fround(got[c]), Math.fround(want[c]))) assert.fail(`${label}, channel ${c}: JS ${got[c]} != C++ ${want[c]}`);
      continue;
    }
    const bound = angles === 'binary64' ? 1e-9 : ulp32(want[c]);
    if (!(Math.abs(got[c] - want[c]) <= bound)) assert.fail(`${label}, channel ${c} (a quaternion node's Euler angle): JS ${got[c]}, C++ ${want[c]}, more than ${bound} apart`);
  }
}
