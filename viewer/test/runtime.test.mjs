// The runtime profile (spec section 9): the XXH64 check values of 9.1.3, and files made from
// v4_rules.kanim that each break one rule of 9.1 or 9.4 (the XXH64 fixed again unless the
// checksum is the point), rejected with the rule's status at the field's file offset, the
// message naming the place as section 7 asks; the same for version 5 (quaternion nodes and
// tracks, records of three curves) from v5_quat_runtime.kanim and v5_blocks_runtime.kanim.
// With the keyanim CLI, `keyanim verify` must agree (status and offset), or give what a case's
// `cpp` states (a known, explained difference).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { decodeKanim } from 'keyanim-three/decoder/kanim.js';
import { xxh64 } from 'keyanim-three/decoder/xxh64.js';
import { vectorsDir, keyanimCli, sourceDir, exists } from './paths.mjs';

test('XXH64 check values of spec 9.1.3', () => {
  assert.equal(xxh64(new Uint8Array(0)), 0xef46db3751d8e999n);
  assert.equal(xxh64(new TextEncoder().encode('123456789')), 0x8cb841db40e6ae83n);
});

const read = (name) => new Uint8Array(fs.readFileSync(path.join(vectorsDir, name)));
const dv = (b) => new DataView(b.buffer, b.byteOffset, b.byteLength);
const fixXxh = (b) => { dv(b).setBigUint64(b.length - 8, xxh64(b.subarray(0, b.length - 8)), true); return b; };

// Where things lie in a runtime file, worked out here from the bytes and spec 9.2 (not from
// the decoder): the sections' file offsets, then IMAG's arrays, each padded to 8 bytes (version
// 5: Quat_Count Q and Quat_Track_Count QT in the header; the quaternion arrays after
// Curve_Channel; nb - 2QT block tracks, a record each per block).
function layout(b) {
  const v = dv(b), count = v.getUint32(16, true), sections = {};
  let at = 24 + 24 * count;
  for (let i = 0; i < count; ++i) {
    const e = 24 + 24 * i, tag = String.fromCharCode(...b.subarray(e, e + 4));
    sections[tag] = { entry: e, at };
    at += Number(v.getBigUint64(e + 8, true));
  }
  const im = sections.IMAG.at, C = v.getUint32(sections.CLIP.at + 8, true), v5 = v.getUint16(8, true) >= 5;
  const [nc, nb, B, M, P, Q, QT] = [4, 8, 12, 16, 20, 24, 28].map((o) => (o < 24 || v5 ? v.getUint32(im + o, true) : 0));
  const L = 4 * Math.ceil(nc / 4), LQ = 4 * Math.ceil(Q / 4), sizes = [
    ['Interpolation', C], ['Tension', 4 * C], ['Key_Count', 4 * C], ['Curve_Of', 4 * C], ['Fixed_Value', 4 * C],
    ['Fixed_Frame', 4 * C], ['Fixed_Channels', 4 * (C - nc)], ['Curves', 24 * nc], ['Curve_S', 4 * L],
    ['First_Frame', 4 * L], ['Last_Frame', 4 * L], ['First_Value', 4 * L], ['Last_Value', 4 * L],
    ['Curve_Linear', 4 * L], ['Curve_Channel', 4 * nc], ['Quat_Node', 4 * Q], ['Quat_Column', 4 * Q], ['Quat_Reference', 16 * LQ],
    ['Lists', 8 * (nc - nb)], ['List_Frames', 4 * M],
    ['List_Values', 4 * M], ['List_Q', 8 * M], ['Record_Offset', 4 * (B * (nb - 2 * QT) + 8)], ['Payload', P + 8]];
  const arrays = {};
  let a = im + 32;
  for (const [name, size] of sizes) { arrays[name] = { at: a, size }; a += Math.ceil(size / 8) * 8; }
  return { sections, arrays, C, nc, nb, P, Q, QT, LQ, frames: v.getUint32(sections.CLIP.at, true) };
}

const base = read('v4_rules.kanim');
// The file offset of node 0's Parent in SKEL (after its Name_Length and name).
const parent0 = (lay, bytes) => lay.sections.SKEL.at + 4 + dv(bytes).getUint32(lay.sections.SKEL.at, true);
const L = layout(base);
const record0 = L.arrays.Payload.at;  // block 0's record of curve 0

