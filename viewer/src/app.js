// The page: opening files (picker, drag and drop, embedded by `keyanim view`), playback, and
// the panels. A .kanim is shown decoded, with its original BVH overlaid when one is opened; a
// bank (.kbank) lists its clips, and the one picked is shown as a .kanim is (a damaged one says
// why, the others still play); a BVH opened alone is played by itself (its frames, nearest
// frame between them). Decoding is
// the keyanim-three package's (packages/keyanim-three/src/decoder/); drawing is view3d.js and
// curves.js; what the camera follows and frames, framing.js; the up axis, upaxis.js.
import { decodeKanim, looksLikeKanim, nodeLabel } from 'keyanim-three/decoder/kanim.js';
import { openBank, decodeBankClip, looksLikeBank } from 'keyanim-three/decoder/bank.js';
import { samplePose } from 'keyanim-three/decoder/sample.js';
import { parseBvh } from './bvh.js';
import { worldPositions, measuredPoints, measuredSettings, skeletonSize, largestDistance } from 'keyanim-three/decoder/pose.js';
import { View3D } from './view3d.js';
import { CurvePanel } from './curves.js';
import { clipFacts, bvhFacts, noteLines } from './facts.js';
import { clipExtent, followedPoint } from './framing.js';
import { detectUpAxis, toYUp } from './upaxis.js';

const $ = (id) => document.getElementById(id);

export class App {
  constructor() {
    this.view = new View3D($('view'));
    this.curves = new CurvePanel($('curve'), $('curve-channel'), $('curve-span'));
    Object.assign(this, { clip: null, original: null, originalName: '', bank: null, bankName: '', position: 0, clock: 0, playing: false, lastTick: 0 });
    this.bindControls();
    this.bindFiles();
  }

  // --- Opening files ---------------------------------------------------------------------

  // A .kanim file: shown, and a bank's list (if one was open) put away.
  loadClip(bytes, name) {
    this.showClip(() => decodeKanim(bytes), name);
    this.closeBank();
  }

  // decode() gives the clip (decodeKanim's), or throws: then the clip shown stays.
  showClip(decode, name) {
    try {
      const clip = decode();
      if (clip.frameCount === 0) throw new Error('the clip has no frames');
      this.clip = clip;
      this.clipName = name;
      this.values = new Float32Array(clip.channelCount);
      if (this.original && !this.matches(this.original)) this.dropOriginal(`${this.originalName} does not have the skeleton of ${name}: not shown`);
      this.setup();
      this.message(`${name}: ${clip.frameCount} frames, ${clip.keyCount} keys`);
    } catch (e) {
      this.error(`${name}: ${e.message}`);
      throw e;
    }
  }

  loadOriginal(text, name) {
    try {
      const original = parseBvh(text);
      original.name = name;
      original.bytes = new TextEncoder().encode(text).length;
      if (this.clip && !this.matches(original)) throw new Error(`its skeleton differs from the clip's (${original.nodes.length} nodes, ${original.channelCount} channels; the clip: ${this.clip.nodes.length}, ${this.clip.channelCount})`);
      if (original.frameCount === 0) throw new Error('the file has no frames');
      this.original = original;
      this.originalName = name;
      this.setup();
      const alone = this.clip ? '' : '; playing the BVH alone: open its .kanim too to compare the two';
      this.message(`${name}: ${original.frameCount} frames${original.warnings.length ? ` (${original.warnings.join('; ')})` : ''}${alone}`);
    } catch (e) {
      this.error(`${name}: ${e.message}`);
      throw e;
    }
  }

