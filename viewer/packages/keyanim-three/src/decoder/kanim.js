// The .kanim decoder, written from spec/FORMAT.md alone: container (sections 1-3), the CLIP,
// SKEL, QUAT, CHAN, KTIM and NOTE sections (4), the checks of sections 5-8, in the order
// section 7 recommends. Archive files of versions 3.0, 4.0 and 5.0 (quaternion nodes, 4.7:
// quat-nodes.js) and, by Appendix E, 1.0 and 2.0; runtime files of 4.0 and 5.0 (section 9:
// table rules in table-rules.js, IMAG in imag.js); a bank's members (section 10.5: decodeClip
// with the bank's skeleton and dictionary; banks: bank.js). Key values: kval.js; sampling
// (Appendix A): sample.js; rotations (4.7, Appendix B): rotation.js.
import { fail, KanimError } from './errors.js';
import { SectionReader } from './reader.js';
import { crc32 } from './crc32.js';
import { xxh64 } from './xxh64.js';
import { archiveRules, runtimeRules } from './table-rules.js';
import { decodeImage } from './imag.js';
import { decompressSection, isZstdFailure } from './zstd.js';
import { decodeKeyValues } from './kval.js';
import { parseQuat } from './quat-nodes.js';

export { KanimError };

const SIGNATURE = [0x89, 0x4b, 0x41, 0x4e, 0x0d, 0x0a, 0x1a, 0x0a];
export const CHANNEL_TYPES = ['Xposition', 'Yposition', 'Zposition', 'Xrotation', 'Yrotation', 'Zrotation'];
export const MAX_FRAMES_V3 = 2 ** 24;

// Spec section 8, limits that follow from the file's size: no zstd frame makes more than 32768
// bytes of each of its bytes (a 4-byte RLE block makes 128 KiB at most, the best any block
// does), and a key takes a byte of KTIM at least (a third of one in version 5, where a
// quaternion node's three keys at a frame share a varint). So a compressed section holds at
// most 32768 times its Stored_Size, and a file of N bytes at most 32768 N keys (98304 N in
// version 5): counts beyond are refused as they are read, before anything is inflated or
// allocated, with the status a later step would give (zstd_error, corrupt).
export const MAX_ZSTD_EXPANSION = 32768;
export const MAX_KEYS_PER_FILE_BYTE = MAX_ZSTD_EXPANSION;
const maxKeysPerFileByte = (major) => (major >= 5 ? 3 : 1) * MAX_KEYS_PER_FILE_BYTE;

// keyanim's defaults (spec section 8).
export const DEFAULT_LIMITS = Object.freeze({
  nodes: 65536, channels: 262144, frames: 2 ** 24, keys: 268435456, rawBytes: 2 ** 30, noteBytes: 2 ** 24,
});

// True when the bytes start like a .kanim file (the signature), for telling it from a BVH.
export function looksLikeKanim(bytes) {
  return bytes.length >= 8 && SIGNATURE.every((b, i) => bytes[i] === b);
}

// How keyanim's tools name node i: its name, or "End Site of PARENT" for an unnamed End Site.
export function nodeLabel(nodes, i) {
  const n = nodes[i];
  if (!n.endSite || n.name !== '') return n.name;
  return n.parent >= 0 ? `End Site of ${nodes[n.parent].name}` : 'End Site';
}

// Decodes and validates a whole file. Returns the clip (see makeClip) or throws KanimError.
export function decodeKanim(input, limits = DEFAULT_LIMITS) {
  return decodeClip(input instanceof Uint8Array ? input : new Uint8Array(input), limits, null);
}

// A file by itself (member null) or a bank's member (spec 10.5; bank.js): member is { runtime,
// skel: the bank's skeleton's content, skelOffset: where its stored bytes lie relative to the
// member's first byte, skelCompressed, dictionary: readDictionary's, or null, major: the bank's
// Major_Version }.
export function decodeClip(bytes, limits, member) {
  const { version, profile, sections } = readContainer(bytes, limits, member);
  const clip = makeClip(version, profile, bytes.length, sections);
  const parsers = parsersOf(profile, version.major);
  for (const s of parseOrder(withMemberSkeleton(sections, profile, member), profile)) {
    const parse = parsers[s.tag];
    if (!parse) continue;  // an ancillary section of a later minor version
    parse(new SectionReader(s.tag, s.content ?? sectionContent(bytes, s, member?.dictionary), s.offset, s.compressed), clip, limits);
  }
  if (profile === 'runtime') nameChannels(clip);
  return clip;
}

