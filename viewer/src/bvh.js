// A BVH reader: the hierarchy as the decoder's node list (name, parent, offset, endSite,
// channels as spec channel type numbers, firstChannel) and the motion as one Float64Array of
// frames x channels. Conventions as spec/FORMAT.md Appendix B: nodes in file order, End Sites
// as nodes, channels numbered in node order. Errors name line and column.
import { CHANNEL_TYPES } from 'keyanim-three/decoder/kanim.js';

export class BvhError extends Error {
  constructor(line, column, detail) {
    super(`${line}:${column}: ${detail}`);
    this.name = 'BvhError';
  }
}

// Splits text into lines of whitespace-separated tokens with their columns (1-based).
// Line ends: LF, CRLF or a lone CR.
function tokenize(text) {
  return text.split(/\r\n|\n|\r/).map((line, i) => {
    const tokens = [];
    for (const m of line.matchAll(/\S+/g)) tokens.push({ text: m[0], line: i + 1, column: m.index + 1 });
    return { tokens, number: i + 1, text: line };
  });
}

class Lines {
  constructor(text) { this.lines = tokenize(text); this.at = 0; }
  // The next line that has tokens (or null at the end).
  next() {
    while (this.at < this.lines.length && this.lines[this.at].tokens.length === 0) ++this.at;
    return this.at < this.lines.length ? this.lines[this.at++] : null;
  }
  peek() { const save = this.at, l = this.next(); this.at = save; return l; }
  endPosition() { return { line: this.lines.length, column: 1 }; }
}

const fail = (where, detail) => { throw new BvhError(where.line, where.column, detail); };

