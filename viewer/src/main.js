// Entry point of the page: the app, a clip embedded by `keyanim view` if there is one, and the
// test hook window.keyanim.
import { App } from './app.js';
import { samplePose } from 'keyanim-three/decoder/sample.js';
import { worldPositions } from 'keyanim-three/decoder/pose.js';

const app = new App();
app.loadEmbedded();

// For tests and scripts: load(arrayBuffer) opens a .kanim (throws on a bad file),
// loadOriginal(text) a BVH; sampleWorld(x) gives every node's world position [x, y, z] at
// frame position x, in node order (the order of `keyanim sample --world --json`).
window.keyanim = {
  load(buffer, name = 'clip.kanim') { app.loadClip(new Uint8Array(buffer), name); },
  loadOriginal(text, name = 'original.bvh') { app.loadOriginal(text, name); },
  get frameCount() { return app.clip ? app.clip.frameCount : 0; },
  get nodeNames() { return app.clip ? app.clip.nodes.map((n) => n.name) : []; },
  sampleWorld(x) {
    if (!app.clip) throw new Error('no clip loaded');
    const p = worldPositions(app.clip.nodes, samplePose(app.clip, x));
    return Array.from({ length: app.clip.nodes.length }, (_, i) => [p[3 * i], p[3 * i + 1], p[3 * i + 2]]);
  },
  show(x) { app.show(x); },
  get comparison() { return app.original ? { ...app.worstOverClip } : null; },
  app,
};
