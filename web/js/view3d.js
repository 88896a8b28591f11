// The 3D view: robot links, the object's surface, gripped nodes, targets (orange arrows from
// node to target, with a handle to drag), the centre-line and collision spheres. World frame,
// metres, z up. Picking, dragging and sketching turn into callbacks; the server decides.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';

const ORANGE = 0xff8c1a;
const HANDLE_GEOMETRY = new THREE.SphereGeometry(0.006, 16, 12);  // radius in m
const HANDLE_MATERIAL = new THREE.MeshBasicMaterial({ color: ORANGE });
const SELECTED_MATERIAL = new THREE.MeshBasicMaterial({ color: 0xffffff });

function linkColor(index) {
  // Golden-angle hues: neighbouring links get clearly different colours.
  return new THREE.Color().setHSL((index * 0.618034) % 1, 0.45, 0.55);
}

function matrixFrom(array16) {
  return new THREE.Matrix4().fromArray(array16);
}

function shapeGeometry(shape) {
  if (shape.kind === 'box') return new THREE.BoxGeometry(...shape.size);
  if (shape.kind === 'cylinder') {
    // three.js cylinders run along y, URDF ones along z.
    return new THREE.CylinderGeometry(shape.radius, shape.radius, shape.length, 24).rotateX(Math.PI / 2);
  }
  return new THREE.SphereGeometry(shape.radius, 24, 16);
}

