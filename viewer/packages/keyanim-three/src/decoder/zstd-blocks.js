// The blocks of a zstd frame (RFC 8878 section 3.1.1.2 to 4), decoded here for the frames of a
// bank's members, which are made with the bank's dictionary (spec/FORMAT.md 10.4): fzstd, which
// decodes every other frame, has no dictionary support. A dictionary (RFC 8878 section 5) gives
// the first block its entropy tables, its repeat offsets and a history its matches may reach.
// Written from the RFC; every read is bounded by the block or the output, and any failure throws
// ZstdFailure through `bad` (the caller reports it as zstd_error).
import { bad } from './zstd-failure.js';

const BLOCK_MAX = 128 * 1024;
const DICTIONARY_MAGIC = 0xec30a437;

// --- Bit streams ------------------------------------------------------------------------------

// Bits `n` (<= 32) at bit `pos` of `bytes`, least significant first; bits before bit 0 read as
// zero (RFC 8878 4.1: a backward stream read past its start gives zeros).
function bitsAt(bytes, pos, n) {
  let v = 0, got = 0;
  if (pos < 0) { got = Math.min(n, -pos); }
  while (got < n) {
    const p = pos + got, shift = p & 7, take = Math.min(8 - shift, n - got);
    v += ((bytes[p >> 3] >> shift) & ((1 << take) - 1)) * 2 ** got;
    got += take;
  }
  return v;
}

// A backward bit stream (RFC 8878 4.1): read from its end; its last byte's highest set bit
// marks where the bits start.
class BackwardBits {
  constructor(bytes, what) {
    const last = bytes.length ? bytes[bytes.length - 1] : 0;
    if (last === 0) bad(`the ${what} bit stream does not end with a 1 bit`);
    this.bytes = bytes;
    this.pos = bytes.length * 8 - 8 + (31 - Math.clz32(last));
  }
  read(n) { this.pos -= n; return n ? bitsAt(this.bytes, this.pos, n) : 0; }
  peek(n) { return bitsAt(this.bytes, this.pos - n, n); }
  get overflowed() { return this.pos < 0; }
  get done() { return this.pos === 0; }
}

// --- FSE tables (RFC 8878 4.1) ------------------------------------------------------------------

// A table description at bytes[at...]: returns { table, end } (end: the byte after it).
function readFseTable(bytes, at, maxLog, maxSymbol, what) {
  let bit = at * 8;
  const limit = bytes.length * 8;
  const take = (n) => { if (bit + n > limit) bad(`the ${what} FSE table description is cut short`); const v = bitsAt(bytes, bit, n); bit += n; return v; };
  const log = take(4) + 5;
  if (log > maxLog) bad(`the ${what} FSE table's accuracy log ${log} is above ${maxLog}`);
  const counts = [];
  let remaining = 1 << log;
  while (remaining > 0) {
    if (counts.length > maxSymbol) bad(`the ${what} FSE table has more than ${maxSymbol + 1} symbols`);
    const bits = 32 - Math.clz32(remaining + 1);  // highest_set_bit(remaining + 1) + 1
    const lowMask = (1 << (bits - 1)) - 1, threshold = (1 << bits) - 1 - (remaining + 1);
    if (bit + bits - 1 > limit) bad(`the ${what} FSE table description is cut short`);
    let v = bitsAt(bytes, bit, Math.min(bits, limit - bit));
    if ((v & lowMask) < threshold) { v &= lowMask; bit += bits - 1; } else { if (bit + bits > limit) bad(`the ${what} FSE table description is cut short`); if (v > lowMask) v -= threshold; bit += bits; }
    const count = v - 1;  // -1: "less than 1", a probability of 1 at the table's high end
    remaining -= Math.abs(count);
    counts.push(count);
    if (count === 0) {
      for (;;) {
        const repeat = take(2);
        for (let i = 0; i < repeat; ++i) counts.push(0);
        if (repeat !== 3) break;
      }
      if (counts.length > maxSymbol + 1) bad(`the ${what} FSE table has more than ${maxSymbol + 1} symbols`);
    }
  }
  if (remaining < 0) bad(`the ${what} FSE table's counts exceed its size`);
  return { table: buildFseTable(counts, log, what), end: Math.ceil(bit / 8) };
}

