// IMAG (spec 9.2 and 9.3), the runtime profile's image: checked by the structure rules of 9.4,
// then turned into the channels an archive file gives (interp, tension, step, keyCount,
// keyFrames, values), so that sampling, the loader and the viewer do not see the profile.
// Version 5: the quaternion nodes (Quat_Node, Quat_Column, Quat_Reference, into clip.quatNodes
// as QUAT gives them), checked against SKEL, which is read first, and the quaternion tracks
// (Quat_Track_Count; their curves first, component-major). Records: imag-records.js; the content
// rules of 9.4: imag-content.js.
import { imageLayout, IMAG_HEADER_BYTES } from './imag-layout.js';
import { recordKeys } from './imag-records.js';
import { checkContent } from './imag-content.js';
import { quatNodeProblem, quatColumn, addQuatNode, checkStoredBound, MAX_REFERENCE_NORM2 } from './quat-nodes.js';

const NONE = 0xffffffff, TWO53 = 2n ** 53n, INF_BITS = 0x7f800000;
const BLOCK_SHIFT = 6;  // blocks of 64 frames
const abs = (x) => (x < 0n ? -x : x);

// r: the SectionReader of IMAG; clip: CLIP's counts (and in version 5 SKEL's nodes). Sets
// clip.channels (nodes named after SKEL) and, in version 5, clip.quatNodes.
export function decodeImage(r, clip) {
  const h = readHeader(r, clip);
  const lay = imageLayout(h);
  if (r.length !== lay.end) r.fail('corrupt', 0, `IMAG holds ${r.length} bytes, its header makes its arrays ${lay.end}`);
  checkPads(r, lay);
  const img = { r, h, lay, a: lay.arrays, F: clip.frameCount };
  const channels = readChannels(img, clip);
  const curves = readCurves(img, channels);
  if (h.v5) readQuatNodes(img, clip, channels);
  const tracks = blockTracks(img, curves);
  readLists(img, curves);
  recordKeys(img, curves, tracks);
  checkQuatFrames(img, clip, channels, curves);
  checkCurveEnds(img, curves);
  checkContent(img, curves);
  for (const cv of curves) Object.assign(channels[cv.channel], { step: cv.step, keyFrames: cv.frames, values: cv.values });
  for (const q of clip.quatNodes) channels[q.column + 1].keyFrames = channels[q.column + 2].keyFrames = channels[q.column].keyFrames;
  clip.channels = channels;
  checkStoredBound(r, clip, 0);
}

function readHeader(r, clip) {
  const C = clip.channelCount, F = clip.frameCount;
  if (r.length < IMAG_HEADER_BYTES) r.fail('corrupt', 0, `IMAG holds ${r.length} bytes, less than its 32-byte header`);
  const shift = r.u32();
  if (shift !== BLOCK_SHIFT) r.fail('corrupt', 0, `Block_Shift ${shift}, not 6`);
  const nc = r.u32();
  if (nc > C) r.fail('corrupt', 4, `Curve_Count ${nc} is above Channel_Count ${C}`);
  const nb = r.u32();
  if (nb > nc) r.fail('corrupt', 8, `Block_Curve_Count ${nb} is above Curve_Count ${nc}`);
  const B = r.u32(), wantB = nc > 0 ? Math.ceil(F / 64) : 0;
  if (B !== wantB) r.fail('corrupt', 12, `Block_Count ${B}, not ${wantB}`);
  const M = r.u32(), P = r.u32(), Q = r.u32(), QT = r.u32();
  if (clip.version.major < 5) {
    if (Q !== 0 || QT !== 0) r.fail('reserved_bits_set', 24, 'Image_Reserved is not 0');
    return { C, nc, nb, B, M, P, Q: 0, QT: 0, v5: false };
  }
  if (Q > clip.nodeCount) r.fail('corrupt', 24, `Quat_Count ${Q} is above Node_Count ${clip.nodeCount}`);
  if (QT > Q || 3 * QT > nb) r.fail('corrupt', 28, `Quat_Track_Count ${QT}: more than Quat_Count ${Q}, or more tracks of three than ${nb} block curves make`);
  return { C, nc, nb, B, M, P, Q, QT, v5: true };
}

