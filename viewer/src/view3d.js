// The 3D view: skeletons as joints (spheres) and bones (lines) drawn with three.js, an orbit
// camera, and a ground grid scaled to the skeleton.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

export const COLORS = { decoded: 0xf08c28, original: 0x3aa0ff, worst: 0xff3050 };

// One drawn skeleton: an instanced sphere per node and an instanced cylinder per bone
// (node -> parent), both of radius proportional to the skeleton size.
class SkeletonFigure {
  // onTop: drawn over everything else (the original, so that it shows through the decoded figure).
  constructor(scene, nodes, color, radius, onTop = false) {
    this.nodes = nodes;
    this.radius = radius;
    this.bones = nodes.map((n, i) => [i, n.parent]).filter(([, p]) => p >= 0);
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

  // A new skeleton of length scale `size`: the grid, the camera and the joint size follow it.
  setSkeleton(nodes, size, firstPose, withOriginal) {
    for (const f of Object.values(this.figures)) f.dispose(this.scene);
    if (this.grid) { this.scene.remove(this.grid); this.grid.geometry.dispose(); }
    const radius = size * 0.012;
    // The original thinner and on top: where the two agree it shows as a blue core.
    this.figures = { decoded: new SkeletonFigure(this.scene, nodes, COLORS.decoded, radius) };
    if (withOriginal) this.figures.original = new SkeletonFigure(this.scene, nodes, COLORS.original, radius * 0.45, true);
    this.worst = this.worst ?? new THREE.Mesh(new THREE.SphereGeometry(1, 16, 12), new THREE.MeshBasicMaterial({ color: COLORS.worst, wireframe: true }));
    this.worst.scale.setScalar(radius * 2.2);
    this.worst.visible = false;
    this.scene.add(this.worst);

    const box = boundsOf(firstPose);
    const center = box.getCenter(new THREE.Vector3());
    this.grid = new THREE.GridHelper(size * 8, 32, 0x66707f, 0x3a404c);
    this.grid.position.set(center.x, box.min.y, center.z);
    this.scene.add(this.grid);
    this.camera.near = size / 200;
    this.camera.far = size * 200;
    this.camera.position.set(center.x + size * 0.8, center.y + size * 0.35, center.z + size * 1.5);
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.update();
    this.lastRoot = null;
  }

  // Moves the figures; with `follow`, the camera target keeps the root in view.
  setPoses(decoded, original, worstNode) {
    this.figures.decoded?.update(decoded);
    if (original && this.figures.original) this.figures.original.update(original);
    if (worstNode >= 0 && original) {
      this.worst.position.set(decoded[3 * worstNode], decoded[3 * worstNode + 1], decoded[3 * worstNode + 2]);
      this.worst.visible = true;
    } else if (this.worst) {
      this.worst.visible = false;
    }
    // Following: camera and target move with the root (node 0), keeping the view as set.
    const root = new THREE.Vector3(decoded[0], decoded[1], decoded[2]);
    if (this.follow && this.lastRoot) {
      const shift = root.clone().sub(this.lastRoot);
      this.controls.target.add(shift);
      this.camera.position.add(shift);
      this.controls.update();
    }
    this.lastRoot = root;
    this.render();
  }

  showOriginal(v) { if (this.figures.original) this.figures.original.visible = v; this.render(); }
  render() { this.renderer.render(this.scene, this.camera); }
}

function boundsOf(p) {
  const box = new THREE.Box3();
  for (let i = 0; i < p.length; i += 3) box.expandByPoint(new THREE.Vector3(p[i], p[i + 1], p[i + 2]));
  return box;
}
