// What the viewer's camera follows and frames (src/framing.js), and the up axis it shows
// (src/upaxis.js), on a Bandai-like clip (test/bandai-like.mjs: a ROOT that stays at the origin,
// its child Hips walking 800 units), and on data/'s CMU walk (the corpus' Bandai walk and
// MakeHuman's z-up files: framing_corpus.test.mjs). "In the picture" is checked with three.js's own
// camera: every point projects inside the view (normalized device coordinates within [-1, 1]).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import * as THREE from 'three';
import { parseBvh } from '../src/bvh.js';
import { followedPoint, fitCamera, VIEW_DIRECTION } from '../src/framing.js';
import { detectUpAxis } from '../src/upaxis.js';
import { skeletonSize } from 'keyanim-three/decoder/pose.js';
import { ASPECT, FOV, poses, extentOf, camera, outside, expectFramed } from './framing-check.mjs';
import { bandaiLikeBvh } from './bandai-like.mjs';
import { sourceDir } from './paths.mjs';

test('Bandai-like: the static ROOT is a placeholder; the followed point moves with Hips', () => {
  const bvh = parseBvh(bandaiLikeBvh()), p = poses(bvh), e = extentOf(bvh, p), size = skeletonSize(bvh.nodes);
  assert.deepEqual(bvh.nodes.map((n, i) => e.placeholders[i] ? n.name : null).filter(Boolean), ['joint_Root']);
  const hips = bvh.nodes.findIndex((n) => n.name === 'Hips'), c0 = followedPoint(p[0], e.placeholders);
  for (let f = 0; f < p.length; ++f) {
    const c = followedPoint(p[f], e.placeholders);
    const off = [0, 1, 2].map((r) => (c[r] - c0[r]) - (p[f][3 * hips + r] - p[0][3 * hips + r]));
    assert.ok(Math.hypot(...off) <= 0.05 * size, `frame ${f}: the followed point is ${Math.hypot(...off)} from moving with Hips`);
    assert.deepEqual([p[f][0], p[f][1], p[f][2]], [0, 0, 0], 'node 0 stays at the origin (following it would lose the walker)');
  }
  const walked = followedPoint(p[p.length - 1], e.placeholders)[2] - c0[2];
  assert.ok(walked > 790 && walked < 810, `the followed point walked ${walked} along z`);
});

test('Bandai-like: every joint is in the picture at every frame, following or not', () => {
  const bvh = parseBvh(bandaiLikeBvh());
  expectFramed(bvh, poses(bvh), 'Bandai-like');
});

// The check above fails on the viewer's old camera: set on the first pose's box at 1.5 skeleton
// sizes, moving with node 0.
test('the old camera (first pose, following node 0) loses the walker: the check can fail', () => {
  const bvh = parseBvh(bandaiLikeBvh()), p = poses(bvh), size = skeletonSize(bvh.nodes);
  const box = new THREE.Box3();
  for (let i = 0; i < p[0].length; i += 3) box.expandByPoint(new THREE.Vector3(p[0][i], p[0][i + 1], p[0][i + 2]));
  const centre = box.getCenter(new THREE.Vector3()).toArray();
  const old = camera({ target: centre, position: centre.map((c, r) => c + size * VIEW_DIRECTION[r]) });
  const head = bvh.nodes.findIndex((n) => n.name === 'Head');
  const lostAt = p.findIndex((q) => outside(old, q, [0, 0, 0], [head]).length > 0);
  assert.ok(lostAt > 0 && lostAt < p.length - 1, `the old camera keeps the head in view until frame ${lostAt}`);
});

test("data/'s CMU walk: no placeholder (Hips is the moving root), every joint framed", () => {
  const bvh = parseBvh(fs.readFileSync(path.join(sourceDir, 'data/cmu_02_01_walk.bvh'), 'utf8'));
  const e = expectFramed(bvh, poses(bvh), 'cmu_02_01_walk');
  assert.equal(e.placeholders.reduce((a, b) => a + b, 0), 0);
});

test('a one-point clip gets a camera at some distance (minRadius), not on the point', () => {
  const point = { min: [1, 2, 3], max: [1, 2, 3] };
  const fit = fitCamera(point, { minRadius: 0.5, fovDegrees: FOV, aspect: ASPECT });
  assert.deepEqual(fit.target, [1, 2, 3]);
  assert.ok(Math.abs(fit.distance - (1.05 * 0.5) / Math.sin((FOV * Math.PI) / 360)) < 1e-12, `distance ${fit.distance}`);
  const c = camera(fit);
  assert.deepEqual(outside(c, [1.2, 2.2, 3], [0, 0, 0], [0]), [], 'a point 0.28 from the target is in view');
});

test('up axis: y detected on y-up skeletons, z on z-up ones; a z-up clip is shown as its y-up twin', () => {
  const y = parseBvh(bandaiLikeBvh('y')), z = parseBvh(bandaiLikeBvh('z'));
  assert.deepEqual([detectUpAxis(y.nodes).axis, detectUpAxis(y.nodes).ambiguous], ['y', false]);
  assert.deepEqual([detectUpAxis(z.nodes).axis, detectUpAxis(z.nodes).ambiguous], ['z', false]);
  const cmu = parseBvh(fs.readFileSync(path.join(sourceDir, 'data/cmu_02_01_walk.bvh'), 'utf8'));
  assert.equal(detectUpAxis(cmu.nodes).axis, 'y');
  // Turned upright, the z-up file's positions are the y-up file's (to the fixture's 6 decimals).
  const py = poses(y), pz = poses(z, 'z');
  for (let f = 0; f < py.length; ++f) for (let k = 0; k < py[f].length; ++k) assert.ok(Math.abs(py[f][k] - pz[f][k]) < 1e-4, `frame ${f}, value ${k}`);
  // A skeleton as deep as it is tall says so.
  const cube = parseBvh('HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 3 Xrotation Yrotation Zrotation\nEnd Site\n{\nOFFSET 0 10 10\n}\n}\nMOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0\n');
  assert.deepEqual([detectUpAxis(cube.nodes).axis, detectUpAxis(cube.nodes).ambiguous], ['y', true]);
});

