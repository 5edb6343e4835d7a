// Rotations of version 5 (spec/FORMAT.md 4.7 and Appendix B), in binary64: a quaternion
// node's reference, its rotation from its stored x, y, z, and the Euler angles (degrees) of a
// rotation in a node's channel order, continuous from one position to the next. Quaternions
// are arrays (x, y, z, w); rotations are right-handed and act on column vectors; Euler angles
// are intrinsic, R = R_1(a_1) R_2(a_2) R_3(a_3) in channel order (Appendix B).

const DEG = Math.PI / 180;

// The reference of a quaternion node (4.7) from its X, Y, Z (integers, X² + Y² + Z² <= 2^30):
// (X 2^-15, Y 2^-15, Z 2^-15, sqrt(1 - (X² + Y² + Z²) 2^-30)), a unit quaternion. The sum of
// squares is an integer below 2^31 and every operation but the square root is exact.
export function referenceRotation([X, Y, Z]) {
  return [X / 32768, Y / 32768, Z / 32768, Math.sqrt(1 - (X * X + Y * Y + Z * Z) / 2 ** 30)];
}

// a ⊗ b (Hamilton product, 4.7) into out at offset o (out may alias neither a nor b).
export function hamilton(a, b, out = new Array(4), o = 0) {
  const [ax, ay, az, aw] = a, [bx, by, bz, bw] = b;
  out[o] = aw * bx + ax * bw + ay * bz - az * by;
  out[o + 1] = aw * by - ax * bz + ay * bw + az * bx;
  out[o + 2] = aw * bz + ax * by - ay * bx + az * bw;
  out[o + 3] = aw * bw - ax * bx - ay * by - az * bz;
  return out;
}

// The rotation of a quaternion node (4.7) whose reference is r (referenceRotation) and whose
// stored x, y, z are sx, sy, sz: r ⊗ (sx, sy, sz, sqrt(max(0, 1 - (sx² + sy² + sz²)))),
// normalized. Into out at offset o.
export function storedRotation(r, sx, sy, sz, out = new Array(4), o = 0) {
  const w = Math.sqrt(Math.max(0, 1 - (sx * sx + sy * sy + sz * sz)));
  hamilton(r, [sx, sy, sz, w], out, o);
  const n = Math.hypot(out[o], out[o + 1], out[o + 2], out[o + 3]);
  for (let k = 0; k < 4; ++k) out[o + k] /= n;
  return out;
}

// The rotation by `degrees` about axis 0 (X), 1 (Y) or 2 (Z): (sin(a/2) u, cos(a/2)).
export function axisQuaternion(axis, degrees) {
  const q = [0, 0, 0, Math.cos((degrees * DEG) / 2)];
  q[axis] = Math.sin((degrees * DEG) / 2);
  return q;
}

// The 3x3 row-major matrix of the unit quaternion q (4.7), into out.
export function quaternionMatrix([x, y, z, w], out = new Array(9)) {
  out[0] = 1 - 2 * (y * y + z * z); out[1] = 2 * (x * y - z * w); out[2] = 2 * (x * z + y * w);
  out[3] = 2 * (x * y + z * w); out[4] = 1 - 2 * (x * x + z * z); out[5] = 2 * (y * z - x * w);
  out[6] = 2 * (x * z - y * w); out[7] = 2 * (y * z + x * w); out[8] = 1 - 2 * (x * x + y * y);
  return out;
}

// The local rotation of a node from its channel values as a quaternion: a quaternion node's
// (node.quaternion set by the decoder: values hold its stored x, y, z), else the product of its
// rotation channels in channel order (angles in degrees). Identity without rotation channels.
export function localRotation(node, values, out = new Array(4)) {
  const rotations = [];
  node.channels.forEach((type, k) => { if (type >= 3) rotations.push(values[node.firstChannel + k]); });
  if (node.quaternion && rotations.length === 3) return storedRotation(node.quaternion.r, rotations[0], rotations[1], rotations[2], out);
  let q = [0, 0, 0, 1];
  let k = 0;
  for (const type of node.channels) if (type >= 3) q = hamilton(q, axisQuaternion(type - 3, rotations[k++]));
  for (let c = 0; c < 4; ++c) out[c] = q[c];
  return out;
}

// The axes (0 X, 1 Y, 2 Z) of a node's rotation channels, in channel order.
export const rotationAxes = (node) => node.channels.filter((t) => t >= 3).map((t) => t - 3);

const wrapNear = (a, near) => a - 360 * Math.round((a - near) / 360);

// Euler angles in degrees of the unit quaternion q in the order `axes` (three different axes
// i, j, k): [a1, a2, a3] with R(q) = R_i(a1) R_j(a2) R_k(a3). Without `previous`, the set with
// a2 in [-90, 90] and a1, a3 in (-180, 180]; with it ([a1, a2, a3] of the position before), of
// the two sets a rotation has, each angle moved by whole turns to be nearest its previous
// value, the one nearest `previous`, by the sum of the angles' distances (Appendix B:
// continuous channels). At gimbal lock (a2 =
// ±90), a1 stays at its previous value (0 without one) and a3 takes the rest.
export function eulerFromQuaternion(q, [i, j, k], previous = null) {
  const M = quaternionMatrix(q), m = (r, c) => M[3 * r + c];
  const s = (j - i + 3) % 3 === 1 ? 1 : -1;  // +1 for the cyclic orders XYZ, YZX, ZXY
  const a2 = Math.atan2(s * m(i, k), Math.hypot(m(i, i), m(i, j)));
  const locked = Math.hypot(m(i, i), m(i, j)) < 1e-12;
  const a1 = locked ? (previous ? previous[0] * DEG : 0) : Math.atan2(-s * m(j, k), m(k, k));
  const set = [a1 / DEG, a2 / DEG, lastAngle(M, [i, j, k], a1, a2) / DEG];
  if (!previous) return set.map((a) => (a === -180 ? 180 : a));
  const other = [set[0] + 180, 180 - set[1], set[2] + 180];
  const near = (angles) => angles.map((a, n) => wrapNear(a, previous[n]));
  // Nearest: the smaller sum of the three angles' distances (what keyanim's converters choose).
  const distance = (angles) => angles.reduce((sum, a, n) => sum + Math.abs(a - previous[n]), 0);
  const [A, B] = [near(set), near(other)];
  return distance(B) < distance(A) ? B : A;
}

// a3 from R = R_i(a1) R_j(a2) R_k(a3): R_k(a3) = R_j(a2)^T R_i(a1)^T R, whose entries (k+1, k+1)
// and (k+2, k+1) are cos a3 and sin a3.
function lastAngle(M, [i, j, k], a1, a2) {
  const N = mul(transpose(axisMatrix(j, a2)), mul(transpose(axisMatrix(i, a1)), M));
  const u = (k + 1) % 3, v = (k + 2) % 3;
  return Math.atan2(N[3 * v + u], N[3 * u + u]);
}

function axisMatrix(axis, radians) {
  const c = Math.cos(radians), s = Math.sin(radians);
  if (axis === 0) return [1, 0, 0, 0, c, -s, 0, s, c];
  if (axis === 1) return [c, 0, s, 0, 1, 0, -s, 0, c];
  return [c, -s, 0, s, c, 0, 0, 0, 1];
}
const transpose = (a) => [a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8]];
function mul(a, b) {
  const out = new Array(9);
  for (let r = 0; r < 3; ++r) for (let c = 0; c < 3; ++c) out[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
  return out;
}