// A member's skeleton is read as its SKEL (10.5.3), where SKEL would lie: after CLIP in the
// archive profile (3.2.3), after IMAG in the runtime profile (9.1.1).
function withMemberSkeleton(sections, profile, member) {
  if (!member) return sections;
  const at = profile === 'runtime' ? 2 : 1;
  const skel = { tag: 'SKEL', content: member.skel, offset: member.skelOffset, compressed: member.skelCompressed };
  return [...sections.slice(0, at), skel, ...sections.slice(at)];
}

// Sections are parsed in table order, but in the runtime profile SKEL before IMAG (section 7):
// in version 5 IMAG's quaternion nodes are checked against the skeleton (9.4).
function parseOrder(sections, profile) {
  if (profile !== 'runtime') return sections;
  const skel = sections.findIndex((s) => s.tag === 'SKEL'), imag = sections.findIndex((s) => s.tag === 'IMAG');
  if (skel < 0 || imag < 0 || skel < imag) return sections;
  const out = sections.slice();
  [out[imag], out[skel]] = [out[skel], out[imag]];
  return out;
}

// profile: 'archive' (sections 2-8) or 'runtime' (section 9); either gives the same clip.
// quatNodes (version 5, 4.7): the quaternion nodes in node order, { node, column: the channel of
// its stored x, reference: [X, Y, Z] (integers), r: the reference as a unit quaternion [x, y, z,
// w] }; the same object is that node's `quaternion` (null for every other node).
function makeClip(version, profile, fileBytes, sections) {
  return {
    version, profile, fileBytes,
    sections: sections.map(({ tag, compressed, storedSize, rawSize }) => ({ tag, compressed, storedSize, rawSize })),
    frameCount: 0, frameTime: 0, tangentRule: 0, nodeCount: 0, channelCount: 0, keyCount: 0,
    nodes: [], channels: [], quatNodes: [], notes: '',
  };
}

// --- Signature, header, section table, file length, raw-size limit, checksum ---------------

function readContainer(bytes, limits, member) {
  for (let i = 0; i < 8; ++i) {
    if (i >= bytes.length) fail('truncated', 'signature', bytes.length, 'the file ends inside the signature');
    if (bytes[i] !== SIGNATURE[i]) fail('bad_signature', 'signature', i, 'not a .kanim file (wrong signature)');
  }
  if (bytes.length < 24) fail('truncated', 'header', bytes.length, 'the file ends inside the header');
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const major = view.getUint16(8, true), minor = view.getUint16(10, true);
  if (major < 1 || major > 5) fail('unsupported_version', 'header', 8, `major version ${major} (this decoder reads versions 1 to 5)`);
  const flags = view.getUint32(12, true);
  checkHeaderFlags(major, flags, member);
  const profile = major >= 4 && (flags & 1) ? 'runtime' : 'archive';
  const checksumBytes = profile === 'runtime' ? 8 : 4;  // XXH64 (9.1.3) or CRC-32 (3.3)
  const count = view.getUint32(16, true);
  if (view.getUint32(20, true) !== 0) fail('reserved_bits_set', 'header', 20, 'Header_Reserved is not 0');
  const tableEnd = 24 + 24 * count;
  if (bytes.length < tableEnd) fail('truncated', 'section table', bytes.length, `the file ends inside the table of ${count} sections`);

  const parsers = parsersOf(profile, major);
  const rules = profile === 'runtime' ? runtimeRules(!!member, major) : archiveRules(!!member, major);
  const sections = readTable(bytes, view, count, rules, checksumBytes);
  checkLength(bytes.length, tableEnd, sections, checksumBytes);
  let raw = member ? BigInt(member.skel.length) : 0n;  // a member's skeleton counts as its SKEL (10.5.3)
  if (raw > BigInt(limits.rawBytes)) fail('limit_exceeded', 'section table', 24, `the bank's skeleton of ${raw} bytes is above the limit of ${limits.rawBytes}`);
  for (const s of sections) {
    if (parsers[s.tag]) raw += s.rawSize;
    if (raw > BigInt(limits.rawBytes)) fail('limit_exceeded', 'section table', s.entry + 16, `the sections decode to ${raw} bytes or more, above the limit of ${limits.rawBytes}`);
    if (s.tag === 'NOTE' && s.rawSize > BigInt(limits.noteBytes ?? DEFAULT_LIMITS.noteBytes)) fail('limit_exceeded', 'section table', s.entry + 16, `NOTE declares ${s.rawSize} bytes, above the limit of ${limits.noteBytes ?? DEFAULT_LIMITS.noteBytes} (notes are informative text)`);
  }
  sections.forEach((s, i) => {
    if (parsers[s.tag] && s.compressed && s.rawSize > BigInt(MAX_ZSTD_EXPANSION) * s.storedSize)
      fail('zstd_error', 'section table', s.entry + 16, `section ${i} (${s.tag}): Raw_Size ${s.rawSize} is more than its ${s.storedSize} stored bytes can make (a zstd frame makes at most ${MAX_ZSTD_EXPANSION} bytes of each)`);
  });
  checkChecksum(bytes, view, profile);
  return { version: { major, minor }, profile, sections };
}

