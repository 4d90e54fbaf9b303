// The 3D path (three.js): the reference (truth) in black, the estimate in orange with its
// deviation from the reference multiplied by the exaggeration, attitude frames (body x red,
// y green, z blue) of the estimate every few seconds with the attitude error exaggerated the same
// way, and a tube around the reference whose radius is the exaggerated horizontal error (Monte
// Carlo RMS, else the first run's error). Render frame: x = east, y = up, z = south.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const D2R = Math.PI / 180;
const toR = (n, e, d) => new THREE.Vector3(e, -d, -n);

// Rotation body->render from roll, pitch, yaw (deg, ZYX): C_b_n, then NED->render.
function frameMatrix(rollDeg, pitchDeg, yawDeg) {
  const q = new THREE.Quaternion();
  const qn = new THREE.Quaternion().setFromEuler(new THREE.Euler(rollDeg * D2R, pitchDeg * D2R, yawDeg * D2R, 'ZYX'));
  // NED -> render: x_r = e, y_r = -d, z_r = -n.
  const m = new THREE.Matrix4().set(0, 1, 0, 0, 0, 0, -1, 0, -1, 0, 0, 0, 0, 0, 0, 1);
  q.setFromRotationMatrix(m);
  return new THREE.Matrix4().makeRotationFromQuaternion(q.multiply(qn));
}

function tubeGeometry(points, radii, sides) {
  const pos = [], idx = [];
  const n = points.length;
  let prevNormal = new THREE.Vector3(0, 1, 0);
  for (let i = 0; i < n; ++i) {
    const a = points[Math.max(0, i - 1)], b = points[Math.min(n - 1, i + 1)];
    const tan = new THREE.Vector3().subVectors(b, a);
    if (tan.lengthSq() < 1e-12) tan.set(1, 0, 0);
    tan.normalize();
    let nrm = new THREE.Vector3().crossVectors(tan, prevNormal);
    if (nrm.lengthSq() < 1e-8) nrm = new THREE.Vector3().crossVectors(tan, new THREE.Vector3(1, 0, 0));
    nrm.normalize();
    const bin = new THREE.Vector3().crossVectors(nrm, tan).normalize();
    prevNormal = bin;
    for (let k = 0; k < sides; ++k) {
      const th = (2 * Math.PI * k) / sides;
      const r = radii[i];
      pos.push(points[i].x + r * (Math.cos(th) * nrm.x + Math.sin(th) * bin.x),
        points[i].y + r * (Math.cos(th) * nrm.y + Math.sin(th) * bin.y),
        points[i].z + r * (Math.cos(th) * nrm.z + Math.sin(th) * bin.z));
    }
    if (i > 0)
      for (let k = 0; k < sides; ++k) {
        const a0 = (i - 1) * sides + k, a1 = (i - 1) * sides + ((k + 1) % sides), b0 = i * sides + k, b1 = i * sides + ((k + 1) % sides);
        idx.push(a0, b0, a1, a1, b0, b1);
      }
  }
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
  g.setIndex(idx);
  g.computeVertexNormals();
  return g;
}

