// Checks keyanim's glTF exports with tools that share no code with keyanim:
//  - the Khronos glTF-Validator: no error and no warning;
//  - the asset's structure against the BVH: one node per joint and End Site (End Sites named
//    "End Site of PARENT", as keyanim sample --world names them), hierarchy, rest translations =
//    OFFSET, one animation spanning the clip, accessors with min/max; one skin whose joints are
//    all those nodes, inverse bind matrices = the inverse of each node's rest world matrix (from
//    the BVH's OFFSETs), bound by a mesh node that is a scene root without a transform; the frame
//    rate and range in the scene's, the animation's and the asset's extras;
//  - three.js (GLTFLoader + AnimationMixer, under node) playing the animation at every source
//    frame, every node's world position and every joint's shell points (at the export's shell
//    distance along its local axes) compared with forward kinematics of the BVH files below, and
//    the skinned bone mesh as three.js deforms it (SkinnedMesh.applyBoneTransform): each bone's
//    head vertex at its parent joint, its tail at its node, within the same bounds; the points of
//      CLIP.bvh: the .kanim decoded by keyanim (what the export had to reproduce): within the
//                export's tolerance (the rotation fit's guarantee);
//      ORIG.bvh: the original capture: joints and End Sites within the clip's tolerance plus the
//                export's (the encoder's guarantee plus the fit's); shell points reported.
// usage: node check_export.mjs [--percent P] [--linear | --fps] ORIG.bvh CLIP.bvh OUT.glb [ORIG CLIP GLB ...]
//   OUT may also be a .gltf (its .bin beside it): validated as it is, played as the same GLB.
//   --percent P  the tolerance the clips were encoded with, in percent of the skeleton size
//                (default 0.05); the export's tolerance must be that (its default)
//   --linear     the exports were made with --linear: every sampler must be LINEAR
//   --fps        the exports were resampled (--fps): every sampler LINEAR, and the error is
//                bounded by what the export reports (asset.extras.keyanim.max_error), not by
//                the tolerance
// Prints one line per file; exits 1 if any check fails.
import fs from 'node:fs';
import path from 'node:path';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import validator from 'gltf-validator';
import { readBvh, skeletonSize, framePoints, pointName } from './bvh.mjs';

const args = process.argv.slice(2);
let percent = 0.05, fpsMode = false, linearOnly = false;
const files = [];
for (let i = 0; i < args.length; ++i) {
  if (args[i] === '--percent') percent = Number(args[++i]);
  else if (args[i] === '--fps') fpsMode = linearOnly = true;
  else if (args[i] === '--linear') linearOnly = true;
  else files.push(args[i]);
}
if (files.length === 0 || files.length % 3 !== 0) {
  console.error('usage: node check_export.mjs [--percent P] [--linear | --fps] ORIG.bvh CLIP.bvh OUT.glb ...');
  process.exit(2);
}

let failures = 0;
function fail(file, message) {
  console.error(`FAIL ${file}: ${message}`);
  ++failures;
}

// The JSON chunk of a GLB.
function glbJson(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (view.getUint32(0, true) !== 0x46546c67) throw new Error('not a GLB');
  const length = view.getUint32(12, true);
  return JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + length)));
}

// A .glb as bytes, or a .gltf with its external buffer: {json, glb (bytes to play), validate()}.
function readAsset(file) {
  const name = path.basename(file);
  if (!file.endsWith('.gltf')) {
    const bytes = fs.readFileSync(file);
    const json = glbJson(bytes), at = 20 + bytes.readUInt32LE(12);
    json.bin = bytes.length > at ? bytes.subarray(at + 8) : new Uint8Array(0);
    return { json, glb: bytes, validate: () => validator.validateBytes(new Uint8Array(bytes), { uri: name, maxIssues: 0 }) };
  }
  const text = fs.readFileSync(file, 'utf8');
  const json = JSON.parse(text);
  const external = (uri) => new Uint8Array(fs.readFileSync(path.join(path.dirname(file), decodeURIComponent(uri))));
  const bin = json.buffers ? external(json.buffers[0].uri) : new Uint8Array(0);
  const glb = makeGlb(json, bin);
  json.bin = bin;
  return { json, glb,
           validate: () => validator.validateString(text, { uri: name, maxIssues: 0, externalResourceFunction: async (u) => external(u) }) };
}