// Bit 0 Runtime in versions 4 and 5 (spec 2.2); bit 1 Member and bit 2 Bank from 4.1 on (10.2,
// 10.5): a member only in its bank, a bank never as a clip; bits 3-15 reserved (0-15 before 4).
// A bank's member is of its bank's major version or a lower one (10.5).
function checkHeaderFlags(major, flags, member) {
  if (flags & (major >= 4 ? 0xfff8 : 0xffff)) fail('reserved_bits_set', 'header', 12, 'reserved Header_Flags bits are set');
  if (major < 4) return;
  if (!member && flags & 4) fail('invalid_argument', 'header', 12, 'a bank of many clips (spec section 10), not a clip: open it as a bank (openBank)');
  if (!member && flags & 2) fail('corrupt', 'header', 12, "a bank's member (Header_Flags bit 1), which only its bank reads");
  if (member && (!(flags & 2) || flags & 4)) fail('corrupt', 'header', 12, "a bank's clip must have Header_Flags bit 1 (Member) set and bit 2 (Bank) clear");
  if (member && (flags & 1) !== (member.runtime ? 1 : 0)) fail('corrupt', 'header', 12, "a bank's clips are of the bank's profile (Header_Flags bit 0)");
  if (member && major > (member.major ?? 4)) fail('corrupt', 'header', 8, `a clip of version ${major} in a bank of version ${member.major ?? 4} (a member's major version is at most its bank's)`);
}

const hex = (v, digits) => v.toString(16).padStart(digits, '0');

function checkChecksum(bytes, view, profile) {
  if (profile === 'runtime') {
    const at = bytes.length - 8, stored = view.getBigUint64(at, true), computed = xxh64(bytes.subarray(0, at));
    if (stored !== computed) fail('checksum_mismatch', 'checksum', at, `XXH64 is 0x${hex(computed, 16)}, the file says 0x${hex(stored, 16)}`);
    return;
  }
  const at = bytes.length - 4, stored = view.getUint32(at, true), computed = crc32(bytes.subarray(0, at));
  if (stored !== computed) fail('checksum_mismatch', 'checksum', at, `CRC-32 is 0x${hex(computed, 8)}, the file says 0x${hex(stored, 8)}`);
}

function tagName(b) {
  const printable = [...b].every((c) => c >= 0x20 && c < 0x7f);
  return printable ? String.fromCharCode(...b) : [...b].map((c) => c.toString(16).padStart(2, '0')).join(' ');
}

// Section 3.1 and rules 3.2.2 to 3.2.4 (9.1.1 in the runtime profile: `rules`), entry by entry.
function readTable(bytes, view, count, rules, checksumBytes) {
  const sections = [];
  let offset = 24n + 24n * BigInt(count);
  for (let i = 0; i < count; ++i) {
    const e = 24 + 24 * i;
    const tag = tagName(bytes.subarray(e, e + 4));
    const where = `section ${i} (${tag})`;
    const flags = view.getUint32(e + 4, true);
    if (flags & 0xfffc) fail('reserved_bits_set', 'section table', e + 4, `${where}: reserved Section_Flags bits are set`);
    const compressed = (flags & 1) !== 0, ancillary = (flags & 2) !== 0;
    rules.entry({ index: i, tag, compressed, ancillary, entry: e, where });
    const storedSize = view.getBigUint64(e + 8, true), rawSize = view.getBigUint64(e + 16, true);
    if (!compressed && rawSize !== storedSize) fail('corrupt', 'section table', e + 8, `${where}: Raw_Size ${rawSize} differs from Stored_Size ${storedSize} in an uncompressed section`);
    sections.push({ tag, compressed, ancillary, storedSize, rawSize, offset, entry: e });
    offset += storedSize;
    if (offset + BigInt(checksumBytes) > BigInt(bytes.length)) fail('truncated', 'section table', bytes.length, `${where}: the file ends before the section's declared end`);
  }
  rules.end();
  return sections;
}

