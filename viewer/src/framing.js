// What the camera follows and frames, from the world positions of every node over a clip: no
// three.js here, so that node tests can check it. Positions are x, y, z per node (pose.js).
//
// Following node 0 loses the figure on files whose ROOT is a placeholder: Bandai's `joint_Root`
// stays at the origin while its child `Hips` carries the translation. So the followed point is
// the centre of the skeleton's nodes (their mean position) leaving out such placeholders, and
// the camera is framed on the box every node spans over the clip.

// A node is "static" when its world position moves by no more than this fraction of the
// skeleton size over the clip (the positions are exact FK, only rounding moves a static node).
const STATIC_FRACTION = 1e-6;

// Placeholders: static nodes at the top of the hierarchy that hold one joint each (a ROOT at the
// origin whose only child carries the motion, and a static chain of such nodes below it). A
// static root with several children (a real hip that does not move) is part of the body.
export function placeholderNodes(nodes, staticNodes) {
  const children = nodes.map(() => 0);
  nodes.forEach((n) => { if (n.parent >= 0 && !n.endSite) children[n.parent] += 1; });
  const out = new Uint8Array(nodes.length);
  nodes.forEach((n, i) => {
    const top = n.parent < 0 || out[n.parent] === 1;
    out[i] = top && staticNodes[i] && !n.endSite && children[i] === 1 ? 1 : 0;
  });
  return out;
}

// The followed point of one pose: the mean position of the nodes that are not placeholders (of
// every node, when all are). Returns [x, y, z].
export function followedPoint(positions, placeholders) {
  const sum = [0, 0, 0];
  let n = 0;
  for (let pass = 0; pass < 2 && n === 0; ++pass) {
    for (let i = 0; i < placeholders.length; ++i) {
      if (pass === 0 && placeholders[i]) continue;
      for (let r = 0; r < 3; ++r) sum[r] += positions[3 * i + r];
      ++n;
    }
  }
  return sum.map((s) => s / Math.max(1, n));
}

const emptyBox = () => ({ min: [Infinity, Infinity, Infinity], max: [-Infinity, -Infinity, -Infinity] });
function grow(box, x, y, z) {
  const p = [x, y, z];
  for (let r = 0; r < 3; ++r) { box.min[r] = Math.min(box.min[r], p[r]); box.max[r] = Math.max(box.max[r], p[r]); }
}

// The clip's extent from poseAt(f), the world positions at source frame f (0 <= f < frameCount):
//   placeholders: per node, 1 for a placeholder (above);
//   world: the box of every node over every frame (the camera's framing without following);
//   body: the box of the other nodes relative to the followed point, over every frame (the
//         framing while following: the figure stays inside it wherever it walks).
// Two passes over the frames: the first finds the static nodes, the second the boxes.
export function clipExtent(nodes, frameCount, poseAt, size) {
  const N = nodes.length, lo = new Float64Array(3 * N).fill(Infinity), hi = new Float64Array(3 * N).fill(-Infinity);
  for (let f = 0; f < frameCount; ++f) {
    const p = poseAt(f);
    for (let k = 0; k < 3 * N; ++k) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
  }
  const staticNodes = nodes.map((_, i) => [0, 1, 2].every((r) => hi[3 * i + r] - lo[3 * i + r] <= STATIC_FRACTION * size));
  const placeholders = placeholderNodes(nodes, staticNodes);
  const world = emptyBox(), body = emptyBox();
  for (let i = 0; i < N; ++i) {
    grow(world, lo[3 * i], lo[3 * i + 1], lo[3 * i + 2]);
    grow(world, hi[3 * i], hi[3 * i + 1], hi[3 * i + 2]);
  }
  const all = placeholders.every((x) => x);  // followedPoint then uses every node
  for (let f = 0; f < frameCount; ++f) {
    const p = poseAt(f), c = followedPoint(p, placeholders);
    for (let i = 0; i < N; ++i) if (all || !placeholders[i]) grow(body, p[3 * i] - c[0], p[3 * i + 1] - c[1], p[3 * i + 2] - c[2]);
  }
  return { placeholders, world, body };
}

// The default view direction (from the target towards the camera): in front, to the right and
// a little above, in the viewer's y-up space.
export const VIEW_DIRECTION = [0.8, 0.35, 1.5];

// A camera that sees the whole box: looking at its centre along -direction from the distance
// at which its bounding sphere fits both the vertical field of view (fovDegrees) and the
// horizontal one (from aspect = width / height), with a 5% margin. `offset` moves the box (the
// followed point, for the body box); the sphere is at least `minRadius` (a clip of one point,
// or a figure that never moves, still gets a camera at some distance: the viewer passes a
// quarter of the skeleton size). Returns { target, position, radius, distance }.
export function fitCamera(box, { fovDegrees = 40, aspect = 1, direction = VIEW_DIRECTION, offset = [0, 0, 0], minRadius = 0 } = {}) {
  const centre = [0, 1, 2].map((r) => (box.min[r] + box.max[r]) / 2 + offset[r]);
  const radius = Math.max(minRadius, 1e-9, Math.hypot(...[0, 1, 2].map((r) => (box.max[r] - box.min[r]) / 2)));
  const half = (fovDegrees * Math.PI) / 360;
  const halfNarrow = Math.min(half, Math.atan(Math.tan(half) * aspect));
  const distance = (1.05 * radius) / Math.sin(halfNarrow);
  const length = Math.hypot(...direction);
  const position = centre.map((c, r) => c + (direction[r] / length) * distance);
  return { target: centre, position, radius, distance };
}