  // A bank: its index is checked (no clip is read), its clips listed to pick from, and its
  // first clip shown. A bad index throws; the clip shown before stays.
  loadBank(bytes, name) {
    let bank;
    try {
      bank = openBank(bytes);
    } catch (e) {
      this.error(`${name}: ${e.message}`);
      throw e;
    }
    Object.assign(this, { bank, bankName: name, bankShown: -1 });
    const list = $('bank-clips');
    list.replaceChildren(...bank.clips.map((c) => {
      const o = el('option', `${c.name} · ${c.frameCount} frames · ${c.duration.toFixed(3)} s`);
      o.value = String(c.index);
      return o;
    }));
    list.disabled = bank.clips.length === 0;
    $('bank').hidden = false;
    $('bank-count').textContent = `${bank.clips.length} clip${bank.clips.length === 1 ? '' : 's'}, ${bank.profile}${bank.dictionaryBytes ? ', dictionary' : ''}`;
    if (bank.clips.length === 0) { this.message(`${name}: a bank without clips`); return; }
    try { this.pickClip(0); } catch { /* shown by error(); the list offers the others */ }
  }

  // Shows clip i of the open bank. A damaged clip throws (shown by error()): it is marked in
  // the list, and the list goes back to the clip still shown.
  pickClip(i) {
    if (!this.bank?.clips[i]) throw new RangeError(`no clip ${i} in ${this.bank ? this.bankName : 'a bank: none is open'}`);
    const c = this.bank.clips[i], option = $('bank-clips').options[i];
    try {
      this.showClip(() => decodeBankClip(this.bank, i), `${this.bankName}:${c.name}`);
      this.bankShown = i;
      $('bank-clips').value = String(i);
    } catch (e) {
      option.classList.add('damaged');
      if (!option.textContent.endsWith(' · damaged')) option.textContent += ' · damaged';
      $('bank-clips').value = String(this.bankShown);
      throw e;
    }
  }

  closeBank() {
    Object.assign(this, { bank: null, bankName: '' });
    $('bank').hidden = true;
    $('bank-clips').replaceChildren();
  }

  // The same hierarchy and channel layout: nodes, parents and channel types, in order.
  matches(o) {
    const a = this.clip.nodes, b = o.nodes;
    return a.length === b.length && a.every((n, i) => n.parent === b[i].parent && n.endSite === b[i].endSite && n.channels.join() === b[i].channels.join());
  }

  dropOriginal(why) {
    this.original = null;
    this.originalName = '';
    this.message(why);
  }

  async openFiles(files) {
    const isBvh = (f) => (/\.bvh$/i.test(f.name) ? 1 : 0);
    for (const file of [...files].sort((a, b) => isBvh(a) - isBvh(b))) {  // the clip first
      const bytes = new Uint8Array(await file.arrayBuffer());
      try {
        if (looksLikeBank(bytes)) this.loadBank(bytes, file.name);
        else if (looksLikeKanim(bytes)) this.loadClip(bytes, file.name);
        else this.loadOriginal(new TextDecoder().decode(bytes), file.name);
      } catch { /* shown by error() */ }
    }
  }

  // A clip (and original) written into the page by `keyanim view`.
  loadEmbedded() {
    const clip = document.getElementById('keyanim-embedded-clip');
    if (!clip) return false;
    const decode = (el) => Uint8Array.from(atob(el.textContent.trim()), (c) => c.charCodeAt(0));
    const original = document.getElementById('keyanim-embedded-original');
    try {
      this.loadClip(decode(clip), clip.dataset.name);
      if (original) this.loadOriginal(new TextDecoder().decode(decode(original)), original.dataset.name);
    } catch { /* shown by error() */ }
    return true;
  }

  // --- Scene and panels --------------------------------------------------------------------

  // What is shown: the clip, or the BVH when it is alone. Its nodes, frames and frame time.
  get subject() { return this.clip ?? this.original; }

  setup() {
    const clip = this.clip, s = this.subject;
    this.position = 0;
    this.clock = 0;
    this.size = skeletonSize(s.nodes) || 1;
    this.detectedUp = detectUpAxis(s.nodes);
    this.worstOverClip = clip && this.original ? this.compareAllFrames() : null;
    this.frameView();
    this.curves.setClip(clip, this.original);
    $('slider').max = String(s.frameCount - 1);
    $('facts').replaceChildren(...(clip ? clipFacts(clip, this.original) : bvhFacts(this.original)).flatMap(([k, v]) => [el('dt', k), el('dd', v)]));
    $('notes').textContent = clip ? noteLines(clip).join('\n') || '(none)' : '(a BVH has none: open its .kanim)';
    $('compare').hidden = !(clip && this.original);
    $('show-original').disabled = !clip;
    document.body.classList.add('loaded');
    this.show(0);
  }

