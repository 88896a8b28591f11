// The gripped object in the 3D view: its surface (optional wireframe) at the streamed node
// positions, the gripped nodes in red, each target as an orange arrow from its node with a
// handle to drag, the centre-line the server follows and the one being sketched, and the markers
// a tracker observed on the real object (cyan points: where the real object is) with the last
// observed point cloud (small magenta points). World frame, metres. Targets being dragged are
// shown where the hand is, ahead of the server.
import * as THREE from 'three';

const ORANGE = 0xff8c1a;
const HANDLE_GEOMETRY = new THREE.SphereGeometry(0.006, 16, 12);  // radius in m
const HANDLE_MATERIAL = new THREE.MeshBasicMaterial({ color: ORANGE });
const SELECTED_MATERIAL = new THREE.MeshBasicMaterial({ color: 0xffffff });
const MIN_ARROW_LENGTH = 1e-4;  // m; a target this close to its node shows only its handle

// Scratch vectors, reused by every target drawing and pick.
const _from = new THREE.Vector3();
const _delta = new THREE.Vector3();
const _target = new THREE.Vector3();
const _vertex = new THREE.Vector3();

// Centre-lines lie inside the bar: drawn over it, or the user would not see them.
function makeLine(color) {
  const material = new THREE.LineBasicMaterial({ color, depthTest: false });
  const line = new THREE.Line(new THREE.BufferGeometry(), material);
  line.frustumCulled = false;
  line.renderOrder = 10;
  return line;
}

// The position attribute of `line` with room for `count` points and only those drawn. A new
// geometry only when it grows: three.js cannot resize an attribute in place.
function linePositions(line, count) {
  let attribute = line.geometry.getAttribute('position');
  if (!attribute || attribute.count < count) {
    line.geometry.dispose();
    line.geometry = new THREE.BufferGeometry();
    attribute = new THREE.BufferAttribute(new Float32Array(3 * Math.max(64, 2 * count)), 3);
    attribute.setUsage(THREE.DynamicDrawUsage);
    line.geometry.setAttribute('position', attribute);
  }
  line.geometry.setDrawRange(0, count);
  attribute.needsUpdate = true;
  return attribute;
}

export class ObjectView {
  constructor() {
    this.group = new THREE.Group();
    this.surfaceGroup = new THREE.Group();  // rebuilt for every scene
    this.targetsGroup = new THREE.Group();  // arrows and handles, reused across states and scenes
    this.group.add(this.surfaceGroup, this.targetsGroup);

    this.positions = null;  // node positions (Float32Array, 3 per node) once a frame arrived
    this.positionAttribute = null;
    this.surfaceGeometry = null;
    this.surfaceMesh = null;
    this.wireframe = null;
    this.wireframeVisible = false;
    this.gripNodes = [];
    this.gripAttribute = null;
    this.gripPoints = null;
    this.centerline = makeLine(ORANGE);
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
    this.sketchLine = makeLine(0xffe08a);

    this.targets = [];             // the last state's [{node, position}]
    this.showHandles = true;       // no handles while a centre-line is the handle
    this.localTargets = new Map(); // node → Vector3 of targets being dragged
    this.selected = null;          // node whose handle is highlighted
    this.arrows = [];              // pool of ArrowHelpers; the first arrowCount are shown
    this.handles = [];             // pool of handle meshes; the first handleCount are shown
    this.arrowCount = 0;
    this.handleCount = 0;
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
    this.gripPoints = new THREE.Points(gripGeometry, new THREE.PointsMaterial({ color: 0xff2222, size: 6, sizeAttenuation: false }));
    this.gripPoints.frustumCulled = false;
    this.surfaceGroup.add(this.surfaceMesh, this.wireframe, this.gripPoints, this.centerline, this.sketchLine);

    this.setCenterline([]);
    this.setSketch([]);
    this.targets = [];
    this.localTargets.clear();
    this.selected = null;
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
    const attribute = linePositions(this.centerline, points.length);
    points.forEach((p, k) => attribute.setXYZ(k, p[0], p[1], p[2]));
    this.centerline.visible = points.length > 1;
  }

  // `points`: the Vector3s of the stroke being sketched (none: hidden).
  setSketch(points) {
    const attribute = linePositions(this.sketchLine, points.length);
    points.forEach((p, k) => attribute.setXYZ(k, p.x, p.y, p.z));
  }

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
    const hit = raycaster.intersectObjects(this.handles.slice(0, this.handleCount), false)[0];
    return hit ? { node: hit.object.userData.node, target: hit.object.position.clone(), point: hit.point } : null;
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
    this.arrowCount = 0;
    this.handleCount = 0;
    if (this.positions) {
      for (const t of this.targets)
        if (!this.localTargets.has(t.node)) this.drawTarget(t.node, _target.fromArray(t.position));
      for (const [node, position] of this.localTargets) this.drawTarget(node, position);
    }
    for (let k = this.arrowCount; k < this.arrows.length; k++) this.arrows[k].visible = false;
    for (let k = this.handleCount; k < this.handles.length; k++) this.handles[k].visible = false;
  }

  drawTarget(node, target) {
    this.nodePosition(node, _from);
    const length = _delta.subVectors(target, _from).length();
    if (length > MIN_ARROW_LENGTH) {
      const arrow = this.nextArrow();
      const head = Math.min(0.02, 0.4 * length);
      arrow.position.copy(_from);
      arrow.setDirection(_delta.divideScalar(length));
      arrow.setLength(length, head, 0.5 * head);
    }
    if (!this.showHandles) return;
    const handle = this.nextHandle();
    handle.position.copy(target);
    handle.material = node === this.selected ? SELECTED_MATERIAL : HANDLE_MATERIAL;
    handle.userData.node = node;
  }

  // The next pooled arrow (handle), created the first time that many are needed.
  nextArrow() {
    if (this.arrowCount === this.arrows.length) this.addToPool(this.arrows, new THREE.ArrowHelper(undefined, undefined, 1, ORANGE));
    const arrow = this.arrows[this.arrowCount++];
    arrow.visible = true;
    return arrow;
  }

  nextHandle() {
    if (this.handleCount === this.handles.length) this.addToPool(this.handles, new THREE.Mesh(HANDLE_GEOMETRY, HANDLE_MATERIAL));
    const handle = this.handles[this.handleCount++];
    handle.visible = true;
    return handle;
  }

  addToPool(pool, object) {
    pool.push(object);
    this.targetsGroup.add(object);
  }
}