// Every Pad (9.2) is zero, and so are Payload's 8 closing bytes and the 8 extra Record_Offset entries.
function checkPads(r, lay) {
  const zeroFrom = (from, to, what) => {
    for (let i = from; i < to; ++i) if (r.bytes[i] !== 0) r.fail('corrupt', i, `${what} is not 0`);
  };
  for (const [name, x] of Object.entries(lay.arrays)) zeroFrom(x.at + x.size, Math.ceil((x.at + x.size) / 8) * 8, `a Pad byte after ${name}`);
  const ro = lay.arrays.Record_Offset, pay = lay.arrays.Payload;
  zeroFrom(ro.at + 4 * lay.R, ro.at + ro.size, 'one of the 8 extra Record_Offset entries');
  zeroFrom(pay.at + pay.size - 8, pay.at + pay.size, "one of Payload's 8 closing bytes");
}

const u32 = (img, name, i) => img.r.view.getUint32(img.a[name].at + 4 * i, true);
const f32 = (img, name, i) => img.r.view.getFloat32(img.a[name].at + 4 * i, true);
const at = (img, name, i, bytes = 4) => img.a[name].at + bytes * i;

// The per-channel arrays, and Fixed_Channels. Returns the channels (curves get their keys later).
function readChannels(img, clip) {
  const { r, h, F } = img, C = h.C;
  const channels = [];
  for (let c = 0; c < C; ++c) {
    const interp = r.bytes[at(img, 'Interpolation', c, 1)];
    if (interp > 1) r.fail('reserved_bits_set', at(img, 'Interpolation', c, 1), `channel ${c}: reserved Interpolation ${interp}`);
    channels.push({ interp });
  }
  channels.forEach((ch, c) => {
    ch.tension = f32(img, 'Tension', c);
    if (!(ch.tension >= -1 && ch.tension <= 1)) r.fail('corrupt', at(img, 'Tension', c), `channel ${c}: Tension ${ch.tension} is not in [-1, 1]`);
  });
  let keys = 0;
  channels.forEach((ch, c) => {
    ch.keyCount = u32(img, 'Key_Count', c);
    if (ch.keyCount > F) r.fail('corrupt', at(img, 'Key_Count', c), `channel ${c}: Key_Count ${ch.keyCount} is above Frame_Count ${F}`);
    keys += ch.keyCount;
  });
  if (keys !== clip.keyCount) r.fail('corrupt', img.a.Key_Count.at, `the channels have ${keys} keys, CLIP says ${clip.keyCount}`);
  readCurveOf(img, channels);
  readFixed(img, channels);
  return channels;
}

// Curve_Of: a curve index for each channel with 2 keys or more, each index used once.
function readCurveOf(img, channels) {
  const { r, h } = img, owner = new Array(h.nc).fill(-1);
  channels.forEach((ch, c) => {
    const i = u32(img, 'Curve_Of', c), where = at(img, 'Curve_Of', c);
    if (ch.keyCount < 2) {
      if (i !== NONE) r.fail('corrupt', where, `channel ${c}: Curve_Of ${i} for a channel of ${ch.keyCount} keys (not 0xFFFFFFFF)`);
      return;
    }
    if (i >= h.nc) r.fail('corrupt', where, `channel ${c}: Curve_Of ${i} is not below Curve_Count ${h.nc}`);
    if (owner[i] >= 0) r.fail('corrupt', where, `channel ${c}: curve ${i} is already channel ${owner[i]}'s`);
    owner[i] = c;
  });
  const missing = owner.indexOf(-1);
  if (missing >= 0) r.fail('corrupt', img.a.Curve_Of.at, `no channel has curve ${missing} (Curve_Count ${h.nc})`);
  img.curveChannel = owner;
  img.curveOf = new Map(owner.map((c, i) => [c, i]));
}

