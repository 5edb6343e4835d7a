// The 3D view: skeletons as joints (spheres) and bones (lines) drawn with three.js, an orbit
// camera, and a ground grid scaled to the skeleton.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { fitCamera, followedPoint as followedPointOf } from './framing.js';

export const COLORS = { decoded: 0xf08c28, original: 0x3aa0ff, worst: 0xff3050 };

// One drawn skeleton: an instanced sphere per node and an instanced cylinder per bone
// (node -> parent), both of radius proportional to the skeleton size. No bone hangs from a
// placeholder (framing.js): Bandai's joint_Root -> Hips would be a stick from the origin to
// wherever the walker is.
class SkeletonFigure {
  // onTop: drawn over everything else (the original, so that it shows through the decoded figure).
  constructor(scene, nodes, color, radius, placeholders, onTop = false) {
    this.nodes = nodes;
    this.radius = radius;
    this.bones = nodes.map((n, i) => [i, n.parent]).filter(([, p]) => p >= 0 && !placeholders[p]);
    const material = new THREE.MeshLambertMaterial({ color, depthTest: !onTop });
    this.joints = new THREE.InstancedMesh(new THREE.SphereGeometry(radius, 12, 8), material, nodes.length);
    const cylinder = new THREE.CylinderGeometry(1, 1, 1, 8).translate(0, 0.5, 0);  // spans y 0..1
    this.links = new THREE.InstancedMesh(cylinder, material, Math.max(1, this.bones.length));
    this.links.count = this.bones.length;
    this.joints.frustumCulled = this.links.frustumCulled = false;  // they move every frame
    this.joints.renderOrder = this.links.renderOrder = onTop ? 1 : 0;
    scene.add(this.joints, this.links);
  }

  // positions: x, y, z per node (Float64Array from pose.js).
  update(positions) {
    const m = new THREE.Matrix4(), a = new THREE.Vector3(), b = new THREE.Vector3();
    const q = new THREE.Quaternion(), s = new THREE.Vector3(), up = new THREE.Vector3(0, 1, 0);
    for (let i = 0; i < this.nodes.length; ++i) {
      m.makeTranslation(positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]);
      this.joints.setMatrixAt(i, m);
    }
    this.bones.forEach(([child, parent], k) => {
      a.fromArray(positions, 3 * parent);
      b.fromArray(positions, 3 * child).sub(a);
      const length = b.length();
      q.setFromUnitVectors(up, length > 0 ? b.divideScalar(length) : up);
      m.compose(a, q, s.set(this.radius * 0.45, length, this.radius * 0.45));
      this.links.setMatrixAt(k, m);
    });
    this.joints.instanceMatrix.needsUpdate = this.links.instanceMatrix.needsUpdate = true;
  }

  set visible(v) { this.joints.visible = this.links.visible = v; }

  dispose(scene) {
    scene.remove(this.joints, this.links);
    this.joints.geometry.dispose();
    this.links.geometry.dispose();
    this.joints.material.dispose();
  }
}

export class View3D {
  constructor(canvas) {
    this.canvas = canvas;
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x1c1f26);
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x445566, 2.2));
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 1000);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.addEventListener('change', () => this.render());
    this.figures = {};
    this.follow = true;
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
  }

  resize() {
    const w = this.canvas.clientWidth || 1, h = this.canvas.clientHeight || 1;
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }

  // A new skeleton of length scale `size` (the joint size follows it); `shown` says which
  // figures there are ({ decoded, original }); `extent` is framing.js's clipExtent, on which the
  // grid and the camera are set; firstPose, the main figure's positions now.
  setSkeleton(nodes, size, shown, extent, firstPose) {
    for (const f of Object.values(this.figures)) f.dispose(this.scene);
    if (this.grid) { this.scene.remove(this.grid); this.grid.geometry.dispose(); }
    const radius = size * 0.012, ph = extent.placeholders;
    // With a clip, the original thinner and on top: where the two agree it shows as a blue core.
    this.figures = {};
    if (shown.decoded) this.figures.decoded = new SkeletonFigure(this.scene, nodes, COLORS.decoded, radius, ph);
    if (shown.original) this.figures.original = shown.decoded ? new SkeletonFigure(this.scene, nodes, COLORS.original, radius * 0.45, ph, true)
      : new SkeletonFigure(this.scene, nodes, COLORS.original, radius, ph);
    this.worst = this.worst ?? new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12), new THREE.MeshBasicMaterial({ color: COLORS.worst, wireframe: true }));
    this.worst.scale.setScalar(radius * 2.2);
    this.worst.visible = false;
    this.scene.add(this.worst);

    // The floor: the lowest point over the clip, under the whole path.
    const { min, max } = extent.world, span = Math.max(max[0] - min[0], max[2] - min[2]);
    this.grid = new THREE.GridHelper(Math.max(size * 8, span * 1.25), 32, 0x66707f, 0x3a404c);
    this.grid.position.set((min[0] + max[0]) / 2, min[1], (min[2] + max[2]) / 2);
    this.scene.add(this.grid);
    this.size = size;
    this.frame(extent, followedPointOf(firstPose, ph));
  }

  // Sets the camera on the clip: following, on the box the body spans around the followed
  // point (at `followed` now); otherwise on the box of every node over the clip. The view
  // direction is kept (the user's orbit), or the default one the first time.
  frame(extent, followed) {
    const direction = this.framed ? this.camera.position.clone().sub(this.controls.target).toArray() : undefined;
    const options = { aspect: this.camera.aspect, fovDegrees: this.camera.fov, direction, minRadius: this.size / 4 };
    const fit = this.follow ? fitCamera(extent.body, { ...options, offset: followed }) : fitCamera(extent.world, options);
    this.camera.near = Math.min(this.size / 200, fit.distance / 100);
    this.camera.far = Math.max(this.size * 200, (fit.distance + fit.radius) * 4);
    this.camera.position.fromArray(fit.position);
    this.camera.updateProjectionMatrix();
    this.controls.target.fromArray(fit.target);
    this.controls.update();
    this.framed = true;
    this.lastFollowed = new THREE.Vector3().fromArray(followed);
  }

  // Normalized device coordinates of positions (x, y, z per point) through the camera: a point
  // is in the picture when x and y are within [-1, 1] and z within [-1, 1]. For the tests.
  project(positions) {
    this.camera.updateMatrixWorld();
    const out = [], v = new THREE.Vector3();
    for (let i = 0; i < positions.length; i += 3) out.push(v.set(positions[i], positions[i + 1], positions[i + 2]).project(this.camera).toArray());
    return out;
  }

  // Moves the figures (either may be null); with `follow`, the camera and its target move with
  // the followed point ([x, y, z], framing.js), keeping the view as the user set it.
  setPoses(decoded, original, worstNode, followed) {
    if (decoded) this.figures.decoded?.update(decoded);
    if (original && this.figures.original) this.figures.original.update(original);
    if (worstNode >= 0 && original && decoded) {
      this.worst.position.set(decoded[3 * worstNode], decoded[3 * worstNode + 1], decoded[3 * worstNode + 2]);
      this.worst.visible = true;
    } else if (this.worst) {
      this.worst.visible = false;
    }
    const point = new THREE.Vector3().fromArray(followed);
    if (this.follow && this.lastFollowed) {
      const shift = point.clone().sub(this.lastFollowed);
      this.controls.target.add(shift);
      this.camera.position.add(shift);
      this.controls.update();
    }
    this.lastFollowed = point;
    this.render();
  }

  showOriginal(v) { if (this.figures.original) this.figures.original.visible = v; this.render(); }
  render() { this.renderer.render(this.scene, this.camera); }
}