// Each case: the bytes, and what the decoder must say: status, place, file offset.
const patch = (fn, fix = true) => { const b = base.slice(); fn(b, dv(b)); return fix ? fixXxh(b) : b; };
const cases = {
  'a Record_Offset one too high': {
    bytes: patch((b, v) => v.setUint32(L.arrays.Record_Offset.at + 4, v.getUint32(L.arrays.Record_Offset.at + 4, true) + 1, true)),
    status: 'corrupt', where: 'section IMAG', offset: L.arrays.Record_Offset.at + 4,
  },
  'Value_Bits 56': { bytes: patch((b) => { b[record0 + 8] = 56; }), status: 'corrupt', where: 'section IMAG', offset: record0 + 8 },
  'a non-zero Pad byte (after Interpolation)': {
    bytes: patch((b) => { b[L.arrays.Interpolation.at + L.C] = 1; }),  // C = 12: bytes 12 to 15 are its Pad
    status: 'corrupt', where: 'section IMAG', offset: L.arrays.Interpolation.at + L.C,
  },
  'Curve_Reserved non-zero': { bytes: patch((b) => { b[L.arrays.Curves.at + 20] = 1; }), status: 'reserved_bits_set', where: 'section IMAG', offset: L.arrays.Curves.at + 20 },
  'a Mask bit beyond Frame_Count': {
    bytes: patch((b, v) => v.setUint32(record0, v.getUint32(record0, true) | (1 << (L.frames + 2)), true)),  // F = 20: frame 22
    status: 'corrupt', where: 'section IMAG', offset: record0,
  },
  'IMAG compressed': { bytes: patch((b) => { b[L.sections.IMAG.entry + 4] |= 1; }), status: 'corrupt', where: 'section table', offset: L.sections.IMAG.entry + 4 },
  'IMAG not at table entry 1': { bytes: fixXxh(swapImagSkel()), status: 'corrupt', where: 'section table', offset: 24 + 24 },
  'a wrong XXH64': { bytes: patch((b) => { b[b.length - 1] ^= 1; }, false), status: 'checksum_mismatch', where: 'checksum', offset: base.length - 8 },
  // More of 9.1 and 9.4, and a content rule this decoder checks (First_Value of a block curve).
  // 4.1 gives Header_Flags bits 1 (Member) and 2 (Bank) meanings (spec 10.2, 10.5); bit 3 stays reserved.
  'Member set in a file by itself': { bytes: patch((b) => { b[12] |= 2; }), status: 'corrupt', where: 'header', offset: 12 },
  'Header_Flags bit 3': { bytes: patch((b) => { b[12] |= 8; }), status: 'reserved_bits_set', where: 'header', offset: 12 },
  'Runtime set in a 3.0 file': { bytes: withCrc32(read('v3_rules.kanim'), (b) => { b[12] = 1; }), status: 'reserved_bits_set', where: 'header', offset: 12 },
  'Runtime clear: IMAG is an unknown critical section': { bytes: patch((b) => { b[12] = 0; }, false), status: 'reserved_bits_set', where: 'section table', offset: L.sections.IMAG.entry },
  // keyanim's C++ names the record's Value_Bits byte for either width; section 7 asks for the field's.
  'Context_Bits 32': { bytes: patch((b) => { b[record0 + 9] = 32; }), status: 'corrupt', where: 'section IMAG', offset: record0 + 9 },
  'Block_Shift 7': { bytes: patch((b) => { b[L.sections.IMAG.at] = 7; }), status: 'corrupt', where: 'section IMAG', offset: L.sections.IMAG.at },
  'Image_Reserved non-zero': { bytes: patch((b) => { b[L.sections.IMAG.at + 28] = 1; }), status: 'reserved_bits_set', where: 'section IMAG', offset: L.sections.IMAG.at + 24 },
  'Interpolation 2': { bytes: patch((b) => { b[L.arrays.Interpolation.at + 3] = 2; }), status: 'reserved_bits_set', where: 'section IMAG', offset: L.arrays.Interpolation.at + 3 },
  // P + 8 = 253 bytes, padded to 256: one more still fits the section, but not the records' end.
  'Payload_Size one more': { bytes: patch((b, v) => v.setUint32(L.sections.IMAG.at + 20, L.P + 1, true)), status: 'corrupt', where: 'section IMAG', offset: L.sections.IMAG.at + 20 },
  'Payload_Size 8 more (the arrays overrun IMAG)': { bytes: patch((b, v) => v.setUint32(L.sections.IMAG.at + 20, L.P + 8, true)), status: 'corrupt', where: 'section IMAG', offset: L.sections.IMAG.at },
  'a non-zero closing byte of Payload': { bytes: patch((b) => { b[L.arrays.Payload.at + L.P + 3] = 1; }), status: 'corrupt', where: 'section IMAG', offset: L.arrays.Payload.at + L.P + 3 },
  // The C++ names Curve_Of (the array Curve_Channel is compared with); this decoder the field changed.
  'Curve_Channel differs from Curve_Of': { bytes: patch((b, v) => v.setUint32(L.arrays.Curve_Channel.at, 99, true)), status: 'corrupt', where: 'section IMAG', offset: L.arrays.Curve_Channel.at, cpp: `corrupt @${L.arrays.Curve_Of.at}` },
  'First_Frame of curve 0 off by one': { bytes: patch((b, v) => v.setFloat32(L.arrays.First_Frame.at, v.getFloat32(L.arrays.First_Frame.at, true) + 1, true)), status: 'corrupt', where: 'section IMAG', offset: L.arrays.First_Frame.at },
  // The C++ rebuilds the whole image and names IMAG's start; this decoder rebuilds field by field.
  'First_Value of curve 0 (a content rule)': { bytes: patch((b, v) => v.setFloat32(L.arrays.First_Value.at, 12345, true)), status: 'corrupt', where: 'section IMAG', offset: L.arrays.First_Value.at, cpp: `corrupt @${L.sections.IMAG.at}` },
  'the file one byte longer': { bytes: fixXxh(Uint8Array.from([...base, 0])), status: 'trailing_bytes', where: 'checksum', offset: base.length },
  // 9.1.1: SKEL is entry 2, so nothing sits between IMAG and SKEL.
  'an ancillary section between IMAG and SKEL': { bytes: fixXxh(insertAfterImag('XTRA', 2)), status: 'corrupt', where: 'section table', offset: 24 + 48 },
  'CHAN in a runtime file': { bytes: fixXxh(insertAfterImag('CHAN', 0)), status: 'corrupt', where: 'section table', offset: 24 + 48 },
  // Version 4: Quat_Count and Quat_Track_Count are version 4's Image_Reserved; QUAT is an unknown tag.
  'v4: Quat_Count non-zero': { bytes: patch((b) => { b[L.sections.IMAG.at + 24] = 1; }), status: 'reserved_bits_set', where: 'section IMAG', offset: L.sections.IMAG.at + 24 },
  // Spec 3.2.3: QUAT is an unknown tag before version 5 (9.1.2 makes it corrupt in version 5's
  // runtime profile only).
  // Section 7: in the runtime profile SKEL is read before IMAG, whose version 5 checks need it.
  'SKEL and IMAG both broken: SKEL\'s error': { bytes: patch((b, v) => { b[L.sections.IMAG.at] = 7; v.setInt32(parent0(L, base), 5, true); }), status: 'corrupt', where: 'section SKEL', offset: parent0(L, base) },
  'v4: a QUAT section after SKEL': { bytes: fixXxh(insertEntry(base, 3, 'QUAT', 0)), status: 'reserved_bits_set', where: 'section table', offset: 24 + 72 },
};