// The decoding table of normalized counts (RFC 8878 4.1.1): per state its symbol, the bits to
// read and the base of the next state.
function buildFseTable(counts, log, what) {
  const size = 1 << log, mask = size - 1;
  const symbol = new Uint8Array(size), bits = new Uint8Array(size), base = new Int32Array(size);
  let high = size;
  const next = new Int32Array(counts.length);
  counts.forEach((c, s) => { if (c === -1) { symbol[--high] = s; next[s] = 1; } });
  const step = (size >> 1) + (size >> 3) + 3;
  let pos = 0;
  counts.forEach((c, s) => {
    for (let i = 0; i < c; ++i) {
      symbol[pos] = s;
      do pos = (pos + step) & mask; while (pos >= high);
    }
    if (c > 0) next[s] = c;
  });
  if (pos !== 0) bad(`the ${what} FSE table's counts do not spread over its states`);
  for (let i = 0; i < size; ++i) {
    const n = next[symbol[i]]++;
    bits[i] = log - (31 - Math.clz32(n));
    base[i] = (n << bits[i]) - size;
  }
  return { log, symbol, bits, base };
}

const rleTable = (s) => ({ log: 0, symbol: Uint8Array.of(s), bits: new Uint8Array(1), base: new Int32Array(1) });

// A decoder state over one table: init reads `log` bits, update the state's bits.
class FseState {
  constructor(table, stream) { this.t = table; this.s = stream; this.state = stream.read(table.log); }
  get symbol() { return this.t.symbol[this.state]; }
  update() { const t = this.t, st = this.state; this.state = t.base[st] + this.s.read(t.bits[st]); }
}

// --- Huffman tables (RFC 8878 4.2) --------------------------------------------------------------

// The tree description at bytes[at...]: returns { table, end }.
function readHuffmanTable(bytes, at) {
  if (at >= bytes.length) bad('the Huffman tree description is cut short');
  const header = bytes[at];
  let weights, end;
  if (header >= 128) {
    const n = header - 127;
    end = at + 1 + Math.ceil(n / 2);
    if (end > bytes.length) bad('the Huffman weights are cut short');
    weights = Array.from({ length: n }, (_, i) => (i & 1 ? bytes[at + 1 + (i >> 1)] & 15 : bytes[at + 1 + (i >> 1)] >> 4));
  } else {
    end = at + 1 + header;
    if (end > bytes.length) bad('the Huffman weights are cut short');
    weights = fseWeights(bytes.subarray(at + 1, end));
  }
  return { table: buildHuffmanTable(weights), end };
}

// Weights compressed with FSE (RFC 8878 4.2.1.2): two interleaved states over one stream.
function fseWeights(bytes) {
  const { table, end } = readFseTable(bytes, 0, 6, 255, 'Huffman weights');
  const stream = new BackwardBits(bytes.subarray(end), 'Huffman weights');
  const a = new FseState(table, stream), b = new FseState(table, stream);
  const weights = [];
  for (;;) {
    if (weights.length > 253) bad('more than 255 Huffman weights');  // two more may follow
    weights.push(a.symbol); a.update();
    if (stream.overflowed) { weights.push(b.symbol); break; }
    weights.push(b.symbol); b.update();
    if (stream.overflowed) { weights.push(a.symbol); break; }
  }
  return weights;
}

// The last symbol's weight is implied (the weights' sum completes a power of two); a table of
// 2^maxBits entries, filled by weight then symbol, maps the next maxBits bits to a symbol.
function buildHuffmanTable(weights) {
  let sum = 0;
  for (const w of weights) { if (w > 11) bad(`a Huffman weight of ${w}`); if (w) sum += 1 << (w - 1); }
  if (sum === 0) bad('the Huffman weights are all 0');
  const maxBits = 32 - Math.clz32(sum);  // highest bit of sum, plus one
  const left = (1 << maxBits) - sum;
  if (maxBits > 11 || left & (left - 1)) bad('the Huffman weights do not make a prefix code');
  const all = [...weights, 32 - Math.clz32(left)];
  if (all.length > 256) bad('more than 256 Huffman symbols');
  const size = 1 << maxBits, symbol = new Uint8Array(size), bits = new Uint8Array(size);
  let pos = 0;
  for (let w = 1; w <= maxBits; ++w) {
    all.forEach((sw, s) => {
      if (sw !== w) return;
      const n = 1 << (w - 1);
      symbol.fill(s, pos, pos + n);
      bits.fill(maxBits + 1 - w, pos, pos + n);
      pos += n;
    });
  }
  return { maxBits, symbol, bits };
}

