// An independent BVH reader and forward kinematics for the glTF tests: written from the BVH
// format and keyanim's stated FK rules (spec/FORMAT.md, keyanim/offline/fk.h), sharing no
// code with keyanim. Rules: a node's local rotation is the product of its rotation channels
// in CHANNELS order (intrinsic), angles in degrees; each position channel replaces the
// matching OFFSET component; world p = p_parent + R_parent t, R = R_parent R_local.
import fs from 'node:fs';

export function readBvh(path) {
  const text = fs.readFileSync(path, 'utf8').replace(/^\uFEFF/, '');
  const lines = text.split(/\r\n|\r|\n/);
  const nodes = [];  // {name, parent, offset: [x,y,z], channels: ['Xrotation', ...], endSite, first}
  const stack = [];
  let pending = null;  // the node whose '{' comes next
  let columns = 0;
  let i = 0;
  for (; i < lines.length; ++i) {
    const line = lines[i].trim();
    if (line === '' || line === 'HIERARCHY') continue;
    if (line === 'MOTION') break;
    const words = line.split(/\s+/);
    const head = words[0];
    if (head === 'ROOT' || head === 'JOINT' || head === 'End') {
      const endSite = head === 'End';
      // A name is the rest of the line (End Sites: after "End Site", usually nothing).
      const name = line.slice(endSite ? line.indexOf('Site') + 4 : head.length).trim().replace(/\s*\{$/, '');
      pending = { name, parent: stack.length ? stack[stack.length - 1] : -1, offset: [0, 0, 0], channels: [], endSite, first: 0 };
      nodes.push(pending);
      if (line.endsWith('{')) { stack.push(nodes.length - 1); pending = null; }
    } else if (head === '{') {
      stack.push(nodes.length - 1);
      pending = null;
    } else if (head === '}') {
      stack.pop();
    } else if (head === 'OFFSET') {
      nodes[stack[stack.length - 1]].offset = words.slice(1, 4).map(Number);
    } else if (head === 'CHANNELS') {
      const node = nodes[stack[stack.length - 1]];
      node.channels = words.slice(2, 2 + Number(words[1]));
      node.first = columns;
      columns += node.channels.length;
    } else {
      throw new Error(`${path}:${i + 1}: unexpected '${head}'`);
    }
  }
  let declared = -1, frameTime = NaN;
  const values = [];
  for (++i; i < lines.length; ++i) {
    const line = lines[i].trim();
    if (line === '') continue;
    if (declared < 0 && line.startsWith('Frames:')) { declared = Number(line.slice(7)); continue; }
    if (Number.isNaN(frameTime) && line.startsWith('Frame Time:')) { frameTime = Number(line.slice(11)); continue; }
    const row = line.split(/\s+/).map(Number);
    if (row.length !== columns || row.some(Number.isNaN)) throw new Error(`${path}:${i + 1}: bad motion line`);
    values.push(row);
  }
  if (values.length < declared) throw new Error(`${path}: ${values.length} motion lines, Frames: ${declared}`);
  return { nodes, columns, frameTime, frames: columns === 0 ? declared : values.length, values };
}

// What keyanim's percentages are of: the largest side of the bounding box of the rest pose
// (OFFSETs only, End Sites included), or for a skeleton without extent (a lone root) of the
// box its nodes sweep over the clip.
export function skeletonSize(bvh) {
  const rest = restSize(bvh);
  if (rest > 0) return rest;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let f = 0; f < bvh.frames; ++f)
    for (const p of framePoints(bvh, f, 0))
      for (let a = 0; a < 3; ++a) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); }
  return bvh.frames > 0 ? Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]) : 0;
}

function restSize(bvh) {
  const pos = [];
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  bvh.nodes.forEach((n, j) => {
    const p = n.parent < 0 ? n.offset.slice() : n.offset.map((v, a) => v + pos[n.parent][a]);
    pos.push(p);
    for (let a = 0; a < 3; ++a) { lo[a] = Math.min(lo[a], p[a]); hi[a] = Math.max(hi[a], p[a]); }
  });
  return Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

function axisMatrix(axis, degrees) {
  const r = degrees * Math.PI / 180, c = Math.cos(r), s = Math.sin(r);
  if (axis === 0) return [1, 0, 0, 0, c, -s, 0, s, c];
  if (axis === 1) return [c, 0, s, 0, 1, 0, -s, 0, c];
  return [c, -s, 0, s, c, 0, 0, 0, 1];
}

function mul(a, b) {
  const o = new Array(9);
  for (let r = 0; r < 3; ++r)
    for (let c = 0; c < 3; ++c) o[3 * r + c] = a[3 * r] * b[c] + a[3 * r + 1] * b[3 + c] + a[3 * r + 2] * b[6 + c];
  return o;
}

const AXIS = { X: 0, Y: 1, Z: 2 };

// Measured points of one frame: node j's position at index j, then (shell > 0) for every
// joint (not End Site) three points at `shell` along its local x, y, z axes, in node order.
export function framePoints(bvh, f, shell) {
  const row = bvh.values[f] || [];
  const pos = [], rot = [];
  bvh.nodes.forEach((n, j) => {
    const t = n.offset.slice();
    let r = [1, 0, 0, 0, 1, 0, 0, 0, 1];
    n.channels.forEach((ch, k) => {
      const axis = AXIS[ch[0].toUpperCase()];
      if (ch.slice(1).toLowerCase() === 'rotation') r = mul(r, axisMatrix(axis, row[n.first + k]));
      else t[axis] = row[n.first + k];
    });
    if (n.parent < 0) {
      pos.push(t);
      rot.push(r);
    } else {
      const pp = pos[n.parent], m = rot[n.parent];
      pos.push([0, 1, 2].map((a) => pp[a] + m[3 * a] * t[0] + m[3 * a + 1] * t[1] + m[3 * a + 2] * t[2]));
      rot.push(mul(m, r));
    }
  });
  const points = pos.slice();
  if (shell > 0)
    bvh.nodes.forEach((n, j) => {
      if (n.endSite) return;
      for (let a = 0; a < 3; ++a) points.push([0, 1, 2].map((k) => pos[j][k] + shell * rot[j][3 * k + a]));
    });
  return points;
}

// Which node a point belongs to, and whether it is a shell point (for messages).
export function pointName(bvh, p) {
  const n = bvh.nodes.length;
  if (p < n) {
    const node = bvh.nodes[p];
    return node.endSite && !node.name ? `End Site of ${bvh.nodes[node.parent].name}` : node.name;
  }
  const joints = bvh.nodes.map((x, j) => j).filter((j) => !bvh.nodes[j].endSite);
  const k = p - n;
  return `${bvh.nodes[joints[Math.floor(k / 3)]].name} +${'xyz'[k % 3]} shell`;
}