// Rule 3.2.1: the file is exactly 28 + 24 n + the stored sizes (32 + ... in the runtime
// profile, 9.1.3; BigInt: no overflow).
function checkLength(length, tableEnd, sections, checksumBytes) {
  const want = sections.reduce((sum, s) => sum + s.storedSize, BigInt(tableEnd) + BigInt(checksumBytes));
  if (BigInt(length) < want) fail('truncated', 'section table', length, `the file holds ${length} bytes, the table declares ${want}`);
  if (BigInt(length) > want) fail('trailing_bytes', 'checksum', Number(want), `${BigInt(length) - want} bytes follow the checksum`);
  for (const s of sections) s.offset = Number(s.offset);
}

function sectionContent(bytes, s, dictionary) {
  const stored = bytes.subarray(s.offset, s.offset + Number(s.storedSize));
  if (!s.compressed) return stored;
  try {
    return decompressSection(stored, Number(s.rawSize), dictionary ?? null);
  } catch (e) {
    if (isZstdFailure(e)) fail('zstd_error', `section ${s.tag}`, s.offset, e.message);
    throw e;
  }
}

// --- Sections -------------------------------------------------------------------------------

function parseClip(r, clip, limits) {
  if (r.length !== 32) r.fail('corrupt', 0, `CLIP holds ${r.length} bytes, not 32`);
  const v3 = clip.version.major >= 3;  // 3.0, 4.0 and 5.0 (both profiles)
  const frames = r.u32();
  if (v3 && frames > MAX_FRAMES_V3) r.fail('corrupt', 0, `Frame_Count ${frames} is above 2^24`);
  if (frames > limits.frames) r.fail('limit_exceeded', 0, `Frame_Count ${frames} is above the limit of ${limits.frames}`);
  const nodes = r.u32();
  if (nodes > limits.nodes) r.fail('limit_exceeded', 4, `Node_Count ${nodes} is above the limit of ${limits.nodes}`);
  const channels = r.u32();
  if (channels > limits.channels) r.fail('limit_exceeded', 8, `Channel_Count ${channels} is above the limit of ${limits.channels}`);
  const rule = r.u8();
  if (rule > 1) r.fail('reserved_bits_set', 12, `reserved Tangent_Rule ${rule}`);
  if (r.u8() !== 0) r.fail('reserved_bits_set', 13, 'reserved Clip_Flags bits are set');
  if (r.u16() !== 0) r.fail('reserved_bits_set', 14, 'Clip_Reserved is not 0');
  const frameTime = r.f64();
  if (!Number.isFinite(frameTime) || frameTime < 0) r.fail('corrupt', 16, `Frame_Time ${frameTime} is not finite and >= 0`);
  if (frames > 1 && !(frameTime > 0)) r.fail('corrupt', 16, `Frame_Time is 0 with ${frames} frames`);
  const keys = r.u64();
  if (keys > BigInt(limits.keys)) r.fail('limit_exceeded', 24, `Key_Count ${keys} is above the limit of ${limits.keys}`);
  const perByte = maxKeysPerFileByte(clip.version.major);
  if (keys > BigInt(perByte) * BigInt(clip.fileBytes)) r.fail('corrupt', 24, `Key_Count ${keys} is more than a file of ${clip.fileBytes} bytes can hold (at most ${perByte} keys a byte: a key takes ${perByte > MAX_KEYS_PER_FILE_BYTE ? 'a third of ' : ''}a byte of KTIM at least, and zstd makes at most ${MAX_ZSTD_EXPANSION} bytes of each)`);
  if (keys > BigInt(channels) * BigInt(frames)) r.fail('corrupt', 24, `Key_Count ${keys} is above Channel_Count x Frame_Count`);
  Object.assign(clip, { frameCount: frames, nodeCount: nodes, channelCount: channels, tangentRule: rule, frameTime, keyCount: Number(keys) });
}

const NODE_MIN_BYTES = 34;  // Name_Length, Parent, Offset, Node_Flags, Node_Channel_Count

