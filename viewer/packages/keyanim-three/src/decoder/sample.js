// Appendix A: the value of a channel at a frame position, in binary32. Every operation is one
// binary64 operation on binary32 operands rounded by Math.fround, which equals the binary32
// operation (binary64 has more than 2 x 24 + 2 bits, so the double rounding is innocuous).
// samplePose gives every channel's stored value (a quaternion node's stored x, y, z: 4.7);
// sampleChannels the BVH channel values (Appendix B: its rotation as Euler angles instead).
import { storedRotation, eulerFromQuaternion, rotationAxes } from './rotation.js';

const f32 = Math.fround;

// Largest j < n - 1 with keyFrames[j] <= f (the caller has f > k_0 and f < k_{n-1}).
function segmentIndex(k, f) {
  let lo = 0, hi = k.length - 2;
  while (lo < hi) {
    const mid = (lo + hi + 1) >> 1;
    if (k[mid] <= f) lo = mid; else hi = mid - 1;
  }
  return lo;
}

// ch: { interp, tension, keyFrames, values }; rule: the clip's Tangent_Rule; f = RN32(x).
export function channelValue(ch, rule, f) {
  const k = ch.keyFrames, v = ch.values, n = k.length;
  if (n === 0) return 0;
  if (n === 1 || !(f > k[0])) return v[0];  // key frames are below 2^24: K_j = k_j exactly
  if (f >= k[n - 1]) return v[n - 1];
  const j = segmentIndex(k, f);
  if (f === k[j]) return v[j];
  const u = f32(f32(f - k[j]) / f32(k[j + 1] - k[j]));
  const p0 = v[j], p1 = v[j + 1];
  if (ch.interp === 1) return f32(p0 + f32(u * f32(p1 - p0)));

  const pm = v[Math.max(j - 1, 0)], p2 = v[Math.min(j + 2, n - 1)];
  const s = f32(f32(1 - ch.tension) * 0.5);
  let a0 = 1, a1 = 1;
  if (rule === 1) {
    const len = f32(k[j + 1] - k[j]);
    if (j > 0) a0 = f32(f32(2 * len) / f32(f32(k[j] - k[j - 1]) + len));
    if (j + 2 < n) a1 = f32(f32(2 * len) / f32(len + f32(k[j + 2] - k[j + 1])));
  }
  const m0 = f32(f32(s * a0) * f32(p1 - pm));
  const m1 = f32(f32(s * a1) * f32(p2 - p0));
  const u2 = f32(u * u);
  const u3 = f32(u2 * u);
  const h01 = f32(f32(-2 * u3) + f32(3 * u2));
  const h10 = f32(f32(u3 - f32(2 * u2)) + u);
  const h11 = f32(u3 - u2);
  return f32(f32(f32(p0 + f32(h01 * f32(p1 - p0))) + f32(h10 * m0)) + f32(h11 * m1));
}

// Every channel at frame position x (a binary64 number of frames), into `out`.
export function samplePose(clip, x, out = new Float32Array(clip.channels.length)) {
  const f = f32(x);
  if (Number.isNaN(f)) throw new RangeError('the frame position is NaN');
  for (let c = 0; c < clip.channels.length; ++c) out[c] = channelValue(clip.channels[c], clip.tangentRule, f);
  return out;
}

// The BVH channel values at frame position x (Appendix B), into `out` (binary64): every channel
// as samplePose gives it, except a quaternion node's rotation channels (version 5), which hold
// the Euler angles in degrees of its rotation (4.7) in its channel order. `previous`: the values
// this gave for the position before in a sequence (or null): each quaternion node then gets,
// of the two sets of angles of its rotation, the one nearest the previous (whole turns added),
// so that the sequence is continuous; without it, the set with the middle angle in [-90, 90].
export function sampleChannels(clip, x, out = new Float64Array(clip.channels.length), previous = null) {
  const stored = samplePose(clip, x);
  out.set(stored);
  for (const q of clip.quatNodes) {
    const c = q.column, node = clip.nodes[q.node];
    const rotation = storedRotation(q.r, stored[c], stored[c + 1], stored[c + 2]);
    const angles = eulerFromQuaternion(rotation, rotationAxes(node), previous ? [previous[c], previous[c + 1], previous[c + 2]] : null);
    out.set(angles, c);
  }
  return out;
}

// Frame position of a time in seconds (Appendix A: x = t / Frame_Time, 0 when Frame_Time is 0).
export const framePositionAt = (clip, seconds) => (clip.frameTime > 0 ? seconds / clip.frameTime : 0);
