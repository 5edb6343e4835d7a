// The curve panel: one channel over time, the original (BVH) against the decoded curve, with
// the keys marked and the playhead (what `keyanim plot` draws, live). With a BVH alone (clip
// null), its curve only. A quaternion node's rotation channel (version 5) holds its stored x, y
// or z, not an angle: the panel shows the channel as BVH has it (spec Appendix B), the Euler
// angle of the node's rotation, continuous from frame to frame, with its keys' frames marked.
import { channelValue, samplePose } from 'keyanim-three/decoder/sample.js';
import { CHANNEL_TYPES, nodeLabel } from 'keyanim-three/decoder/kanim.js';
import { storedRotation, eulerFromQuaternion, rotationAxes } from 'keyanim-three/decoder/rotation.js';
import { COLORS } from './view3d.js';

const css = (hex) => `#${hex.toString(16).padStart(6, '0')}`;

// Rotation channels are stored unwrapped (Appendix B): consecutive frames differ by at most
// 180 degrees. The original is unwrapped the same way so that both curves can be compared.
export function unwrapDegrees(values) {
  const out = Float64Array.from(values);
  for (let i = 1; i < out.length; ++i) out[i] -= 360 * Math.round((out[i] - out[i - 1]) / 360);
  return out;
}

export class CurvePanel {
  constructor(canvas, channelSelect, spanSelect) {
    Object.assign(this, { canvas, channelSelect, spanSelect, clip: null, original: null, position: 0 });
    channelSelect.addEventListener('change', () => this.draw());
    spanSelect.addEventListener('change', () => this.draw());
    new ResizeObserver(() => this.draw()).observe(canvas);
  }

  setClip(clip, original) {
    this.clip = clip;
    this.original = original;
    this.originalCache = new Map();
    this.eulerCache = new Map();
    // channel -> [quaternion node, index of the channel among its three rotation channels]
    this.quatOf = new Map((clip?.quatNodes ?? []).flatMap((q) => [0, 1, 2].map((k) => [q.column + k, [q, k]])));
    const nodes = (clip ?? original).nodes, options = [];
    this.types = [];
    nodes.forEach((n, i) => n.channels.forEach((t, k) => { options.push([n.firstChannel + k, `${nodeLabel(nodes, i)} ${CHANNEL_TYPES[t]}`]); this.types[n.firstChannel + k] = t; }));
    const keys = (c) => (clip ? clip.channels[c].keyCount : 0);
    const what = (c) => `${keys(c)} keys${this.quatOf.has(c) ? ', of the quaternion' : ''}`;
    this.channelSelect.replaceChildren(...options.map(([c, label]) => new Option(clip ? `${label} (${what(c)})` : label, c)));
    // Start on the busiest rotation channel: the one with the most keys (the first one, alone).
    const busiest = options.map(([c]) => c).filter((c) => this.types[c] >= 3).sort((a, b) => keys(b) - keys(a))[0];
    if (busiest !== undefined) this.channelSelect.value = String(busiest);
    this.draw();
  }

  get frameCount() { return (this.clip ?? this.original)?.frameCount ?? 0; }

  setPosition(position) { this.position = position; this.draw(); }

  originalValues(c) {
    if (!this.originalCache.has(c)) {
      const o = this.original, n = o.channelCount;
      const v = Array.from({ length: o.frameCount }, (_, f) => o.frames[f * n + c]);
      this.originalCache.set(c, this.types[c] >= 3 ? unwrapDegrees(v) : Float64Array.from(v));
    }
    return this.originalCache.get(c);
  }

  // The Euler angles (degrees) of quaternion node q at every source frame, continuous from frame
  // 0, where they start nearest the original's (when one is loaded), else with the middle angle
  // in [-90, 90]: F x 3 values.
  eulerFrames(q) {
    if (!this.eulerCache.has(q)) {
      const clip = this.clip, axes = rotationAxes(clip.nodes[q.node]), out = new Float64Array(3 * clip.frameCount);
      const values = new Float32Array(clip.channelCount), c = q.column;
      let previous = this.original ? [0, 1, 2].map((k) => this.originalValues(c + k)[0]) : null;
      for (let f = 0; f < clip.frameCount; ++f) {
        samplePose(clip, f, values);
        previous = eulerFromQuaternion(storedRotation(q.r, values[c], values[c + 1], values[c + 2]), axes, previous);
        out.set(previous, 3 * f);
      }
      this.eulerCache.set(q, out);
    }
    return this.eulerCache.get(q);
  }