// The same asset as a GLB: the buffer embedded instead of referenced.
function makeGlb(json, bin) {
  const copy = JSON.parse(JSON.stringify(json));
  if (copy.buffers) delete copy.buffers[0].uri;
  let text = JSON.stringify(copy);
  while (text.length % 4) text += ' ';
  const jsonBytes = new TextEncoder().encode(text);
  const binLength = bin.length ? 8 + bin.length + ((4 - bin.length % 4) % 4) : 0;
  const out = Buffer.alloc(12 + 8 + jsonBytes.length + binLength);
  out.writeUInt32LE(0x46546c67, 0); out.writeUInt32LE(2, 4); out.writeUInt32LE(out.length, 8);
  out.writeUInt32LE(jsonBytes.length, 12); out.writeUInt32LE(0x4e4f534a, 16); out.set(jsonBytes, 20);
  if (bin.length) {
    const at = 20 + jsonBytes.length;
    out.writeUInt32LE(binLength - 8, at); out.writeUInt32LE(0x004e4942, at + 4); out.set(bin, at + 8);
  }
  return out;
}

async function validate(file, asset) {
  const report = await asset.validate();
  const { numErrors, numWarnings, messages } = report.issues;
  if (numErrors > 0 || numWarnings > 0) {
    const shown = messages.filter((m) => m.severity <= 1).slice(0, 5).map((m) => `${m.code} ${m.pointer}: ${m.message}`);
    fail(file, `glTF-Validator: ${numErrors} errors, ${numWarnings} warnings: ${shown.join('; ')}`);
  }
}

function checkStructure(file, gltf, bvh) {
  const nodes = gltf.nodes || [];
  const meshed = hasSegment(bvh);
  if (nodes.length !== bvh.nodes.length + meshed)
    return fail(file, `${nodes.length} nodes, the BVH has ${bvh.nodes.length}${meshed ? ' and a mesh' : ''}`);
  const roots = [];
  bvh.nodes.forEach((n, j) => {
    const g = nodes[j];
    const name = n.endSite && !n.name ? `End Site of ${bvh.nodes[n.parent].name}` : n.name;
    if (g.name !== name) fail(file, `node ${j} is named '${g.name}', expected '${name}'`);
    const t = g.translation || [0, 0, 0];
    if (t.some((v, a) => v !== n.offset[a])) fail(file, `node ${j} (${name}): translation ${t} is not OFFSET ${n.offset}`);
    if (g.rotation || g.scale || g.matrix) fail(file, `node ${j} (${name}): rest pose is not OFFSET only`);
    const children = bvh.nodes.map((c, k) => k).filter((k) => bvh.nodes[k].parent === j);
    if (JSON.stringify(g.children || []) !== JSON.stringify(children)) fail(file, `node ${j} (${name}): children ${g.children}`);
    if (n.parent < 0) roots.push(j);
  });
  checkSkin(file, gltf, bvh, roots);
  if (JSON.stringify(gltf.scenes[gltf.scene].nodes) !== JSON.stringify(meshed ? [...roots, bvh.nodes.length] : roots))
    fail(file, 'scene roots are not the BVH roots (and the mesh node)');
  const animations = (gltf.animations || []).length;
  if (animations !== (bvh.frames > 0 ? 1 : 0)) return fail(file, `${animations} animations for ${bvh.frames} frames`);
  for (const a of gltf.accessors || [])
    if (!a.min || !a.max) fail(file, 'an accessor without min/max');
  for (const s of animations ? gltf.animations[0].samplers : [])
    if (!['LINEAR', 'CUBICSPLINE'].includes(s.interpolation) || (linearOnly && s.interpolation !== 'LINEAR'))
      fail(file, `sampler interpolation ${s.interpolation}`);
}

// Whether a bone mesh can be drawn: some node below another with a non-zero OFFSET.
function hasSegment(bvh) { return bvh.nodes.some((n) => n.parent >= 0 && n.offset.some((o) => o !== 0)); }

// Accessor `index` as numbers (integers as stored, normalized or not).
function accessorValues(gltf, bin, index) {
  const a = gltf.accessors[index], view = gltf.bufferViews[a.bufferView];
  const k = { SCALAR: 1, VEC3: 3, VEC4: 4, MAT4: 16 }[a.type];
  const Type = { 5121: Uint8Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array }[a.componentType];
  const at = bin.byteOffset + (view.byteOffset || 0) + (a.byteOffset || 0);
  return Array.from(new Type(bin.buffer.slice(at, at + Type.BYTES_PER_ELEMENT * k * a.count)));
}

