// The animation as three.js keyframe tracks: each bone's local rotation (QuaternionKeyframeTrack)
// and, for bones with position channels, local position (VectorKeyframeTrack), sampled from the
// Cardinal curves (spec Appendix A, sample.js) at a grid of frame positions and made into local
// transforms as spec Appendix B says (pose.js): rotation channels multiplied in channel order,
// or for a quaternion node (version 5) its rotation from its stored x, y, z and its reference
// (spec 4.7, rotation.js), position channels replacing the Offset's component. A track's
// quaternions stay in one hemisphere from key to key (q and -q are the same rotation).
//
// three.js interpolates linearly between keys (slerp for rotations), the Cardinal curves do not:
// between two keys the chord can leave the curve. So each interval of the grid is checked
// against the curves (world positions of every node, at its middle and quarters and at the
// source frames inside it) and halved, with a key in the middle, until the chord stays within the
// budget. On a source-frame grid this adds keys where the motion bends fast for the budget.
import { Quaternion, Vector3, QuaternionKeyframeTrack, VectorKeyframeTrack } from 'three';
import { samplePose } from '../decoder/sample.js';
import { storedRotation } from '../decoder/rotation.js';

const DEG = Math.PI / 180;
const AXES = [new Vector3(1, 0, 0), new Vector3(0, 1, 0), new Vector3(0, 0, 1)];
const MAX_DEPTH = 10;        // at most 2^10 - 1 keys added inside one interval of the grid
const MAX_ADDED = 63;        // and at most 63 per key of the grid in all: memory stays bounded
const MAX_GRID = 2 ** 24;    // keys of a caller's rate: as many as a clip may have frames

// Frame positions of the keys before refinement: every source frame, or with `fps` the times
// k / fps from 0 up to the clip's end (and the end itself).
export function frameGrid(clip, fps) {
  const last = clip.frameCount - 1;
  if (last < 0) return [];
  if (fps == null || !(clip.frameTime > 0)) return Array.from({ length: clip.frameCount }, (_, f) => f);
  const step = 1 / (fps * clip.frameTime);  // source frames per key
  if (last / step + 2 > MAX_GRID) throw new RangeError(`${fps} fps gives more than ${MAX_GRID} keys for this clip`);
  const grid = [];
  for (let k = 0; k * step <= last + 1e-9; ++k) grid.push(Math.min(k * step, last));
  if (grid[grid.length - 1] < last - 1e-9) grid.push(last);
  return grid;
}

// Quaternion arithmetic on arrays (x, y, z, w at offset o), in binary64: the hot loop of the
// refinement, without objects.
function multiply(a, ao, b, bo, out, oo) {
  const ax = a[ao], ay = a[ao + 1], az = a[ao + 2], aw = a[ao + 3];
  const bx = b[bo], by = b[bo + 1], bz = b[bo + 2], bw = b[bo + 3];
  out[oo] = ax * bw + aw * bx + ay * bz - az * by;
  out[oo + 1] = ay * bw + aw * by + az * bx - ax * bz;
  out[oo + 2] = az * bw + aw * bz + ax * by - ay * bx;
  out[oo + 3] = aw * bw - ax * bx - ay * by - az * bz;
}

function identity(q, o) { q[o] = q[o + 1] = q[o + 2] = 0; q[o + 3] = 1; }

// v rotated by q, added to base: out = base + q v q*.
function rotateAdd(q, qo, v, vo, base, bo, out, oo) {
  const qx = q[qo], qy = q[qo + 1], qz = q[qo + 2], qw = q[qo + 3], vx = v[vo], vy = v[vo + 1], vz = v[vo + 2];
  const tx = 2 * (qy * vz - qz * vy), ty = 2 * (qz * vx - qx * vz), tz = 2 * (qx * vy - qy * vx);
  out[oo] = base[bo] + vx + qw * tx + qy * tz - qz * ty;
  out[oo + 1] = base[bo + 1] + vy + qw * ty + qz * tx - qx * tz;
  out[oo + 2] = base[bo + 2] + vz + qw * tz + qx * ty - qy * tx;
}

