// Banks (spec section 10) in the JS decoder, against keyanim's C++ side: banks packed by the
// CLI from data/*.bvh (and one clip again under a folder, so that two clips share a skeleton),
// archive without and with a dictionary and runtime (version 5.0: clips with quaternion nodes),
// and archive with --rotations euler (version 4.1): the clips' names, frames, frame times,
// skeletons and sizes equal `keyanim list --json`; every clip samples as `keyanim sample
// BANK:NAME --json` (bit for bit, but a quaternion node's Euler angles within a binary32 ulp:
// channels.mjs), and decodes to the same clip as its own file from `keyanim unpack`. Then banks
// that each break one rule of 10.1 to 10.5, refused with the status and offset that `keyanim
// list` (the bank) or `keyanim verify BANK:NAME` (a clip) give.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync, spawnSync } from 'node:child_process';
import { decodeKanim, nodeLabel, CHANNEL_TYPES } from 'keyanim-three/decoder/kanim.js';
import { openBank, decodeBankClip, findBankClip, looksLikeBank } from 'keyanim-three/decoder/bank.js';
import { sampleChannels } from 'keyanim-three/decoder/sample.js';
import { expectChannels } from './channels.mjs';
import { xxh64 } from 'keyanim-three/decoder/xxh64.js';
import { crc32 } from 'keyanim-three/decoder/crc32.js';
import { keyanimCli, sourceDir, exists } from './paths.mjs';

const skip = exists(keyanimCli) ? false : `no keyanim CLI at ${keyanimCli}`;
const cli = (...args) => execFileSync(keyanimCli, args, { maxBuffer: 1 << 28, encoding: 'utf8' });
const KINDS = { archive: ['--dictionary', 'off'], dictionary: ['--dictionary', 'on'], runtime: ['--runtime'], euler: ['--dictionary', 'off', '--rotations', 'euler'] };
const VERSION = { archive: '5.0', dictionary: '5.0', runtime: '5.0', euler: '4.1' };

let dir;
const banks = {};  // kind -> { file, bytes }
before(() => {
  if (skip) return;
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-bank-'));
  const input = path.join(dir, 'in');
  fs.mkdirSync(path.join(input, 'again'), { recursive: true });
  for (const f of ['cmu_02_01_walk.bvh', 'cmu_131_03_hop.bvh']) fs.copyFileSync(path.join(sourceDir, 'data', f), path.join(input, f));
  fs.copyFileSync(path.join(sourceDir, 'data/cmu_02_01_walk.bvh'), path.join(input, 'again/walk.bvh'));
  for (const [kind, args] of Object.entries(KINDS)) {
    const file = path.join(dir, `${kind}.kbank`);
    cli('pack', input, '-o', file, '-q', ...args);
    banks[kind] = { file, bytes: new Uint8Array(fs.readFileSync(file)) };
  }
});
after(() => dir && fs.rmSync(dir, { recursive: true, force: true }));

// `keyanim sample --json` channel values in frame-column order.
function cliChannels(clip, json) {
  const byName = new Map(json.joints.map((j) => [j.name, j]));
  return clip.nodes.flatMap((n, i) => n.channels.map((t) => byName.get(nodeLabel(clip.nodes, i))[CHANNEL_TYPES[t]]));
}

// What a clip is made of, for comparing two decodings of it.
const essence = (c) => ({
  frames: c.frameCount, frameTime: c.frameTime, rule: c.tangentRule, notes: c.notes,
  nodes: c.nodes.map((n) => [n.name, n.parent, n.offset, n.endSite, n.channels]),
  quatNodes: c.quatNodes.map((q) => [q.node, q.reference]),
  channels: c.channels.map((ch) => [ch.interp, ch.tension, Array.from(ch.keyFrames), Array.from(ch.values)]),
});