// Fixed_Value, Fixed_Frame and Fixed_Channels: a fixed channel's key, or none; zero for curves.
function readFixed(img, channels) {
  const { r, F } = img;
  channels.forEach((ch, c) => {
    const bits = u32(img, 'Fixed_Value', c), v = f32(img, 'Fixed_Value', c), where = at(img, 'Fixed_Value', c);
    if (ch.keyCount === 1 ? !Number.isFinite(v) : bits !== 0) r.fail('corrupt', where, `channel ${c}: Fixed_Value ${v} (${ch.keyCount === 1 ? 'not finite' : 'not +0.0 for a channel without exactly one key'})`);
  });
  channels.forEach((ch, c) => {
    const k = u32(img, 'Fixed_Frame', c), where = at(img, 'Fixed_Frame', c);
    if (ch.keyCount === 1 ? k >= F : k !== 0) r.fail('corrupt', where, `channel ${c}: Fixed_Frame ${k} (${ch.keyCount === 1 ? `not below Frame_Count ${F}` : 'not 0 for a channel without exactly one key'})`);
    if (ch.keyCount < 2) fixedKeys(ch, k, f32(img, 'Fixed_Value', c));
  });
  let j = 0;
  channels.forEach((ch, c) => {
    if (ch.keyCount >= 2) return;
    const got = u32(img, 'Fixed_Channels', j);
    if (got !== c) r.fail('corrupt', at(img, 'Fixed_Channels', j), `Fixed_Channels entry ${j} is ${got}, not channel ${c}`);
    ++j;
  });
}

// A fixed channel as the archive profile holds it (9.3): no key, or one, at q = +-1 and
// Step = |value| (+0.0: q = 0, Step 1; -0.0: q = -1, the smallest positive Step).
function fixedKeys(ch, frame, value) {
  ch.keyFrames = new Int32Array(ch.keyCount).fill(frame);
  ch.values = new Float32Array(ch.keyCount).fill(value);
  ch.step = ch.keyCount === 0 || value === 0 ? (Object.is(value, -0) ? Number.MIN_VALUE : 1) : Math.abs(value);
}

// Curves, the curve lanes (L entries) and Curve_Channel. Returns one entry per curve.
function readCurves(img, channels) {
  const { r, h } = img, view = r.view, blocksOfF = Math.ceil(img.F / 64);
  const curves = img.curveChannel.map((c, i) => {
    const ch = channels[c], e = at(img, 'Curves', i, 24), list = i >= h.nb;
    if ((4 * ch.keyCount < blocksOfF) !== list) r.fail('corrupt', at(img, 'Curve_Of', c), `channel ${c} (${ch.keyCount} keys, ${blocksOfF} blocks) is a ${list ? 'list' : 'block'} curve, ${i}, and should not be (9.2)`);
    // In channel order within each group: block curves after the quaternion tracks' (3 QT, in
    // version 5, whose order readQuatNodes checks), then list curves.
    if (i > 3 * h.QT && i !== h.nb && img.curveChannel[i - 1] > c) r.fail('corrupt', at(img, 'Curve_Of', c), `curve ${i} is channel ${c}, after channel ${img.curveChannel[i - 1]} (curves go in channel order)`);
    const qBase = view.getBigInt64(e, true), step = view.getFloat64(e + 8, true), baseBits = view.getUint32(e + 16, true);
    if (abs(qBase) > TWO53) r.fail('corrupt', e, `curve ${i}: Q_Base ${qBase} is above 2^53`);
    if (!(Number.isFinite(step) && step > 0)) r.fail('corrupt', e + 8, `curve ${i}: Step ${step} is not finite and > 0`);
    if (baseBits > 55) r.fail('corrupt', e + 16, `curve ${i}: Base_Bits ${baseBits} (at most 55)`);
    if (view.getUint32(e + 20, true) !== 0) r.fail('reserved_bits_set', e + 20, `curve ${i}: Curve_Reserved is not 0`);
    return { index: i, channel: c, n: ch.keyCount, interp: ch.interp, tension: ch.tension, qBase, step, baseBits, list };
  });
  checkLanes(img, curves);
  curves.forEach((cv, i) => {
    const got = u32(img, 'Curve_Channel', i);
    if (got !== cv.channel) r.fail('corrupt', at(img, 'Curve_Channel', i), `Curve_Channel ${i} is ${got}, not ${cv.channel} (its Curve_Of)`);
  });
  return curves;
}