  // The up axis shown: the control's, or the one detected from the rest pose (upaxis.js).
  get up() { return $('up').value === 'auto' ? this.detectedUp.axis : $('up').value; }

  // The figures and the camera for the subject: what the camera follows and frames comes from
  // every source frame of the main figure (framing.js), in the viewer's y-up space.
  frameView() {
    const s = this.subject, auto = $('up').options[0];
    auto.textContent = `auto (${this.detectedUp.axis}${this.detectedUp.ambiguous ? ', unclear' : ''})`;
    this.extent = clipExtent(s.nodes, s.frameCount, (f) => this.mainAt(f), this.size);
    this.view.setSkeleton(s.nodes, this.size, { decoded: !!this.clip, original: !!this.original }, this.extent, this.mainAt(this.position));
  }

  // World positions of the main figure (decoded, or the BVH alone) at frame position x, y-up.
  mainAt(x) { return this.clip ? this.decodedAt(x) : this.originalAt(x); }

  // The point the camera follows at frame position x (framing.js).
  followedAt(x) { return followedPoint(this.mainAt(x), this.extent.placeholders); }

  // Largest distance between original and decoded over every source frame both have, on the
  // points the encoder's error covers (joints, End Sites, shell points; each reading it lists).
  compareAllFrames() {
    const frames = Math.min(this.clip.frameCount, this.original.frameCount);
    let worst = { distance: 0, node: 0, point: 0, frame: 0 };
    for (let f = 0; f < frames; ++f) {
      const d = this.compareAt(f);
      if (d.distance > worst.distance) worst = { ...d, frame: f };
    }
    return worst;
  }

  // The largest distance at source frame f, and where.
  compareAt(f) {
    const { shell, readings } = measuredSettings(this.clip.notes, this.size);
    const o = this.original, values = samplePose(this.clip, f, this.values);
    const row = o.frames.subarray(f * o.channelCount, (f + 1) * o.channelCount);
    let worst = { distance: 0, node: 0, point: 0 };
    for (const reading of readings) {
      const d = largestDistance(measuredPoints(this.clip.nodes, values, shell, reading), measuredPoints(o.nodes, row, shell, reading), 4);
      if (d.distance > worst.distance) worst = d;
    }
    return worst;
  }

  decodedAt(x) { return toYUp(worldPositions(this.clip.nodes, samplePose(this.clip, x, this.values)), this.up); }

  // The original at frame position x: its nearest frame (a BVH has nothing in between).
  originalAt(x) {
    const o = this.original, f = Math.min(o.frameCount - 1, Math.max(0, Math.round(x)));
    return toYUp(worldPositions(o.nodes, o.frames.subarray(f * o.channelCount, (f + 1) * o.channelCount)), this.up);
  }

  // Draws frame position x everywhere.
  show(x) {
    const clip = this.clip, s = this.subject;
    this.position = x;
    const decoded = clip ? this.decodedAt(x) : null;
    let original = null, worst = null;
    if (!clip) {
      original = this.originalAt(x);
    } else if (this.original) {
      // Compared at the nearest source frame: the original has nothing in between.
      const f = Math.min(Math.max(Math.round(x), 0), this.original.frameCount - 1);
      original = this.originalAt(f);
      worst = this.compareAt(f);
      const w = this.worstOverClip;
      const where = (d) => nodeLabel(clip.nodes, d.node) + (d.point ? ` shell ${'xyz'[d.point - 1]}` : '');
      $('compare-frame').textContent = `${fmtLength(worst.distance)} at ${where(worst)} (${pct(worst.distance, this.size)} of the skeleton size${f === x ? '' : `; at frame ${f}, the nearest`})`;
      $('compare-clip').textContent = `${fmtLength(w.distance)} at ${where(w)}, frame ${w.frame} (${pct(w.distance, this.size)})`;
    }
    const withOriginal = !clip || $('show-original').checked;
    this.view.setPoses(decoded, withOriginal ? original : null, worst ? worst.node : -1, followedPoint(decoded ?? original, this.extent.placeholders));
    this.view.showOriginal(withOriginal);
    $('slider').value = String(x);
    const t = s.frameTime * x;
    $('frame-label').textContent = `frame ${fmtFrame(x)} / ${s.frameCount - 1} · ${t.toFixed(3)} s`;
    this.curves.setPosition(x);
  }

