// KVAL (spec 4.5, of 3.0 and 4.0 archive files; Appendix E for 1.0 and 2.0): residuals ->
// quantized values q -> key values v = RN32(q x Step). q can reach 2^53 and residuals 2^57,
// so they are BigInts.

import { checkStoredBound } from './quat-nodes.js';

const TWO53 = 2n ** 53n, TWO57 = 2n ** 57n, TWO54 = 2n ** 54n, TWO40 = 2n ** 40n;
const abs = (x) => (x < 0n ? -x : x);
const unzigzag = (u) => (u & 1n ? -((u + 1n) >> 1n) : u >> 1n);

// ⌊a / b⌋ for b > 0 (BigInt division truncates toward zero).
const floorDiv = (a, b) => { const q = a / b; return a % b < 0n ? q - 1n : q; };

export function decodeKeyValues(r, clip) {
  const major = clip.version.major;
  const next = major >= 3 ? fixedWidthResiduals(r, clip.channels) : varintPlaneResiduals(r, clip.keyCount);
  const rBound = major === 1 ? TWO54 : TWO57;
  clip.channels.forEach((ch, c) => {
    const frames = ch.keyFrames, values = new Float32Array(ch.keyCount);
    let q1 = 0n, q2 = 0n;  // q_{i-1}, q_{i-2}
    let channelAt = 0;  // where the channel's residuals start: keyanim reports a value there
    for (let i = 0; i < ch.keyCount; ++i) {
      const { residual, at } = next(ch);
      if (i === 0) channelAt = at;
      if (abs(residual) > rBound) r.fail('corrupt', at, `channel ${c} key ${i}: residual ${residual} is above 2^${major === 1 ? 54 : 57}`);
      const q = predict(ch, i, q1, q2, frames) + residual;
      if (abs(q) > TWO53) r.fail('corrupt', at, `channel ${c} key ${i}: quantized value ${q} is above 2^53`);
      const v = Math.fround(Number(q) * ch.step);  // exact conversion, one binary64 rounding, then RN32
      if (!Number.isFinite(v)) r.fail('corrupt', channelAt, `channel ${c} key ${i}: value ${Number(q)} x ${ch.step} is not finite in binary32`);
      values[i] = v;
      q2 = q1;
      q1 = q;
    }
    ch.values = values;
  });
  checkStoredBound(r, clip, 0);
}

// pred_i of section 4.5 (Value_Coding 0 for every channel of a 1.0 file).
function predict(ch, i, q1, q2, k) {
  if (i === 0) return 0n;
  if (i === 1 || ch.valueCoding === 0) return q1;
  const d = q1 - q2, g0 = k[i - 1] - k[i - 2], g1 = k[i] - k[i - 1];
  if (abs(d) < TWO40 && g0 < 65536 && g1 < 65536) {
    const G0 = BigInt(g0);
    return q1 + floorDiv(2n * d * BigInt(g1) + G0, 2n * G0);
  }
  return q1 + d;
}

// 3.0: zigzag residuals of Residual_Bytes bytes each, in byte planes. Returns next(channel).
function fixedWidthResiduals(r, channels) {
  const planeSize = new Array(8).fill(0);
  let total = 0;
  for (const ch of channels) {
    for (let k = 0; k < ch.residualBytes; ++k) planeSize[k] += ch.keyCount;
    total += ch.keyCount * ch.residualBytes;
  }
  if (r.length !== total) r.fail('corrupt', 0, `KVAL holds ${r.length} bytes, the channels need ${total}`);
  const cursor = [];
  for (let k = 0, start = 0; k < 8; start += planeSize[k++]) cursor.push(start);
  const bytes = r.bytes;
  return (ch) => {
    const at = cursor[0];
    let lo = 0, hi = 0;  // low 32 and high 32 bits of the zigzag value
    for (let k = 0; k < ch.residualBytes; ++k) {
      const b = bytes[cursor[k]++];
      if (k < 4) lo += b * 2 ** (8 * k); else hi += b * 2 ** (8 * (k - 4));
    }
    return { residual: unzigzag((BigInt(hi) << 32n) | BigInt(lo)), at };
  };
}

// 1.0 and 2.0 (Appendix E): Plane_Count, Plane_Size[], then the varints' bytes in planes.
function varintPlaneResiduals(r, keyCount) {
  const planes = r.u8('Plane_Count');
  if (planes > 10) r.fail('corrupt', 0, `Plane_Count ${planes} (at most 10)`);
  if ((planes === 0) !== (keyCount === 0)) r.fail('corrupt', 0, `Plane_Count ${planes} with ${keyCount} keys`);
  const cursor = [], end = [];
  let start = 1 + 4 * planes;
  for (let k = 0; k < planes; ++k) {
    const at = r.pos, size = r.u32('Plane_Size');
    if (size === 0) r.fail('corrupt', at, `plane ${k} is empty`);
    if (k === 0 && size !== keyCount) r.fail('corrupt', at, `plane 0 holds ${size} bytes, not one per key (${keyCount})`);
    cursor.push(start);
    end.push(start += size);
  }
  if (r.length !== start) r.fail('corrupt', 0, `KVAL holds ${r.length} bytes, its planes need ${start}`);
  let left = keyCount;
  const bytes = r.bytes;
  return () => {
    const at = cursor[0];
    let u = 0n;
    for (let k = 0; ; ++k) {
      if (k === planes || cursor[k] === end[k]) r.fail('corrupt', at, `a varint needs a byte from plane ${k}, which has none left`);
      const b = bytes[cursor[k]++];
      u |= BigInt(b & 0x7f) << BigInt(7 * k);
      if (b & 0x80) continue;
      if (b === 0 && k > 0) r.fail('corrupt', at, 'over-long varint');
      if (u >> 64n) r.fail('corrupt', at, 'varint value does not fit 64 bits');
      break;
    }
    if (--left === 0) {
      for (let k = 0; k < planes; ++k) if (cursor[k] !== end[k]) r.fail('corrupt', end[k], `${end[k] - cursor[k]} unread bytes in plane ${k}`);
    }
    return { residual: unzigzag(u), at };
  };
}