function parseSkel(r, clip) {
  const n = clip.nodeCount;
  if (n * NODE_MIN_BYTES > r.length) r.fail('corrupt', 0, `SKEL is too short for ${n} nodes`);
  const names = new TextDecoder('utf-8');  // names are shown, never compared as bytes here
  let channelSum = 0;
  for (let i = 0; i < n; ++i) {
    const start = r.pos, what = `node ${i}`;
    const nameLength = r.u32(`${what}: Name_Length`);
    if (nameLength > r.remaining) r.fail('corrupt', start, `${what}: the name runs past the end of SKEL`);
    const name = names.decode(r.take(nameLength));
    const parentAt = r.pos, parent = r.i32(`${what}: Parent`);
    if (parent < -1 || parent >= i) r.fail('corrupt', parentAt, `${what}: Parent ${parent} is not -1 or an earlier node`);
    if (parent >= 0 && clip.nodes[parent].endSite) r.fail('corrupt', parentAt, `${what}: its parent ${parent} is an End Site`);
    const offset = [];
    for (let k = 0; k < 3; ++k) {
      const at = r.pos, v = r.f64(`${what}: Offset`);
      if (!Number.isFinite(v)) r.fail('corrupt', at, `${what}: Offset ${'XYZ'[k]} is not finite`);
      offset.push(v);
    }
    const flagsAt = r.pos, flags = r.u8(`${what}: Node_Flags`);
    if (flags & 0xfe) r.fail('reserved_bits_set', flagsAt, `${what}: reserved Node_Flags bits are set`);
    const endSite = (flags & 1) !== 0;
    if (endSite && parent < 0) r.fail('corrupt', parentAt, `${what}: an End Site without a parent`);
    const countAt = r.pos, count = r.u8(`${what}: Node_Channel_Count`);
    if (count > 6) r.fail('corrupt', countAt, `${what}: ${count} channels (at most 6)`);
    if (endSite && count > 0) r.fail('corrupt', countAt, `${what}: an End Site with channels`);
    const channels = [];
    for (let k = 0; k < count; ++k) {
      const at = r.pos, type = r.u8(`${what}: Channel_Types`);
      if (type > 5) r.fail('reserved_bits_set', at, `${what}: reserved channel type ${type}`);
      channels.push(type);
    }
    clip.nodes.push({ name, parent, offset, endSite, channels, firstChannel: channelSum, quaternion: null });
    channelSum += count;
  }
  r.expectEnd(`the ${n} node records`);
  if (channelSum !== clip.channelCount) r.fail('corrupt', 0, `the nodes have ${channelSum} channels, CLIP says ${clip.channelCount}`);
}

function parseChan(r, clip) {
  const c = clip.channelCount, major = clip.version.major;
  const perChannel = { 1: 17, 2: 18, 3: 19, 4: 19, 5: 19 }[major];
  if (r.length !== perChannel * c) r.fail('corrupt', 0, `CHAN holds ${r.length} bytes, not ${perChannel} x ${c}`);
  const channels = [];
  clip.nodes.forEach((node, n) => node.channels.forEach((type) => channels.push({ node: n, type })));
  const each = (fn) => channels.forEach((ch, i) => fn(ch, i, r.pos));
  each((ch, i, at) => {
    ch.interp = r.u8();
    if (ch.interp > 1) r.fail('reserved_bits_set', at, `channel ${i}: reserved Interpolation ${ch.interp}`);
  });
  each((ch, i, at) => {
    ch.tension = r.f32();
    if (!(ch.tension >= -1 && ch.tension <= 1)) r.fail('corrupt', at, `channel ${i}: Tension ${ch.tension} is not in [-1, 1]`);
  });
  each((ch, i, at) => {
    ch.step = r.f64();
    if (!(Number.isFinite(ch.step) && ch.step > 0)) r.fail('corrupt', at, `channel ${i}: Step ${ch.step} is not finite and > 0`);
  });
  let keys = 0;
  each((ch, i, at) => {
    ch.keyCount = r.u32();
    if (ch.keyCount > clip.frameCount) r.fail('corrupt', at, `channel ${i}: Key_Count ${ch.keyCount} is above Frame_Count ${clip.frameCount}`);
    keys += ch.keyCount;
  });
  each((ch, i, at) => {
    ch.valueCoding = major >= 2 ? r.u8() : 0;
    if (ch.valueCoding > 1) r.fail('reserved_bits_set', at, `channel ${i}: reserved Value_Coding ${ch.valueCoding}`);
  });
  if (major >= 3) {
    each((ch, i, at) => {
      ch.residualBytes = r.u8();
      if (ch.residualBytes > 8) r.fail('corrupt', at, `channel ${i}: Residual_Bytes ${ch.residualBytes} (at most 8)`);
      if (ch.keyCount === 0 && ch.residualBytes !== 0) r.fail('corrupt', at, `channel ${i}: Residual_Bytes ${ch.residualBytes} for a channel without keys`);
    });
  }
  if (keys !== clip.keyCount) r.fail('corrupt', 13 * c, `the channels have ${keys} keys, CLIP says ${clip.keyCount}`);
  checkQuatChannels(r, clip, channels);
  clip.channels = channels;
}