for (const kind of Object.keys(KINDS)) {
  test(`${kind} bank: its clips as keyanim list --json lists them`, { skip }, () => {
    const { file, bytes } = banks[kind];
    const bank = openBank(bytes), want = JSON.parse(cli('list', file, '--json'));
    assert.ok(looksLikeBank(bytes));
    assert.equal(`${bank.version.major}.${bank.version.minor}`, VERSION[kind]);
    assert.equal(bank.profile, want.profile);
    assert.equal(bank.skeletonCount, want.skeletons);
    assert.equal(bank.dictionaryBytes, want.dictionary_bytes);
    if (kind === 'dictionary') assert.ok(bank.dictionaryBytes > 0, 'packed with --dictionary on');
    assert.equal(bank.skeletonCount, 2, 'the walk twice shares a skeleton');
    assert.deepEqual(bank.clips.map((c) => ({ index: c.index, name: c.name, frames: c.frameCount, skeleton: c.skeleton, bytes: c.size })),
      want.clips.map((c) => ({ index: c.index, name: c.name, frames: c.frames, skeleton: c.skeleton, bytes: c.bytes })));
    bank.clips.forEach((c, i) => {
      // list prints 8 significant digits of the frame time and duration
      assert.ok(Math.abs(c.frameTime - want.clips[i].frame_time) <= 1e-7 * c.frameTime, `${c.name}: frame time`);
      assert.ok(Math.abs(c.duration - want.clips[i].duration) <= 1e-6 * c.duration, `${c.name}: duration`);
      assert.equal(findBankClip(bank, c.name), i);
    });
    assert.equal(findBankClip(bank, 'no such clip'), -1);
    assert.ok(bank.clips.some((c) => c.name === 'again/walk'));
  });

  test(`${kind} bank: every clip samples as keyanim sample BANK:NAME, and is its unpacked file's clip`, { skip }, () => {
    const { file, bytes } = banks[kind];
    const bank = openBank(bytes), out = path.join(dir, `unpacked-${kind}`);
    cli('unpack', file, '-o', out, '-q');
    for (const c of bank.clips) {
      const clip = decodeBankClip(bank, c.index);
      assert.equal(clip.profile, bank.profile);
      assert.deepEqual(clip.bank, { name: c.name, index: c.index });
      assert.equal(clip.version.major, kind === 'euler' ? 4 : 5, 'the CLI stores rotations as quaternions unless told otherwise');
      assert.equal(clip.quatNodes.length > 0, kind !== 'euler');
      const F = clip.frameCount;
      for (const x of [0, 0.37, F / 3 + 0.123, F - 1.5, F - 1]) {
        const want = cliChannels(clip, JSON.parse(cli('sample', `${file}:${c.name}`, '--frame', String(x), '--json')));
        expectChannels(clip, sampleChannels(clip, x), want, `${c.name} frame ${x}`, 'binary32');
      }
      const own = decodeKanim(fs.readFileSync(path.join(out, `${c.name}.kanim`)));
      assert.deepEqual(essence(clip), essence(own), c.name);
    }
  });
}

// Spec 9: both profiles hold the same clip (the quaternion nodes and their references too).
test('the runtime bank\'s clips are the archive bank\'s', { skip }, () => {
  const archive = openBank(banks.archive.bytes), runtime = openBank(banks.runtime.bytes);
  for (const c of archive.clips) {
    const a = decodeBankClip(archive, c.index), r = decodeBankClip(runtime, findBankClip(runtime, c.name));
    assert.ok(a.quatNodes.length > 0, c.name);
    assert.deepEqual(essence(r), essence(a), c.name);
  }
});

test('a dictionary bank\'s members have sections compressed with the dictionary', { skip }, () => {
  // Otherwise the test above would not reach the dictionary decoder (zstd-blocks.js).
  const bank = openBank(banks.dictionary.bytes);
  const clip = decodeBankClip(bank, 0);
  assert.ok(clip.sections.some((s) => s.compressed), clip.sections.map((s) => s.tag).join());
  assert.deepEqual(clip.sections.map((s) => s.tag).slice(0, 5), ['CLIP', 'QUAT', 'CHAN', 'KTIM', 'KVAL'], 'a member holds no SKEL');
});

test('a bank is not a clip, a clip not a bank, and a member alone is refused', { skip }, () => {
  const bytes = banks.archive.bytes;
  assert.throws(() => decodeKanim(bytes), (e) => e.status === 'invalid_argument' && /open it as a bank/.test(e.message));
  const kanim = new Uint8Array(fs.readFileSync(path.join(dir, 'unpacked-archive', 'cmu_02_01_walk.kanim')));
  assert.throws(() => openBank(kanim), (e) => e.status === 'invalid_argument' && /not a bank/.test(e.message));
  const bank = openBank(bytes), c = bank.clips[0];
  const member = bytes.slice(c.offset, c.offset + c.size);
  assert.throws(() => decodeKanim(member), (e) => e.status === 'corrupt' && e.where === 'header' && e.offset === 12);
});

// --- Rejections ---------------------------------------------------------------------------------

