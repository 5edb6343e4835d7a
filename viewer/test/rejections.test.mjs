// The JS decoder rejects what keyanim's C++ loader rejects, with the same status and offset:
// files that each break one rule of spec/FORMAT.md (sections 2-6), and a few that bend an
// "unused" rule and must load. The C++ side is `keyanim verify`. Version 5 (QUAT, CHAN's and
// KTIM's rules for quaternion nodes, section 8's key bound) from v5_quat.kanim.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { decodeKanim } from 'keyanim-three/decoder/kanim.js';
import { splitKanim, buildKanim, fixCrc, zstdRawFrame, concat } from './kanim-builder.mjs';
import { vectorsDir, keyanimCli, exists } from './paths.mjs';

const read = (name) => new Uint8Array(fs.readFileSync(path.join(vectorsDir, name)));
const section = (m, tag) => m.sections.find((s) => s.tag === tag);
const setU8 = (b, at, v) => { b[at] = v; };
const dv = (b) => new DataView(b.buffer, b.byteOffset, b.byteLength);

// Field offsets of the SKEL records (name length, name, parent, offset, flags, count, types).
function skelRecords(content) {
  const out = [];
  for (let at = 0; at < content.length;) {
    const r = { start: at, parent: at + 4 + dv(content).getUint32(at, true) };
    r.offset = r.parent + 4; r.flags = r.offset + 24; r.count = r.flags + 1; r.types = r.count + 1;
    out.push(r);
    at = r.types + content[r.count];
  }
  return out;
}

// Each case: a base vector and a change to its model (sections with raw content) or bytes.
const edit = (base, fn) => () => { const m = splitKanim(read(base)); fn(m); return buildKanim(m); };
const patch = (base, fn, crc = true) => () => { const b = read(base).slice(); fn(b); return crc ? fixCrc(b) : b; };
const content = (tag, fn, base = 'v3_rules.kanim') => edit(base, (m) => fn(section(m, tag).content, m));
const C = 12;  // channels of v3_rules
const chan = (fn) => content('CHAN', (b) => fn(b, dv(b)));
const skel = (fn) => content('SKEL', (b) => fn(b, skelRecords(b), dv(b)));
const withSection = (base, fn) => edit(base, (m) => { m.sections = fn(m.sections); });

// Version 5: v5_quat.kanim's nodes are Hips (0: Xpos Ypos Zpos Zrot Xrot Yrot, not a quaternion
// node), Chest (1), Arm (2), Hand (3), an End Site (4), Neck (5), Head (6: Zrot Xpos Xrot Yrot,
// its rotations not consecutive), Jaw (7: Xrot Zrot) and an End Site (8); QUAT lists 1, 2, 3, 5
// (entries of 10 bytes after Quat_Count), whose stored x are channels 6, 9, 13, 16.
const Q5 = 'v5_quat.kanim', C5 = 25;
const quat = (fn) => content('QUAT', (b, m) => fn(b, dv(b), m), Q5);
const chan5 = (fn) => content('CHAN', (b) => fn(b, dv(b)), Q5);
const entry = (j) => 4 + 10 * j;  // QUAT entry j: Node, then Reference X, Y, Z
const CHAN5 = 612;  // where the edited files' CHAN starts (its content follows a 3-byte block header)
// Section 8's bound on Key_Count, per byte of the (edited) file: F = 2^24 and K = perByte x its
// size + extra (the size does not depend on K).
const keysPerByte = (perByte, extra) => () => {
  const make = (k) => content('CLIP', (b) => { dv(b).setUint32(0, 2 ** 24, true); dv(b).setBigUint64(24, k, true); }, Q5)();
  return make(perByte * BigInt(make(0n).length) + extra);
};
// A version 5 file from a 3.0 one: Major_Version 5 and an empty QUAT after SKEL.
const asVersion5 = (base, quatContent = new Uint8Array(4)) => edit(base, (m) => {
  m.header[8] = 5;
  m.sections.splice(2, 0, { tag: 'QUAT', flags: 0, content: quatContent });
});

