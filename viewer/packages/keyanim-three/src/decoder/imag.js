// IMAG (spec 9.2 and 9.3), the runtime profile's image: checked by the structure rules of 9.4,
// then turned into the channels an archive file gives (interp, tension, step, keyCount,
// keyFrames, values), so that sampling, the loader and the viewer do not see the profile.
// Records: imag-records.js; the content rules of 9.4: imag-content.js.
import { imageLayout, IMAG_HEADER_BYTES } from './imag-layout.js';
import { recordKeys } from './imag-records.js';
import { checkContent } from './imag-content.js';

const NONE = 0xffffffff, TWO53 = 2n ** 53n, INF_BITS = 0x7f800000;
const BLOCK_SHIFT = 6;  // blocks of 64 frames
const abs = (x) => (x < 0n ? -x : x);

// r: the SectionReader of IMAG; clip: CLIP's counts. Sets clip.channels (nodes named after SKEL).
export function decodeImage(r, clip) {
  const h = readHeader(r, clip);
  const lay = imageLayout(h);
  if (r.length !== lay.end) r.fail('corrupt', 0, `IMAG holds ${r.length} bytes, its header makes its arrays ${lay.end}`);
  checkPads(r, lay);
  const img = { r, h, lay, a: lay.arrays, F: clip.frameCount };
  const channels = readChannels(img, clip);
  const curves = readCurves(img, channels);
  readLists(img, curves);
  recordKeys(img, curves);
  checkCurveEnds(img, curves);
  checkContent(img, curves);
  for (const cv of curves) Object.assign(channels[cv.channel], { step: cv.step, keyFrames: cv.frames, values: cv.values });
  clip.channels = channels;
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
  const M = r.u32(), P = r.u32();
  if (r.u32() !== 0 || r.u32() !== 0) r.fail('reserved_bits_set', 24, 'Image_Reserved is not 0');
  return { C, nc, nb, B, M, P };
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
    if (i > 0 && i !== h.nb && img.curveChannel[i - 1] > c) r.fail('corrupt', at(img, 'Curve_Of', c), `curve ${i} is channel ${c}, after channel ${img.curveChannel[i - 1]} (curves go in channel order)`);
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