// The skin and its mesh node; the timing extras (fps = 1 / Frame Time, a frame range as long as
// the BVH: with --frames the BVH is that range, so its first frame is not known here).
function checkSkin(file, gltf, bvh, roots) {
  const skin = (gltf.skins || [])[0];
  if (!skin || gltf.skins.length !== 1) return fail(file, 'not one skin');
  if (JSON.stringify(skin.joints) !== JSON.stringify(bvh.nodes.map((n, j) => j))) fail(file, 'skin joints are not every node');
  if (roots.length === 1 ? skin.skeleton !== roots[0] : skin.skeleton !== undefined) fail(file, `skin.skeleton ${skin.skeleton}`);
  const rest = [];
  bvh.nodes.forEach((n, j) => { rest[j] = n.offset.map((o, a) => o + (n.parent < 0 ? 0 : rest[n.parent][a])); });
  const ibm = accessorValues(gltf, gltf.bin, skin.inverseBindMatrices);
  bvh.nodes.forEach((n, j) => {
    const want = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -rest[j][0], -rest[j][1], -rest[j][2], 1];
    if (want.some((v, c) => ibm[16 * j + c] !== Math.fround(v))) fail(file, `inverse bind matrix of node ${j} is not its rest pose's`);
  });
  const mesh = gltf.nodes[bvh.nodes.length] || { mesh: 0, skin: 0 };  // none without a segment to draw
  if (mesh.mesh !== 0 || mesh.skin !== 0 || mesh.translation || mesh.rotation || mesh.scale || mesh.matrix || mesh.children)
    fail(file, 'the mesh node is not a skinned mesh without transform or children');
  const frames = bvh.frames;
  for (const at of [gltf.scenes[gltf.scene], gltf.asset, ...(frames ? [gltf.animations[0]] : [])]) {
    const k = at.extras && at.extras.keyanim;
    if (!k || k.frame_count !== frames || (frames && !(k.first_frame >= 0 && k.last_frame - k.first_frame === frames - 1)) ||
        (bvh.frameTime > 0 && !(Math.abs(k.fps * bvh.frameTime - 1) <= 1e-12)))
      fail(file, `timing extras ${JSON.stringify(k)}: expected ${frames} frames at 1/${bvh.frameTime} fps`);
  }
}

async function loadGlb(bytes) {
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  return new Promise((resolve, reject) => new GLTFLoader().parse(ab, '', resolve, reject));
}

// The bone mesh's vertices that sit at their joint's rest position (each bone's head and tail):
// [{mesh (the THREE.SkinnedMesh), vertex, joint}]; three.js must move each with its joint.
function skinnedVertices(gltf, json, bvh) {
  let mesh = null;
  gltf.scene.traverse((o) => { if (o.isSkinnedMesh) mesh = o; });
  if (!mesh) return [];
  const rest = [];
  bvh.nodes.forEach((n, j) => { rest[j] = n.offset.map((o, a) => o + (n.parent < 0 ? 0 : rest[n.parent][a])); });
  const { position, skinIndex, skinWeight } = mesh.geometry.attributes;
  const out = [];
  for (let i = 0; i < position.count; ++i) {
    const joint = skinIndex.getX(i);
    if (skinWeight.getX(i) !== 1) throw new Error(`vertex ${i}: weight ${skinWeight.getX(i)}, not 1`);
    if ([position.getX(i), position.getY(i), position.getZ(i)].every((x, a) => x === Math.fround(rest[joint][a])))
      out.push({ mesh, vertex: i, joint });
  }
  const segments = bvh.nodes.filter((n) => n.parent >= 0 && n.offset.some((o) => o !== 0)).length;
  if (out.length !== 2 * segments) throw new Error(`${out.length} bone ends in the mesh, expected ${2 * segments}`);
  return out;
}

// Plays the animation at source frame f (time f * frameTime) and returns the measured points in
// framePoints' order.
function player(gltf, json, bvh, shell) {
  const objects = [];
  for (const [object, ref] of gltf.parser.associations)
    if (ref && ref.nodes !== undefined && ref.nodes < bvh.nodes.length) objects[ref.nodes] = object;
  const skinned = skinnedVertices(gltf, json, bvh);
  const mixer = new THREE.AnimationMixer(gltf.scene);
  const action = mixer.clipAction(gltf.animations[0]);
  action.setLoop(THREE.LoopOnce);
  action.clampWhenFinished = true;
  action.play();
  const v = new THREE.Vector3();
  return (f) => {
    action.reset();  // LoopOnce pauses at the end; start again from time 0
    mixer.setTime(f * bvh.frameTime);
    gltf.scene.updateMatrixWorld(true);
    const points = objects.map((o) => v.setFromMatrixPosition(o.matrixWorld).toArray());
    points.skinned = skinned.map(({ mesh, vertex, joint }) =>
      [joint, mesh.applyBoneTransform(vertex, v.fromBufferAttribute(mesh.geometry.attributes.position, vertex))
        .applyMatrix4(mesh.matrixWorld).toArray()]);
    if (shell > 0)
      bvh.nodes.forEach((n, j) => {
        if (n.endSite) return;
        for (let a = 0; a < 3; ++a) {
          const local = [0, 0, 0];
          local[a] = shell;
          points.push(v.fromArray(local).applyMatrix4(objects[j].matrixWorld).toArray());
        }
      });
    return points;
  };
}