function huffmanStream(table, bytes, out, from, count) {
  const stream = new BackwardBits(bytes, 'Huffman literals');
  for (let i = 0; i < count; ++i) {
    const k = stream.peek(table.maxBits);
    out[from + i] = table.symbol[k];
    stream.read(table.bits[k]);
    if (stream.overflowed) bad('a Huffman literals stream is cut short');
  }
  if (!stream.done) bad('a Huffman literals stream holds bits after its literals');
}

// --- Literals section (RFC 8878 3.1.1.3.1) ------------------------------------------------------

const le = (b, at, n) => { let v = 0; for (let i = 0; i < n; ++i) v += b[at + i] * 2 ** (8 * i); return v; };

function readLiterals(block, state) {
  if (block.length < 1) bad('an empty compressed block');
  const type = block[0] & 3, format = (block[0] >> 2) & 3;
  if (type < 2) {
    const head = format === 1 ? 2 : format === 3 ? 3 : 1;
    if (block.length < head) bad('the literals header is cut short');
    const size = head === 1 ? block[0] >> 3 : Math.floor(le(block, 0, head) / 16);
    const dataEnd = head + (type === 0 ? size : 1);
    if (dataEnd > block.length) bad('the literals are cut short');
    const literals = type === 0 ? block.subarray(head, dataEnd) : new Uint8Array(size).fill(block[head]);
    return { literals, end: dataEnd };
  }
  const head = [3, 3, 4, 5][format], width = [10, 10, 14, 18][format], streams = format === 0 ? 1 : 4;
  if (block.length < head) bad('the literals header is cut short');
  const h = Math.floor(le(block, 0, head) / 16);
  const size = h % 2 ** width, compressed = Math.floor(h / 2 ** width);
  if (size > BLOCK_MAX) bad(`${size} literals, above the block maximum`);
  const end = head + compressed;
  if (end > block.length) bad('the compressed literals are cut short');
  let at = head;
  if (type === 2) {
    const tree = readHuffmanTable(block.subarray(0, end), at);
    state.huffman = tree.table;
    at = tree.end;
  } else if (!state.huffman) {
    bad('treeless literals without an earlier Huffman table');
  }
  const literals = new Uint8Array(size), data = block.subarray(at, end);
  if (streams === 1) {
    huffmanStream(state.huffman, data, literals, 0, size);
  } else {
    if (data.length < 6) bad('the literals jump table is cut short');
    const s1 = le(data, 0, 2), s2 = le(data, 2, 2), s3 = le(data, 4, 2), s4 = data.length - 6 - s1 - s2 - s3;
    const seg = Math.ceil(size / 4), last = size - 3 * seg;
    if (s4 < 1 || last < 0) bad('the literals jump table does not fit its streams');
    let from = 6;
    [[s1, seg], [s2, seg], [s3, seg], [s4, last]].forEach(([n, count], k) => {
      huffmanStream(state.huffman, data.subarray(from, from + n), literals, k * seg, count);
      from += n;
    });
  }
  return { literals, end };
}

// --- Sequences section (RFC 8878 3.1.1.3.2) -----------------------------------------------------