const cases = {
  // signature, header, table
  'valid v3_rules': patch('v3_rules.kanim', () => {}),
  // The CLI tells a .kanim by its first bytes and calls anything else "not a .kanim file" (no
  // offset) before its loader sees it (a wrong signature); an empty file reaches the loader.
  'empty file': () => new Uint8Array(0),
  'half a signature': () => read('v3_rules.kanim').slice(0, 4),
  'bad signature': { make: patch('v3_rules.kanim', (b) => setU8(b, 3, 0x4f)), cpp: 'bad_signature', js: 'bad_signature @3' },
  'line-end conversion': patch('v3_rules.kanim', (b) => setU8(b, 4, 0x0a)),
  'header cut': () => read('v3_rules.kanim').slice(0, 20),
  'major version 4': patch('v3_rules.kanim', (b) => setU8(b, 8, 4)),
  'major version 0': patch('v3_rules.kanim', (b) => setU8(b, 8, 0)),
  'minor version 7 (accepted)': patch('v3_rules.kanim', (b) => setU8(b, 10, 7)),
  'reserved header flag': patch('v3_rules.kanim', (b) => setU8(b, 12, 1)),
  'unused header flag (accepted)': patch('v3_rules.kanim', (b) => setU8(b, 14, 1)),
  'header reserved': patch('v3_rules.kanim', (b) => setU8(b, 21, 1)),
  'table cut': () => read('v3_rules.kanim').slice(0, 60),
  'section count too high': patch('v3_rules.kanim', (b) => setU8(b, 16, 9)),
  'reserved section flag': patch('v3_rules.kanim', (b) => setU8(b, 24 + 24 * 2 + 4, 0x04)),
  'unused section flag (accepted)': patch('v3_rules.kanim', (b) => setU8(b, 24 + 24 * 2 + 6, 0x01)),
  'unknown critical section': withSection('v3_rules.kanim', (s) => [...s, { tag: 'XTRA', flags: 0, content: new Uint8Array(3) }]),
  'unknown ancillary section (accepted)': withSection('v3_rules.kanim', (s) => [s[0], { tag: 'XTRA', flags: 2, content: new Uint8Array(3) }, ...s.slice(1)]),
  'CLIP marked ancillary': edit('v3_rules.kanim', (m) => { m.sections[0].flags |= 2; }),
  'SKEL before CLIP': withSection('v3_rules.kanim', (s) => [s[1], s[0], ...s.slice(2)]),
  'CHAN twice': withSection('v3_rules.kanim', (s) => [...s.slice(0, 3), s[2], ...s.slice(3)]),
  'no KVAL': withSection('v3_rules.kanim', (s) => s.slice(0, 4)),
  'NOTE critical': edit('v3_single.kanim', (m) => { section(m, 'NOTE').flags = 0; }),
  'two NOTEs': withSection('v3_single.kanim', (s) => [...s, s.find((x) => x.tag === 'NOTE')]),
  'Raw_Size differs uncompressed': edit('v3_rules.kanim', (m) => { m.sections[4].rawSize = 75; }),
  'file one byte short': () => fixCrc(read('v3_rules.kanim').slice(0, -1)),
  'trailing byte': () => fixCrc(concat(read('v3_rules.kanim'), new Uint8Array(1))),
  'checksum': patch('v3_rules.kanim', (b) => { b[b.length - 1] ^= 1; }, false),
  'damaged key byte': patch('v3_rules.kanim', (b) => { b[b.length - 10] ^= 0x40; }, false),
  'raw sizes above 1 GiB': edit('v3_rules.kanim', (m) => { m.sections[1].rawSize = 2 ** 30 + 1; }),
  // zstd frames
  'compressed, not zstd': edit('v3_rules.kanim', (m) => { m.sections[1].stored = new Uint8Array(20); }),
  'zstd size not declared': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); m.sections[1].stored = concat(f.subarray(0, 4), [0x00, 0x00], f.subarray(7)); }),
  'zstd size differs': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); f[5] -= 1; m.sections[1].stored = f; }),
  'zstd trailing byte': edit('v3_rules.kanim', (m) => { m.sections[1].stored = concat(zstdRawFrame(m.sections[1].content), [0]); }),
  'zstd second frame': edit('v3_rules.kanim', (m) => { m.sections[1].stored = concat(zstdRawFrame(m.sections[1].content), zstdRawFrame(new Uint8Array(0))); }),
  'zstd skippable frame': edit('v3_rules.kanim', (m) => { m.sections[1].stored = concat([0x50, 0x2a, 0x4d, 0x18, 4, 0, 0, 0], new Uint8Array(4), zstdRawFrame(m.sections[1].content)); }),
  'zstd reserved bit': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); f[4] |= 8; m.sections[1].stored = f; }),
  'zstd block cut': edit('v3_rules.kanim', (m) => { m.sections[1].stored = zstdRawFrame(m.sections[1].content).slice(0, -3); }),
  'zstd reserved block type': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); f[6] |= 6; m.sections[1].stored = f; }),
  'zstd with checksum': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); f[4] |= 4; m.sections[1].stored = concat(f, [1, 2, 3, 4]); }),
  'zstd dictionary': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); m.sections[1].stored = concat(f.subarray(0, 4), [f[4] | 1, 7], f.subarray(5)); }),
  'zstd blocks too small for Raw_Size': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); f[5] += 5; m.sections[1].stored = f; m.sections[1].rawSize = m.sections[1].content.length + 5; }),
  'zstd compressed block damaged (KVAL)': () => { const b = read('v3_long.kanim').slice(); b[b.length - 4 - 86 - 100] ^= 0x5a; return fixCrc(b); },
  'zstd compressed block damaged (KTIM)': () => { const b = read('v3_long.kanim').slice(); b[353] ^= 0x21; return fixCrc(b); },
  'zstd block decodes to too much': () => { const b = read('v3_long.kanim').slice(); b[355] ^= 0x80; return fixCrc(b); },
  'zstd compressed block damaged (NOTE)': () => { const b = read('v3_long.kanim').slice(); b[b.length - 4 - 40] ^= 0x10; return fixCrc(b); },
  // CLIP
  'CLIP 33 bytes': content('CLIP', (b, m) => { section(m, 'CLIP').content = concat(b, [0]); }),
  'Frame_Count above 2^24': content('CLIP', (b) => dv(b).setUint32(0, 2 ** 24 + 1, true)),
  'Node_Count above limit': content('CLIP', (b) => dv(b).setUint32(4, 70000, true)),
  'Channel_Count above limit': content('CLIP', (b) => dv(b).setUint32(8, 300000, true)),
  'Tangent_Rule 2': content('CLIP', (b) => setU8(b, 12, 2)),
  'Clip_Flags': content('CLIP', (b) => setU8(b, 13, 1)),
  'Clip_Reserved': content('CLIP', (b) => setU8(b, 15, 1)),
  'Frame_Time NaN': content('CLIP', (b) => dv(b).setFloat64(16, NaN, true)),
  'Frame_Time negative': content('CLIP', (b) => dv(b).setFloat64(16, -1, true)),
  'Frame_Time 0 with 20 frames': content('CLIP', (b) => dv(b).setFloat64(16, 0, true)),
  'Key_Count above C x F': content('CLIP', (b) => dv(b).setBigUint64(24, 241n, true)),
  'Key_Count above limit': content('CLIP', (b) => dv(b).setBigUint64(24, 2n ** 40n, true)),
  // Spec section 8: at most 32768 keys a byte of the file (v3_rules: 522 bytes), refused as
  // CLIP is read; at the bound the rule lets the file through to CHAN's disagreeing key counts.
  'Key_Count beyond what the file can hold': content('CLIP', (b) => { dv(b).setUint32(0, 2 ** 24, true); dv(b).setBigUint64(24, 2n ** 27n, true); }),
  'Key_Count at what the file can hold': content('CLIP', (b) => { dv(b).setUint32(0, 2 ** 24, true); dv(b).setBigUint64(24, 32768n * BigInt(read('v3_rules.kanim').length), true); }),
  // A compressed section declaring more than 32768 bytes for each stored one: refused from the table.
  'Raw_Size beyond what its frame can make': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); m.sections[1].flags |= 1; m.sections[1].stored = f; m.sections[1].rawSize = 32768 * f.length + 1; }),
  // A NOTE above the note limit (16 MiB): refused from the table, before its frame is looked at.
  'NOTE above its limit': edit('v3_long.kanim', (m) => { section(m, 'NOTE').rawSize = 2 ** 24 + 1; }),
  'Raw_Size at what its frame can make': edit('v3_rules.kanim', (m) => { const f = zstdRawFrame(m.sections[1].content); m.sections[1].flags |= 1; m.sections[1].stored = f; m.sections[1].rawSize = 32768 * f.length; }),
  'Key_Count differs from CHAN': content('CLIP', (b) => dv(b).setBigUint64(24, 54n, true)),
  'Channel_Count differs from SKEL': content('CLIP', (b) => dv(b).setUint32(8, 13, true)),
  'Node_Count one less': content('CLIP', (b) => dv(b).setUint32(4, 4, true)),
  // SKEL
  'name past the end': skel((b, r, v) => v.setUint32(r[3].start, 1000, true)),
  'parent is itself': skel((b, r, v) => v.setInt32(r[1].parent, 1, true)),
  'parent -2': skel((b, r, v) => v.setInt32(r[1].parent, -2, true)),
  'parent is an End Site': skel((b, r, v) => v.setInt32(r[3].parent, 2, true)),
  'offset infinite': skel((b, r, v) => v.setFloat64(r[1].offset + 8, Infinity, true)),
  'reserved node flag': skel((b, r) => setU8(b, r[1].flags, 2)),
  'End Site without parent': skel((b, r, v) => v.setInt32(r[2].parent, -1, true)),
  'End Site with channels': skel((b, r) => { setU8(b, r[1].count, 0); setU8(b, r[2].flags, 1); }),
  '7 channels': skel((b, r) => setU8(b, r[0].count, 7)),
  'channel type 6': skel((b, r) => setU8(b, r[3].types + 1, 6)),
  'SKEL byte left over': content('SKEL', (b, m) => { section(m, 'SKEL').content = concat(b, [0]); }),
  // CHAN
  'CHAN one byte short': content('CHAN', (b, m) => { section(m, 'CHAN').content = b.slice(0, -1); }),
  'Interpolation 2': chan((b) => setU8(b, 4, 2)),
  'Tension 1.5': chan((b, v) => v.setFloat32(C + 4 * 5, 1.5, true)),
  'Tension NaN': chan((b, v) => v.setFloat32(C + 4 * 5, NaN, true)),
  'Step 0': chan((b, v) => v.setFloat64(5 * C + 8 * 6, 0, true)),
  'Step infinite': chan((b, v) => v.setFloat64(5 * C + 8 * 6, Infinity, true)),
  'Key_Count above F': chan((b, v) => v.setUint32(13 * C + 4 * 2, 21, true)),
  'Value_Coding 2': chan((b) => setU8(b, 17 * C + 3, 2)),
  'Residual_Bytes 9': chan((b) => setU8(b, 18 * C + 3, 9)),
  'Residual_Bytes on a channel without keys': chan((b, v) => { for (let c = 0; c < C; ++c) if (v.getUint32(13 * C + 4 * c, true) === 0) setU8(b, 18 * C + c, 1); }),
  // KTIM
  'over-long varint': content('KTIM', (b, m) => { section(m, 'KTIM').content = concat([b[0] | 0x80, 0x00], b.subarray(1)); }),
  'varint of 6 bytes': content('KTIM', (b, m) => { section(m, 'KTIM').content = concat([0x80, 0x80, 0x80, 0x80, 0x80, 0x00], b.subarray(1)); }),
  'varint above 2^32': content('KTIM', (b, m) => { section(m, 'KTIM').content = concat([0x80, 0x80, 0x80, 0x80, 0x10], b.subarray(1)); }),
  'key frame not below F': content('KTIM', (b) => setU8(b, b.length - 1, 30)),
  'KTIM byte left over': content('KTIM', (b, m) => { section(m, 'KTIM').content = concat(b, [0]); }),
  'KTIM cut': content('KTIM', (b, m) => { section(m, 'KTIM').content = concat(b.slice(0, -1), [0x81]); }),
  // KVAL
  'KVAL one byte short': content('KVAL', (b, m) => { section(m, 'KVAL').content = b.slice(0, -1); }),
  'residual above 2^57': content('KVAL', (b, m) => {
    const ch = section(m, 'CHAN').content, v = dv(ch);
    const c = [...Array(C).keys()].find((i) => v.getUint32(13 * C + 4 * i, true) > 0);  // first channel with keys
    const n = v.getUint32(13 * C + 4 * c, true);
    const residuals = splitResiduals(b, ch);
    setU8(ch, 18 * C + c, 8);
    residuals[c] = Array.from({ length: n }, (_, i) => (i === 0 ? 2n ** 59n : 0n));  // zigzag of 2^58
    section(m, 'KVAL').content = joinResiduals(residuals, ch);
  }),
  'quantized value above 2^53': content('KVAL', (b, m) => {
    const ch = section(m, 'CHAN').content;
    const residuals = splitResiduals(b, ch);
    const c = residuals.findIndex((r) => r.length >= 2);
    setU8(ch, 18 * C + c, 8);
    residuals[c] = residuals[c].map((_, i) => [2n ** 54n, 2n][i] ?? 0n);  // zigzag: q0 = 2^53, q1 = 2^53 + 1
    section(m, 'KVAL').content = joinResiduals(residuals, ch);
  }),
  'value not finite in binary32': edit('v3_rules.kanim', (m) => {
    const ch = section(m, 'CHAN').content, v = dv(ch);
    const c = [...Array(C).keys()].find((i) => v.getUint32(13 * C + 4 * i, true) > 1 && ch[18 * C + i] > 0);
    v.setFloat64(5 * C + 8 * c, 1e300, true);
  }),
  // version 5: QUAT (4.7), CHAN's and KTIM's rules for quaternion nodes (4.3, 4.4), limits (8)
  'valid v5_quat': patch(Q5, () => {}),
  'valid v5_blocks': patch('v5_blocks.kanim', () => {}),
  'major version 6': patch(Q5, (b) => setU8(b, 8, 6)),
  'v5 without QUAT': withSection(Q5, (s) => s.filter((x) => x.tag !== 'QUAT')),
  'v5 QUAT marked ancillary': edit(Q5, (m) => { section(m, 'QUAT').flags |= 2; }),
  'v5 QUAT after CHAN': withSection(Q5, (s) => [s[0], s[1], s[3], s[2], ...s.slice(4)]),
  'v5 QUAT twice': withSection(Q5, (s) => [...s.slice(0, 3), s[2], ...s.slice(3)]),
  'v3 with a QUAT section': withSection('v3_rules.kanim', (s) => [s[0], s[1], { tag: 'QUAT', flags: 0, content: new Uint8Array(4) }, ...s.slice(2)]),
  'v3 with an ancillary QUAT section (accepted)': withSection('v3_rules.kanim', (s) => [s[0], s[1], { tag: 'QUAT', flags: 2, content: new Uint8Array(3) }, ...s.slice(2)]),
  'v3_rules as 5.0 with no quaternion node (accepted)': asVersion5('v3_rules.kanim'),
  'v5 QUAT cut inside Quat_Count': asVersion5('v3_rules.kanim', new Uint8Array(3)),
  'v5 QUAT one byte short': quat((b, v, m) => { section(m, 'QUAT').content = b.slice(0, -1); }),
  'v5 QUAT one byte more': quat((b, v, m) => { section(m, 'QUAT').content = concat(b, [0]); }),
  'v5 Quat_Count above Node_Count': quat((b, v) => v.setUint32(0, 10, true)),
  'v5 Quat_Count one less': quat((b, v) => v.setUint32(0, 3, true)),
  // Q = 10 > N = 9 with the 10 entries it declares (the last six repeat Neck's): refused at Quat_Count.
  'v5 Quat_Count above Node_Count, with its entries': quat((b, v, m) => {
    const more = concat(b, ...Array.from({ length: 6 }, () => b.subarray(entry(3), entry(4))));
    dv(more).setUint32(0, 10, true);
    section(m, 'QUAT').content = more;
  }),
  'v5 QUAT nodes not increasing': quat((b) => { const a = b.slice(entry(0), entry(1)); b.copyWithin(entry(0), entry(1), entry(2)); b.set(a, entry(1)); }),
  'v5 QUAT a node twice': quat((b, v) => v.setUint32(entry(1), 1, true)),
  'v5 QUAT node not below Node_Count': quat((b, v) => v.setUint32(entry(3), 9, true)),
  'v5 QUAT node with rotation channels apart': quat((b, v) => v.setUint32(entry(3), 6, true)),
  'v5 QUAT node with two rotation channels': quat((b, v) => v.setUint32(entry(3), 7, true)),
  'v5 QUAT an End Site': quat((b, v) => v.setUint32(entry(3), 8, true)),
  // Head made Zrot Xrot Xrot Yrot: its first three rotations would do, but it has four.
  'v5 QUAT node with four rotation channels': edit(Q5, (m) => {
    const s = section(m, 'SKEL').content, r = skelRecords(s);
    assert.deepEqual(Array.from(s.subarray(r[6].types, r[6].types + 4)), [5, 0, 3, 4]);
    setU8(s, r[6].types + 1, 3);
    dv(section(m, 'QUAT').content).setUint32(entry(3), 6, true);
  }),
  'v5 QUAT node with two rotations about one axis': edit(Q5, (m) => {
    const s = section(m, 'SKEL').content, r = skelRecords(s);
    setU8(s, r[1].types + 2, 3);  // Chest: Zrot Xrot Xrot
  }),
  'v5 QUAT reference of norm 2^30 (accepted)': quat((b, v) => { v.setInt16(entry(3) + 4, -32768, true); v.setInt16(entry(3) + 6, 0, true); v.setInt16(entry(3) + 8, 0, true); }),
  'v5 QUAT reference above 2^30': quat((b, v) => { v.setInt16(entry(3) + 4, -32768, true); v.setInt16(entry(3) + 6, 1, true); v.setInt16(entry(3) + 8, 0, true); }),
  'v5 stored y of another Interpolation': chan5((b) => setU8(b, 7, b[7] ^ 1)),
  // keyanim's C++ names the channel's first CHAN field (its Interpolation) whichever differs;
  // section 7 asks for the offending field's offset, which this decoder gives.
  'v5 stored z of another Tension': {
    make: chan5((b, v) => v.setFloat32(C5 + 4 * 11, v.getFloat32(C5 + 4 * 11, true) === 0.5 ? 0.25 : 0.5, true)),
    cpp: `corrupt @${CHAN5}+11`, js: `corrupt @${CHAN5}+${C5 + 4 * 11}`,
  },
  'v5 stored z of Tension -0.0 (the x has +0.0)': {
    make: chan5((b, v) => { assert.ok(Object.is(v.getFloat32(C5 + 4 * 9, true), 0)); v.setFloat32(C5 + 4 * 11, -0, true); }),
    cpp: `corrupt @${CHAN5}+11`, js: `corrupt @${CHAN5}+${C5 + 4 * 11}`,
  },
  'v5 stored y of another Key_Count': {
    make: chan5((b, v) => {
      // Chest's y one key fewer and Hips' Xposition one more: CLIP's Key_Count still holds.
      v.setUint32(13 * C5 + 4 * 7, v.getUint32(13 * C5 + 4 * 7, true) - 1, true);
      v.setUint32(13 * C5, v.getUint32(13 * C5, true) + 1, true);
    }),
    cpp: `corrupt @${CHAN5}+7`, js: `corrupt @${CHAN5}+${13 * C5 + 4 * 7}`,
  },
  'v5 KTIM with one varint more': content('KTIM', (b, m) => { section(m, 'KTIM').content = concat(b, [0]); }, Q5),
  'v5 KTIM with one varint less': content('KTIM', (b, m) => { section(m, 'KTIM').content = b.slice(0, -1); }, Q5),
  // Spec section 8 in version 5: at most 98304 keys a byte of the file.
  'v5 Key_Count beyond what the file can hold': keysPerByte(98304n, 1n),
  'v5 Key_Count at what the file can hold': keysPerByte(98304n, 0n),
  // versions 1 and 2 (Appendix E)
  'valid v2_long': patch('v2_long.kanim', () => {}),
  'valid v1_long': patch('v1_long.kanim', () => {}),
  'v2 Plane_Count 11': content('KVAL', (b) => setU8(b, 0, 11), 'v2_rules.kanim'),
  'v2 plane 0 size': content('KVAL', (b) => dv(b).setUint32(1, dv(b).getUint32(1, true) - 1, true), 'v2_rules.kanim'),
  'v2 CHAN as v3': patch('v2_rules.kanim', (b) => setU8(b, 8, 3)),
  'v1 residual above 2^54': content('KVAL', (b, m) => {
    // v1_rules' KVAL: Plane_Count, sizes, planes. Replace all with one 9-byte varint first.
    const k = Number(dv(section(m, 'CLIP').content).getBigUint64(24, true));
    const big = [0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x80, 0x01];  // 2^56 -> zigzag 2^55
    const planes = [[big[0], ...new Array(k - 1).fill(0)], ...big.slice(1).map((x) => [x])];
    const head = new Uint8Array(1 + 4 * planes.length);
    head[0] = planes.length;
    planes.forEach((p, i) => dv(head).setUint32(1 + 4 * i, p.length, true));
    section(m, 'KVAL').content = concat(head, ...planes.map((p) => Uint8Array.from(p)));
  }, 'v1_rules.kanim'),
};

