// Entry point of the page: the app, a clip embedded by `keyanim view` if there is one, and the
// test hook window.keyanim.
import { App } from './app.js';
import { samplePose } from 'keyanim-three/decoder/sample.js';
import { worldPositions } from 'keyanim-three/decoder/pose.js';

const app = new App();
app.loadEmbedded();

// For tests and scripts: load(arrayBuffer) opens a .kanim (throws on a bad file),
// loadBank(arrayBuffer) a .kbank (throws on a bad index; lists its clips and shows clip 0,
// or says why it does not decode), pickClip(i) shows the bank's clip i (throws on a damaged
// one), bankClips lists the bank's clips ({ index, name, frameCount, duration }) and
// bankShown the one shown; loadOriginal(text) a BVH; sampleWorld(x) gives every node's world position [x, y, z] at
// frame position x, in node order (the order of `keyanim sample --world --json`); frameCount and
// nodeNames are the clip's, or the BVH's when it is shown alone; inView(x) shows frame position
// x and gives, per node of the figure shown, its normalized device coordinates through the
// page's camera and whether it is a placeholder (framing.js); curveAt(c, x) is channel c at frame
// position x as the curve panel draws it (a quaternion node's rotation channel: its Euler angle,
// spec Appendix B).
window.keyanim = {
  load(buffer, name = 'clip.kanim') { app.loadClip(new Uint8Array(buffer), name); },
  loadBank(buffer, name = 'clips.kbank') { app.loadBank(new Uint8Array(buffer), name); },
  pickClip(i) { app.pickClip(i); },
  get bankClips() { return app.bank ? app.bank.clips.map(({ index, name, frameCount, duration }) => ({ index, name, frameCount, duration })) : []; },
  get bankShown() { return app.bank ? app.bankShown : -1; },
  loadOriginal(text, name = 'original.bvh') { app.loadOriginal(text, name); },
  get frameCount() { return app.subject ? app.subject.frameCount : 0; },
  get nodeNames() { return app.subject ? app.subject.nodes.map((n) => n.name) : []; },
  sampleWorld(x) {
    if (!app.clip) throw new Error('no clip loaded');
    const p = worldPositions(app.clip.nodes, samplePose(app.clip, x));
    return Array.from({ length: app.clip.nodes.length }, (_, i) => [p[3 * i], p[3 * i + 1], p[3 * i + 2]]);
  },
  show(x) { app.show(x); },
  curveAt(c, x) {
    if (!app.clip) throw new Error('no clip loaded');
    return app.curves.valueAt(c, x);
  },
  inView(x) {
    app.show(x);
    return app.view.project(app.mainAt(x)).map((ndc, i) => ({ ndc, placeholder: app.extent.placeholders[i] === 1 }));
  },
  get up() { return app.subject ? app.up : null; },
  get comparison() { return app.original ? { ...app.worstOverClip } : null; },
  app,
};
