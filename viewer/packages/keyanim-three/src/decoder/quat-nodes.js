// Quaternion nodes (spec/FORMAT.md 4.7, version 5): the QUAT section of the archive profile,
// and the rules a quaternion node meets whichever section lists it (QUAT, or IMAG's Quat_Node in
// the runtime profile, 9.2): a node of SKEL with exactly three rotation channels, consecutive in
// its Channel_Types, about three different axes; a reference with X² + Y² + Z² <= 2^30.
import { referenceRotation } from './rotation.js';

export const QUAT_ENTRY_BYTES = 10;
export const MAX_REFERENCE_NORM2 = 2 ** 30;

// Why node n of `nodes` cannot be a quaternion node, or '' when it can.
export function quatNodeProblem(nodes, n) {
  if (n >= nodes.length) return `node ${n} is not below Node_Count ${nodes.length}`;
  const rotations = [];
  nodes[n].channels.forEach((type, k) => { if (type >= 3) rotations.push(k); });
  if (rotations.length !== 3) return `node ${n} has ${rotations.length} rotation channels, not 3`;
  if (rotations[2] - rotations[0] !== 2) return `node ${n}: its rotation channels are not consecutive in its Channel_Types`;
  const axes = new Set(rotations.map((k) => nodes[n].channels[k]));
  if (axes.size !== 3) return `node ${n}: its rotation channels are not about three different axes`;
  return '';
}

// The channel of quaternion node n's stored x: its first rotation channel (quatNodeProblem '').
export function quatColumn(node) {
  return node.firstChannel + node.channels.findIndex((t) => t >= 3);
}

// Records quaternion node n with reference [X, Y, Z] in the clip (clip.quatNodes, in node order,
// and the node's `quaternion`).
export function addQuatNode(clip, n, reference) {
  const node = clip.nodes[n];
  const q = { node: n, column: quatColumn(node), reference, r: referenceRotation(reference) };
  node.quaternion = q;
  clip.quatNodes.push(q);
  return q;
}

// QUAT (4.7): Quat_Count, then Q entries of Node (u32) and Reference (i16[3]).
export function parseQuat(r, clip) {
  if (r.length < 4) r.fail('corrupt', 0, `QUAT holds ${r.length} bytes, less than its Quat_Count`);
  const count = r.u32();
  if (count > clip.nodeCount) r.fail('corrupt', 0, `Quat_Count ${count} is above Node_Count ${clip.nodeCount}`);
  if (r.length !== 4 + QUAT_ENTRY_BYTES * count) r.fail('corrupt', 0, `QUAT holds ${r.length} bytes, not 4 + 10 x ${count}`);
  let previous = -1;
  for (let j = 0; j < count; ++j) {
    const at = r.pos, n = r.u32();
    if (n <= previous) r.fail('corrupt', at, `entry ${j}: node ${n} does not follow node ${previous} (entries list nodes in strictly increasing order)`);
    const problem = quatNodeProblem(clip.nodes, n);
    if (problem) r.fail('corrupt', at, `entry ${j}: ${problem}, so it cannot be a quaternion node (4.7)`);
    const refAt = r.pos, reference = [r.i16(), r.i16(), r.i16()];
    const norm2 = reference.reduce((s, v) => s + v * v, 0);
    if (norm2 > MAX_REFERENCE_NORM2) r.fail('corrupt', refAt, `entry ${j}: Reference ${reference.join(', ')} has X² + Y² + Z² = ${norm2}, above 2^30`);
    addQuatNode(clip, n, reference);
    previous = n;
  }
}

// 4.7: every key of a quaternion node's stored x, y, z within ±16 (a content rule of the runtime
// profile, 9.4), once the channels' values are known; `at`: where a failure is reported.
export function checkStoredBound(r, clip, at) {
  for (const q of clip.quatNodes) {
    for (let k = 0; k < 3; ++k) {
      const c = q.column + k;
      for (const v of clip.channels[c].values) {
        if (!(Math.abs(v) <= 16)) r.fail('corrupt', at, `channel ${c}: a key value ${v} of quaternion node ${q.node}'s stored ${'xyz'[k]} is beyond ±16 (4.7)`);
      }
    }
  }
}
