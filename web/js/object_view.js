// The gripped object in the 3D view: its surface (optional wireframe) at the streamed node
// positions, the gripped nodes in red, each target as an orange arrow from its node with a
// handle to drag, the centre-line the server follows and the one being sketched, and the markers
// a tracker observed on the real object (cyan points: where the real object is) with the last
// observed point cloud (small magenta points). World frame, metres. Targets being dragged are
// shown where the hand is, ahead of the server.
import * as THREE from 'three';
import { ScreenLine } from './screen_line.js';
import { TargetGlyphs, TARGET_ORANGE } from './target_glyphs.js';

const MIN_ARROW_LENGTH = 1e-4;  // m; a target this close to its node shows only its handle
const LINE_PIXELS = 4;          // centre-line width on screen
const GRIP_PIXELS = 7;          // gripped-node marker size on screen

// Scratch vectors, reused by every target drawing and pick.
const _from = new THREE.Vector3();
const _target = new THREE.Vector3();
const _vertex = new THREE.Vector3();

export class ObjectView {
  constructor() {
    this.group = new THREE.Group();
    this.surfaceGroup = new THREE.Group();  // rebuilt for every scene
    this.glyphs = new TargetGlyphs();       // arrows and handles, reused across states and scenes
    this.group.add(this.surfaceGroup, this.glyphs.group);

    this.positions = null;  // node positions (Float32Array, 3 per node) once a frame arrived
    this.positionAttribute = null;
    this.surfaceGeometry = null;
    this.surfaceMesh = null;
    this.wireframe = null;
    this.wireframeVisible = false;
    this.gripNodes = [];
    this.gripAttribute = null;
    this.gripPoints = null;
    // Centre-lines lie inside the bar: drawn over it, or the user would not see them.
    this.centerline = new ScreenLine(TARGET_ORANGE, LINE_PIXELS, 10);
    this.sketchLine = new ScreenLine(0xffe08a, LINE_PIXELS, 11);
    this.group.add(this.centerline.object, this.sketchLine.object);
    // Observed markers: one Points object, its buffer regrown only when more markers arrive.
    this.observedGeometry = new THREE.BufferGeometry();
    this.observed = new THREE.Points(this.observedGeometry,
      new THREE.PointsMaterial({ color: 0x22d3ee, size: 9, sizeAttenuation: false, depthTest: false }));
    this.observed.renderOrder = 2;
    this.observed.frustumCulled = false;
    this.group.add(this.observed);
    // The last observed point cloud: small magenta points, over the surface they lie on.
    this.cloudGeometry = new THREE.BufferGeometry();
    this.cloud = new THREE.Points(this.cloudGeometry,
      new THREE.PointsMaterial({ color: 0xff4fd8, size: 3, sizeAttenuation: false, depthTest: false }));
    this.cloud.renderOrder = 1;
    this.cloud.frustumCulled = false;
    this.cloud.visible = false;
    this.cloudCount = 0;       // points in the last cloud
    this.cloudEnabled = true;  // the page's checkbox
    this.group.add(this.cloud);

    this.targets = [];             // the last state's [{node, position}]
    this.showHandles = true;       // no handles while a centre-line is the handle
    this.localTargets = new Map(); // node → Vector3 of targets being dragged
    this.selected = null;          // node whose handle is highlighted
    this.hovered = null;           // node whose handle is under the pointer
  }

  // Rebuilds the surface from a scene message; targets and positions start empty.
  setScene(description) {
    for (const o of [this.surfaceMesh, this.wireframe, this.gripPoints]) {
      o?.geometry.dispose();
      o?.material.dispose();
    }
    this.surfaceGroup.clear();
    const n = description.node_count;
    this.positions = null;
    this.surfaceGeometry = new THREE.BufferGeometry();
    this.positionAttribute = new THREE.BufferAttribute(new Float32Array(3 * n), 3);
    this.positionAttribute.setUsage(THREE.DynamicDrawUsage);
    this.surfaceGeometry.setAttribute('position', this.positionAttribute);
    this.surfaceGeometry.setIndex(description.triangles);
    this.surfaceMesh = new THREE.Mesh(this.surfaceGeometry, new THREE.MeshStandardMaterial({
      color: 0x9fc8e8, roughness: 0.8, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    }));
    this.surfaceMesh.frustumCulled = false;
    this.wireframe = new THREE.Mesh(this.surfaceGeometry, new THREE.MeshBasicMaterial({ color: 0x203040, wireframe: true }));
    this.wireframe.frustumCulled = false;
    this.wireframe.visible = this.wireframeVisible;

    this.gripNodes = description.grips.flatMap((g) => g.nodes);
    const gripGeometry = new THREE.BufferGeometry();
    this.gripAttribute = new THREE.BufferAttribute(new Float32Array(3 * this.gripNodes.length), 3);
    gripGeometry.setAttribute('position', this.gripAttribute);
    this.gripPoints = new THREE.Points(gripGeometry, new THREE.PointsMaterial({ color: 0xff2222, size: GRIP_PIXELS, sizeAttenuation: false, depthTest: false }));
    this.gripPoints.frustumCulled = false;
    this.gripPoints.renderOrder = 3;  // over the grippers that hold them
    this.surfaceGroup.add(this.surfaceMesh, this.wireframe, this.gripPoints);

    this.setCenterline([]);
    this.setSketch([]);
    this.targets = [];
    this.localTargets.clear();
    this.selected = null;
    this.hovered = null;
    this.drawTargets();
  }