// Samples the clip into keys: { x (frame position), rot (x, y, z, w per rotated node), pos
// (x, y, z per moved node) }, both binary32 as the tracks store them.
class Sampler {
  constructor(clip) {
    this.clip = clip;
    this.nodes = clip.nodes;
    this.rotated = [];  // nodes with rotation channels
    this.moved = [];    // nodes with position channels
    const n = clip.nodes.length;
    this.rotIndex = new Int32Array(n).fill(-1);
    this.posIndex = new Int32Array(n).fill(-1);
    clip.nodes.forEach((node, i) => {
      if (node.channels.some((t) => t >= 3)) this.rotIndex[i] = this.rotated.push(i) - 1;
      if (node.channels.some((t) => t < 3)) this.posIndex[i] = this.moved.push(i) - 1;
    });
    this.values = new Float32Array(clip.channelCount);
    // Scratch: local rotations and translations, world rotations, world positions (twice).
    Object.assign(this, {
      q: new Float64Array(4 * n), t: new Float64Array(3 * n), qw: new Float64Array(4 * n),
      truth: new Float64Array(3 * n), approx: new Float64Array(3 * n), axis: new Quaternion(), tmp: new Float64Array(4),
    });
  }

  // Every node's local rotation and translation at frame position x, into this.q and this.t
  // (spec Appendix B, reading 'replace').
  localAt(x) {
    samplePose(this.clip, x, this.values);
    const { q, t, tmp, nodes, values } = this;
    for (let i = 0; i < nodes.length; ++i) {
      const node = nodes[i];
      identity(q, 4 * i);
      for (let a = 0; a < 3; ++a) t[3 * i + a] = node.offset[a];
      for (let c = 0; c < node.channels.length; ++c) {
        const type = node.channels[c], v = values[node.firstChannel + c];
        if (type < 3) { t[3 * i + type] = v; continue; }
        if (node.quaternion) continue;  // below, from the three stored values
        this.axis.setFromAxisAngle(AXES[type - 3], v * DEG).toArray(tmp);
        multiply(q, 4 * i, tmp, 0, q, 4 * i);
      }
      const quat = node.quaternion;
      if (quat) storedRotation(quat.r, values[quat.column], values[quat.column + 1], values[quat.column + 2], q, 4 * i);
    }
  }

  keyAt(x) {
    this.localAt(x);
    const rot = new Float32Array(4 * this.rotated.length), pos = new Float32Array(3 * this.moved.length);
    this.rotated.forEach((i, k) => rot.set(this.q.subarray(4 * i, 4 * i + 4), 4 * k));
    this.moved.forEach((i, k) => pos.set(this.t.subarray(3 * i, 3 * i + 3), 3 * k));
    return { x, rot, pos };
  }

  // Locals as three.js interpolates keys A and B at fraction u: slerp (QuaternionLinearInterpolant)
  // and lerp (LinearInterpolant) of the stored binary32 values.
  interpolate(A, B, u) {
    const { q, t, nodes } = this;
    for (let i = 0; i < nodes.length; ++i) {
      const r = this.rotIndex[i], p = this.posIndex[i];
      if (r >= 0) Quaternion.slerpFlat(q, 4 * i, A.rot, 4 * r, B.rot, 4 * r, u);
      else identity(q, 4 * i);
      for (let a = 0; a < 3; ++a) t[3 * i + a] = p >= 0 ? A.pos[3 * p + a] + (B.pos[3 * p + a] - A.pos[3 * p + a]) * u : nodes[i].offset[a];
    }
  }

  // World positions from this.q and this.t, into out: p = p_parent + R_parent t, R = R_parent R.
  world(out) {
    const { q, t, qw, nodes } = this;
    for (let i = 0; i < nodes.length; ++i) {
      const p = nodes[i].parent;
      if (p < 0) {
        for (let c = 0; c < 4; ++c) qw[4 * i + c] = q[4 * i + c];
        for (let c = 0; c < 3; ++c) out[3 * i + c] = t[3 * i + c];
      } else {
        multiply(qw, 4 * p, q, 4 * i, qw, 4 * i);
        rotateAdd(qw, 4 * p, t, 3 * i, out, 3 * p, out, 3 * i);
      }
    }
    return out;
  }

  // The largest distance, over the nodes, between the curves and three.js's interpolation of
  // keys A and B at frame position x (A.x < x < B.x).
  chordError(A, B, x) {
    this.localAt(x);
    const truth = this.world(this.truth);
    this.interpolate(A, B, (x - A.x) / (B.x - A.x));
    const approx = this.world(this.approx);
    let worst = 0;
    for (let k = 0; k < truth.length; k += 3) {
      worst = Math.max(worst, Math.hypot(approx[k] - truth[k], approx[k + 1] - truth[k + 1], approx[k + 2] - truth[k + 2]));
    }
    return worst;
  }