// Version 5 (spec 9.2 to 9.4). v5_quat_runtime: nodes Hips (0), Chest (1), Arm (2), Hand (3), an
// End Site, Neck (5), Head (6: rotation channels apart), Jaw (7), an End Site; Quat_Node 1, 2
// (the QT = 2 quaternion tracks: curves 0, 1 their x's, 2, 3 their y's, 4, 5 their z's; stored
// x at channels 6 and 9), then 3 (Hand: channels 13-15, one key each) and 5 (Neck: no key).
// v5_blocks_runtime: Quat_Node 1 (a track), 2 (channels 7-9: list curves of 3 keys, List_Frames
// 12-14, 15-17, 18-20); Q = 2, so the references have padding lanes 2 and 3.
const v5q = read('v5_quat_runtime.kanim'), L5 = layout(v5q);
const v5b = read('v5_blocks_runtime.kanim'), L5b = layout(v5b);
const patchOf = (bytes) => (fn, fix = true) => { const b = bytes.slice(); fn(b, dv(b)); return fix ? fixXxh(b) : b; };
const patch5 = patchOf(v5q), patch5b = patchOf(v5b);
const im5 = L5.sections.IMAG.at, a5 = L5.arrays, a5b = L5b.arrays;
const el = (a, name, j, bytes = 4) => a[name].at + bytes * j;  // entry j of an array
const lane = (lay, k, j) => lay.arrays.Quat_Reference.at + 4 * (k * lay.LQ + j);  // rx, ry, rz, rw of node j
const rec5 = a5.Payload.at;  // block 0's record of quaternion track 0 (Chest: curves 0, 2, 4)
// Block 3's record of track 0 (frames 192 to 255 of 200): Mask bit 63 is frame 255.
const rec5last = a5.Payload.at + dv(v5q).getUint32(el(a5, 'Record_Offset', 3 * (L5.nb - 2 * L5.QT)), true);
const swap = (b, at1, at2, n) => { const t = b.slice(at1, at1 + n); b.copyWithin(at1, at2, at2 + n); b.set(t, at2); };
// In rec5 (9.3: Mask, three Value_Bits, Context_Bits, Context, three Bases, then the x's m + 4
// values, then the y's), the lowest bit of the y's Values[0]: the window's first key.
const yValue0 = (() => {
  const v = dv(v5q), wk = v5q[rec5 + 11], baseBits = [0, 2, 4].map((i) => v.getUint32(el(a5, 'Curves', i, 24) + 16, true));
  let m = 0;
  for (let t = 0; t < 64; ++t) m += (v5q[rec5 + (t >> 3)] >> (t & 7)) & 1;
  const p = 96 + 4 * wk + baseBits[0] + baseBits[1] + baseBits[2] + (m + 4) * v5q[rec5 + 8];
  return { byte: rec5 + (p >> 3), bit: 1 << (p & 7) };
})();
// Quaternion node entries j and k swapped in Quat_Node, Quat_Column and Quat_Reference.
const swapQuatNodes = (b, j, k) => {
  for (const name of ['Quat_Node', 'Quat_Column']) swap(b, el(a5, name, j), el(a5, name, k), 4);
  for (let c = 0; c < 4; ++c) swap(b, lane(L5, c, j), lane(L5, c, k), 4);
};
const v5cases = {
  'v5: Quat_Count above Node_Count': { bytes: patch5((b, v) => v.setUint32(im5 + 24, 10, true)), status: 'corrupt', where: 'section IMAG', offset: im5 + 24 },
  'v5: Quat_Track_Count beyond the block curves': { bytes: patch5((b, v) => v.setUint32(im5 + 28, 7, true)), status: 'corrupt', where: 'section IMAG', offset: im5 + 28 },
  'v5: Quat_Node not a quaternion node (rotation channels apart)': { bytes: patch5((b, v) => v.setUint32(el(a5, 'Quat_Node', 3), 6, true)), status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Quat_Node', 3) },
  'v5: Quat_Node an End Site': { bytes: patch5((b, v) => v.setUint32(el(a5, 'Quat_Node', 3), 8, true)), status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Quat_Node', 3) },
  'v5: Quat_Node a track after another node': { bytes: patch5((b) => swapQuatNodes(b, 1, 2)), status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Quat_Node', 1) },
  'v5: Quat_Node the other nodes not increasing': { bytes: patch5((b) => swapQuatNodes(b, 2, 3)), status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Quat_Node', 3) },
  // The tracks' nodes swapped, not their curves: curve 0 is no longer track 0's x.
  'v5: Quat_Node the tracks swapped': { bytes: patch5((b) => swapQuatNodes(b, 0, 1)), status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Curve_Channel', 0) },
  'v5: Quat_Column off by one': { bytes: patch5((b, v) => v.setUint32(el(a5, 'Quat_Column', 1), 10, true)), status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Quat_Column', 1) },
  'v5: a reference lane not a multiple of 2^-15': { bytes: patch5((b, v) => v.setFloat32(lane(L5, 0, 1), v.getFloat32(lane(L5, 0, 1), true) + 2 ** -20, true)), status: 'corrupt', where: 'section IMAG', offset: lane(L5, 0, 1) },
  'v5: a reference lane -0.0': { bytes: patch5((b, v) => { assert.ok(Object.is(v.getFloat32(lane(L5, 0, 0), true), 0)); v.setFloat32(lane(L5, 0, 0), -0, true); }), status: 'corrupt', where: 'section IMAG', offset: lane(L5, 0, 0) },
  // keyanim's C++ names a reference's rx lane whichever lane is wrong (also a padding lane's);
  // section 7 asks for the offending field's offset, which this decoder gives.
  'v5: a reference rw one ulp off': { bytes: patch5((b, v) => v.setUint32(lane(L5, 3, 1), v.getUint32(lane(L5, 3, 1), true) + 1, true)), status: 'corrupt', where: 'section IMAG', offset: lane(L5, 3, 1), cpp: `corrupt @${lane(L5, 0, 1)}` },
  'v5: a reference of X² + Y² + Z² above 2^30': {
    bytes: patch5((b, v) => { v.setFloat32(lane(L5, 0, 1), -1, true); v.setFloat32(lane(L5, 1, 1), 2 ** -15, true); v.setFloat32(lane(L5, 2, 1), 0, true); v.setFloat32(lane(L5, 3, 1), 0, true); }),
    status: 'corrupt', where: 'section IMAG', offset: lane(L5, 0, 1),
  },
  'v5: a padding lane of the references': { bytes: patch5b((b, v) => v.setFloat32(lane(L5b, 3, 2), 0, true)), status: 'corrupt', where: 'section IMAG', offset: lane(L5b, 3, 2), cpp: `corrupt @${lane(L5b, 0, 2)}` },
  // A quaternion node's stored x, y, z: one Interpolation, Tension, Key_Count (the facts that
  // follow from them changed too, so that only this rule breaks). keyanim's C++ names the
  // channel's Key_Count entry whichever differs; this decoder the field that does.
  'v5: a stored y of another Interpolation': {
    bytes: patch5((b, v) => { b[el(a5, 'Interpolation', 7, 1)] = 1; v.setUint32(el(a5, 'Curve_Linear', 2), 0xffffffff, true); }),
    status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Interpolation', 7, 1), cpp: `corrupt @${el(a5, 'Key_Count', 7)}`,
  },
  'v5: a stored z of another Tension': {
    bytes: patch5((b, v) => { v.setFloat32(el(a5, 'Tension', 8), 0.5, true); v.setFloat32(el(a5, 'Curve_S', 4), 0.25, true); }),
    status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Tension', 8), cpp: `corrupt @${el(a5, 'Key_Count', 8)}`,
  },
  'v5: a stored y of another Key_Count': {
    bytes: patch5((b, v) => {
      for (const name of ['Key_Count', 'Fixed_Value', 'Fixed_Frame']) v.setUint32(el(a5, name, 14), 0, true);  // Hand's y: no key
      v.setBigUint64(L5.sections.CLIP.at + 24, v.getBigUint64(L5.sections.CLIP.at + 24, true) - 1n, true);
    }),
    status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Key_Count', 14),
  },
  // Curves 1 and 2 (Arm's x, Chest's y) swapped, with every fact of theirs: track 0's y (channel 7) is
  // then curve 1, and curve 2, where it belongs, is Arm's x.
  'v5: the quaternion tracks\' curves out of order': {
    bytes: patch5((b, v) => {
      v.setUint32(el(a5, 'Curve_Of', 7), 1, true); v.setUint32(el(a5, 'Curve_Of', 9), 2, true);
      swap(b, el(a5, 'Curve_Channel', 1), el(a5, 'Curve_Channel', 2), 4);
      swap(b, el(a5, 'Curves', 1, 24), el(a5, 'Curves', 2, 24), 24);
      for (const name of ['Curve_S', 'First_Frame', 'Last_Frame', 'First_Value', 'Last_Value', 'Curve_Linear']) swap(b, el(a5, name, 1), el(a5, name, 2), 4);
    }),
    status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Curve_Channel', 2),
  },
  // A quaternion node's stored y and z have its stored x's key frames (4.4: in the archive profile
  // they have none of their own; a record of three curves has one Mask). Where the image keeps
  // them apart, in lists and fixed channels, they are checked (the clip the archive profile
  // would hold; 9.4 does not list the rule).
  'v5: a stored y\'s list key at another frame than its x\'s': {
    bytes: patch5b((b, v) => v.setUint32(el(a5b, 'List_Frames', 16), v.getUint32(el(a5b, 'List_Frames', 16), true) + 1, true)),
    status: 'corrupt', where: 'section IMAG', offset: el(a5b, 'List_Frames', 16),
  },
  'v5: a stored z\'s Fixed_Frame not its x\'s': {
    bytes: patch5((b, v) => v.setUint32(el(a5, 'Fixed_Frame', 15), v.getUint32(el(a5, 'Fixed_Frame', 15), true) + 1, true)),
    status: 'corrupt', where: 'section IMAG', offset: el(a5, 'Fixed_Frame', 15),
  },
  'v5: a record of three curves: Value_Bits 56 (its z)': { bytes: patch5((b) => { b[rec5 + 10] = 56; }), status: 'corrupt', where: 'section IMAG', offset: rec5 + 10 },
  'v5: a record of three curves: Context_Bits 32': { bytes: patch5((b) => { b[rec5 + 11] = 32; }), status: 'corrupt', where: 'section IMAG', offset: rec5 + 11 },
  'v5: a record of three curves: a Mask bit beyond Frame_Count': { bytes: patch5((b, v) => v.setUint32(rec5last + 4, 0x80000000, true)), status: 'corrupt', where: 'section IMAG', offset: rec5last },
  // The C++ rebuilds the whole image and names IMAG's start; this decoder rebuilds field by field.
  'v5: a record of three curves: its y\'s Values[0] (a content rule)': { bytes: patch5((b) => { b[yValue0.byte] ^= yValue0.bit; }), status: 'corrupt', where: 'section IMAG', offset: rec5, cpp: `corrupt @${im5}` },
  'v5: SKEL and IMAG both broken: SKEL\'s error': { bytes: patch5((b, v) => { b[im5] = 7; v.setInt32(parent0(L5, v5q), 5, true); }), status: 'corrupt', where: 'section SKEL', offset: parent0(L5, v5q) },
  'v5: QUAT in a runtime file': { bytes: fixXxh(insertEntry(v5q, 3, 'QUAT', 0)), status: 'corrupt', where: 'section table', offset: 24 + 72 },
  'v5: Runtime clear (IMAG an unknown critical section)': { bytes: patch5((b) => { b[12] = 0; }, false), status: 'reserved_bits_set', where: 'section table', offset: L5.sections.IMAG.entry },
};
Object.assign(cases, v5cases);

// A table entry for an empty section `tag` inserted as entry `index` of the file's table.
function insertEntry(bytes, index, tag, flags) {
  const entry = new Uint8Array(24), at = 24 + 24 * index;
  entry.set(new TextEncoder().encode(tag));
  dv(entry).setUint32(4, flags, true);
  const b = Uint8Array.from([...bytes.subarray(0, at), ...entry, ...bytes.subarray(at)]);
  dv(b).setUint32(16, dv(bytes).getUint32(16, true) + 1, true);
  return b;
}

// A table entry for an empty section `tag` inserted as entry 2, before SKEL.
function insertAfterImag(tag, flags) {
  const entry = new Uint8Array(24);
  entry.set(new TextEncoder().encode(tag));
  dv(entry).setUint32(4, flags, true);
  const b = Uint8Array.from([...base.subarray(0, 72), ...entry, ...base.subarray(72)]);
  dv(b).setUint32(16, dv(base).getUint32(16, true) + 1, true);
  return b;
}

// CLIP, SKEL, IMAG: SKEL's bytes move up to entry 1's place, IMAG's after them.
function swapImagSkel() {
  const v = dv(base), s = L.sections, imagSize = s.SKEL.at - s.IMAG.at, skelSize = Number(v.getBigUint64(s.SKEL.entry + 8, true));
  const b = base.slice();
  b.set(base.subarray(s.SKEL.entry, s.SKEL.entry + 24), s.IMAG.entry);
  b.set(base.subarray(s.IMAG.entry, s.IMAG.entry + 24), s.SKEL.entry);
  b.set(base.subarray(s.SKEL.at, s.SKEL.at + skelSize), s.IMAG.at);
  b.set(base.subarray(s.IMAG.at, s.IMAG.at + imagSize), s.IMAG.at + skelSize);
  return b;
}

// An archive file patched, its CRC-32 fixed (spec 3.3).
function withCrc32(bytes, fn) {
  const b = bytes.slice();
  fn(b);
  let c = 0xffffffff;
  for (let i = 0; i < b.length - 4; ++i) { c ^= b[i]; for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1; }
  dv(b).setUint32(b.length - 4, (c ^ 0xffffffff) >>> 0, true);
  return b;
}

test('v4_rules.kanim itself decodes (the cases below start from a valid file)', () => {
  assert.equal(decodeKanim(base).profile, 'runtime');
});

test('the v5 runtime vectors decode (the v5 cases start from them), as laid out here', () => {
  for (const [bytes, lay] of [[v5q, L5], [v5b, L5b]]) {
    const clip = decodeKanim(bytes);
    assert.deepEqual([clip.profile, clip.version.major], ['runtime', 5]);
    assert.equal(lay.sections.IMAG.at + Number(dv(bytes).getBigUint64(lay.sections.IMAG.entry + 8, true)), lay.arrays.Payload.at + Math.ceil((lay.P + 8) / 8) * 8, 'the layout here ends where IMAG does');
    assert.equal(clip.quatNodes.length, lay.Q);
  }
  assert.deepEqual([L5.Q, L5.QT, L5b.Q, L5b.QT], [4, 2, 2, 1]);
  assert.deepEqual([0, 1, 2, 3].map((j) => dv(v5q).getUint32(el(a5, 'Quat_Node', j), true)), [1, 2, 3, 5]);
  assert.deepEqual([0, 1, 2, 3, 4, 5].map((i) => dv(v5q).getUint32(el(a5, 'Curve_Channel', i), true)), [6, 9, 7, 10, 8, 11]);
});

for (const [name, c] of Object.entries(cases)) {
  test(`runtime profile rejected: ${name}`, () => {
    assert.throws(() => decodeKanim(c.bytes), (e) => {
      assert.equal(e.name, 'KanimError', e.message);
      assert.deepEqual({ status: e.status, where: e.where, offset: e.offset }, { status: c.status, where: c.where, offset: c.offset }, e.message);
      assert.ok(e.message.startsWith(`${c.where}, offset ${c.offset} (0x${c.offset.toString(16)}): ${c.status}: `), e.message);
      return true;
    });
  });
}

// 4.7's bound (a content rule of 9.4, which this decoder checks): v5_blocks_runtime's curve 0,
// its quaternion track's x, with its Step scaled so that its largest key is 16 (decodes) or 16.5
// (refused), its First_Value and Last_Value made to match the scaled keys.
test('v5: a quaternion node\'s stored value beyond ±16 is refused, 16 is not', () => {
  const x = dv(v5b).getUint32(el(a5b, 'Curve_Channel', 0), true);
  const keys = decodeKanim(v5b).channels[x].values;
  const step = dv(v5b).getFloat64(el(a5b, 'Curves', 0, 24) + 8, true);
  const qs = Array.from(keys, (v) => Math.round(v / step));
  const top = Math.max(...qs.map(Math.abs));
  assert.ok(top > 0 && Math.max(...Array.from(keys, Math.abs)) <= 1);
  const scaled = (bound) => patch5b((b, v) => {
    const s = bound / top;
    v.setFloat64(el(a5b, 'Curves', 0, 24) + 8, s, true);
    v.setFloat32(el(a5b, 'First_Value', 0), Math.fround(qs[0] * s), true);
    v.setFloat32(el(a5b, 'Last_Value', 0), Math.fround(qs[qs.length - 1] * s), true);
  });
  const ok = decodeKanim(scaled(16)).channels[x].values;
  assert.equal(Math.max(...Array.from(ok, Math.abs)), 16);
  assert.throws(() => decodeKanim(scaled(16.5)), (e) => {
    assert.equal(e.status, 'corrupt', e.message);
    assert.ok(e.message.includes(`channel ${x}`) && e.message.includes('±16'), e.message);
    return true;
  });
});

test('a 4.0 file with Runtime clear is an archive file (v3_rules as 4.0)', () => {
  const got = decodeKanim(withCrc32(read('v3_rules.kanim'), (b) => { b[8] = 4; }));
  const want = decodeKanim(read('v3_rules.kanim'));
  assert.deepEqual([got.version, got.profile], [{ major: 4, minor: 0 }, 'archive']);
  assert.deepEqual(got.channels.map((ch) => [Array.from(ch.keyFrames), Array.from(ch.values)]), want.channels.map((ch) => [Array.from(ch.keyFrames), Array.from(ch.values)]));
});

const skip = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;

// A BVH of 4000 frames: Hips and Arm move fast, Still (between them) turns slowly about z, so
// that its x, y, z take few keys: list curves, a quaternion node that is no track.
function threeJointBvh() {
  const F = 4000, lines = ['HIERARCHY', 'ROOT Hips', '{', 'OFFSET 0 0 0', 'CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation',
    'JOINT Still', '{', 'OFFSET 0 10 0', 'CHANNELS 3 Zrotation Xrotation Yrotation', 'JOINT Arm', '{', 'OFFSET 10 0 0',
    'CHANNELS 3 Zrotation Xrotation Yrotation', 'End Site', '{', 'OFFSET 10 0 0', '}', '}', '}', '}', 'MOTION', `Frames: ${F}`, 'Frame Time: 0.0333333'];
  for (let f = 0; f < F; ++f) {
    const p = (2 * Math.PI * f) / 50;
    lines.push([5 * Math.sin(p), 90, f * 0.05, 20 * Math.sin(p), 10 * Math.cos(p), 5 * Math.sin(2 * p), 10 + 0.005 * f, 20, 30,
      40 * Math.sin(p), 30 * Math.cos(1.3 * p), 60 * Math.sin(0.7 * p)].map((v) => v.toFixed(6)).join(' '));
  }
  return `${lines.join('\n')}\n`;
}

// Spec 9: a clip and its runtime profile (`keyanim convert --runtime`) decode to the same clip.
// In version 5 Quat_Node lists the quaternion tracks first; the decoded clip lists every
// quaternion node in node order, as QUAT does. Here Still, a quaternion node that is no track,
// comes between two that are, so the order is at stake.
test('an encoded clip and its runtime profile decode to the same clip', { skip }, (t) => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-convert-'));
  t.after(() => fs.rmSync(dir, { recursive: true, force: true }));
  const bvh = path.join(dir, 'three.bvh'), archive = path.join(dir, 'three.kanim'), runtime = path.join(dir, 'three.runtime.kanim');
  fs.writeFileSync(bvh, threeJointBvh());
  spawnSync(keyanimCli, ['encode', bvh, '-o', archive, '-q']);
  spawnSync(keyanimCli, ['convert', archive, '--runtime', '-o', runtime, '-q']);
  const a = decodeKanim(fs.readFileSync(archive)), r = decodeKanim(fs.readFileSync(runtime));
  assert.deepEqual([a.profile, r.profile, a.version.major, r.version.major], ['archive', 'runtime', 5, 5]);
  const track = (clip, q) => clip.channels[q.column].keyCount >= 2 && 4 * clip.channels[q.column].keyCount >= Math.ceil(clip.frameCount / 64);
  const first = a.quatNodes.findIndex((q) => !track(a, q));
  assert.ok(first >= 0 && a.quatNodes.slice(first).some((q) => track(a, q)), 'a quaternion node that is no track before one that is');
  assert.deepEqual(r.quatNodes, a.quatNodes);
  r.nodes.forEach((n, i) => assert.deepEqual(n.quaternion, a.nodes[i].quaternion, `node ${i}`));
  r.channels.forEach((ch, c) => {
    assert.deepEqual([ch.interp, ch.keyCount, Array.from(ch.keyFrames)], [a.channels[c].interp, a.channels[c].keyCount, Array.from(a.channels[c].keyFrames)], `channel ${c}`);
    ch.values.forEach((v, k) => { if (!Object.is(v, a.channels[c].values[k])) assert.fail(`channel ${c} key ${k}: ${v}, the archive's ${a.channels[c].values[k]}`); });
  });
});
test('keyanim verify gives the same status and offset on every case', { skip }, (t) => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-runtime-'));
  t.after(() => fs.rmSync(dir, { recursive: true, force: true }));
  const mismatches = [];
  for (const [name, c] of Object.entries(cases)) {
    const file = path.join(dir, 'case.kanim');
    fs.writeFileSync(file, c.bytes);
    const r = spawnSync(keyanimCli, ['verify', file], { encoding: 'utf8' });
    const m = /offset (\d+) \(0x[0-9A-Fa-f]+\): ([a-z_]+):/.exec(r.stderr);
    const cpp = r.status === 0 ? 'ok' : m ? `${m[2]} @${m[1]}` : `exit ${r.status}: ${r.stderr.trim()}`;
    if (cpp !== (c.cpp ?? `${c.status} @${c.offset}`)) mismatches.push(`${name}: C++ ${cpp}, JS ${c.status} @${c.offset}`);
  }
  assert.deepEqual(mismatches, []);
});
