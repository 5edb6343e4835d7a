// The zstd block decoder of zstd-blocks.js (written from RFC 8878 for banks' dictionary frames,
// spec 10.4, which fzstd cannot decode), against independent references: frames made by the
// zstd command-line tool (Debian's, libzstd's reference implementation) with and without a
// dictionary it trained, at levels from 1 to 22, decode to the tool's input; without a
// dictionary it agrees with fzstd on every compressed section of the test vectors; damaged
// frames fail with a ZstdFailure (zstd_error), never another exception.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync, spawnSync } from 'node:child_process';
import { decompressSection, isZstdFailure } from 'keyanim-three/decoder/zstd.js';
import { readDictionary, NO_DICTIONARY } from 'keyanim-three/decoder/zstd-blocks.js';
import { vectorsDir, sourceDir, corpusDir, bvhFilesBelow } from './paths.mjs';

const zstdTool = process.env.KEYANIM_ZSTD || '/usr/bin/zstd';
const skip = spawnSync(zstdTool, ['--version']).status === 0 ? false : `no zstd tool at ${zstdTool}`;

// Samples: BVH text (the data/ clips, and corpus clips when there), cut to sizes around block
// boundaries (a block holds at most 128 KiB), and a few made-up byte patterns.
let dir, samples, dictBytes;
before(() => {
  if (skip) return;
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'keyanim-viewer-zstd-'));
  const texts = [...bvhFilesBelow(path.join(sourceDir, 'data')), ...bvhFilesBelow(corpusDir).slice(0, 4)].map((f) => fs.readFileSync(f));
  const cuts = [1, 100, 5000, 131072, 131073, 300000];
  samples = texts.flatMap((t, i) => cuts.filter((n) => n <= t.length).map((n) => ({ name: `text${i}_${n}`, bytes: t.subarray(0, n) })));
  let x = 12345;
  const noise = Uint8Array.from({ length: 70000 }, () => (x = (x * 1103515245 + 12345) >>> 0) >>> 24);
  samples.push({ name: 'noise', bytes: noise }, { name: 'zeros', bytes: new Uint8Array(200000) },
    { name: 'ramp', bytes: Uint8Array.from({ length: 50000 }, (_, i) => (i * 7) & 0xff) });
  const training = path.join(dir, 'train');
  fs.mkdirSync(training);
  texts.forEach((t, i) => { for (let k = 0; k < 8; ++k) fs.writeFileSync(path.join(training, `${i}_${k}`), t.subarray(k * 4000, k * 4000 + 4000)); });
  execFileSync(zstdTool, ['-q', '--train', '-r', training, '--maxdict=16384', '-o', path.join(dir, 'dict')]);
  dictBytes = new Uint8Array(fs.readFileSync(path.join(dir, 'dict')));
  for (const s of samples) fs.writeFileSync(path.join(dir, s.name), s.bytes);
});
after(() => dir && fs.rmSync(dir, { recursive: true, force: true }));

const compress = (name, args) => new Uint8Array(execFileSync(zstdTool, ['-q', '-c', ...args, path.join(dir, name)], { maxBuffer: 1 << 28 }));
const LEVELS = [['-1'], ['-3'], ['-9'], ['-19'], ['--ultra', '-22']];

test('frames made with a dictionary by the zstd tool decode to its input', { skip }, () => {
  const dict = readDictionary(dictBytes);
  assert.ok(dict.content.length > 0 && dict.huffman && dict.ll && dict.of && dict.ml, 'the trained dictionary has entropy tables and content');
  let frames = 0;
  for (const s of samples) {
    for (const level of LEVELS) {
      const frame = compress(s.name, [...level, '-D', path.join(dir, 'dict')]);
      const got = decompressSection(frame, s.bytes.length, dict);
      assert.ok(Buffer.from(got).equals(Buffer.from(s.bytes)), `${s.name} at ${level.join(' ')}: decoded bytes differ`);
      ++frames;
    }
  }
  assert.equal(frames, samples.length * LEVELS.length);
});

test('frames without a dictionary: this decoder = the tool\'s input = fzstd', { skip }, () => {
  for (const s of samples) {
    for (const level of LEVELS) {
      const frame = compress(s.name, level);
      const ours = decompressSection(frame, s.bytes.length, NO_DICTIONARY);
      assert.ok(Buffer.from(ours).equals(Buffer.from(s.bytes)), `${s.name} at ${level.join(' ')}`);
      assert.ok(Buffer.from(decompressSection(frame, s.bytes.length)).equals(Buffer.from(s.bytes)), `fzstd: ${s.name}`);
    }
  }
});

test('every compressed section of the test vectors: this decoder = fzstd', () => {
  let checked = 0;
  for (const f of fs.readdirSync(vectorsDir).filter((n) => n.endsWith('.kanim'))) {
    const bytes = new Uint8Array(fs.readFileSync(path.join(vectorsDir, f)));
    const view = new DataView(bytes.buffer, bytes.byteOffset), count = view.getUint32(16, true);
    let at = 24 + 24 * count;
    for (let i = 0; i < count; ++i) {
      const e = 24 + 24 * i, stored = Number(view.getBigUint64(e + 8, true)), raw = Number(view.getBigUint64(e + 16, true));
      if (view.getUint32(e + 4, true) & 1) {
        const frame = bytes.subarray(at, at + stored);
        assert.deepEqual(decompressSection(frame, raw, NO_DICTIONARY), decompressSection(frame, raw), `${f} section ${i}`);
        ++checked;
      }
      at += stored;
    }
  }
  assert.ok(checked >= 10, `${checked} compressed sections`);
});

test('damaged dictionary frames fail with zstd_error, never another exception', { skip }, () => {
  const dict = readDictionary(dictBytes);
  const s = samples.find((x) => x.name.startsWith('text') && x.bytes.length === 131073) ?? samples[0];
  let x = 99, failures = 0, decoded = 0;
  for (const level of [['-3'], ['-19']]) {
    const frame = compress(s.name, [...level, '-D', path.join(dir, 'dict'), '--no-check']);
    for (let k = 0; k < 300; ++k) {
      const bad = frame.slice();
      x = (x * 1103515245 + 12345) >>> 0;
      const at = 6 + (x % (bad.length - 6));  // past the header: its checks have their own tests
      bad[at] ^= 1 << ((x >>> 8) & 7);
      try {
        decompressSection(bad, s.bytes.length, dict);
        ++decoded;  // a flip the frame does not notice (no checksum here): the bank's CRC does
      } catch (e) {
        assert.ok(isZstdFailure(e), `flip at ${at}: ${e.stack}`);
        ++failures;
      }
    }
    for (const cut of [frame.length - 1, frame.length >> 1, 10]) {
      assert.throws(() => decompressSection(frame.subarray(0, cut), s.bytes.length, dict), (e) => isZstdFailure(e));
    }
  }
  assert.ok(failures > 100, `${failures} of ${failures + decoded} damaged frames refused`);
});

test('a dictionary without its magic number, or cut inside its tables, is refused', { skip }, () => {
  assert.throws(() => readDictionary(dictBytes.subarray(4)), (e) => isZstdFailure(e));
  for (const cut of [8, 12, 40]) assert.throws(() => readDictionary(dictBytes.subarray(0, cut)), (e) => isZstdFailure(e), `cut at ${cut}`);
});