  // `positions`: 3 numbers per node, as streamed.
  setPositions(positions) {
    this.positionAttribute.array.set(positions);
    this.positionAttribute.needsUpdate = true;
    this.positions = this.positionAttribute.array;
    this.surfaceGeometry.computeVertexNormals();
    this.surfaceGeometry.computeBoundingSphere();  // for picking
    this.gripNodes.forEach((node, k) => this.gripAttribute.setXYZ(k, positions[3 * node], positions[3 * node + 1], positions[3 * node + 2]));
    this.gripAttribute.needsUpdate = true;
    this.drawTargets();
  }

  // `points`: a state's "centerline", [x, y, z] each.
  setCenterline(points) {
    this.centerline.setPoints(points);
  }

  // `points`: the Vector3s of the stroke being sketched (none: hidden).
  setSketch(points) {
    this.sketchLine.setPoints(points);
  }

  // Sizes what is drawn in screen pixels for `camera` in a `width` × `height` pixel view.
  fitToScreen(camera, width, height) {
    this.glyphs.fitToScreen(camera, height);
    this.centerline.setResolution(width, height);
    this.sketchLine.setResolution(width, height);
  }

  get arrowCount() { return this.glyphs.arrowCount; }
  get handleCount() { return this.glyphs.handleCount; }

  // `targets`: a state's "targets"; `showHandles` false when a centre-line stands for them.
  setTargets(targets, showHandles) {
    this.targets = targets;
    this.showHandles = showHandles;
    this.drawTargets();
  }

  setLocalTarget(node, position) {
    const local = this.localTargets.get(node);
    if (local) local.copy(position);
    else this.localTargets.set(node, position.clone());
    this.drawTargets();
  }

  dropLocalTarget(node) {
    this.localTargets.delete(node);
    this.drawTargets();
  }

  setSelected(node) {
    this.selected = node;
    this.drawTargets();
  }

  // False when it already was.
  setHovered(node) {
    if (node === this.hovered) return false;
    this.hovered = node;
    this.drawTargets();
    return true;
  }

  // [[node, x, y, z], ...] from the state's "observed_markers".
  setObservedMarkers(markers) {
    const n = markers?.length ?? 0;
    let attribute = this.observedGeometry.getAttribute('position');
    if (!attribute || attribute.count < n) {
      attribute = new THREE.BufferAttribute(new Float32Array(3 * Math.max(n, 16)), 3);
      this.observedGeometry.setAttribute('position', attribute);
    }
    for (let k = 0; k < n; ++k) attribute.setXYZ(k, markers[k][1], markers[k][2], markers[k][3]);
    attribute.needsUpdate = true;
    this.observedGeometry.setDrawRange(0, n);
  }

  // [[x, y, z], ...] from the state's "observed_points"; hidden when empty.
  setObservedPoints(points) {
    const n = points?.length ?? 0;
    let attribute = this.cloudGeometry.getAttribute('position');
    if (!attribute || attribute.count < n) {
      attribute = new THREE.BufferAttribute(new Float32Array(3 * Math.max(n, 256)), 3);
      attribute.setUsage(THREE.DynamicDrawUsage);
      this.cloudGeometry.setAttribute('position', attribute);
    }
    for (let k = 0; k < n; ++k) attribute.setXYZ(k, points[k][0], points[k][1], points[k][2]);
    attribute.needsUpdate = true;
    this.cloudGeometry.setDrawRange(0, n);
    this.cloudCount = n;
    this.cloud.visible = this.cloudEnabled && n > 0;
  }

  setObservedPointsVisible(on) {
    this.cloudEnabled = on;
    this.cloud.visible = on && this.cloudCount > 0;
  }

  setWireframe(on) {
    this.wireframeVisible = on;
    if (this.wireframe) this.wireframe.visible = on;
  }

  setVisible(on) { this.group.visible = on; }

  // Where `node`'s target is (into `out`), the local one first; null when it has none.
  targetPosition(node, out) {
    const local = this.localTargets.get(node);
    if (local) return out.copy(local);
    const t = this.targets.find((x) => x.node === node);
    return t ? out.fromArray(t.position) : null;
  }

  nodePosition(node, out) {
    return out.fromArray(this.positions, 3 * node);
  }

  centroid(out) {
    const x = this.positions, n = x.length / 3;
    out.set(0, 0, 0);
    for (let i = 0; i < n; i++) out.x += x[3 * i], out.y += x[3 * i + 1], out.z += x[3 * i + 2];
    return out.multiplyScalar(1 / n);
  }

  // The shown handle nearest along `raycaster`: {node, target, point} or null.
  pickHandle(raycaster) {
    return this.glyphs.pick(raycaster);
  }

  // The surface node under `raycaster` (the nearest vertex of the hit triangle): {node, point} or null.
  pickNode(raycaster) {
    const hit = raycaster.intersectObject(this.surfaceMesh, false)[0];
    if (!hit?.face) return null;
    let node = hit.face.a, best = Infinity;
    for (const v of [hit.face.a, hit.face.b, hit.face.c]) {
      const d = this.nodePosition(v, _vertex).distanceTo(hit.point);
      if (d < best) { best = d; node = v; }
    }
    return { node, point: hit.point };
  }

  // Poses the pooled arrows and handles for the current targets and hides the rest.
  drawTargets() {
    this.glyphs.begin();
    if (this.positions) {
      for (const t of this.targets)
        if (!this.localTargets.has(t.node)) this.drawTarget(t.node, _target.fromArray(t.position));
      for (const [node, position] of this.localTargets) this.drawTarget(node, position);
    }
    this.glyphs.end();
  }

  drawTarget(node, target) {
    this.nodePosition(node, _from);
    if (_from.distanceTo(target) > MIN_ARROW_LENGTH) this.glyphs.addArrow(_from, target);
    if (this.showHandles) this.glyphs.addHandle(node, target, node === this.selected, node === this.hovered);
  }
}
