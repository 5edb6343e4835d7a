// Banks (spec/FORMAT.md section 10, versions 4.1 and 5.0): many clips in one file, each distinct
// skeleton once; a bank of version 5 may hold clips of version 5 (quaternion nodes). openBank checks the index (10.1 to 10.4, in the order keyanim does: header, where every
// part lies, the bank's checksum, then names, name order and dictionary) without reading any
// member; decodeBankClip decodes one member (10.5) into the clip decodeKanim makes of a file, so
// that a damaged clip is refused by name while the others still decode.
import { fail, KanimError } from './errors.js';
import { xxh64 } from './xxh64.js';
import { decodeClip, DEFAULT_LIMITS, MAX_ZSTD_EXPANSION, looksLikeKanim } from './kanim.js';
import { decompressSection, isZstdFailure } from './zstd.js';
import { readDictionary } from './zstd-blocks.js';

const HEADER = 40, SKELETON_ENTRY = 32, CLIP_ENTRY = 40, ORDER_ENTRY = 4, CHECKSUM = 8;
const MAX_NAME_BYTES = 1024;
const DICTIONARY_MAGIC = 0xec30a437;  // RFC 8878 section 5
const SIGNATURE = [0x89, 0x4b, 0x41, 0x4e, 0x0d, 0x0a, 0x1a, 0x0a];  // as a file's (2.1)

const next8 = (end) => Math.ceil(end / 8) * 8;  // "the next multiple of 8" (10.1)

// True when the bytes start like a bank: the signature, and Header_Flags bit 2 (10.2).
export function looksLikeBank(bytes) {
  return looksLikeKanim(bytes) && bytes.length >= 16 && (bytes[12] & 4) !== 0;
}

// Opens and checks a bank's index. Returns { version, profile, byteLength, skeletonCount,
// dictionaryBytes, clips: [{ index, name, frameCount, frameTime, duration, skeleton, offset,
// size }] (in clip-table order) } or throws KanimError. Its clips decode with decodeBankClip.
export function openBank(input, limits = DEFAULT_LIMITS) {
  const bytes = input instanceof Uint8Array ? input : new Uint8Array(input);
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const h = readHeader(bytes, view);
  const layout = indexLayout(h, bytes.length);
  const skeletons = placeSkeletons(bytes, view, h, layout);
  const clips = placeClips(bytes, view, h, layout, skeletons.checksumAt);
  checkBankChecksum(bytes, view, skeletons.checksumAt);
  const names = readNames(bytes, view, h, layout, clips);
  checkNameOrder(bytes, view, h, layout, names);
  const dictionary = readBankDictionary(bytes, layout, h);
  const contents = inflateSkeletons(bytes, skeletons.entries, limits);
  return {
    version: { major: h.major, minor: h.minor }, profile: h.runtime ? 'runtime' : 'archive', byteLength: bytes.length,
    skeletonCount: h.skeletons, dictionaryBytes: Number(h.dictionarySize), order: names.order,
    clips: clips.map((c, i) => ({ ...c, name: names.text[i], duration: c.frameCount > 1 ? (c.frameCount - 1) * c.frameTime : 0 })),
    [BANK]: { bytes, view, major: h.major, runtime: h.runtime, dictionary, skeletons: skeletons.entries, contents, names: names.bytes },
  };
}

const BANK = Symbol('keyanim bank internals');

// --- 10.2 Header ------------------------------------------------------------------------------

function readHeader(bytes, view) {
  for (let i = 0; i < 8; ++i) {
    if (i >= bytes.length) fail('truncated', 'signature', bytes.length, 'the file ends inside the signature');
    if (bytes[i] !== SIGNATURE[i]) fail('bad_signature', 'signature', i, 'not a keyanim bank (wrong signature)');
  }
  if (bytes.length < HEADER) fail('truncated', 'bank header', bytes.length, 'the file ends inside the bank header');
  const major = view.getUint16(8, true), minor = view.getUint16(10, true), flags = view.getUint32(12, true);
  if (!(flags & 4)) fail('invalid_argument', 'bank header', 12, 'a file of one clip, not a bank (Header_Flags bit 2 is clear): open it as a clip');
  if (major !== 4 && major !== 5) fail('unsupported_version', 'bank header', 8, `major version ${major} (banks are versions 4 and 5, section 10)`);
  if (flags & 0xfff8) fail('reserved_bits_set', 'bank header', 12, 'reserved Header_Flags bits are set');
  if (flags & 2) fail('corrupt', 'bank header', 12, "a bank's header has Header_Flags bit 1 (Member) set");
  const runtime = (flags & 1) !== 0;
  const namesSize = view.getBigUint64(24, true), dictionarySize = view.getBigUint64(32, true);
  if (runtime && dictionarySize !== 0n) fail('corrupt', 'bank header', 32, 'a runtime-profile bank has no dictionary (Dictionary_Size must be 0)');
  return { major, minor, runtime, clips: view.getUint32(16, true), skeletons: view.getUint32(20, true), namesSize, dictionarySize };
}