  // Where a chord is checked: its middle, where a chord of a smooth curve is farthest from it;
  // its quarters, for a curve that bends at one end (the middle alone let 1.7 times the budget
  // through on data/cmu_131_03_hop.bvh); the source frames strictly inside, where it may bend
  // sharply.
  static checkPoints(a, b) {
    const points = [0.5, 0.25, 0.75].map((u) => a + u * (b - a));
    for (let f = Math.floor(a) + 1; f < b; ++f) points.push(f);
    return points;
  }

  // Where to halve [a, b]: at the source frame nearest the middle if there is one inside, else
  // the middle. The curves' keys are at source frames and a curve's slope may jump at a key
  // (Tangent_Rule step_adjusted), so a chord across one leaves the curve by the jump's share of
  // the chord's length however short it is; once every source frame inside is a key, each
  // halving divides the chord's error by about 4.
  static splitPoint(a, b) {
    const m = (a + b) / 2, f = Math.round(m);
    if (f > a && f < b) return f;
    const lo = Math.floor(m), hi = Math.ceil(m);
    if (lo > a) return lo;
    if (hi < b) return hi;
    return m;
  }

  // Keys strictly between A and B, in order, so that the chord between neighbours stays
  // within `budget` at the check points.
  refine(A, B, budget, out, depth = 0) {
    const points = Sampler.checkPoints(A.x, B.x);
    if (!points.some((x) => this.chordError(A, B, x) > budget)) return;
    if (depth >= MAX_DEPTH || this.added >= this.maxAdded) { this.budgetMet = false; return; }
    const M = this.keyAt(Sampler.splitPoint(A.x, B.x));
    ++this.added;
    this.refine(A, M, budget, out, depth + 1);
    out.push(M);
    this.refine(M, B, budget, out, depth + 1);
  }
}

// The keys of the clip on `grid`, refined to `budget` (Infinity: the grid alone). budgetMet is
// false where the refinement stopped short: MAX_DEPTH in an interval, or MAX_ADDED x the grid's
// keys in all (the corpus needs at most 7 x).
export function sampleKeys(clip, grid, budget) {
  const sampler = new Sampler(clip), keys = [];
  Object.assign(sampler, { added: 0, maxAdded: MAX_ADDED * grid.length, budgetMet: true });
  let prev = null;
  for (const x of grid) {
    const key = sampler.keyAt(x);
    if (prev && Number.isFinite(budget)) sampler.refine(prev, key, budget, keys);
    keys.push(key);
    prev = key;
  }
  return { keys, rotated: sampler.rotated, moved: sampler.moved, budgetMet: sampler.budgetMet };
}

// q and -q are the same rotation; neighbouring keys on the same side keep any interpolation
// (three.js takes the short way anyway) and any later processing on the short path.
function sameHemisphere(values) {
  for (let k = 4; k < values.length; k += 4) {
    const dot = values[k] * values[k - 4] + values[k + 1] * values[k - 3] + values[k + 2] * values[k - 2] + values[k + 3] * values[k - 1];
    if (dot < 0) for (let c = 0; c < 4; ++c) values[k + c] = -values[k + c];
  }
  return values;
}

// The tracks: trackNames[i] is how the track of node i names its bone.
export function buildTracks(clip, { keys, rotated, moved }, trackNames) {
  const times = Float32Array.from(keys, (k) => k.x * clip.frameTime);
  const gather = (field, slot, width) => {
    const out = new Float32Array(width * keys.length);
    keys.forEach((k, j) => { for (let c = 0; c < width; ++c) out[width * j + c] = k[field][width * slot + c]; });
    return out;
  };
  // Each track gets its own times: KeyframeTrack.shift/scale/trim change them in place.
  const tracks = rotated.map((i, k) => new QuaternionKeyframeTrack(`${trackNames[i]}.quaternion`, times.slice(), sameHemisphere(gather('rot', k, 4))));
  moved.forEach((i, k) => tracks.push(new VectorKeyframeTrack(`${trackNames[i]}.position`, times.slice(), gather('pos', k, 3))));
  return tracks;
}