// Curve_S and Curve_Linear follow from the channel; the frame and value lanes are kept for
// checkCurveEnds and checkContent. Padding lanes: 0, or +infinity for the frames.
function checkLanes(img, curves) {
  const { r, lay } = img;
  for (let i = 0; i < lay.L; ++i) {
    const cv = curves[i];
    const lane = (name, want) => {
      if (u32(img, name, i) !== want) r.fail('corrupt', at(img, name, i), `${name} ${i}: 0x${u32(img, name, i).toString(16)}, not 0x${want.toString(16)}${cv ? '' : ' (a padding lane)'}`);
    };
    const s = cv ? Math.fround(Math.fround(1 - cv.tension) * 0.5) : 0;
    if (!Object.is(f32(img, 'Curve_S', i), s)) r.fail('corrupt', at(img, 'Curve_S', i), `Curve_S ${i} is ${f32(img, 'Curve_S', i)}, not ${s}${cv ? ` (from Tension ${cv.tension})` : ' (a padding lane)'}`);
    if (!cv) ['First_Frame', 'Last_Frame'].forEach((name) => lane(name, INF_BITS));
    if (!cv) ['First_Value', 'Last_Value'].forEach((name) => lane(name, 0));
    lane('Curve_Linear', cv?.interp === 1 ? NONE : 0);
    if (cv) ['First_Frame', 'Last_Frame', 'First_Value', 'Last_Value'].forEach((name) => { cv[name] = f32(img, name, i); });
  }
}

