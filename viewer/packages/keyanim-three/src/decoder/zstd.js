// A compressed section (spec 3.2 rule 5): exactly one zstd frame (RFC 8878) that declares its
// content size, equal to Raw_Size, and decompresses to exactly that with nothing left over.
// The frame's structure is checked here, before anything is allocated; the blocks are then
// decoded by fzstd, or, for a frame made with a bank's dictionary (spec 10.4), which fzstd does
// not support, by zstd-blocks.js. Failures throw a ZstdFailure for the caller to report as
// zstd_error.
import { Decompress } from 'fzstd';
import { xxh64Low32 } from './xxh64.js';
import { bad, isZstdFailure } from './zstd-failure.js';
import { decodeBlocks } from './zstd-blocks.js';

export { isZstdFailure };

const MAGIC = 0xfd2fb528;
const BLOCK_MAX = 128 * 1024;

function readLE(bytes, at, n) {
  let v = 0;
  for (let i = 0; i < n; ++i) v += bytes[at + i] * 2 ** (8 * i);
  return v;  // n <= 8: exact below 2^53, which covers every size this decoder accepts
}

// Frame header (RFC 8878 3.1.1.1). Returns where the blocks start and the header's fields.
function readFrameHeader(frame) {
  if (frame.length < 5) bad('the zstd frame header is cut short');
  const magic = readLE(frame, 0, 4);
  if ((magic & 0xfffffff0) >>> 0 === 0x184d2a50) bad('a skippable frame, not a zstd frame');
  if (magic !== MAGIC) bad('no zstd frame magic number');
  const fhd = frame[4];
  const fcsFlag = fhd >> 6, singleSegment = (fhd >> 5) & 1, checksum = (fhd >> 2) & 1;
  if (fhd & 0x08) bad('the zstd frame header sets its reserved bit');
  const dictBytes = [0, 1, 2, 4][fhd & 3];
  const fcsBytes = [singleSegment ? 1 : 0, 2, 4, 8][fcsFlag];
  let at = 5;
  const headerEnd = at + (singleSegment ? 0 : 1) + dictBytes + fcsBytes;
  if (frame.length < headerEnd) bad('the zstd frame header is cut short');
  let windowSize = 0;
  if (!singleSegment) {
    const wd = frame[at++];
    const base = 2 ** (10 + (wd >> 3));
    windowSize = base + (base / 8) * (wd & 7);
  }
  const dictId = readLE(frame, at, dictBytes);
  at += dictBytes;
  if (fcsBytes === 0) bad('the zstd frame does not declare its content size');
  let contentSize = readLE(frame, at, fcsBytes);
  if (fcsBytes === 8 && (frame[at + 6] > 0x1f || frame[at + 7] !== 0)) contentSize = Infinity;  // >= 2^53
  if (fcsBytes === 2) contentSize += 256;
  if (singleSegment) windowSize = contentSize;
  return { blocksStart: headerEnd, contentSize, windowSize, dictId, checksum };
}

// Walks the block headers (RFC 8878 3.1.1.2): where the frame ends, and the most bytes its
// blocks can produce (Raw: its size, RLE: its Block_Size, Compressed: one block's maximum).
function walkBlocks(frame, start, blockMax) {
  let at = start, bound = 0;
  for (;;) {
    if (at + 3 > frame.length) bad('a zstd block header is cut short');
    const h = readLE(frame, at, 3);
    at += 3;
    const last = h & 1, type = (h >> 1) & 3, size = h >>> 3;
    if (type === 3) bad('a zstd block of the reserved type');
    if (size > blockMax) bad(`a zstd block of ${size} bytes, above the block maximum ${blockMax}`);
    const stored = type === 1 ? 1 : size;
    if (at + stored > frame.length) bad('a zstd block is cut short');
    at += stored;
    bound += type === 2 ? blockMax : size;
    if (last) return { end: at, bound };
  }
}

// The frame again, with a single-segment header that declares `size` in 4 bytes: fzstd then
// allocates that, never a window the original header may claim. Same blocks, same meaning for a
// valid frame (a single segment's window is the whole content). The caller declares one block
// more than Raw_Size: fzstd decodes a block into a buffer of at most the declared size and drops
// what does not fit without a word, so a damaged block that decodes to too much must find room
// to show it.
function singleSegmentFrame(frame, blocksStart, size, checksum) {
  const out = new Uint8Array(9 + frame.length - blocksStart);
  out.set([0x28, 0xb5, 0x2f, 0xfd, 0xa0 | (checksum << 2)]);
  new DataView(out.buffer).setUint32(5, size, true);
  out.set(frame.subarray(blocksStart), 9);
  return out;
}

// The raw content of a section stored compressed: `rawSize` bytes, or a ZstdFailure.
// `dictionary`: a bank's (readDictionary of zstd-blocks.js), or null.
export function decompressSection(frame, rawSize, dictionary = null) {
  const h = readFrameHeader(frame);
  if (h.contentSize !== rawSize) bad(`the zstd frame declares ${h.contentSize} bytes, Raw_Size is ${rawSize}`);
  if (h.dictId !== 0 && h.dictId !== dictionary?.id) bad(`the zstd frame needs dictionary ${h.dictId}${dictionary ? `, the bank's is ${dictionary.id}` : ''}`);
  const blockMax = Math.min(BLOCK_MAX, h.windowSize);
  const { end, bound } = walkBlocks(frame, h.blocksStart, blockMax);
  const frameEnd = end + 4 * h.checksum;
  if (frameEnd > frame.length) bad('the zstd frame checksum is cut short');
  if (frameEnd < frame.length) bad(`${frame.length - frameEnd} bytes follow the zstd frame`);
  if (bound < rawSize) bad(`the zstd frame's blocks cannot produce ${rawSize} bytes (at most ${bound})`);

  const out = new Uint8Array(rawSize);
  const filled = dictionary ? withDictionary(frame, h, out, dictionary) : inflate(frame, h, out);
  if (filled !== rawSize) bad(`the zstd frame decompresses to ${filled} bytes, not ${rawSize}`);
  if (h.checksum && xxh64Low32(out) !== readLE(frame, end, 4)) bad('the zstd frame checksum does not match');
  return out;
}

// zstd-blocks.js's decoding of the blocks into out; returns the bytes made.
function withDictionary(frame, h, out, dictionary) {
  try {
    return decodeBlocks(frame, h.blocksStart, out, dictionary);
  } catch (e) {
    if (isZstdFailure(e)) throw e;
    bad(`zstd cannot decompress the frame (${e.message})`);
  }
}

// fzstd's decoding of the blocks into out; returns the bytes made.
function inflate(frame, h, out) {
  const rawSize = out.length;
  let filled = 0;
  const sink = new Decompress((chunk) => {
    if (chunk.length > rawSize - filled) bad(`the zstd frame decompresses to more than ${rawSize} bytes`);
    out.set(chunk, filled);
    filled += chunk.length;
  });
  try {
    sink.push(singleSegmentFrame(frame, h.blocksStart, rawSize + BLOCK_MAX, h.checksum), true);
  } catch (e) {
    if (isZstdFailure(e)) throw e;
    bad(`zstd cannot decompress the frame (${e.message})`);
  }
  return filled;
}