const dv = (b) => new DataView(b.buffer, b.byteOffset, b.byteLength);
// Where things lie, read here from the bytes by the spec (10.1), not by the decoder.
function layoutOf(b) {
  const v = dv(b), clips = v.getUint32(16, true), skeletons = v.getUint32(20, true);
  const clipTable = 40 + 32 * skeletons, nameOrder = clipTable + 40 * clips, names = nameOrder + 4 * clips;
  const clip = (i) => { const e = clipTable + 40 * i; return { entry: e, offset: Number(v.getBigUint64(e, true)), size: Number(v.getBigUint64(e + 8, true)), nameOffset: v.getUint32(e + 32, true), nameSize: v.getUint32(e + 36, true) }; };
  const checksumAt = clip(0).offset - 8;  // members follow the checksum, the first at once
  const dictionary = Math.ceil((names + Number(v.getBigUint64(24, true))) / 8) * 8;
  return { clips, skeletons, clipTable, nameOrder, names, clip, checksumAt, dictionary };
}
const fixBank = (b) => { const L = layoutOf(b); dv(b).setBigUint64(L.checksumAt, xxh64(b.subarray(0, L.checksumAt)), true); return b; };
// A member's own checksum (3.3, or 9.1.3 in a runtime bank) after a patch of its bytes.
function fixMember(b, i, runtime) {
  const c = layoutOf(b).clip(i), m = b.subarray(c.offset, c.offset + c.size);
  if (runtime) dv(m).setBigUint64(m.length - 8, xxh64(m.subarray(0, m.length - 8)), true);
  else dv(m).setUint32(m.length - 4, crc32(m.subarray(0, m.length - 4)), true);
  return b;
}
const patched = (kind, fn) => Object.assign(() => { const b = banks[kind].bytes.slice(); fn(b, dv(b), layoutOf(b)); return b; }, { kind });