// 3.0 KVAL helpers: residual lists (zigzag values) per channel from the planes, and back.
function splitResiduals(kval, chanBytes) {
  const v = dv(chanBytes), counts = [], widths = [];
  for (let c = 0; c < C; ++c) { counts.push(v.getUint32(13 * C + 4 * c, true)); widths.push(chanBytes[18 * C + c]); }
  const cursor = [];
  for (let k = 0, at = 0; k < 8; ++k) { cursor.push(at); at += counts.reduce((s, n, c) => s + (widths[c] > k ? n : 0), 0); }
  return counts.map((n, c) => Array.from({ length: n }, () => {
    let z = 0n;
    for (let k = 0; k < widths[c]; ++k) z |= BigInt(kval[cursor[k]++]) << BigInt(8 * k);
    return z;
  }));
}
function joinResiduals(residuals, chanBytes) {
  const planes = Array.from({ length: 8 }, () => []);
  residuals.forEach((list, c) => list.forEach((z) => { for (let k = 0; k < chanBytes[18 * C + c]; ++k) planes[k].push(Number((z >> BigInt(8 * k)) & 255n)); }));
  return Uint8Array.from(planes.flat());
}

// In a compressed section, the byte of the decompressed content that the message names.
const atByte = (message) => { const m = /\(at byte (\d+) of the decompressed section\)/.exec(message); return m ? `+${m[1]}` : ''; };