// --- 10.1 Layout --------------------------------------------------------------------------------

// Where the index's parts start, from the header's counts; the tables and names must fit in the
// file before anything they size is allocated (a bank of N bytes has fewer than N / 44 clips).
// Numbers: 40 + 32 (2^32 - 1) + 44 (2^32 - 1) is below 2^38, exact; sizes are compared as BigInt.
function indexLayout(h, size) {
  const clipTable = HEADER + SKELETON_ENTRY * h.skeletons;
  const nameOrder = clipTable + CLIP_ENTRY * h.clips;
  const names = nameOrder + ORDER_ENTRY * h.clips;
  const tooBig = () => fail('truncated', 'bank header', size, `the file ends inside the index of ${h.clips} clips, ${h.skeletons} skeletons, ${h.namesSize} bytes of names and ${h.dictionarySize} of dictionary`);
  if (names > size || h.namesSize > BigInt(size - names)) tooBig();
  const namesEnd = names + Number(h.namesSize), dictionary = next8(namesEnd);
  if (dictionary > size || h.dictionarySize > BigInt(size - dictionary)) tooBig();
  return { clipTable, nameOrder, names, namesEnd, dictionary, dictionaryEnd: dictionary + Number(h.dictionarySize) };
}

const isZero = (bytes, from, to) => bytes.subarray(from, to).every((b) => b === 0);

// A part of the table entry at `at` (Offset, then a size), placed at the next multiple of 8
// after `end`; returns its end. Offsets and sizes are u64: compared as BigInt, then Numbers.
function place(bytes, view, at, end, table, what, size, checkPadding) {
  const offset = view.getBigUint64(at, true), want = next8(end);
  if (offset !== BigInt(want)) fail('corrupt', table, at, `${what}: Offset ${offset}, not ${want} (each part starts at the next multiple of 8 after the one before)`);
  if (want > bytes.length || size > BigInt(bytes.length - want)) fail('truncated', table, at + 8, `${what}: the file ends before its ${size} bytes`);
  if (checkPadding && !isZero(bytes, end, want)) fail('corrupt', 'padding', end, `${what}: the padding before it is not zero`);
  return want + Number(size);
}

// Skeleton entries (10.3): flags, sizes, placement. Returns the entries and where the bank's
// checksum lies.
function placeSkeletons(bytes, view, h, layout) {
  if (!isZero(bytes, layout.namesEnd, layout.dictionary)) fail('corrupt', 'padding', layout.namesEnd, 'the padding after the names is not zero');
  let end = layout.dictionaryEnd;
  const entries = [];
  for (let s = 0; s < h.skeletons; ++s) {
    const at = HEADER + SKELETON_ENTRY * s, what = `skeleton ${s}`;
    const stored = view.getBigUint64(at + 8, true), raw = view.getBigUint64(at + 16, true);
    end = place(bytes, view, at, end, 'skeleton table', what, stored, true);
    const flags = view.getUint32(at + 24, true);
    if (flags & 0xfffe || view.getUint32(at + 28, true) !== 0) fail('reserved_bits_set', 'skeleton table', at + 24, `${what}: reserved Skeleton_Flags bits or Skeleton_Reserved set`);
    const compressed = (flags & 1) !== 0;
    if (stored === 0n || raw === 0n) fail('corrupt', 'skeleton table', at + 8, `${what}: size 0 (a skeleton is a SKEL section's content)`);
    if (!compressed && raw !== stored) fail('corrupt', 'skeleton table', at + 16, `${what}: uncompressed, but Raw_Size ${raw} differs from Stored_Size ${stored}`);
    if (compressed && raw > BigInt(MAX_ZSTD_EXPANSION) * stored) fail('zstd_error', 'skeleton table', at + 16, `${what}: Raw_Size ${raw} is more than its ${stored} stored bytes can make (a zstd frame makes at most ${MAX_ZSTD_EXPANSION} bytes of each)`);
    entries.push({ entry: at, offset: end - Number(stored), stored: Number(stored), raw, compressed });
  }
  const checksumAt = next8(end);
  if (checksumAt + CHECKSUM > bytes.length) fail('truncated', 'bank checksum', bytes.length, "the file ends before the bank's checksum");
  if (!isZero(bytes, end, checksumAt)) fail('corrupt', 'padding', end, 'the padding before the checksum is not zero');
  return { entries, checksumAt };
}