const LL_BASE = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 18, 20, 22, 24, 28, 32, 40, 48, 64, 128, 256, 512, 1024, 2048, 4096, 8192, 16384, 32768, 65536];
const LL_BITS = [0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 3, 3, 4, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16];
const ML_BASE = [...Array.from({ length: 32 }, (_, i) => i + 3), 35, 37, 39, 41, 43, 47, 51, 59, 67, 83, 99, 131, 259, 515, 1027, 2051, 4099, 8195, 16387, 32771, 65539];
const ML_BITS = [...new Array(32).fill(0), 1, 1, 1, 1, 2, 2, 3, 3, 4, 4, 5, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16];
// Predefined distributions (RFC 8878 3.1.1.3.2.2).
const PREDEFINED = {
  ll: buildFseTable([4, 3, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 2, 3, 2, 1, 1, 1, 1, 1, -1, -1, -1, -1], 6, 'literal lengths'),
  of: buildFseTable([1, 1, 1, 1, 1, 1, 2, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, -1, -1, -1, -1, -1], 5, 'offsets'),
  ml: buildFseTable([1, 4, 3, 2, 2, 2, 2, 2, 2, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, -1, -1, -1, -1, -1, -1, -1], 6, 'match lengths'),
};
const KINDS = [['ll', 9, 35, 'literal lengths'], ['of', 8, 31, 'offsets'], ['ml', 9, 52, 'match lengths']];

// Number_of_Sequences, the modes and the three tables: returns { count, end }.
function readSequencesHeader(block, at, state) {
  if (at >= block.length) bad('the sequences section is missing');
  const b0 = block[at];
  let count, pos;
  if (b0 < 128) { count = b0; pos = at + 1; }
  else if (b0 < 255) { if (at + 2 > block.length) bad('the sequence count is cut short'); count = ((b0 - 128) << 8) + block[at + 1]; pos = at + 2; }
  else { if (at + 3 > block.length) bad('the sequence count is cut short'); count = block[at + 1] + (block[at + 2] << 8) + 0x7f00; pos = at + 3; }
  if (count === 0) return { count, end: pos };
  if (pos >= block.length) bad('the sequence modes are cut short');
  const modes = block[pos++];
  if (modes & 3) bad('the sequence modes set their reserved bits');
  KINDS.forEach(([kind, maxLog, maxSymbol, what], k) => {
    const mode = (modes >> (6 - 2 * k)) & 3;
    if (mode === 0) state[kind] = PREDEFINED[kind];
    else if (mode === 1) {
      if (pos >= block.length) bad(`the ${what} RLE symbol is cut short`);
      if (block[pos] > maxSymbol) bad(`the ${what} RLE symbol ${block[pos]} is above ${maxSymbol}`);
      state[kind] = rleTable(block[pos++]);
    } else if (mode === 2) {
      const { table, end } = readFseTable(block, pos, maxLog, maxSymbol, what);
      state[kind] = table;
      pos = end;
    } else if (!state[kind]) bad(`the ${what} repeat an FSE table there is none of`);
  });
  return { count, end: pos };
}

// The repeat offsets (RFC 8878 3.1.1.5): the offset of a sequence, with rep updated.
function offsetOf(code, literalLength, rep) {
  if (code > 3) { rep[2] = rep[1]; rep[1] = rep[0]; rep[0] = code - 3; return rep[0]; }
  const idx = code - 1 + (literalLength === 0 ? 1 : 0);
  if (idx === 0) return rep[0];
  const offset = idx === 3 ? rep[0] - 1 : rep[idx];
  if (offset === 0) bad('a repeat offset of 0');
  if (idx !== 1) rep[2] = rep[1];
  rep[1] = rep[0];
  rep[0] = offset;
  return offset;
}