function number(tok, what) {
  if (!/^[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?$/.test(tok.text)) {
    if (/^[+-]?(inf|infinity|nan)$/i.test(tok.text)) fail(tok, `expected a finite number, found '${tok.text}'`);
    fail(tok, `expected ${what}, found '${tok.text}'`);
  }
  const v = Number(tok.text);
  if (!Number.isFinite(v)) fail(tok, `expected a finite number, found '${tok.text}'`);
  return v;
}

// A whole, non-negative number, as keyanim reads counts (Frames: -3 or 2.5 is refused).
function count(tok, what) {
  if (!/^\+?\d+$/.test(tok.text) || !Number.isSafeInteger(Number(tok.text))) fail(tok, `expected ${what}, found '${tok.text}'`);
  return Number(tok.text);
}

// The rest of a line after its first token: a name may contain spaces.
const restOfLine = (line) => line.text.slice(line.tokens[0].column - 1 + line.tokens[0].text.length).trim();

function expectLine(lines, keyword) {
  const l = lines.next();
  if (!l) fail(lines.endPosition(), `expected '${keyword}', found the end of the file`);
  if (l.tokens[0].text !== keyword) fail(l.tokens[0], `expected '${keyword}', found '${l.tokens[0].text}'`);
  return l;
}

function readOffset(lines) {
  const l = expectLine(lines, 'OFFSET');
  if (l.tokens.length !== 4) fail(l.tokens[0], `OFFSET needs 3 values, found ${l.tokens.length - 1}`);
  return l.tokens.slice(1).map((t) => number(t, 'a number'));
}

// One ROOT/JOINT/End Site node from its keyword line to its channels, into nodes.
function startNode(lines, head, parent, nodes, channelCount) {
  const keyword = head.tokens[0].text;
  const endSite = keyword === 'End';
  if (endSite && head.tokens[1]?.text !== 'Site') fail(head.tokens[0], "expected 'End Site'");
  const name = endSite ? head.text.trim().replace(/^End\s+Site\s*/, '') : restOfLine(head);
  const node = { name, parent, offset: null, endSite, channels: [], firstChannel: channelCount.n };
  nodes.push(node);
  expectLine(lines, '{');
  node.offset = readOffset(lines);
  if (!endSite) {
    const l = lines.peek();
    if (l && l.tokens[0].text === 'CHANNELS') {
      lines.next();
      const n = number(l.tokens[1] ?? l.tokens[0], 'a channel count');
      if (!Number.isInteger(n) || n < 0 || n > 6 || l.tokens.length !== n + 2) fail(l.tokens[0], `CHANNELS ${n} needs ${n} channel names (at most 6)`);
      node.channels = l.tokens.slice(2).map((t) => {
        const type = CHANNEL_TYPES.indexOf(t.text);
        if (type < 0) fail(t, `unknown channel '${t.text}'`);
        return type;
      });
      channelCount.n += n;
    }
  }
  return { index: nodes.length - 1, endSite };
}

// A ROOT (its keyword line already read) and everything below it, into nodes. A loop over an
// explicit stack of the nodes still open, not recursion: a chain as deep as keyanim accepts
// (65536 nodes) would overflow the call stack.
function readTree(lines, head, nodes, channelCount) {
  const open = [startNode(lines, head, -1, nodes, channelCount)];
  while (open.length > 0) {
    const top = open[open.length - 1];
    const l = lines.next();
    if (!l) fail(lines.endPosition(), "expected '}', found the end of the file");
    const t = l.tokens[0].text;
    if (t === '}') { open.pop(); continue; }
    if (top.endSite || (t !== 'JOINT' && t !== 'End')) fail(l.tokens[0], `expected ${top.endSite ? "'}'" : "JOINT, End Site or '}'"}, found '${t}'`);
    open.push(startNode(lines, l, top.index, nodes, channelCount));
  }
}

// Returns { nodes, channelCount, frameCount, frameTime, frames (Float64Array), warnings }.
export function parseBvh(text) {
  const lines = new Lines(text);
  expectLine(lines, 'HIERARCHY');
  const nodes = [], channelCount = { n: 0 };
  for (;;) {
    const l = lines.next();
    if (!l) fail(lines.endPosition(), "expected ROOT or MOTION, found the end of the file");
    if (l.tokens[0].text === 'MOTION') break;
    if (l.tokens[0].text !== 'ROOT') fail(l.tokens[0], `expected ROOT or MOTION, found '${l.tokens[0].text}'`);
    readTree(lines, l, nodes, channelCount);
  }
  if (nodes.length === 0) fail(lines.endPosition(), 'no ROOT in the hierarchy');
  const framesLine = expectLine(lines, 'Frames:');
  const declared = count(framesLine.tokens[1] ?? framesLine.tokens[0], 'a frame count');
  const timeLine = lines.next();
  if (!timeLine || timeLine.tokens[0].text !== 'Frame' || timeLine.tokens[1]?.text !== 'Time:') fail(timeLine ? timeLine.tokens[0] : lines.endPosition(), "expected 'Frame Time:'");
  const frameTime = number(timeLine.tokens[2] ?? timeLine.tokens[1], 'a frame time');
  return { nodes, channelCount: channelCount.n, frameTime, ...readMotion(lines, declared, channelCount.n, framesLine) };
}

// Motion lines: one per frame, each exactly `c` values. More lines than declared are kept
// (with a warning), fewer are an error.
function readMotion(lines, declared, c, framesLine) {
  const rows = [], warnings = [];
  for (let l; (l = lines.next());) {
    if (l.tokens.length !== c) fail(l.tokens[Math.min(c, l.tokens.length - 1)], `expected ${c} values on this motion line, found ${l.tokens.length}`);
    rows.push(l.tokens.map((t) => number(t, 'a number')));
  }
  if (rows.length < declared) fail(framesLine.tokens[0], `expected ${declared} motion lines (Frames: ${declared}), found ${rows.length}`);
  if (rows.length > declared) warnings.push(`Frames: declares ${declared} frames, but ${rows.length} motion lines follow; all are kept`);
  const frames = new Float64Array(rows.length * c);
  rows.forEach((row, i) => frames.set(row, i * c));
  return { frameCount: rows.length, frames, warnings };
}