// Version 5: Quat_Node, Quat_Column and Quat_Reference (9.2): the quaternion nodes, each one
// QUAT could list (4.7) with its stored x's channel; the references' lanes RN32 of X 2^-15,
// Y 2^-15, Z 2^-15 and sqrt(1 - (X² + Y² + Z²) 2^-30) for integers X, Y, Z of 16 bits with
// X² + Y² + Z² <= 2^30; padding lanes (0, 0, 0, 1). Then: the stored x, y, z of each have one
// Interpolation, Tension (bits) and Key_Count (reported at y's or z's entry); the nodes whose
// x, y, z are block curves, the quaternion tracks, are Quat_Track_Count and come first in
// Quat_Node; track t's x, y, z are curves t, QT + t, 2QT + t (Curve_Channel); each group of
// Quat_Node is in increasing node order.
function readQuatNodes(img, clip, channels) {
  const { r, h, lay } = img, found = [];
  for (let j = 0; j < lay.LQ; ++j) {
    const lane = (k) => at(img, 'Quat_Reference', k * lay.LQ + j), value = (k) => f32(img, 'Quat_Reference', k * lay.LQ + j);
    if (j >= h.Q) {
      [0, 0, 0, 1].forEach((want, k) => { if (!Object.is(value(k), want)) r.fail('corrupt', lane(k), `Quat_Reference padding lane ${j}: r${'xyzw'[k]} is ${value(k)}, not ${want}`); });
      continue;
    }
    const n = u32(img, 'Quat_Node', j);
    const problem = quatNodeProblem(clip.nodes, n);
    if (problem) r.fail('corrupt', at(img, 'Quat_Node', j), `Quat_Node ${j}: ${problem}, so it cannot be a quaternion node (4.7)`);
    const column = u32(img, 'Quat_Column', j), want = quatColumn(clip.nodes[n]);
    if (column !== want) r.fail('corrupt', at(img, 'Quat_Column', j), `Quat_Column ${j} is ${column}, not channel ${want} (node ${n}'s first rotation channel)`);
    const reference = [0, 1, 2].map((k) => {
      const X = value(k) * 32768 + 0;  // -0.0 is no integer's lane: X = +0 gives +0.0
      if (!(Number.isInteger(X) && X >= -32768 && X <= 32767 && Object.is(value(k), X / 32768))) r.fail('corrupt', lane(k), `Quat_Reference ${j}: r${'xyz'[k]} ${value(k)} is not an integer of 16 bits times 2^-15`);
      return X;
    });
    const norm2 = reference.reduce((s, v) => s + v * v, 0);
    if (norm2 > MAX_REFERENCE_NORM2) r.fail('corrupt', lane(0), `Quat_Reference ${j}: X² + Y² + Z² = ${norm2} (X, Y, Z = ${reference.join(', ')}), above 2^30`);
    const rw = Math.fround(Math.sqrt(1 - norm2 / 2 ** 30));
    if (!Object.is(value(3), rw)) r.fail('corrupt', lane(3), `Quat_Reference ${j}: rw ${value(3)}, not ${rw} (RN32 of sqrt(1 - (X² + Y² + Z²) 2^-30))`);
    found.push({ n, column, reference });
  }
  const arrays = [
    ['Interpolation', (c) => channels[c].interp, (c) => at(img, 'Interpolation', c, 1)],
    ['Tension', (c) => u32(img, 'Tension', c), (c) => at(img, 'Tension', c)],
    ['Key_Count', (c) => channels[c].keyCount, (c) => at(img, 'Key_Count', c)],
  ];
  for (const { n, column } of found) {
    for (const [name, get, where] of arrays) {
      for (const c of [column + 1, column + 2]) {
        if (get(c) !== get(column)) r.fail('corrupt', where(c), `channel ${c}: its ${name} differs from channel ${column}'s, and both are stored x, y, z of quaternion node ${n} (9.4)`);
      }
    }
  }
  const isTrack = ({ column }) => channels[column].keyCount >= 2 && img.curveOf.get(column) < h.nb;
  const QT = found.filter(isTrack).length;
  if (QT !== h.QT) r.fail('corrupt', 28, `Quat_Track_Count ${h.QT}, but ${QT} quaternion nodes have their stored x, y, z as block curves`);
  found.forEach((q, j) => {
    if (isTrack(q) !== j < QT) r.fail('corrupt', at(img, 'Quat_Node', j), `Quat_Node ${j} is node ${q.n}, whose stored x, y, z are ${isTrack(q) ? '' : 'not '}block curves: Quat_Node lists the ${QT} quaternion tracks' nodes first, then the others`);
  });
  for (let t = 0; t < QT; ++t) for (let k = 0; k < 3; ++k) {
    const i = k * QT + t, want = found[t].column + k, got = img.curveChannel[i];
    if (got !== want) r.fail('corrupt', at(img, 'Curve_Channel', i), `Curve_Channel ${i} is channel ${got}, not ${want}: the stored ${'xyz'[k]} of quaternion track ${t} (node ${found[t].n}; the tracks' x's come first, then their y's, then their z's)`);
  }
  found.forEach((q, j) => {
    if (j > 0 && j !== QT && q.n <= found[j - 1].n) r.fail('corrupt', at(img, 'Quat_Node', j), `Quat_Node ${j} is node ${q.n}, not after node ${found[j - 1].n} (strictly increasing, the quaternion tracks' first, then the others')`);
  });
  for (const q of found.slice().sort((a, b) => a.n - b.n)) addQuatNode(clip, q.n, q.reference);
}

// The block tracks (9.2): quaternion track t < QT is curves t, QT + t, 2QT + t (its x, y, z),
// track QT + j block curve 3QT + j alone. Returns them as lists of curves.
function blockTracks(img, curves) {
  const { h, lay } = img, QT = h.QT;
  return Array.from({ length: lay.nt }, (_, t) => (t < QT ? [curves[t], curves[QT + t], curves[2 * QT + t]] : [curves[2 * QT + t]]));
}

// Version 5 (4.4): a quaternion node's stored y and z have the key frames of its stored x. The
// records of a track of three give them one Mask; list curves and fixed channels hold each
// curve's frames, compared here key by key. The y and z then share the x's array, as from KTIM.
function checkQuatFrames(img, clip, channels, curves) {
  const { r } = img;
  for (const q of clip.quatNodes) {
    const x = channels[q.column];
    const frames = (c) => (channels[c].keyCount >= 2 ? curves[img.curveOf.get(c)].frames : channels[c].keyFrames);
    for (const c of [q.column + 1, q.column + 2]) {
      const a = frames(q.column), b = frames(c);
      for (let k = 0; k < b.length; ++k) {
        if (a[k] === b[k]) continue;
        const where = x.keyCount >= 2 ? at(img, 'List_Frames', curves[img.curveOf.get(c)].listFirst + k) : at(img, 'Fixed_Frame', c);
        r.fail('corrupt', where, `channel ${c}: its key ${k} is at frame ${b[k]}, channel ${q.column}'s at ${a[k]}; both are stored x, y, z of quaternion node ${q.node}, whose key frames are the x's (4.4)`);
      }
    }
  }
}

