// Forward kinematics as spec/FORMAT.md Appendix B: a node's local rotation is the product of
// its rotation channels in channel order (intrinsic, degrees, right-handed), or for a quaternion
// node (version 5, 4.7: node.quaternion set by the decoder) the rotation its stored x, y, z make
// with its reference; its translation is its Offset with each position channel replacing its
// component (reading 'replace', Blender's and the default) or added to it ('add', three.js's);
// p = p_parent + R_parent p_local, R = R_parent R_local. In binary64. Works on the node lists
// of kanim.js and bvh.js alike: with a decoded clip's nodes, `values` are the channel values
// samplePose gives (a quaternion node's stored x, y, z); with a BVH's, its channels.
import { storedRotation, quaternionMatrix } from './rotation.js';

const DEG = Math.PI / 180;

// 3x3 row-major: a x b into out (out may not alias a or b).
function mul(a, b, out) {
  for (let r = 0; r < 3; ++r)
    for (let c = 0; c < 3; ++c) out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
}

function axisRotation(axis, degrees, out) {
  const c = Math.cos(degrees * DEG), s = Math.sin(degrees * DEG);
  if (axis === 0) out.set([1, 0, 0, 0, c, -s, 0, s, c]);
  else if (axis === 1) out.set([c, 0, s, 0, 1, 0, -s, 0, c]);
  else out.set([c, -s, 0, s, c, 0, 0, 0, 1]);
}

// World positions of every node for one frame: `values` holds every channel (frame column
// order); `out` gets x, y, z per node; `rot`, if given, each node's world rotation (9 values,
// row-major). Returns out.
export function worldPositions(nodes, values, out = new Float64Array(3 * nodes.length), reading = 'replace',
                               rot = new Float64Array(9 * nodes.length)) {
  const local = new Float64Array(9), axis = new Float64Array(9), tmp = new Float64Array(9), stored = [];
  for (let i = 0; i < nodes.length; ++i) {
    const node = nodes[i];
    const t = node.offset.slice();
    local.set([1, 0, 0, 0, 1, 0, 0, 0, 1]);
    stored.length = 0;
    node.channels.forEach((type, k) => {
      const v = values[node.firstChannel + k];
      if (type < 3) { t[type] = reading === 'add' ? node.offset[type] + v : v; return; }
      if (node.quaternion) { stored.push(v); return; }
      axisRotation(type - 3, v, axis);
      mul(local, axis, tmp);
      local.set(tmp);
    });
    if (stored.length === 3) local.set(quaternionMatrix(storedRotation(node.quaternion.r, stored[0], stored[1], stored[2])));
    const R = rot.subarray(9 * i, 9 * i + 9);
    if (node.parent < 0) {
      R.set(local);
      out.set(t, 3 * i);
      continue;
    }
    const P = rot.subarray(9 * node.parent, 9 * node.parent + 9), p = 3 * node.parent;
    mul(P, local, R);
    for (let r = 0; r < 3; ++r) out[3 * i + r] = out[p + r] + P[3 * r] * t[0] + P[3 * r + 1] * t[1] + P[3 * r + 2] * t[2];
  }
  return out;
}

// The largest side of the box around the rest pose (every channel 0 but positions keep the
// Offset): the length scale of the skeleton, for tolerances, the camera and the grid.
export function skeletonSize(nodes) {
  const rest = nodes.map((n) => ({ ...n, channels: [], quaternion: null }));
  const p = worldPositions(rest, []);
  let size = 0;
  for (let axis = 0; axis < 3; ++axis) {
    let lo = Infinity, hi = -Infinity;
    for (let i = axis; i < p.length; i += 3) { lo = Math.min(lo, p[i]); hi = Math.max(hi, p[i]); }
    size = Math.max(size, hi - lo);
  }
  return size;
}

// The largest distance between two point arrays of the same skeleton, `perNode` points per node
// (1: worldPositions; 4: measuredPoints), and where: the node and its point (0: the node, 1-3:
// its shell point on x, y, z).
export function largestDistance(a, b, perNode = 1) {
  let worst = 0, at = 0;
  for (let i = 0; i < a.length; i += 3) {
    const d = Math.hypot(a[i] - b[i], a[i + 1] - b[i + 1], a[i + 2] - b[i + 2]);
    if (d > worst) { worst = d; at = i / 3; }
  }
  return { distance: worst, node: Math.floor(at / perNode), point: at % perNode };
}

// What the encoder's error covers, from the clip's notes: the shell distance (shell_units, else
// 2% of `size`) and the readings of position channels (readings, else replace).
export function measuredSettings(notes, size) {
  const shell = Number(/^shell_units=(.*)$/m.exec(notes)?.[1]);
  const readings = /^readings=(.*)$/m.exec(notes)?.[1]?.split(',') ?? ['replace'];
  return { shell: Number.isFinite(shell) && shell >= 0 ? shell : 0.02 * size, readings };
}

// The points the encoder's error covers (keyanim/offline/metrics.h), 4 per node: the node, then
// its shell points at distance `shell` along the columns of its world rotation (for an End Site,
// or with shell 0, copies of the node).
export function measuredPoints(nodes, values, shell, reading = 'replace') {
  const pos = new Float64Array(3 * nodes.length), rot = new Float64Array(9 * nodes.length);
  worldPositions(nodes, values, pos, reading, rot);
  const out = new Float64Array(12 * nodes.length);
  nodes.forEach((node, i) => {
    for (let k = 0; k < 4; ++k) {
      const axis = k - 1, on = k > 0 && shell > 0 && !node.endSite;
      for (let r = 0; r < 3; ++r) out[12 * i + 3 * k + r] = pos[3 * i + r] + (on ? shell * rot[9 * i + 3 * r + axis] : 0);
    }
  });
  return out;
}