  // --- Playback ----------------------------------------------------------------------------

  // The frame position at clip time `seconds`: on the grid of the playback rate (source rate:
  // whole frames; 24/30/60/120 fps: in-betweens from the curves).
  positionAt(seconds) {
    const s = this.subject;
    if (!(s.frameTime > 0)) return 0;
    const rate = $('rate').value === 'source' ? 1 / s.frameTime : Number($('rate').value);
    return Math.floor(seconds * rate + 1e-9) / rate / s.frameTime;
  }

  tick(now) {
    if (!this.playing) return;
    const dt = this.lastTick ? (now - this.lastTick) / 1000 : 0;
    this.lastTick = now;
    const s = this.subject, duration = (s.frameCount - 1) * s.frameTime;
    this.clock += dt * Number($('speed').value);
    if (this.clock > duration) this.clock = duration > 0 ? this.clock % duration : 0;
    const x = this.positionAt(this.clock);
    if (x !== this.position) this.show(x);
    requestAnimationFrame((t) => this.tick(t));
  }

  setPlaying(on) {
    this.playing = on && !!this.subject && this.subject.frameCount > 1;
    $('play').textContent = this.playing ? 'Pause' : 'Play';
    this.lastTick = 0;
    if (this.playing) requestAnimationFrame((t) => this.tick(t));
  }

  bindControls() {
    this.view.follow = $('follow').checked;
    $('play').addEventListener('click', () => this.setPlaying(!this.playing));
    $('slider').addEventListener('input', () => {
      if (!this.subject) return;
      this.clock = Number($('slider').value) * this.subject.frameTime;
      this.show(this.positionAt(this.clock));
    });
    $('rate').addEventListener('change', () => this.subject && this.show(this.positionAt(this.clock)));
    $('show-original').addEventListener('change', () => this.clip && this.show(this.position));
    // Following on: the camera frames the body and moves with it; off: the whole clip's box.
    $('follow').addEventListener('change', () => {
      this.view.follow = $('follow').checked;
      if (this.subject) { this.view.frame(this.extent, this.followedAt(this.position)); this.show(this.position); }
    });
    $('up').addEventListener('change', () => { if (this.subject) { this.frameView(); this.show(this.position); } });
    document.addEventListener('keydown', (e) => {
      if (e.target.tagName === 'SELECT' || e.target.tagName === 'INPUT' && e.target.type !== 'range') return;
      if (e.code === 'Space') { e.preventDefault(); this.setPlaying(!this.playing); }
    });
  }

  bindFiles() {
    $('open').addEventListener('change', (e) => this.openFiles(e.target.files));
    $('bank-clips').addEventListener('change', (e) => {
      try { this.pickClip(Number(e.target.value)); } catch { /* shown by error() */ }
    });
    window.addEventListener('dragover', (e) => { e.preventDefault(); document.body.classList.add('dragging'); });
    window.addEventListener('dragleave', () => document.body.classList.remove('dragging'));
    window.addEventListener('drop', (e) => {
      e.preventDefault();
      document.body.classList.remove('dragging');
      this.openFiles(e.dataTransfer.files);
    });
  }

  message(text) { const m = $('message'); m.textContent = text; m.className = ''; }
  error(text) { const m = $('message'); m.textContent = text; m.className = 'error'; console.warn(text); }
}

function el(tag, text) { const e = document.createElement(tag); e.textContent = text; return e; }
const fmtLength = (d) => Number(d.toPrecision(3)).toString();
const pct = (d, size) => `${Number(((100 * d) / size).toPrecision(2))}%`;
const fmtFrame = (x) => (Number.isInteger(x) ? String(x) : x.toFixed(2));