// Lists, List_Frames, List_Values, List_Q: the keys of the list curves, checked key by key.
function readLists(img, curves) {
  const { r, h } = img, view = r.view;
  let first = 0;
  for (const cv of curves.filter((c) => c.list)) {
    const j = cv.index - h.nb, e = at(img, 'Lists', j, 8);
    const gotFirst = view.getUint32(e, true), count = view.getUint32(e + 4, true);
    if (gotFirst !== first) r.fail('corrupt', e, `list ${j}: First ${gotFirst}, not ${first} (the earlier lists' counts)`);
    if (count !== cv.n) r.fail('corrupt', e + 4, `list ${j}: Count ${count}, not its channel's Key_Count ${cv.n}`);
    if (first + count > h.M) r.fail('corrupt', e + 4, `list ${j}: its keys end at ${first + count}, beyond List_Key_Count ${h.M}`);
    cv.frames = new Int32Array(count);
    cv.values = new Float32Array(count);
    cv.q = new Array(count);
    cv.listFirst = first;
    for (let k = 0; k < count; ++k) listKey(img, cv, k, first + k);
    first += count;
  }
  if (first !== h.M) r.fail('corrupt', 16, `List_Key_Count ${h.M}, the lists hold ${first} keys`);
}

function listKey(img, cv, k, m) {
  const { r, F } = img;
  const frame = u32(img, 'List_Frames', m);
  if (frame >= F) r.fail('corrupt', at(img, 'List_Frames', m), `curve ${cv.index} key ${k}: frame ${frame} is not below Frame_Count ${F}`);
  if (k > 0 && frame <= cv.frames[k - 1]) r.fail('corrupt', at(img, 'List_Frames', m), `curve ${cv.index} key ${k}: frame ${frame} does not follow ${cv.frames[k - 1]}`);
  const q = r.view.getBigInt64(at(img, 'List_Q', m, 8), true);
  if (abs(q) > TWO53) r.fail('corrupt', at(img, 'List_Q', m, 8), `curve ${cv.index} key ${k}: List_Q ${q} is above 2^53`);
  const v = Math.fround(Number(q) * cv.step), got = f32(img, 'List_Values', m);
  if (!Number.isFinite(v)) r.fail('corrupt', at(img, 'List_Q', m, 8), `curve ${cv.index} key ${k}: value ${Number(q)} x ${cv.step} is not finite in binary32`);
  if (!Object.is(got, v)) r.fail('corrupt', at(img, 'List_Values', m), `curve ${cv.index} key ${k}: List_Values ${got}, not ${v} (List_Q ${q} x Step)`);
  cv.frames[k] = frame;
  cv.values[k] = v;
  cv.q[k] = q;
}

// First_Frame and Last_Frame are the curve's first and last key; for a list curve First_Value
// and Last_Value too (for a block curve they are content: imag-content.js).
function checkCurveEnds(img, curves) {
  const { r } = img;
  for (const cv of curves) {
    const n = cv.n, ends = { First_Frame: Math.fround(cv.frames[0]), Last_Frame: Math.fround(cv.frames[n - 1]) };
    if (cv.list) Object.assign(ends, { First_Value: cv.values[0], Last_Value: cv.values[n - 1] });
    for (const [name, want] of Object.entries(ends)) {
      if (!Object.is(cv[name], want)) r.fail('corrupt', at(img, name, cv.index), `curve ${cv.index}: ${name} ${cv[name]}, not ${want} (its ${name.startsWith('First') ? 'first' : 'last'} key)`);
    }
  }
}