// Each case: the bytes; `clip` (a name) when the bank opens and that clip is refused, the
// others decoding (or, with everyClip, refused as well); what the JS decoder must say: status,
// where, offset.
const cases = {
  'cut inside the header': { make: () => banks.archive.bytes.slice(0, 30), status: 'truncated', where: 'bank header', offset: 30 },
  'cut inside the index': { make: () => banks.archive.bytes.slice(0, 200), status: 'truncated', where: 'bank header', offset: 200 },
  'cut inside the last clip': { make: () => { const b = banks.archive.bytes; return b.slice(0, b.length - 5); }, status: 'truncated', where: 'clip table', offset: (L) => L.clip(L.clips - 1).entry + 8 },
  'a byte after the last clip': { make: () => Uint8Array.from([...banks.archive.bytes, 0]), status: 'trailing_bytes', where: 'bank', offset: (L, b) => b.length - 1 },
  'a wrong Bank_Checksum': { make: patched('archive', (b, v, L) => { b[L.checksumAt] ^= 1; }), status: 'checksum_mismatch', where: 'bank checksum', offset: (L) => L.checksumAt },
  'a name byte changed (the checksum not fixed)': { make: patched('archive', (b, v, L) => { b[L.names] ^= 0x20; }), status: 'checksum_mismatch', where: 'bank checksum', offset: (L) => L.checksumAt },
  '2^32 - 1 clips declared': { make: patched('archive', (b, v) => v.setUint32(16, 0xffffffff, true)), status: 'truncated', where: 'bank header', offset: (L, b) => b.length },
  '2^32 - 1 skeletons declared': { make: patched('archive', (b, v) => v.setUint32(20, 0xffffffff, true)), status: 'truncated', where: 'bank header', offset: (L, b) => b.length },
  'Names_Size 2^64 - 1': { make: patched('archive', (b, v) => v.setBigUint64(24, 2n ** 64n - 1n, true)), status: 'truncated', where: 'bank header', offset: (L, b) => b.length },
  'major version 6': { make: patched('archive', (b) => { b[8] = 6; }), status: 'unsupported_version', where: 'bank header', offset: 8 },
  'major version 3': { make: patched('euler', (b) => { b[8] = 3; }), status: 'unsupported_version', where: 'bank header', offset: 8 },
  'a reserved Header_Flags bit': { make: patched('archive', (b) => { b[12] |= 8; }), status: 'reserved_bits_set', where: 'bank header', offset: 12 },
  'the Member bit in a bank header': { make: patched('archive', (b) => { b[12] |= 2; }), status: 'corrupt', where: 'bank header', offset: 12 },
  'a clip Offset one off': { make: patched('archive', (b, v, L) => { v.setBigUint64(L.clip(1).entry, BigInt(L.clip(1).offset + 8), true); fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(1).entry },
  'a skeleton reserved flag': { make: patched('archive', (b) => { b[40 + 24] |= 2; fixBank(b); }), status: 'reserved_bits_set', where: 'skeleton table', offset: 40 + 24 },
  'a runtime bank with a dictionary size': { make: patched('runtime', (b, v) => v.setBigUint64(32, 8n, true)), status: 'corrupt', where: 'bank header', offset: 32 },
  'a name with a ".." part': { make: patched('archive', (b, v, L) => { const c = L.clip(0); b.set([0x2e, 0x2e, 0x2f], L.names + c.nameOffset); fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(0).entry + 32 },
  'a name with an empty part': { make: patched('archive', (b, v, L) => { const c = L.clip(0); b[L.names + c.nameOffset] = 0x2f; fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(0).entry + 32 },
  'a name with a byte 0': { make: patched('archive', (b, v, L) => { const c = L.clip(0); b[L.names + c.nameOffset + 2] = 0; fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(0).entry + 32 },
  'Name_Size 0': { make: patched('archive', (b, v, L) => { v.setUint32(L.clip(0).entry + 36, 0, true); fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(0).entry + 32 },
  'a name outside the pool': { make: patched('archive', (b, v, L) => { v.setUint32(L.clip(0).entry + 32, 1 << 20, true); fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(0).entry + 32 },
  'two clips of one name': { make: patched('archive', (b, v, L) => { const c = L.clip(0), e = L.clip(1).entry; v.setUint32(e + 32, c.nameOffset, true); v.setUint32(e + 36, c.nameSize, true); fixBank(b); }), status: 'corrupt', where: 'name order', offset: 'order of clip 1' },
  'the name order not increasing': { make: patched('archive', (b, v, L) => { const a = v.getUint32(L.nameOrder, true); v.setUint32(L.nameOrder, v.getUint32(L.nameOrder + 4, true), true); v.setUint32(L.nameOrder + 4, a, true); fixBank(b); }), status: 'corrupt', where: 'name order', offset: (L) => L.nameOrder + 4 },
  'a clip listed twice in the name order': { make: patched('archive', (b, v, L) => { v.setUint32(L.nameOrder + 4, v.getUint32(L.nameOrder, true), true); fixBank(b); }), status: 'corrupt', where: 'name order', offset: (L) => L.nameOrder + 4 },
  'a skeleton index out of range': { make: patched('archive', (b, v, L) => { v.setUint32(L.clip(1).entry + 28, 2, true); fixBank(b); }), status: 'corrupt', where: 'clip table', offset: (L) => L.clip(1).entry + 28 },
  'a dictionary without its magic number': { make: patched('dictionary', (b, v, L) => { b[L.dictionary] ^= 1; fixBank(b); }), status: 'corrupt', where: 'dictionary', offset: (L) => L.dictionary },
  // Members: the bank opens, the clip is refused by name, the others decode.
  'a damaged member': { make: patched('dictionary', (b, v, L) => { const c = L.clip(1); b[c.offset + (c.size >> 1)] ^= 0x10; }), clip: 1, status: 'checksum_mismatch', where: 'checksum', offset: (L) => L.clip(1).offset + L.clip(1).size - 4 },
  'a damaged runtime member': { make: patched('runtime', (b, v, L) => { const c = L.clip(1); b[c.offset + (c.size >> 1)] ^= 0x10; }), clip: 1, status: 'checksum_mismatch', where: 'checksum', offset: (L) => L.clip(1).offset + L.clip(1).size - 8 },
  'a member without the Member bit': { make: patched('archive', (b, v, L) => { b[L.clip(1).offset + 12] &= ~2; fixMember(b, 1, false); }), clip: 1, status: 'corrupt', where: 'header', offset: (L) => L.clip(1).offset + 12 },
  'an archive member in a runtime bank': { make: patched('runtime', (b, v, L) => { b[L.clip(0).offset + 12] &= ~1; fixMember(b, 0, true); }), clip: 0, status: 'corrupt', where: 'header', offset: (L) => L.clip(0).offset + 12 },
  'Frame_Count of the clip table one more': { make: patched('archive', (b, v, L) => { const e = L.clip(1).entry + 24; v.setUint32(e, v.getUint32(e, true) + 1, true); fixBank(b); }), clip: 1, status: 'corrupt', where: 'clip table', offset: (L) => L.clip(1).entry + 24 },
  'Frame_Time of the clip table doubled': { make: patched('runtime', (b, v, L) => { const e = L.clip(0).entry + 16; v.setFloat64(e, 2 * v.getFloat64(e, true), true); fixBank(b); }), clip: 0, status: 'corrupt', where: 'clip table', offset: (L) => L.clip(0).entry + 16 },
  // 10.5: a member's major version is at most its bank's (the version 5.0 bank made 4.1).
  'a member of version 5 in a bank of version 4': { make: patched('archive', (b) => { b[8] = 4; b[10] = 1; fixBank(b); }), clip: 0, status: 'corrupt', where: 'header', offset: (L) => L.clip(0).offset + 8, everyClip: true },
  'a non-zero padding byte before a member': { make: patched('archive', (b, v, L) => { const prev = L.clip(0), gap = L.clip(1).offset - (prev.offset + prev.size); assert.ok(gap > 0, 'the members leave padding'); b[prev.offset + prev.size] = 1; }), clip: 1, status: 'corrupt', where: 'padding', offset: (L) => L.clip(0).offset + L.clip(0).size },
};

const resolve = (c, b) => {
  const L = layoutOf(banks[c.make.kind ?? 'archive'].bytes);  // the bank the case was made from
  const offset = c.offset === 'order of clip 1' ? L.nameOrder + 4 * [...Array(L.clips).keys()].findIndex((k) => dv(b).getUint32(L.nameOrder + 4 * k, true) === 1) : typeof c.offset === 'function' ? c.offset(L, b) : c.offset;
  return offset;
};

for (const [name, c] of Object.entries(cases)) {
  test(`bank rejected: ${name}`, { skip }, () => {
    const b = c.make(), offset = resolve(c, b);
    const expect = (e) => {
      assert.equal(e.name, 'KanimError', e.stack);
      assert.deepEqual({ status: e.status, offset: e.offset }, { status: c.status, offset }, e.message);
      assert.ok(e.where.endsWith(c.where), e.message);
      return true;
    };
    if (c.clip === undefined) { assert.throws(() => openBank(b), expect); return; }
    const bank = openBank(b), label = bank.clips[c.clip].name;
    assert.throws(() => decodeBankClip(bank, c.clip), (e) => expect(e) && e.where.startsWith(`clip ${JSON.stringify(label)} (#${c.clip})`));
    if (c.everyClip) return;  // the others are refused too
    for (const other of bank.clips.filter((o) => o.index !== c.clip)) assert.equal(decodeBankClip(bank, other.index).frameCount, other.frameCount, `${other.name} still decodes`);
  });
}

// 10.5 the other way: members of version 4 in a bank of version 5.0 (the 4.1 bank relabelled) decode.
test('a bank of version 5.0 whose members are of version 4 opens, and its clips decode', { skip }, () => {
  const b = banks.euler.bytes.slice();
  b[8] = 5; b[10] = 0;
  fixBank(b);
  const bank = openBank(b), file = path.join(dir, 'relabelled.kbank');
  assert.deepEqual(bank.version, { major: 5, minor: 0 });
  fs.writeFileSync(file, b);
  for (const c of bank.clips) {
    assert.equal(decodeBankClip(bank, c.index).version.major, 4);
    assert.equal(spawnSync(keyanimCli, ['verify', `${file}:${c.name}`], { encoding: 'utf8' }).status, 0, `keyanim verify ${c.name}`);
  }
});

// The C++ side on the same bytes: `keyanim list` opens the bank, `keyanim verify BANK:NAME`
// reads a clip; both print "offset N (0x...): status:".
test('keyanim list / verify give the same status and offset on every case', { skip }, () => {
  const mismatches = [];
  for (const [name, c] of Object.entries(cases)) {
    const b = c.make(), offset = resolve(c, b), file = path.join(dir, 'case.kbank');
    fs.writeFileSync(file, b);
    let target = file;
    if (c.clip !== undefined) target = `${file}:${openBank(b).clips[c.clip].name}`;
    const r = spawnSync(keyanimCli, c.clip === undefined ? ['list', target] : ['verify', target], { encoding: 'utf8' });
    const m = /offset (\d+) \(0x[0-9A-Fa-f]+\): ([a-z_]+):/.exec(r.stderr);
    const cpp = r.status === 0 ? 'ok' : m ? `${m[2]} @${m[1]}` : `exit ${r.status}: ${r.stderr.trim()}`;
    const want = `${c.status} @${offset}`;
    if (cpp !== want) mismatches.push(`${name}: C++ ${cpp}, expected ${want} (JS ${c.status} @${offset})`);
  }
  assert.deepEqual(mismatches, []);
});