export class View3D {
  constructor(container, callbacks) {
    this.container = container;
    this.callbacks = callbacks;  // addTarget(node, position), moveTarget(node, position), sketch(points), select(node)
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.appendChild(this.renderer.domElement);

    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x1d2025);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 50);
    this.camera.up.set(0, 0, 1);
    this.camera.position.set(1.4, -0.9, 0.9);
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.target.set(0.35, 0, 0.15);
    this.controls.update();

    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -1, 2);
    this.scene.add(sun);
    const grid = new THREE.GridHelper(2, 20, 0x444444, 0x333333);
    grid.rotateX(Math.PI / 2);
    this.scene.add(grid);

    this.robotGroup = new THREE.Group();
    this.objectGroup = new THREE.Group();
    this.targetsGroup = new THREE.Group();
    this.scene.add(this.robotGroup, this.objectGroup, this.targetsGroup);

    this.raycaster = new THREE.Raycaster();
    this.selected = null;  // node id of the selected target
    this.drag = null;      // {node, plane, offset, lastSent}
    this.sketching = false;
    this.sketchPoints = null;
    this.localTargets = new Map();  // node → Vector3 while dragging (ahead of the server)

    const canvas = this.renderer.domElement;
    // Capture phase: decide before OrbitControls whether this press is ours.
    canvas.addEventListener('pointerdown', (e) => this.onPointerDown(e), { capture: true });
    canvas.addEventListener('pointermove', (e) => this.onPointerMove(e));
    canvas.addEventListener('pointerup', (e) => this.onPointerUp(e));
    canvas.addEventListener('pointercancel', (e) => this.onPointerUp(e));
    // Render on demand only: software WebGL (headless, remote desktops) can't afford 60 fps.
    this.controls.addEventListener('change', () => this.requestRender());
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  requestRender() {
    if (this.renderPending) return;
    this.renderPending = true;
    requestAnimationFrame(() => { this.renderPending = false; this.render(); });
  }

  resize() {
    const w = Math.max(1, this.container.clientWidth), h = Math.max(1, this.container.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  render() {
    this.renderer.render(this.scene, this.camera);
    this.frames = (this.frames ?? 0) + 1;
  }

  // ---- scene description ----
  setScene(description) {
    this.description = description;
    for (const group of [this.robotGroup, this.objectGroup, this.targetsGroup]) {
      group.traverse((o) => { o.geometry?.dispose?.(); });
      group.clear();
    }
    this.linkGroups = [];
    this.sphereMeshes = [];
    this.localTargets.clear();
    this.selected = null;
    this.drag = null;
    if (description.robot) this.buildRobot(description.robot);
    this.buildObject(description);
    this.positions = null;
    this.state = null;
  }

  buildRobot(robot) {
    robot.links.forEach((link, index) => {
      const group = new THREE.Group();
      group.matrixAutoUpdate = false;
      group.name = link.name;
      const material = new THREE.MeshStandardMaterial({ color: linkColor(index), roughness: 0.6, metalness: 0.1 });
      for (const shape of link.visuals) {
        const mesh = new THREE.Mesh(shapeGeometry(shape), material);
        mesh.matrixAutoUpdate = false;
        mesh.matrix.copy(matrixFrom(shape.pose));
        group.add(mesh);
      }
      this.robotGroup.add(group);
      this.linkGroups.push(group);
    });
    const sphereMaterial = new THREE.MeshBasicMaterial({ color: 0x66ccff, wireframe: true, transparent: true, opacity: 0.35 });
    for (const s of robot.collision_spheres) {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(s.radius, 12, 8), sphereMaterial);
      mesh.position.set(...s.center);
      this.linkGroups[s.link]?.add(mesh);
      this.sphereMeshes.push(mesh);
    }
    this.setSpheresVisible(this.spheresVisible ?? false);
    this.setRobotVisible(this.robotVisible ?? true);
  }

  buildObject(description) {
    const n = description.node_count;
    const geometry = new THREE.BufferGeometry();
    this.positionAttribute = new THREE.BufferAttribute(new Float32Array(3 * n), 3);
    this.positionAttribute.setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute('position', this.positionAttribute);
    geometry.setIndex(description.triangles);
    this.objectGeometry = geometry;
    this.objectMesh = new THREE.Mesh(geometry, new THREE.MeshStandardMaterial({
      color: 0x9fc8e8, roughness: 0.8, side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    }));
    this.objectMesh.frustumCulled = false;
    this.wireframe = new THREE.Mesh(geometry, new THREE.MeshBasicMaterial({ color: 0x203040, wireframe: true }));
    this.wireframe.frustumCulled = false;
    this.wireframe.visible = this.wireframeVisible ?? false;

    this.gripNodes = description.grips.flatMap((g) => g.nodes);
    const gripGeometry = new THREE.BufferGeometry();
    this.gripAttribute = new THREE.BufferAttribute(new Float32Array(3 * this.gripNodes.length), 3);
    gripGeometry.setAttribute('position', this.gripAttribute);
    this.gripPoints = new THREE.Points(gripGeometry, new THREE.PointsMaterial({ color: 0xff2222, size: 6, sizeAttenuation: false }));
    this.gripPoints.frustumCulled = false;

    this.centerline = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: ORANGE }));
    this.centerline.frustumCulled = false;
    this.sketchLine = new THREE.Line(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0xffe08a }));
    this.sketchLine.frustumCulled = false;
    this.objectGroup.add(this.objectMesh, this.wireframe, this.gripPoints, this.centerline, this.sketchLine);
  }

  // ---- streamed state ----
  setPositions(positions) {
    const first = !this.positions;
    this.positions = positions;
    if (first) this.frameObject();
    this.positionAttribute.array.set(positions);
    this.positionAttribute.needsUpdate = true;
    this.objectGeometry.computeVertexNormals();
    this.objectGeometry.computeBoundingSphere();
    this.gripNodes.forEach((node, k) => this.gripAttribute.setXYZ(k, positions[3 * node], positions[3 * node + 1], positions[3 * node + 2]));
    this.gripAttribute.needsUpdate = true;
    this.updateTargets();
    this.requestRender();
  }

  // Looks at the object from the front (+x, where the robot faces), a little from the side and above.
  frameObject() {
    const c = this.objectCentroid();
    this.controls.target.copy(c);
    this.camera.position.copy(c).add(new THREE.Vector3(0.95, -0.5, 0.45));
    this.controls.update();
  }

  // Looks at a bar square on from the robot's front, so the sketch plane contains its axis.
  faceBar(direction) {
    const c = this.objectCentroid();
    const side = new THREE.Vector3(...direction).cross(new THREE.Vector3(0, 0, 1)).normalize();
    if (side.x < 0) side.negate();
    this.controls.target.copy(c);
    this.camera.position.copy(c).addScaledVector(side, 0.8).add(new THREE.Vector3(0, 0, 0.2));
    this.controls.update();
  }

  setState(state) {
    const unchanged = this.state && this.state.seq === state.seq && this.state.scene === state.scene;
    this.state = state;
    if (unchanged) return;  // same snapshot: nothing to redraw (saves software-GL time)
    state.links.forEach((pose, k) => {
      const group = this.linkGroups[k];
      if (group) { group.matrix.fromArray(pose); group.matrixWorldNeedsUpdate = true; }
    });
    const points = state.centerline.map((p) => new THREE.Vector3(...p));
    this.centerline.geometry.setFromPoints(points);
    this.centerline.visible = points.length > 1;
    this.updateTargets();
    this.requestRender();
  }

  nodePosition(node) {
    const x = this.positions;
    return new THREE.Vector3(x[3 * node], x[3 * node + 1], x[3 * node + 2]);
  }

  targetPositions() {
    const targets = new Map();
    for (const t of this.state?.targets ?? []) targets.set(t.node, new THREE.Vector3(...t.position));
    for (const [node, p] of this.localTargets) targets.set(node, p);
    return targets;
  }

  updateTargets() {
    if (!this.positions || !this.state) return;
    this.targetsGroup.clear();
    const fromCenterline = this.state.centerline.length > 0;
    for (const [node, target] of this.targetPositions()) {
      const from = this.nodePosition(node);
      const delta = target.clone().sub(from);
      const length = delta.length();
      if (length > 1e-4) {
        const head = Math.min(0.02, 0.4 * length);
        const arrow = new THREE.ArrowHelper(delta.normalize(), from, length, ORANGE, head, 0.5 * head);
        this.targetsGroup.add(arrow);
      }
      if (fromCenterline) continue;  // the curve is the handle there
      const handle = new THREE.Mesh(HANDLE_GEOMETRY, node === this.selected ? SELECTED_MATERIAL : HANDLE_MATERIAL);
      handle.position.copy(target);
      handle.userData.node = node;
      this.targetsGroup.add(handle);
    }
    this.arrowCount = this.targetsGroup.children.filter((c) => c.userData.node === undefined).length;
    this.requestRender();
  }

  // ---- display toggles ----
  setWireframe(on) { this.wireframeVisible = on; if (this.wireframe) this.wireframe.visible = on; this.requestRender(); }
  setSpheresVisible(on) { this.spheresVisible = on; for (const m of this.sphereMeshes ?? []) m.visible = on; this.requestRender(); }
  setRobotVisible(on) {
    this.robotVisible = on;
    for (const g of this.linkGroups ?? []) for (const c of g.children) if (!(this.sphereMeshes ?? []).includes(c)) c.visible = on;
    this.requestRender();
  }
  setObjectVisible(on) { this.objectGroup.visible = on; this.targetsGroup.visible = on; this.requestRender(); }

  // ---- picking, dragging, sketching ----
  setSketchMode(on) {
    this.sketchMode = on;
    this.container.classList.toggle('sketching', on);
  }

  pointerRay(event) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(ndc, this.camera);
    return this.raycaster;
  }

  viewPlaneThrough(point) {
    const normal = new THREE.Vector3();
    this.camera.getWorldDirection(normal);
    return new THREE.Plane().setFromNormalAndCoplanarPoint(normal, point);
  }

  objectCentroid() {
    const x = this.positions, n = x.length / 3, c = new THREE.Vector3();
    for (let i = 0; i < n; i++) c.x += x[3 * i], c.y += x[3 * i + 1], c.z += x[3 * i + 2];
    return c.multiplyScalar(1 / n);
  }

  onPointerDown(event) {
    if (event.button !== 0 || !this.positions) return;
    const ray = this.pointerRay(event);
    if (this.sketchMode) {
      // The sketch lies in the plane through the object facing the camera.
      this.sketchPlane = this.viewPlaneThrough(this.objectCentroid());
      this.sketchPoints = [];
      this.addSketchPoint(ray);
      this.beginGesture(event);
      return;
    }
    const handles = this.targetsGroup.children.filter((c) => c.userData.node !== undefined);
    const handleHit = ray.intersectObjects(handles, false)[0];
    if (handleHit) {
      this.startDrag(handleHit.object.userData.node, handleHit.object.position.clone(), handleHit.point, event);
      return;
    }
    const hit = ray.intersectObject(this.objectMesh, false)[0];
    if (!hit || !hit.face) return;
    // The nearest vertex of the hit triangle is the picked node.
    const node = [hit.face.a, hit.face.b, hit.face.c]
      .map((v) => ({ v, d: this.nodePosition(v).distanceTo(hit.point) }))
      .sort((p, q) => p.d - q.d)[0].v;
    const existing = this.targetPositions().get(node);
    const start = existing ?? this.nodePosition(node);
    if (!existing) this.callbacks.addTarget(node, start.toArray());
    this.startDrag(node, start.clone(), hit.point, event);
  }

  beginGesture(event) {
    this.controls.enabled = false;
    this.renderer.domElement.setPointerCapture(event.pointerId);
    event.stopPropagation();
    event.preventDefault();
  }

  startDrag(node, targetPosition, grabPoint, event) {
    this.select(node);
    this.drag = { node, plane: this.viewPlaneThrough(grabPoint), offset: targetPosition.clone().sub(grabPoint), lastSent: 0, moved: false };
    this.localTargets.set(node, targetPosition);
    this.beginGesture(event);
  }

  select(node) {
    this.selected = node;
    this.callbacks.select(node);
    this.updateTargets();
  }

  addSketchPoint(ray) {
    const p = new THREE.Vector3();
    if (!ray.ray.intersectPlane(this.sketchPlane, p)) return;
    const last = this.sketchPoints[this.sketchPoints.length - 1];
    if (last && last.distanceTo(p) < 0.002) return;
    this.sketchPoints.push(p);
    this.sketchLine.geometry.setFromPoints(this.sketchPoints);
    this.requestRender();
  }

  onPointerMove(event) {
    if (this.sketchPoints) { this.addSketchPoint(this.pointerRay(event)); return; }
    if (!this.drag) return;
    const p = new THREE.Vector3();
    if (!this.pointerRay(event).ray.intersectPlane(this.drag.plane, p)) return;
    const target = p.add(this.drag.offset);
    this.localTargets.set(this.drag.node, target);
    this.drag.moved = true;
    this.updateTargets();
    const now = performance.now();
    if (now - this.drag.lastSent > 33) {  // ~30 edits per second
      this.drag.lastSent = now;
      this.callbacks.moveTarget(this.drag.node, target.toArray());
    }
  }

  onPointerUp(event) {
    if (this.sketchPoints) {
      const points = this.sketchPoints;
      this.sketchPoints = null;
      this.sketchLine.geometry.setFromPoints([]);
      this.controls.enabled = true;
      if (points.length >= 2) this.callbacks.sketch(resample(points, 64).map((p) => p.toArray()));
      return;
    }
    if (!this.drag) return;
    const { node, moved } = this.drag;
    this.drag = null;
    this.controls.enabled = true;
    if (moved) this.callbacks.moveTarget(node, this.localTargets.get(node).toArray());
    // Keep showing the local target until the server's state has caught up.
    setTimeout(() => { if (!this.drag) { this.localTargets.delete(node); this.updateTargets(); } }, 300);
  }

  // ---- for tests and tools: page coordinates of a world point ----
  worldToPage(point) {
    const v = new THREE.Vector3(...point).project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height };
  }
}

// Evenly spaced points along a polyline (by arc length), at most `count`.
function resample(points, count) {
  const lengths = [0];
  for (let i = 1; i < points.length; i++) lengths.push(lengths[i - 1] + points[i].distanceTo(points[i - 1]));
  const total = lengths[lengths.length - 1];
  if (points.length <= count || total === 0) return points;
  const out = [];
  let j = 0;
  for (let k = 0; k < count; k++) {
    const s = total * k / (count - 1);
    while (j < points.length - 2 && lengths[j + 1] < s) j++;
    const t = (s - lengths[j]) / Math.max(1e-12, lengths[j + 1] - lengths[j]);
    out.push(points[j].clone().lerp(points[j + 1], Math.min(1, Math.max(0, t))));
  }
  return out;
}