// Clip entries: placement after the checksum (their padding is checked as each is decoded),
// and the file's end. Returns each clip's fields (names come later, after the checksum).
function placeClips(bytes, view, h, layout, checksumAt) {
  let end = checksumAt + CHECKSUM;
  const clips = [];
  for (let i = 0; i < h.clips; ++i) {
    const at = layout.clipTable + CLIP_ENTRY * i;
    const size = view.getBigUint64(at + 8, true);
    end = place(bytes, view, at, end, 'clip table', `clip table entry ${i}`, size, false);
    clips.push({ index: i, entry: at, offset: end - Number(size), size: Number(size), frameTime: view.getFloat64(at + 16, true), frameCount: view.getUint32(at + 24, true), skeleton: view.getUint32(at + 28, true) });
  }
  if (end !== bytes.length) fail('trailing_bytes', 'bank', end, `${bytes.length - end} bytes after the last clip`);
  return clips;
}

// 10.4: the XXH64 of every byte before it, checked before any name or skeleton is read.
function checkBankChecksum(bytes, view, at) {
  const stored = view.getBigUint64(at, true), computed = xxh64(bytes.subarray(0, at));
  if (stored !== computed) fail('checksum_mismatch', 'bank checksum', at, `XXH64 of the bank's header, index, dictionary and skeletons is 0x${computed.toString(16).padStart(16, '0')}, the bank says 0x${stored.toString(16).padStart(16, '0')}`);
}

// --- 10.3 Names ---------------------------------------------------------------------------------

// Why a name breaks 10.3's rules, or '' (bytes: a Uint8Array).
export function bankNameProblem(name) {
  if (name.length < 1 || name.length > MAX_NAME_BYTES) return `Name_Size must be 1 to ${MAX_NAME_BYTES}`;
  if (name.includes(0)) return 'a name holds no byte 0';
  let from = 0;
  for (let i = 0; i <= name.length; ++i) {
    if (i < name.length && name[i] !== 0x2f) continue;
    const part = name.subarray(from, i);
    if (part.length === 0 || (part[0] === 0x2e && (part.length === 1 || (part.length === 2 && part[1] === 0x2e))))
      return "no part of a name between '/' is empty, '.' or '..'";
    from = i + 1;
  }
  return '';
}

function readNames(bytes, view, h, layout, clips) {
  const pool = bytes.subarray(layout.names, layout.namesEnd), utf8 = new TextDecoder('utf-8');
  const raw = clips.map((c) => {
    const at = c.entry;
    if (c.skeleton >= h.skeletons) fail('corrupt', 'clip table', at + 28, `clip ${c.index}: skeleton ${c.skeleton} of ${h.skeletons}`);
    const offset = view.getUint32(at + 32, true), size = view.getUint32(at + 36, true);
    if (offset > pool.length || size > pool.length - offset) fail('corrupt', 'clip table', at + 32, `clip ${c.index}: its name lies outside the name pool`);
    const name = pool.subarray(offset, offset + size), problem = bankNameProblem(name);
    if (problem) fail('corrupt', 'clip table', at + 32, `clip ${c.index}: ${problem}`);
    return name;
  });
  return { bytes: raw, text: raw.map((n) => utf8.decode(n)) };
}

// Byte-wise unsigned comparison; a name before every longer name it begins.
export function compareNames(a, b) {
  const n = Math.min(a.length, b.length);
  for (let i = 0; i < n; ++i) if (a[i] !== b[i]) return a[i] - b[i];
  return a.length - b.length;
}

function checkNameOrder(bytes, view, h, layout, names) {
  const listed = new Uint8Array(h.clips), order = new Uint32Array(h.clips);
  for (let k = 0; k < h.clips; ++k) {
    const at = layout.nameOrder + ORDER_ENTRY * k, i = view.getUint32(at, true);
    if (i >= h.clips || listed[i]) fail('corrupt', 'name order', at, 'the name order must list every clip once');
    listed[i] = 1;
    order[k] = i;
    if (k > 0) {
      const c = compareNames(names.bytes[order[k - 1]], names.bytes[i]);
      if (c >= 0) fail('corrupt', 'name order', at, `names must be in strictly increasing order (clip ${i}${c === 0 ? ': a second clip of its name)' : ')'}`);
    }
  }
  names.order = order;
}

// --- 10.4 Dictionary, 10.3 skeletons ------------------------------------------------------------

