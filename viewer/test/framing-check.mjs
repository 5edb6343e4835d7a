// The framing tests' checks (framing.test.mjs, framing_corpus.test.mjs): poses of a parsed BVH
// turned y-up, the clip's extent, three.js's camera on a fit, and "every node in the picture".
import assert from 'node:assert/strict';
import * as THREE from 'three';
import { clipExtent, followedPoint, fitCamera } from '../src/framing.js';
import { toYUp } from '../src/upaxis.js';
import { worldPositions, skeletonSize } from 'keyanim-three/decoder/pose.js';

export const ASPECT = 1.6, FOV = 40;
export const poses = (bvh, up = 'y') => Array.from({ length: bvh.frameCount }, (_, f) =>
  toYUp(worldPositions(bvh.nodes, bvh.frames.subarray(f * bvh.channelCount, (f + 1) * bvh.channelCount)), up));
export const extentOf = (bvh, p) => clipExtent(bvh.nodes, bvh.frameCount, (f) => p[f], skeletonSize(bvh.nodes));

export function camera(fit) {
  const c = new THREE.PerspectiveCamera(FOV, ASPECT, 0.01, 1e6);
  c.position.fromArray(fit.position);
  c.lookAt(new THREE.Vector3().fromArray(fit.target));
  c.updateMatrixWorld();
  return c;
}

// The nodes (indices) at frame f that project outside the camera moved by `shift`.
export function outside(cam, positions, shift, nodes) {
  const out = [], v = new THREE.Vector3();
  for (const i of nodes) {
    v.set(positions[3 * i] - shift[0], positions[3 * i + 1] - shift[1], positions[3 * i + 2] - shift[2]).project(cam);
    if (!(Math.abs(v.x) <= 1 && Math.abs(v.y) <= 1 && Math.abs(v.z) < 1)) out.push(i);
  }
  return out;
}

// Every node in the picture at every frame: without following, the camera on the clip's box;
// following, the camera on the body's box and moved with the followed point.
export function expectFramed(bvh, p, label) {
  const e = extentOf(bvh, p), all = bvh.nodes.map((_, i) => i), body = all.filter((i) => !e.placeholders[i]);
  const still = camera(fitCamera(e.world, { aspect: ASPECT, fovDegrees: FOV }));
  const c0 = followedPoint(p[0], e.placeholders);
  const moving = camera(fitCamera(e.body, { aspect: ASPECT, fovDegrees: FOV, offset: c0 }));
  for (let f = 0; f < p.length; ++f) {
    const lost = outside(still, p[f], [0, 0, 0], all);
    assert.deepEqual(lost, [], `${label}, frame ${f}, whole-clip framing: ${lost.map((i) => bvh.nodes[i].name)} outside`);
    const c = followedPoint(p[f], e.placeholders), shift = c.map((x, r) => x - c0[r]);
    const lostFollowing = outside(moving, p[f], shift, body);
    assert.deepEqual(lostFollowing, [], `${label}, frame ${f}, following: ${lostFollowing.map((i) => bvh.nodes[i].name)} outside`);
  }
  return e;
}
