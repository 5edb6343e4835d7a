// The runtime profile (spec section 9): the XXH64 check values of 9.1.3, and files made from
// v4_rules.kanim that each break one rule of 9.1 or 9.4 (the XXH64 fixed again unless the
// checksum is the point), rejected with the rule's status at the field's file offset, the
// message naming the place as section 7 asks. With the keyanim CLI, `keyanim verify` must
// agree (status and offset), or give what a case's `cpp` states (a known, explained difference).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { decodeKanim } from 'keyanim-three/decoder/kanim.js';
import { xxh64 } from 'keyanim-three/decoder/xxh64.js';
import { vectorsDir, keyanimCli, exists } from './paths.mjs';

test('XXH64 check values of spec 9.1.3', () => {
  assert.equal(xxh64(new Uint8Array(0)), 0xef46db3751d8e999n);
  assert.equal(xxh64(new TextEncoder().encode('123456789')), 0x8cb841db40e6ae83n);
});

const read = (name) => new Uint8Array(fs.readFileSync(path.join(vectorsDir, name)));
const dv = (b) => new DataView(b.buffer, b.byteOffset, b.byteLength);
const fixXxh = (b) => { dv(b).setBigUint64(b.length - 8, xxh64(b.subarray(0, b.length - 8)), true); return b; };

// Where things lie in v4_rules.kanim, worked out here from the bytes and spec 9.2 (not from the
// decoder): the sections' file offsets, then IMAG's arrays, each padded to 8 bytes.
function layout(b) {
  const v = dv(b), count = v.getUint32(16, true), sections = {};
  let at = 24 + 24 * count;
  for (let i = 0; i < count; ++i) {
    const e = 24 + 24 * i, tag = String.fromCharCode(...b.subarray(e, e + 4));
    sections[tag] = { entry: e, at };
    at += Number(v.getBigUint64(e + 8, true));
  }
  const im = sections.IMAG.at, C = v.getUint32(sections.CLIP.at + 8, true);
  const [nc, nb, B, M, P] = [4, 8, 12, 16, 20].map((o) => v.getUint32(im + o, true));
  const L = 4 * Math.ceil(nc / 4), sizes = [
    ['Interpolation', C], ['Tension', 4 * C], ['Key_Count', 4 * C], ['Curve_Of', 4 * C], ['Fixed_Value', 4 * C],
    ['Fixed_Frame', 4 * C], ['Fixed_Channels', 4 * (C - nc)], ['Curves', 24 * nc], ['Curve_S', 4 * L],
    ['First_Frame', 4 * L], ['Last_Frame', 4 * L], ['First_Value', 4 * L], ['Last_Value', 4 * L],
    ['Curve_Linear', 4 * L], ['Curve_Channel', 4 * nc], ['Lists', 8 * (nc - nb)], ['List_Frames', 4 * M],
    ['List_Values', 4 * M], ['List_Q', 8 * M], ['Record_Offset', 4 * (B * nb + 8)], ['Payload', P + 8]];
  const arrays = {};
  let a = im + 32;
  for (const [name, size] of sizes) { arrays[name] = { at: a, size }; a += Math.ceil(size / 8) * 8; }
  return { sections, arrays, C, nc, nb, P, frames: v.getUint32(sections.CLIP.at, true) };
}

const base = read('v4_rules.kanim');
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
};

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

test('a 4.0 file with Runtime clear is an archive file (v3_rules as 4.0)', () => {
  const got = decodeKanim(withCrc32(read('v3_rules.kanim'), (b) => { b[8] = 4; }));
  const want = decodeKanim(read('v3_rules.kanim'));
  assert.deepEqual([got.version, got.profile], [{ major: 4, minor: 0 }, 'archive']);
  assert.deepEqual(got.channels.map((ch) => [Array.from(ch.keyFrames), Array.from(ch.values)]), want.channels.map((ch) => [Array.from(ch.keyFrames), Array.from(ch.values)]));
});

const skip = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;
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