export class View3D {
  constructor(host) {
    this.host = host;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
    this.renderer.setClearColor(0xf4f6f9);
    host.appendChild(this.renderer.domElement);
    this.renderer.domElement.setAttribute('aria-label', '3D view of the path');
    this.renderer.domElement.tabIndex = 0;
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(45, 1, 0.1, 1e7);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.listenToKeyEvents(this.renderer.domElement);
    this.controls.addEventListener('change', () => this.render());
    this.scene.add(new THREE.AmbientLight(0xffffff, 0.7));
    const dl = new THREE.DirectionalLight(0xffffff, 0.8);
    dl.position.set(1, 2, 1);
    this.scene.add(dl);
    this.group = new THREE.Group();
    this.scene.add(this.group);
    this.data = null;
    this.exaggeration = 20;
  }
  resize() {
    const w = this.host.clientWidth || 800, h = this.host.clientHeight || 500;
    this.renderer.setSize(w, h, false);
    this.renderer.domElement.style.width = '100%';
    this.renderer.domElement.style.height = h + 'px';
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.render();
  }
  // truth, nav: parsed CSVs; sigmaH: horizontal error per sample (array, same length) or null.
  setData(truth, nav, sigmaH) {
    this.data = { truth, nav, sigmaH };
    this.build();
  }
  // A/B comparison: run A's estimate (blue, deviation from A's reference x the exaggeration) and
  // A's reference (grey) when it is not the shown run's; null removes them. toShown: a function
  // (n, e, d) -> [n, e, d] from A's local NED to the shown run's (geo.js nedFrameChange, for
  // runs with other scene origins); omitted: the same frame.
  setCompare(truthA, navA, toShown) {
    this.compare = truthA && navA ? { truth: truthA, nav: navA, toShown: toShown || ((n, e, d) => [n, e, d]) } : null;
    if (this.data) this.build(false);
  }
  // The first point of a drawn line ('ref', 'est', 'refA', 'estA') as local NED [n, e, d] of the
  // shown run, read back from the line's geometry (what the GPU gets); null when not drawn.
  firstNed(which) {
    const l = this.lines && this.lines[which];
    if (!l) return null;
    const p = l.geometry.getAttribute('position');
    return [-p.getZ(0), p.getX(0), -p.getY(0)];
  }
  setExaggeration(k) {
    this.exaggeration = k;
    if (this.data) this.build(false);
  }
  build(resetCamera = true) {
    const { truth, nav, sigmaH } = this.data;
    const k = this.exaggeration;
    for (const c of [...this.group.children]) {
      this.group.remove(c);
      c.traverse((o) => { if (o.geometry) o.geometry.dispose(); if (o.material) o.material.dispose(); });
    }
    const n = truth.length;
    const step = Math.max(1, Math.ceil(n / 3000));
    const ref = [], est = [], rad = [];
    for (let i = 0; i < n; i += step) {
      const r = toR(truth.pos_n_m[i], truth.pos_e_m[i], truth.pos_d_m[i]);
      ref.push(r);
      if (nav && i < nav.length) {
        const e = toR(nav.pos_n_m[i], nav.pos_e_m[i], nav.pos_d_m[i]);
        est.push(r.clone().add(e.sub(r).multiplyScalar(k)));
      }
      rad.push(sigmaH ? Math.max(0, k * sigmaH[i]) : 0);
    }
    const refA = [], estA = [];
    let sameRef = true;
    if (this.compare) {
      // A's positions in the shown run's local frame (through latitude, longitude and height
      // when the scene origins differ), then drawn as the shown run's.
      const { truth: tA, nav: nA, toShown } = this.compare;
      const stepA = Math.max(1, Math.ceil(tA.length / 3000));
      if (tA.length !== n) sameRef = false;
      for (let i = 0; i < tA.length; i += stepA) {
        const [rn, re, rd] = toShown(tA.pos_n_m[i], tA.pos_e_m[i], tA.pos_d_m[i]);
        const r = toR(rn, re, rd);
        refA.push(r);
        if (sameRef && Math.abs(rn - truth.pos_n_m[i]) + Math.abs(re - truth.pos_e_m[i]) + Math.abs(rd - truth.pos_d_m[i]) > 1e-3) sameRef = false;
        if (i < nA.length) {
          const e = toR(...toShown(nA.pos_n_m[i], nA.pos_e_m[i], nA.pos_d_m[i]));
          estA.push(r.clone().add(e.sub(r).multiplyScalar(k)));
        }
      }
    }
    const box = new THREE.Box3().setFromPoints(sameRef ? ref : [...ref, ...refA]);
    const size = box.getSize(new THREE.Vector3()).length() || 10;
    this.lines = {};
    const line = (name, pts, color) => {
      this.lines[name] = new THREE.Line(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color }));
      this.group.add(this.lines[name]);
    };
    line('ref', ref, 0x111111);
    if (est.length > 1) line('est', est, 0xd1401f);
    if (!sameRef && refA.length > 1) line('refA', refA, 0x8a8f98);
    if (estA.length > 1) line('estA', estA, 0x1f5fbf);
    if (sigmaH && ref.length > 1) {
      const maxR = size * 0.08;
      const tube = new THREE.Mesh(tubeGeometry(ref, rad.map((r) => Math.min(r, maxR)), 12),
        new THREE.MeshLambertMaterial({ color: 0x1f5fbf, transparent: true, opacity: 0.25, depthWrite: false, side: THREE.DoubleSide }));
      this.group.add(tube);
    }
    // Attitude frames of the estimate, about 40 along the path, attitude error x k.
    const frames = 40;
    const len = size * 0.03;
    const axes = [new THREE.Vector3(1, 0, 0), new THREE.Vector3(0, 1, 0), new THREE.Vector3(0, 0, 1)];
    const cols = [0xd62728, 0x2ca02c, 0x1f77b4];
    const seg = [[], [], []];
    const fstep = Math.max(1, Math.floor(n / frames));
    for (let i = 0; i < n; i += fstep) {
      const src = nav && i < nav.length ? nav : truth;
      const ex = (a, b) => a + k * (b - a);
      const roll = src === nav ? ex(truth.roll_deg[i], nav.roll_deg[i]) : truth.roll_deg[i];
      const pitch = src === nav ? ex(truth.pitch_deg[i], nav.pitch_deg[i]) : truth.pitch_deg[i];
      let dy = src === nav ? nav.yaw_deg[i] - truth.yaw_deg[i] : 0;
      dy = ((dy + 540) % 360) - 180;
      const yaw = truth.yaw_deg[i] + k * dy;
      const m = frameMatrix(roll, pitch, yaw);
      const p = toR(truth.pos_n_m[i], truth.pos_e_m[i], truth.pos_d_m[i]);
      axes.forEach((a, j) => {
        const tip = a.clone().applyMatrix4(m).multiplyScalar(len).add(p);
        seg[j].push(p, tip);
      });
    }
    seg.forEach((s, j) => this.group.add(new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(s), new THREE.LineBasicMaterial({ color: cols[j] }))));
    const grid = new THREE.GridHelper(size * 1.5, 20, 0xb0b6c0, 0xd8dce2);
    const c = box.getCenter(new THREE.Vector3());
    grid.position.set(c.x, box.min.y - 1, c.z);
    this.group.add(grid);
    if (resetCamera) {
      this.controls.target.copy(c);
      this.camera.position.set(c.x + size * 0.6, c.y + size * 0.7, c.z + size * 0.9);
      this.camera.near = size / 1000;
      this.camera.far = size * 100;
      this.camera.updateProjectionMatrix();
      this.controls.update();
    }
    this.resize();
  }
  render() { this.renderer.render(this.scene, this.camera); }
}
