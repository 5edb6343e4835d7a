// The records of IMAG (spec 9.3): the keys of the block curves, read block by block and track by
// track (a curve, or in version 5 a quaternion node's stored x, y, z: one Mask and one Context
// for the three), with the structure rules of 9.4 on the way: offsets and sizes, Value_Bits and
// Context_Bits, the zero bits after the fields, Mask bits beyond Frame_Count, popcount sums, the
// window's order. Work in proportion to the records and keys; fields are BigInts (values reach
// 55 bits).
const TWO53 = 2n ** 53n;
const abs = (x) => (x < 0n ? -x : x);
const unzigzag = (u) => (u % 2 === 0 ? u / 2 : -(u + 1) / 2);  // u < 2^31: exact in a Number

function popcount32(x) {
  x -= (x >>> 1) & 0x55555555;
  x = (x & 0x33333333) + ((x >>> 2) & 0x33333333);
  return (((x + (x >>> 4)) & 0x0f0f0f0f) * 0x01010101) >>> 24;
}

// The field of width w at bit p of the record at byte `base` (9.3: least significant bit first).
function field(bytes, base, p, w) {
  if (w === 0) return 0n;
  let v = 0n;
  for (let k = (p + w - 1) >> 3; k >= p >> 3; --k) v = (v << 8n) | BigInt(bytes[base + k]);
  return (v >> BigInt(p & 7)) & ((1n << BigInt(w)) - 1n);
}

// Fills each block curve's frames, values and q, and keeps its records (one per curve, a
// record of three curves seen as each curve's own) for imag-content.js. tracks: the block
// tracks, each a list of 1 or 3 curves.
export function recordKeys(img, curves, tracks) {
  const { r, h } = img, block = curves.slice(0, h.nb), ro = img.a.Record_Offset.at, nt = tracks.length;
  for (const cv of block) Object.assign(cv, { frames: new Int32Array(cv.n), values: new Float32Array(cv.n), q: new Array(cv.n), records: [], filled: 0 });
  let end = 0;
  for (let b = 0; b < h.B; ++b) {
    for (let t = 0; t < nt; ++t) {
      const e = b * nt + t, off = r.view.getUint32(ro + 4 * e, true);
      if (off !== end) r.fail('corrupt', ro + 4 * e, `Record_Offset ${e} is ${off}, not ${end} (${e === 0 ? 'the first record starts at 0' : 'where the record before ends'})`);
      const recs = readRecord(img, tracks[t], b, off);
      tracks[t].forEach((cv, k) => takeKeys(img, cv, b, recs[k]));
      end = off + recs[0].size;
    }
  }
  if (end !== h.P) r.fail('corrupt', 20, `Payload_Size ${h.P}, the records end at ${end}`);
  for (const cv of block) {
    if (cv.filled !== cv.n) r.fail('corrupt', img.a.Key_Count.at + 4 * cv.channel, `curve ${cv.index}: its records hold ${cv.filled} keys, its channel's Key_Count is ${cv.n}`);
  }
}