function readBankDictionary(bytes, layout, h) {
  if (h.dictionarySize === 0n) return null;
  const dict = bytes.subarray(layout.dictionary, layout.dictionaryEnd);
  const magic = dict.length >= 4 ? new DataView(dict.buffer, dict.byteOffset, 4).getUint32(0, true) : 0;
  if (dict.length < 8 || magic !== DICTIONARY_MAGIC) fail('corrupt', 'dictionary', layout.dictionary, 'not a zstd dictionary (RFC 8878 section 5)');
  try {
    return readDictionary(dict);  // digested once for all the bank's clips
  } catch (e) {
    if (isZstdFailure(e)) fail('zstd_error', 'dictionary', layout.dictionary, e.message);
    throw e;
  }
}

// Every skeleton's content, inflated once (without the dictionary, 10.3) after their sizes'
// sum is compared with the limit of decompressed bytes.
function inflateSkeletons(bytes, entries, limits) {
  let total = 0n;
  for (const k of entries) {
    total += k.raw;
    if (total > BigInt(limits.rawBytes)) fail('limit_exceeded', 'skeleton table', k.entry + 16, `the bank's skeletons decode to ${total} bytes or more, above the limit of ${limits.rawBytes}`);
  }
  return entries.map((k, s) => {
    const stored = bytes.subarray(k.offset, k.offset + k.stored);
    if (!k.compressed) return stored;
    try {
      return decompressSection(stored, Number(k.raw));
    } catch (e) {
      if (isZstdFailure(e)) fail('zstd_error', 'skeleton', k.offset, `skeleton ${s}: ${e.message}`);
      throw e;
    }
  });
}

// --- 10.5 Members -------------------------------------------------------------------------------

// The index of the clip named `name` (a string, compared as its UTF-8 bytes), or -1: a binary
// search over the name order.
export function findBankClip(bank, name) {
  const key = new TextEncoder().encode(name), names = bank[BANK].names;
  let lo = 0, hi = bank.order.length;
  while (lo < hi) {
    const mid = (lo + hi) >> 1, c = compareNames(names[bank.order[mid]], key);
    if (c === 0) return bank.order[mid];
    if (c < 0) lo = mid + 1; else hi = mid;
  }
  return -1;
}

// Clip i of the bank as decodeKanim makes a file's clip (with clip.bank = { name, index }), or
// a KanimError naming the clip, at offsets from the bank's first byte.
export function decodeBankClip(bank, i, limits = DEFAULT_LIMITS) {
  const c = bank.clips[i];
  if (!c) throw new RangeError(`the bank has no clip ${i} (${bank.clips.length} clips)`);
  const b = bank[BANK], label = `clip ${JSON.stringify(c.name)} (#${i})`;
  try {
    // The padding before the member (10.1): the checksum's end is a multiple of 8, so clip 0 has none.
    const end = i === 0 ? c.offset : bank.clips[i - 1].offset + bank.clips[i - 1].size;
    if (!isZero(b.bytes, end, c.offset)) fail('corrupt', 'padding', end, `clip table entry ${i}: the padding before it is not zero`);
    const k = b.skeletons[c.skeleton];
    const member = { major: b.major, runtime: b.runtime, skel: b.contents[c.skeleton], skelOffset: k.offset - c.offset, skelCompressed: k.compressed, dictionary: b.dictionary };
    const clip = inMember(c.offset, () => decodeClip(b.bytes.subarray(c.offset, c.offset + c.size), limits, member));
    if (clip.frameCount !== c.frameCount) fail('corrupt', 'clip table', c.entry + 24, `Frame_Count ${c.frameCount}, the clip's CLIP says ${clip.frameCount}`);
    if (!sameBits(clip.frameTime, c.frameTime)) fail('corrupt', 'clip table', c.entry + 16, `Frame_Time ${c.frameTime}, the clip's CLIP says ${clip.frameTime}`);
    clip.bank = { name: c.name, index: i };
    return clip;
  } catch (e) {
    if (e instanceof KanimError) throw new KanimError(e.status, `${label}: ${e.where}`, e.offset, e.detail);
    throw e;
  }
}

// A member's errors at offsets from the bank's first byte (10.5).
function inMember(base, decode) {
  try {
    return decode();
  } catch (e) {
    if (e instanceof KanimError) throw new KanimError(e.status, e.where, e.offset + base, e.detail);
    throw e;
  }
}

function sameBits(a, b) {
  const v = new DataView(new ArrayBuffer(16));
  v.setFloat64(0, a, true);
  v.setFloat64(8, b, true);
  return v.getBigUint64(0, true) === v.getBigUint64(8, true);
}