function cppVerdict(file) {
  const r = spawnSync(keyanimCli, ['verify', file], { encoding: 'utf8' });
  if (r.status === 0) return 'ok';
  const m = /offset (\d+) \(0x[0-9A-Fa-f]+\): ([a-z_]+):/.exec(r.stderr);
  if (m) return `${m[2]} @${m[1]}${atByte(r.stderr)}`;
  // The CLI tells a .kanim by its signature before it loads anything.
  if (r.stderr.includes('not a .kanim file (bad signature)')) return 'bad_signature';
  return `exit ${r.status}: ${r.stderr.trim()}`;
}
function jsVerdict(bytes) {
  try { decodeKanim(bytes); return 'ok'; } catch (e) { return e.status ? `${e.status} @${e.offset}${atByte(e.message)}` : `exception ${e.message}`; }
}

const skip = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;
test('every damaged file: same status and offset as the C++ loader', { skip }, (t) => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-reject-'));
  t.after(() => fs.rmSync(dir, { recursive: true, force: true }));
  const mismatches = [];
  let rejected = 0;
  for (const [name, c] of Object.entries(cases)) {
    const bytes = (c.make ?? c)(), file = path.join(dir, 'case.kanim');
    fs.writeFileSync(file, bytes);
    let cpp = cppVerdict(file), js = jsVerdict(bytes);
    if (c.cpp) {  // a known, explained difference: both sides must still give what is stated
      if (cpp !== c.cpp || js !== c.js) mismatches.push(`${name}: expected C++ ${c.cpp} and JS ${c.js}, got C++ ${cpp}, JS ${js}`);
      ++rejected;
      continue;
    }
    if (name.includes('accepted') || name.startsWith('valid')) assert.equal(cpp, 'ok', `${name}: the C++ loader should accept it`);
    else if (cpp !== 'ok') ++rejected;
    if (process.env.KEYANIM_TEST_VERBOSE) console.log(`${name}: ${js}`);
    if (cpp !== js) mismatches.push(`${name}: C++ ${cpp}, JS ${js}`);
  }
  assert.deepEqual(mismatches, []);
  // Every case is rejected but those named as accepted (or valid), 'major version 4' (a 4.0
  // archive file is a 3.0 one) and the two damaged zstd blocks that still decode (KVAL, NOTE).
  const accepted = Object.keys(cases).filter((n) => n.includes('accepted') || n.startsWith('valid')).length;
  assert.ok(rejected >= Object.keys(cases).length - accepted - 3, `only ${rejected} cases rejected: the cases do not test what they say`);
});
