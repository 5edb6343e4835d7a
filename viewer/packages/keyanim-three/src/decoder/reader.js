// Little-endian reading of one section's raw content, with errors that say where they happened:
// the file offset for a section stored uncompressed, or the section's start plus the byte
// within the decompressed content for a compressed one.
import { fail } from './errors.js';

export class SectionReader {
  constructor(tag, bytes, fileOffset, compressed) {
    this.tag = tag;
    this.bytes = bytes;
    this.view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
    this.fileOffset = fileOffset;
    this.compressed = compressed;
    this.pos = 0;
  }

  get length() { return this.bytes.length; }
  get remaining() { return this.bytes.length - this.pos; }

  fail(status, pos, detail) {
    if (this.compressed) fail(status, `section ${this.tag}`, this.fileOffset, `${detail} (at byte ${pos} of the decompressed section)`);
    fail(status, `section ${this.tag}`, this.fileOffset + pos, detail);
  }

  // Fails with `corrupt` unless `n` more bytes are there; `what` names the field for the message.
  need(n, what) {
    if (n > this.remaining) this.fail('corrupt', this.pos, `${what} runs past the end of ${this.tag}`);
  }

  u8(what) { this.need(1, what); return this.bytes[this.pos++]; }
  i16(what) { this.need(2, what); const v = this.view.getInt16(this.pos, true); this.pos += 2; return v; }
  u16(what) { this.need(2, what); const v = this.view.getUint16(this.pos, true); this.pos += 2; return v; }
  u32(what) { this.need(4, what); const v = this.view.getUint32(this.pos, true); this.pos += 4; return v; }
  i32(what) { this.need(4, what); const v = this.view.getInt32(this.pos, true); this.pos += 4; return v; }
  f32(what) { this.need(4, what); const v = this.view.getFloat32(this.pos, true); this.pos += 4; return v; }
  f64(what) { this.need(8, what); const v = this.view.getFloat64(this.pos, true); this.pos += 8; return v; }
  u64(what) { this.need(8, what); const v = this.view.getBigUint64(this.pos, true); this.pos += 8; return v; }
  take(n, what) { this.need(n, what); const s = this.bytes.subarray(this.pos, this.pos + n); this.pos += n; return s; }

  // Unsigned LEB128 (section 6.1): at most `maxBytes` bytes, shortest form, value below 2^bits.
  // Returns a Number when bits <= 32, else a BigInt.
  varint(maxBytes, bits, what) {
    const start = this.pos;
    const big = bits > 32;  // 32-bit values stay exact in a Number (at most 35 bits are read)
    let value = big ? 0n : 0;
    for (let i = 0; ; ++i) {
      if (i === maxBytes) this.fail('corrupt', start, `${what}: varint longer than ${maxBytes} bytes`);
      if (this.pos >= this.bytes.length) this.fail('corrupt', start, `${what}: varint cut by the end of ${this.tag}`);
      const b = this.bytes[this.pos++];
      if (big) value |= BigInt(b & 0x7f) << BigInt(7 * i);
      else value += (b & 0x7f) * 2 ** (7 * i);
      if (b & 0x80) continue;
      if (b === 0 && i > 0) this.fail('corrupt', start, `${what}: over-long varint`);
      break;
    }
    if (big ? value >> BigInt(bits) : value >= 2 ** bits) this.fail('corrupt', start, `${what}: varint value does not fit ${bits} bits`);
    return value;
  }

  // The section must be used up exactly (section 4: Raw_Size neither more nor less).
  expectEnd(what) {
    if (this.remaining !== 0) this.fail('corrupt', this.pos, `${this.remaining} bytes left over after ${what}`);
  }
}