// Version 5 (4.3): a quaternion node's stored x, y, z have one Interpolation, one Tension (the
// same bits) and one Key_Count; reported at the y's or z's entry that differs from the x's.
function checkQuatChannels(r, clip, channels) {
  const c = clip.channelCount, bits = new DataView(new ArrayBuffer(4));
  const tensionBits = (t) => { bits.setFloat32(0, t, true); return bits.getUint32(0, true); };
  const arrays = [
    ['Interpolation', (ch) => ch.interp, (k) => k],
    ['Tension', (ch) => tensionBits(ch.tension), (k) => c + 4 * k],
    ['Key_Count', (ch) => ch.keyCount, (k) => 13 * c + 4 * k],
  ];
  for (const q of clip.quatNodes) {
    for (const [name, get, at] of arrays) {
      for (const k of [q.column + 1, q.column + 2]) {
        if (get(channels[k]) !== get(channels[q.column])) r.fail('corrupt', at(k), `channel ${k}: its ${name} differs from channel ${q.column}'s, and both are stored x, y, z of quaternion node ${q.node} (4.3)`);
      }
    }
  }
}

// Version 5 (4.4): a quaternion node's stored y and z have no varints; their key frames are its
// stored x's (the same array). KF, the key frame count, is K without their keys.
function parseKtim(r, clip) {
  const shared = new Map();  // channel -> the channel whose key frames it shares
  for (const q of clip.quatNodes) { shared.set(q.column + 1, q.column); shared.set(q.column + 2, q.column); }
  let frameCount = clip.keyCount;
  for (const c of shared.keys()) frameCount -= clip.channels[c].keyCount;
  if (frameCount > r.length) r.fail('corrupt', 0, `KTIM is too short for ${frameCount} key frames`);
  clip.channels.forEach((ch, c) => {
    if (shared.has(c)) { ch.keyFrames = clip.channels[shared.get(c)].keyFrames; return; }
    const frames = new Int32Array(ch.keyCount);
    let prev = -1;
    for (let i = 0; i < ch.keyCount; ++i) {
      const at = r.pos, gap = r.varint(5, 32, `channel ${c} key ${i}`);
      const frame = prev + 1 + gap;  // exact: below 2^33
      if (frame >= clip.frameCount) r.fail('corrupt', at, `channel ${c} key ${i}: frame ${frame} is not below Frame_Count ${clip.frameCount}`);
      frames[i] = prev = frame;
    }
    ch.keyFrames = frames;
  });
  r.expectEnd(`the ${frameCount} key frames`);
}

function parseNote(r, clip) {
  clip.notes = new TextDecoder('utf-8').decode(r.bytes);
}

// IMAG (9.2) comes before SKEL: it fills clip.channels without their nodes, named here.
function nameChannels(clip) {
  clip.nodes.forEach((node, n) => node.channels.forEach((type, k) => Object.assign(clip.channels[node.firstChannel + k], { node: n, type })));
}

// The sections each profile decodes (and counts for rule 3.2.6); any other is skipped. QUAT is
// a section of version 5 only: before, it is an unknown tag (3.2.3).
const PARSERS = {
  archive: { CLIP: parseClip, SKEL: parseSkel, CHAN: parseChan, KTIM: parseKtim, KVAL: decodeKeyValues, NOTE: parseNote },
  archive5: { CLIP: parseClip, SKEL: parseSkel, QUAT: parseQuat, CHAN: parseChan, KTIM: parseKtim, KVAL: decodeKeyValues, NOTE: parseNote },
  runtime: { CLIP: parseClip, IMAG: decodeImage, SKEL: parseSkel, NOTE: parseNote },
};
const parsersOf = (profile, major) => PARSERS[profile === 'archive' && major >= 5 ? 'archive5' : profile];
