// Takes a .kanim apart into sections (raw content) and puts one together again, so that tests
// can make files that break exactly one rule. A section marked compressed is written as a zstd
// frame of Raw blocks (a valid frame: RFC 8878 3.1.1.2.2), which keeps its content editable.
import { crc32 } from 'keyanim-three/decoder/crc32.js';
import { decompressSection } from 'keyanim-three/decoder/zstd.js';

const le = (n, bytes) => { const b = new Uint8Array(8); new DataView(b.buffer).setBigUint64(0, BigInt(n), true); return b.subarray(0, bytes); };
const u32 = (n) => { const b = new Uint8Array(4); new DataView(b.buffer).setUint32(0, n >>> 0, true); return b; };
export const concat = (...parts) => {
  const out = new Uint8Array(parts.reduce((s, p) => s + p.length, 0));
  let at = 0;
  for (const p of parts) { out.set(p, at); at += p.length; }
  return out;
};

export function splitKanim(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const count = view.getUint32(16, true);
  const sections = [];
  let at = 24 + 24 * count;
  for (let i = 0; i < count; ++i) {
    const e = 24 + 24 * i;
    const tag = String.fromCharCode(...bytes.subarray(e, e + 4));
    const flags = view.getUint32(e + 4, true);
    const stored = Number(view.getBigUint64(e + 8, true)), raw = Number(view.getBigUint64(e + 16, true));
    const data = bytes.slice(at, at + stored);
    sections.push({ tag, flags, content: flags & 1 ? decompressSection(data, raw) : data });
    at += stored;
  }
  return { header: bytes.slice(0, 24), sections };
}

// A zstd frame holding `content` in Raw blocks, declaring its size.
export function zstdRawFrame(content) {
  const n = content.length;
  const [fhd, fcs] = n < 256 ? [0x20, le(n, 1)] : n < 65792 ? [0x60, le(n - 256, 2)] : [0xa0, le(n, 4)];
  const parts = [new Uint8Array([0x28, 0xb5, 0x2f, 0xfd, fhd]), fcs];
  let at = 0;
  do {
    const size = Math.min(n - at, 128 * 1024), last = at + size === n ? 1 : 0;
    parts.push(le(last | (size << 3), 3), content.subarray(at, at + size));
    at += size;
  } while (at < n);
  return concat(...parts);
}

// sections: [{ tag, flags, content, stored?, rawSize? }]: stored defaults to the content (or
// its Raw-block frame when Compressed is set), rawSize to the content's length.
export function buildKanim({ header, sections }, { crc = true } = {}) {
  const h = header.slice();
  new DataView(h.buffer).setUint32(16, sections.length, true);
  const table = [], data = [];
  for (const s of sections) {
    const stored = s.stored ?? (s.flags & 1 ? zstdRawFrame(s.content) : s.content);
    table.push(new TextEncoder().encode(s.tag.padEnd(4).slice(0, 4)), u32(s.flags), le(stored.length, 8), le(s.rawSize ?? s.content.length, 8));
    data.push(stored);
  }
  const body = concat(h, ...table, ...data);
  return concat(body, u32(crc ? crc32(body) : 0));
}

// The same file with its checksum recomputed after a byte patch.
export function fixCrc(bytes) {
  const out = bytes.slice();
  new DataView(out.buffer).setUint32(out.length - 4, crc32(out.subarray(0, out.length - 4)), true);
  return out;
}