function distance(a, b) { return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

async function checkFile(origPath, clipPath, glbPath) {
  const name = path.basename(glbPath);
  const asset = readAsset(glbPath);
  await validate(name, asset);
  const json = asset.json, bytes = asset.glb;
  const orig = readBvh(origPath), clip = readBvh(clipPath);
  checkStructure(name, json, clip);
  const size = skeletonSize(orig);
  const extras = json.asset.extras.keyanim;
  const tol = extras.tolerance, shell = extras.shell_distance;
  const clipTol = percent / 100 * size;
  if (!(Math.abs(tol - clipTol) <= 1e-5 * clipTol)) fail(name, `tolerance ${tol}, expected ${percent}% of ${size}`);
  // The export takes the shell distance the clip was encoded with (its notes): 2% of the
  // original's size, as the encoder measured it.
  if (!(Math.abs(shell - 0.02 * size) <= 1e-9 * size)) fail(name, `shell distance ${shell}, expected 2% of ${size}`);
  if (clip.frames !== orig.frames) fail(name, `the decoded clip has ${clip.frames} frames, the original ${orig.frames}`);

  if (clip.frames === 0) return console.log(`${name.padEnd(48)}     0 frames: nodes only`);
  const gltf = await loadGlb(bytes);
  const duration = (clip.frames - 1) * clip.frameTime;
  if (!(Math.abs(gltf.animations[0].duration - duration) <= 1e-6 * Math.max(1, duration)))
    fail(name, `animation lasts ${gltf.animations[0].duration} s, the clip ${duration} s`);
  const play = player(gltf, json, clip, shell);
  // Bounds: the fit's tolerance against the clip (or the reported error with --fps); against
  // the original, the encoder's plus the fit's. Slack: binary64 evaluation-order differences.
  const slack = 1e-6 * tol + 1e-9 * size;
  const boundClip = (fpsMode ? extras.max_error : tol) + slack;
  const boundOrig = clipTol + (fpsMode ? extras.max_error : tol) + slack;
  const worst = { clip: [0], origNode: [0], origShell: [0], clipVsOrig: [0], mesh: [0] };
  const note = (key, e, p, f) => { if (!(e <= worst[key][0])) worst[key] = [e, p, f]; };
  const nodeCount = clip.nodes.length;
  for (let f = 0; f < clip.frames; ++f) {
    const got = play(f);
    const refClip = framePoints(clip, f, shell), refOrig = framePoints(orig, f, shell);
    if (got.length !== refClip.length) return fail(name, `${got.length} points played, ${refClip.length} expected`);
    for (let p = 0; p < got.length; ++p) {
      note('clip', distance(got[p], refClip[p]), p, f);
      note(p < nodeCount ? 'origNode' : 'origShell', distance(got[p], refOrig[p]), p, f);
      note('clipVsOrig', distance(refClip[p], refOrig[p]), p, f);
    }
    for (const [joint, at] of got.skinned) note('mesh', distance(at, refClip[joint]), joint, f);
  }
  const where = (w) => (w.length > 1 ? `${pointName(clip, w[1])}, frame ${w[2]}` : '-');
  if (!(worst.clip[0] <= boundClip)) fail(name, `three.js vs the clip: ${worst.clip[0]} at ${where(worst.clip)} > ${boundClip}`);
  // The mesh's float32 positions and inverse bind matrices round by a few ulps of the skeleton.
  if (!(worst.mesh[0] <= boundClip + 1e-6 * size))
    fail(name, `the skinned bone mesh vs the clip: ${worst.mesh[0]} at ${where(worst.mesh)} > ${boundClip + 1e-6 * size}`);
  if (!(worst.origNode[0] <= boundOrig))
    fail(name, `three.js vs the original: ${worst.origNode[0]} at ${where(worst.origNode)} > ${boundOrig}`);
  // In units of the tolerance: three.js vs clip (all points), vs original (nodes; shell), clip vs original.
  const r = (x) => (x / tol).toFixed(3);
  console.log(`${name.padEnd(48)} ${String(clip.frames).padStart(5)} frames ${String(bytes.length).padStart(9)} B  ` +
              `tol ${tol.toPrecision(4)}  player-vs-clip ${r(worst.clip[0])}  vs-orig nodes ${r(worst.origNode[0])} ` +
              `shell ${r(worst.origShell[0])}  clip-vs-orig ${r(worst.clipVsOrig[0])}  mesh ${r(worst.mesh[0])}  (${where(worst.clip)})`);
}

for (let i = 0; i < files.length; i += 3) {
  try {
    await checkFile(files[i], files[i + 1], files[i + 2]);
  } catch (e) {
    fail(path.basename(files[i + 2]), e.stack || String(e));
  }
}
if (failures > 0) {
  console.error(`${failures} check(s) failed`);
  process.exit(1);
}
