// The up axis of a skeleton, and the turn that shows a z-up file upright in the viewer's y-up
// space. BVH does not say which axis is up: CMU, Bandai and most files are y-up, MakeHuman's
// exports z-up. The rule (the same as `keyanim render`'s, tools/keyanim/conventions.cpp): in the
// rest pose (every Offset, no channel), a body is taller than it is deep, so the axis of y and z
// along which the skeleton spans more is up; when neither spans 1.5 times the other the file is
// ambiguous and y is taken.
import { worldPositions } from 'keyanim-three/decoder/pose.js';

export const AMBIGUOUS_RATIO = 1.5;

// Returns { axis: 'y' | 'z', ambiguous, extents: [x, y, z] } for a node list of kanim.js or bvh.js.
export function detectUpAxis(nodes) {
  const p = worldPositions(nodes.map((n) => ({ ...n, channels: [] })), []);
  const extents = [0, 1, 2].map((r) => {
    let lo = Infinity, hi = -Infinity;
    for (let i = r; i < p.length; i += 3) { lo = Math.min(lo, p[i]); hi = Math.max(hi, p[i]); }
    return p.length ? hi - lo : 0;
  });
  const [, y, z] = extents;
  const ambiguous = !(y > AMBIGUOUS_RATIO * z || z > AMBIGUOUS_RATIO * y);
  return { axis: !ambiguous && z > y ? 'z' : 'y', ambiguous, extents };
}

// Positions in the viewer's y-up space: unchanged for 'y'; for 'z', turned -90 degrees about x
// ((x, y, z) -> (x, z, -y), a rotation: lengths and handedness kept). In place; returns p.
export function toYUp(p, axis) {
  if (axis !== 'z') return p;
  for (let i = 0; i < p.length; i += 3) {
    const y = p[i + 1];
    p[i + 1] = p[i + 2];
    p[i + 2] = -y;
  }
  return p;
}