// Executes the block's sequences into out (from `pos`, with `history` bytes of the dictionary
// before out's first byte); returns the new position.
function executeSequences(block, at, count, literals, state, out, pos, history) {
  const blockEnd = Math.min(out.length, pos + BLOCK_MAX);
  const stream = new BackwardBits(block.subarray(at), 'sequences');
  const ll = new FseState(state.ll, stream), of = new FseState(state.of, stream), ml = new FseState(state.ml, stream);
  let lit = 0;
  for (let i = 0; i < count; ++i) {
    const ofCode = of.symbol, llCode = ll.symbol, mlCode = ml.symbol;
    if (ofCode > 31) bad(`an offset code of ${ofCode}`);
    const offsetValue = 2 ** ofCode + stream.read(ofCode);
    const matchLength = ML_BASE[mlCode] + stream.read(ML_BITS[mlCode]);
    const literalLength = LL_BASE[llCode] + stream.read(LL_BITS[llCode]);
    if (stream.overflowed) bad('the sequences bit stream is cut short');
    if (i + 1 < count) { ll.update(); ml.update(); of.update(); }
    const offset = offsetOf(offsetValue, literalLength, state.rep);
    if (lit + literalLength > literals.length) bad('a sequence takes more literals than the block has');
    if (pos + literalLength + matchLength > blockEnd) bad('the block decompresses to more than the frame declares');
    out.set(literals.subarray(lit, lit + literalLength), pos);
    pos += literalLength;
    lit += literalLength;
    if (offset > pos + history.length) bad(`a match ${offset} bytes back, before the start of the content and its dictionary`);
    for (let k = 0; k < matchLength; ++k, ++pos) out[pos] = pos - offset >= 0 ? out[pos - offset] : history[history.length + pos - offset];
  }
  if (stream.overflowed || !stream.done) bad('the sequences bit stream holds bits after its sequences');
  if (pos + literals.length - lit > blockEnd) bad('the block decompresses to more than the frame declares');
  out.set(literals.subarray(lit), pos);
  return pos + literals.length - lit;
}

// --- Dictionary (RFC 8878 section 5) ------------------------------------------------------------

// Its ID, entropy tables, repeat offsets and content; throws ZstdFailure if it is not one.
export function readDictionary(bytes) {
  if (bytes.length < 8 || le(bytes, 0, 4) !== DICTIONARY_MAGIC) bad('not a zstd dictionary (no magic number)');
  const id = le(bytes, 4, 4);
  const huffman = readHuffmanTable(bytes, 8);
  let at = huffman.end;
  const tables = {};
  for (const [kind, maxLog, maxSymbol, what] of [KINDS[1], KINDS[2], KINDS[0]]) {  // offsets, match lengths, literal lengths
    const t = readFseTable(bytes, at, maxLog, maxSymbol, `dictionary ${what}`);
    tables[kind] = t.table;
    at = t.end;
  }
  if (at + 12 > bytes.length) bad('the dictionary ends inside its repeat offsets');
  const content = bytes.subarray(at + 12);
  const rep = [le(bytes, at, 4), le(bytes, at + 4, 4), le(bytes, at + 8, 4)];
  if (rep.some((r) => r === 0 || r > content.length)) bad('a dictionary repeat offset is 0 or beyond its content');
  return { id, huffman: huffman.table, ...tables, rep, content };
}

// --- Frame ---------------------------------------------------------------------------------------

// Decodes the blocks from frame[start] into out (out.length bytes, the declared content size),
// with the dictionary's tables, offsets and history; returns the bytes made. The block headers
// were walked by the caller (their sizes are within the frame and the block maximum).
export function decodeBlocks(frame, start, out, dict) {
  const state = { huffman: dict.huffman, ll: dict.ll, of: dict.of, ml: dict.ml, rep: [...dict.rep] };
  let at = start, pos = 0;
  for (;;) {
    const h = le(frame, at, 3), last = h & 1, type = (h >> 1) & 3, size = h >>> 3;
    at += 3;
    const room = out.length - pos;
    if (type === 0 || type === 1) {
      if (size > room) bad(`the zstd frame decompresses to more than ${out.length} bytes`);
      if (type === 0) out.set(frame.subarray(at, at + size), pos); else out.fill(frame[at], pos, pos + size);
      pos += size;
      at += type === 0 ? size : 1;
    } else {
      const block = frame.subarray(at, at + size);
      const { literals, end } = readLiterals(block, state);
      const seq = readSequencesHeader(block, end, state);
      if (seq.count === 0) {
        if (seq.end !== block.length) bad('bytes after a block without sequences');
        if (literals.length > room) bad(`the zstd frame decompresses to more than ${out.length} bytes`);
        out.set(literals, pos);
        pos += literals.length;
      } else {
        pos = executeSequences(block, seq.end, seq.count, literals, state, out, pos, dict.content);
      }
      at += size;
    }
    if (last) return pos;
  }
}

// No dictionary: the same decoding from empty tables and history (tests compare it with fzstd).
export const NO_DICTIONARY = Object.freeze({ huffman: null, ll: null, of: null, ml: null, rep: [1, 4, 8], content: new Uint8Array(0) });