  // Channel c of the clip at frame position x as the panel draws it: its value (Appendix A), or
  // for a quaternion node's rotation channel the Euler angle nearest that of the nearest frame.
  valueAt(c, x) {
    const clip = this.clip, quat = this.quatOf.get(c);
    if (!quat) return channelValue(clip.channels[c], clip.tangentRule, Math.fround(x));
    const [q, k] = quat, frames = this.eulerFrames(q), f = Math.min(clip.frameCount - 1, Math.max(0, Math.round(x)));
    if (x === f) return frames[3 * f + k];
    const values = samplePose(clip, x), s = q.column;
    const angles = eulerFromQuaternion(storedRotation(q.r, values[s], values[s + 1], values[s + 2]), rotationAxes(clip.nodes[q.node]), frames.subarray(3 * f, 3 * f + 3));
    return angles[k];
  }

  draw() {
    const { canvas, clip } = this;
    const w = canvas.clientWidth, h = canvas.clientHeight, ratio = window.devicePixelRatio || 1;
    canvas.width = Math.max(1, w * ratio);
    canvas.height = Math.max(1, h * ratio);
    const g = canvas.getContext('2d');
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    g.clearRect(0, 0, w, h);
    if (this.frameCount === 0 || w < 50 || this.channelSelect.value === '') return;
    const c = Number(this.channelSelect.value), ch = clip ? clip.channels[c] : null;
    const [a, b] = this.span();
    const decoded = [];
    if (ch) for (let x = 0; x <= w - 60; ++x) decoded.push(this.valueAt(c, a + ((b - a) * x) / (w - 60)));
    const orig = this.original ? this.originalValues(c) : null;
    // A quaternion node's keys are of its stored x, y, z: marked at their frames on the angle.
    const keyValue = (k, i) => (this.quatOf.has(c) ? this.valueAt(c, k) : ch.values[i]);
    const keys = ch ? [...ch.keyFrames].map((k, i) => [k, i]).filter(([k]) => k >= a && k <= b).map(([k, i]) => [k, keyValue(k, i)]) : [];
    const shown = [...decoded, ...keys.map(([, v]) => v)];
    if (orig) for (let f = Math.max(0, Math.floor(a)); f <= Math.min(orig.length - 1, b); ++f) shown.push(orig[f]);
    let lo = Infinity, hi = -Infinity;
    for (const v of shown) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    if (!(hi > lo)) { lo -= 1; hi += 1; }
    const pad = (hi - lo) * 0.08;
    lo -= pad; hi += pad;
    const X = (f) => 50 + ((f - a) / (b - a || 1)) * (w - 60), Y = (v) => h - 20 - ((v - lo) / (hi - lo)) * (h - 30);

    g.font = '11px system-ui, sans-serif';
    g.fillStyle = '#9aa3b2';
    g.fillText(hi.toPrecision(4), 2, 14);
    g.fillText(lo.toPrecision(4), 2, h - 22);
    g.fillText(`frame ${Math.round(a)}`, 50, h - 5);
    g.fillText(`${Math.round(b)}`, w - 40, h - 5);
    if (orig) this.polyline(g, css(COLORS.original), 1.5, Array.from({ length: Math.min(orig.length - 1, Math.floor(b)) - Math.max(0, Math.ceil(a)) + 1 }, (_, i) => { const f = Math.max(0, Math.ceil(a)) + i; return [X(f), Y(orig[f])]; }));
    this.polyline(g, css(COLORS.decoded), 1.5, decoded.map((v, x) => [50 + x, Y(v)]));
    g.fillStyle = css(COLORS.decoded);
    for (const [k, v] of keys) { g.beginPath(); g.arc(X(k), Y(v), 3, 0, 2 * Math.PI); g.fill(); }
    g.strokeStyle = '#e8e8e8';
    g.beginPath(); g.moveTo(X(this.position), 4); g.lineTo(X(this.position), h - 18); g.stroke();
  }

  polyline(g, color, width, points) {
    g.strokeStyle = color;
    g.lineWidth = width;
    g.beginPath();
    points.forEach(([x, y], i) => (i ? g.lineTo(x, y) : g.moveTo(x, y)));
    g.stroke();
  }

  // Frames shown: the whole clip, or a window around the playhead.
  span() {
    const last = Math.max(1, this.frameCount - 1), span = this.spanSelect.value;
    if (span === 'all' || Number(span) >= last) return [0, last];
    const half = Number(span) / 2;
    const a = Math.min(Math.max(0, this.position - half), last - 2 * half);
    return [a, a + 2 * half];
  }
}