// Block b's record of a track (curves: 1, or 3 in version 5) at byte `off` of Payload: its
// header, size and closing bits. Mask, Value_Bits (one byte per curve), Context_Bits, Context,
// then each curve's Base, then each curve's Values (9.3). Returns one record per curve: { b,
// base, lo, hi (Mask), m, w (the curve's Value_Bits), wk, ctx (e_0 ... e_3), size, what,
// baseValue, fields (Values) }.
function readRecord(img, track, b, off) {
  const { r, h, F } = img, bytes = r.bytes, base = img.a.Payload.at + off, k = track.length;
  const what = k === 1 ? `block ${b}'s record of curve ${track[0].index}` : `block ${b}'s record of curves ${track.map((cv) => cv.index).join(', ')} (a quaternion track)`;
  const headerBytes = 8 + k + 1, contextAt = 8 * headerBytes;  // 80 bits, or 96 for three curves
  if (off + headerBytes > h.P) r.fail('corrupt', base, `${what} runs past Payload_Size ${h.P}`);
  const lo = r.view.getUint32(base, true), hi = r.view.getUint32(base + 4, true);
  const ws = track.map((_, i) => bytes[base + 8 + i]), wk = bytes[base + 8 + k];
  ws.forEach((w, i) => { if (w > 55) r.fail('corrupt', base + 8 + i, `${what}: Value_Bits ${w}${k > 1 ? ` of curve ${track[i].index}` : ''} (at most 55)`); });
  if (wk > 31) r.fail('corrupt', base + 8 + k, `${what}: Context_Bits ${wk} (at most 31)`);
  const limit = F - 64 * b;  // Mask bits t >= limit are frames >= F
  if (limit < 64 && (limit < 32 ? (lo >>> limit) !== 0 || hi !== 0 : (hi >>> (limit - 32)) !== 0)) r.fail('corrupt', base, `${what}: Mask has a key at a frame >= Frame_Count ${F}`);
  const m = popcount32(lo) + popcount32(hi);
  const sumBase = track.reduce((s, cv) => s + cv.baseBits, 0), sumW = ws.reduce((s, w) => s + w, 0);
  const bits = contextAt + 4 * wk + sumBase + (m + 4) * sumW, size = Math.ceil(bits / 8);
  if (off + size > h.P) r.fail('corrupt', base, `${what}: its ${size} bytes run past Payload_Size ${h.P}`);
  if (bits % 8 && bytes[base + size - 1] >> (bits % 8)) r.fail('corrupt', base + size - 1, `${what}: the bits after its last field are not 0`);
  const ctx = [0, 1, 2, 3].map((j) => unzigzag(Number(field(bytes, base, contextAt + j * wk, wk))) + 64 * b + (j >= 2 ? 64 : 0));
  checkWindowOrder(img, { b, base, lo, hi, m, ctx, what }, headerBytes);
  let p = contextAt + 4 * wk;
  const recs = track.map((cv, i) => {
    const rec = { b, base, lo, hi, m, w: ws[i], wk, ctx, size, what, baseValue: field(bytes, base, p, cv.baseBits) };
    p += cv.baseBits;
    return rec;
  });
  recs.forEach((rec) => {
    rec.fields = Array.from({ length: m + 4 }, (_, j) => field(bytes, base, p + j * rec.w, rec.w));
    p += (m + 4) * rec.w;
  });
  return recs;
}

const lowBit = (x) => 31 - Math.clz32(x & -x);  // x != 0
const highBit = (x) => 31 - Math.clz32(x);

// 9.4: e_0 < e_1 < the block's first key, its last key < e_2 < e_3 (e_1 < e_2 without keys).
// Reported at the Context's first byte (after the header's `headerBytes`).
function checkWindowOrder(img, rec, headerBytes) {
  const [e0, e1, e2, e3] = rec.ctx, start = 64 * rec.b;
  let ok = e0 < e1 && e2 < e3;
  if (rec.m === 0) ok &&= e1 < e2;
  else {
    const first = start + (rec.lo ? lowBit(rec.lo) : 32 + lowBit(rec.hi));
    const last = start + (rec.hi ? 32 + highBit(rec.hi) : highBit(rec.lo));
    ok &&= e1 < first && last < e2;
  }
  if (!ok) img.r.fail('corrupt', rec.base + headerBytes, `${rec.what}: its window frames ${e0}, ${e1}, ${e2}, ${e3} are not in order around its keys`);
}

// The record's keys, in frame order: frame 64 b + t for each set bit t, q = Q_Base + Base +
// Values[2 + j]. |q| <= 2^53 and a finite value are content rules this decoder checks here.
function takeKeys(img, cv, b, rec) {
  const { r } = img;
  if (cv.filled + rec.m > cv.n) r.fail('corrupt', rec.base, `${rec.what}: curve ${cv.index} has ${cv.n} keys, its records so far more`);
  let j = 0;
  for (let t = 0; t < 64; ++t) {
    if (!((t < 32 ? rec.lo >>> t : rec.hi >>> (t - 32)) & 1)) continue;
    const q = cv.qBase + rec.baseValue + rec.fields[2 + j++];
    if (abs(q) > TWO53) r.fail('corrupt', rec.base, `${rec.what}: the key at frame ${64 * b + t} has q = ${q}, above 2^53`);
    const v = Math.fround(Number(q) * cv.step);
    if (!Number.isFinite(v)) r.fail('corrupt', rec.base, `${rec.what}: the key at frame ${64 * b + t}: ${Number(q)} x ${cv.step} is not finite in binary32`);
    cv.frames[cv.filled] = 64 * b + t;
    cv.values[cv.filled] = v;
    cv.q[cv.filled++] = q;
  }
  cv.records.push(rec);
}
