// The 3D view: owns the renderer, camera and orbit controls, the robot and object views and
// the target controls, and wires them together. World frame, metres, z up. Picking, dragging
// and sketching turn into callbacks; the server decides.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { ObjectView } from './object_view.js';
import { RobotView } from './robot_view.js';
import { GhostView } from './ghost_view.js';
import { ObstaclesView } from './obstacles_view.js';
import { ContactsView } from './contacts_view.js';
import { TargetControls } from './target_controls.js';
import { TargetGizmo } from './target_gizmo.js';
import { fitCamera, fitSphere } from './fit_view.js';
import { Occlusion } from './occlusion.js';

const MOVE_INTERVAL_MS = 33;       // ~30 target edits per second while dragging
const LOCAL_TARGET_HOLD_MS = 300;  // a dropped target shows where it was left until the server has it
const FRONT_VIEW = new THREE.Vector3(0.95, -0.5, 0.45);  // fit-view: from the scene towards the camera
const UP = new THREE.Vector3(0, 0, 1);

export class View3D {
  constructor(container, callbacks) {
    this.container = container;
    // addTarget(node, position), moveTarget(node, position), sketch(points), select(node), and
    // beginEdit() before a gesture changes the targets (for undo)
    this.callbacks = callbacks;
    this.renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true, stencil: true });  // stencil: robot_view.js' fade
    this.renderer.setPixelRatio(window.devicePixelRatio);
    container.appendChild(this.renderer.domElement);

    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color(0x1d2025);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 50);
    this.camera.up.copy(UP);
    this.camera.position.set(1.4, -0.9, 0.9);
    this.orbit = new OrbitControls(this.camera, this.renderer.domElement);
    this.orbit.target.set(0.35, 0, 0.15);
    this.orbit.update();

    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x444444, 2.0));
    const sun = new THREE.DirectionalLight(0xffffff, 1.5);
    sun.position.set(1, -1, 2);
    this.scene.add(sun);
    const grid = new THREE.GridHelper(2, 20, 0x444444, 0x333333);
    grid.rotateX(Math.PI / 2);
    this.scene.add(grid);

    this.robotView = new RobotView();
    this.ghostView = new GhostView();
    this.objectView = new ObjectView();
    this.obstaclesView = new ObstaclesView();
    this.contactsView = new ContactsView();
    this.occlusion = new Occlusion(this.robotView, this.objectView);
    this.scene.add(this.robotView.group, this.ghostView.group, this.objectView.group, this.obstaclesView.group, this.contactsView.group);
    this.targetControls = new TargetControls(this.camera, this.objectView, this.renderer.domElement);
    this.gizmo = new TargetGizmo(this.camera, this.renderer.domElement, this.scene);
    this.targetControls.yieldsTo = (event) => this.gizmo.hits(event);

    this.robotSeeThrough = false;  // the t key
    this.fitPending = false;       // a new scene waits for its shape and pose to be framed
    this.framed = null;            // 'all' or 'object': the camera is as fitView/fitObject left it, a resize frames anew
    this.state = null;             // the last state message shown
    this.frames = 0;               // frames rendered (tests wait for a few)
    this.renderPending = false;
    this.moveSentAt = -Infinity;   // performance.now() of the last moveTarget while dragging
    this.scratch = new THREE.Vector3();
    this.viewSize = new THREE.Vector2();

    this.wireTargetControls();
    // Render on demand only: software WebGL (headless, remote desktops) can't afford 60 fps.
    this.orbit.addEventListener('change', () => this.requestRender());
    this.orbit.addEventListener('start', () => { this.framed = null; });  // the user's view now
    new ResizeObserver(() => this.resize()).observe(container);
    this.resize();
  }

  wireTargetControls() {
    const controls = this.targetControls;
    controls.addEventListener('dragstart', ({ node, position, added }) => {
      this.gizmo.setEnabled(false);
      this.startTargetDrag(node, position, added);
    });
    controls.addEventListener('drag', ({ node, position }) => this.dragTarget(node, position));
    controls.addEventListener('dragend', ({ node, position, moved }) => {
      this.gizmo.setEnabled(true);
      this.endTargetDrag(node, position, moved);
    });
    this.gizmo.addEventListener('dragstart', ({ node, position }) => this.startTargetDrag(node, position, false));
    this.gizmo.addEventListener('drag', ({ node, position }) => this.dragTarget(node, position));
    this.gizmo.addEventListener('dragend', ({ node, position }) => this.endTargetDrag(node, position, true));
    this.gizmo.addChangeListener(() => this.requestRender());
    controls.addEventListener('sketchstart', () => { this.orbit.enabled = false; });
    controls.addEventListener('sketch', ({ points }) => {
      this.objectView.setSketch(points);
      this.requestRender();
    });
    controls.addEventListener('sketchend', ({ points }) => {
      this.orbit.enabled = true;
      this.objectView.setSketch([]);
      this.requestRender();
      if (points.length < 2) return;
      this.callbacks.beginEdit();
      this.callbacks.sketch(points.map((p) => p.toArray()));
    });
  }

  // A target drag (by handle, surface or gizmo): shown locally at once, sent ~30 times a second.
  startTargetDrag(node, position, added) {
    this.orbit.enabled = false;
    this.callbacks.beginEdit();
    if (added) this.callbacks.addTarget(node, position.toArray());
    this.moveSentAt = -Infinity;
    this.objectView.setLocalTarget(node, position);
    this.select(node);
  }

  dragTarget(node, position) {
    this.objectView.setLocalTarget(node, position);
    if (!this.gizmo.dragging) this.gizmo.attach(node, position);
    this.requestRender();
    const now = performance.now();
    if (now - this.moveSentAt < MOVE_INTERVAL_MS) return;
    this.moveSentAt = now;
    this.callbacks.moveTarget(node, position.toArray());
  }

  endTargetDrag(node, position, moved) {
    this.orbit.enabled = true;
    if (moved) this.callbacks.moveTarget(node, position.toArray());
    setTimeout(() => {
      if (this.targetControls.dragging || this.gizmo.dragging) return;
      this.objectView.dropLocalTarget(node);
      this.requestRender();
    }, LOCAL_TARGET_HOLD_MS);
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
    const from = this.scratch.subVectors(this.camera.position, this.orbit.target);
    if (this.framed === 'all') this.fitView(from);
    else if (this.framed === 'object') this.fitObject(from);
    this.requestRender();
  }

  render() {
    const size = this.renderer.getSize(this.viewSize);
    this.objectView.fitToScreen(this.camera, size.x, size.y);
    if (this.occlusion.update(this.camera, performance.now())) this.requestRender();  // a link still fading
    this.renderer.render(this.scene, this.camera);
    this.frames++;
  }

  // ---- scene description and streamed state ----
  setScene(description) {
    this.targetControls.cancel();
    this.gizmo.attach(null);
    this.orbit.enabled = true;
    this.robotView.setRobot(description.robot);
    this.occlusion.setScene(description);
    this.ghostView.setRobot(description.robot);
    this.objectView.setScene(description);
    this.obstaclesView.setObstacles(description.obstacles);
    this.contactsView.set(null);
    this.obstaclesCentred = false;  // a plane goes under the object once its shape arrived
    this.state = null;
    this.fitPending = true;
    this.requestRender();
  }

  setPositions(positions) {
    this.objectView.setPositions(positions);
    if (!this.obstaclesCentred) {
      this.obstaclesView.centreUnder(this.objectView.centroid(this.scratch));
      this.obstaclesCentred = true;
    }
    this.fitOnceShown();
    this.requestRender();
  }

  // A new scene is framed once both its shape and its robot's pose have arrived.
  fitOnceShown() {
    if (!this.fitPending || !this.objectView.positions || !this.state) return;
    this.fitPending = false;
    this.fitView();
  }

  setState(state) {
    const unchanged = this.state && this.state.seq === state.seq && this.state.scene === state.scene;
    this.state = state;
    // The measured robot moves between snapshots.
    if (this.ghostView.setState(state)) this.requestRender();
    if (unchanged) return;  // same snapshot: nothing to redraw (saves software-GL time)
    this.robotView.setLinkPoses(state.links);
    this.obstaclesView.setLinkPoses(state.links, this.robotView.linkGroups.map((g) => g.name));
    this.objectView.setCenterline(state.centerline);
    this.objectView.setTargets(state.targets, state.centerline.length === 0);  // the curve is the handle there
    this.objectView.setObservedMarkers(state.observed_markers);
    this.objectView.setObservedPoints(state.observed_points);
    this.contactsView.set(state.contacts);
    this.placeGizmo();
    this.fitOnceShown();
    this.requestRender();
  }

  // The gizmo on the selected target, where it is drawn; off without one.
  placeGizmo() {
    const node = this.objectView.selected;
    const at = node === null || !this.objectView.showHandles ? null : this.objectView.targetPosition(node, this.scratch);
    this.gizmo.attach(at ? node : null, at);
  }

  // Frames the robot and the object from `direction` (towards the camera; by default the front,
  // +x where the robot faces, a little from the side and above), all of both in view (on load,
  // on a scene switch, and on a resize from where the camera looks).
  fitView(direction = FRONT_VIEW) {
    if (!this.objectView.positions) return;
    const robot = this.robotView.group, object = this.objectView.positionAttribute, point = new THREE.Vector3();
    robot.updateMatrixWorld(true);  // link poses set since the last render
    const box = new THREE.Box3().setFromBufferAttribute(object).union(new THREE.Box3().setFromObject(robot));
    fitCamera(this.camera, this.orbit, box.getCenter(new THREE.Vector3()), direction, (visit) => {
      for (let i = 0; i < object.count; i++) visit(point.fromBufferAttribute(object, i));
      // Primitive visuals, and loaded mesh visuals inside their holders.
      for (const visual of this.robotView.visualMeshes) visual.traverse((mesh) => {
        const vertices = mesh.isMesh ? mesh.geometry.getAttribute('position') : null;
        for (let i = 0; i < (vertices?.count ?? 0); i++) visit(point.fromBufferAttribute(vertices, i).applyMatrix4(mesh.matrixWorld));
      });
    });
    this.framed = 'all';
    this.requestRender();
  }

  // Frames the object alone (the f key): its bounding sphere fills the view, seen from `direction`
  // as fitView; the robot may reach out of view.
  fitObject(direction = FRONT_VIEW) {
    if (!this.objectView.positions) return;
    const sphere = this.objectView.surfaceGeometry.boundingSphere;  // kept by setPositions
    fitSphere(this.camera, this.orbit, sphere.center, sphere.radius, direction);
    this.framed = 'object';
    this.requestRender();
  }

  // Looks at a bar square on from the robot's front, so the sketch plane contains its axis.
  faceBar(direction) {
    const side = this.scratch.fromArray(direction).cross(UP).normalize();
    if (side.x < 0) side.negate();
    this.objectView.centroid(this.orbit.target);
    this.camera.position.copy(this.orbit.target).addScaledVector(side, 0.8);
    this.camera.position.z += 0.2;
    this.framed = null;
    this.orbit.update();
    this.camera.updateMatrixWorld();
  }

  // ---- selection and display toggles ----
  get selected() { return this.objectView.selected; }
  get sketchMode() { return this.targetControls.sketchMode; }
  get positions() { return this.objectView.positions; }
  get arrowCount() { return this.objectView.arrowCount; }
  // Observed cloud points drawn now (0 when hidden).
  get observedPointsDrawn() {
    const cloud = this.objectView.cloud;
    return cloud.visible && cloud.parent.visible ? cloud.geometry.drawRange.count : 0;
  }

  select(node) {
    this.objectView.setSelected(node);
    this.placeGizmo();
    this.callbacks.select(node);
    this.requestRender();
  }

  setSketchMode(on) {
    this.targetControls.sketchMode = on;
    this.container.classList.toggle('sketching', on);
    this.renderer.domElement.style.cursor = '';  // the sketch's crosshair (style.css), or the hover's again
  }

  setWireframe(on) { this.objectView.setWireframe(on); this.requestRender(); }
  setSpheresVisible(on) { this.robotView.setSpheresVisible(on); this.requestRender(); }
  // A see-through robot: targets behind the arms show through them.
  setRobotSeeThrough(on) {
    this.robotSeeThrough = on;
    this.occlusion.setAll(on);
    this.requestRender();
  }
  // The links hiding the object drawn see-through (occlusion.js).
  setSeeThroughArms(on) { this.occlusion.setEnabled(on); this.requestRender(); }
  // Handles, arrows and the gizmo (tests compare the view with and without them).
  setTargetsVisible(on) { this.objectView.glyphs.group.visible = on; this.gizmo.setVisible(on); this.requestRender(); }
  setRobotVisible(on) { this.robotView.setVisible(on); this.requestRender(); }
  setObjectVisible(on) { this.objectView.setVisible(on); this.requestRender(); }
  setObservedPointsVisible(on) { this.objectView.setObservedPointsVisible(on); this.requestRender(); }
  setContactsVisible(on) { this.contactsView.setEnabled(on); this.requestRender(); }

  // ---- for tests and tools (new arrays and vectors: callers keep them) ----
  nodePosition(node) { return this.objectView.nodePosition(node, new THREE.Vector3()); }
  objectCentroid() { return this.objectView.centroid(new THREE.Vector3()); }
  cameraDirection() { return this.camera.getWorldDirection(new THREE.Vector3()).toArray(); }
  observedPoints() {
    const geometry = this.objectView.cloud.geometry, attribute = geometry.getAttribute('position');
    return Array.from({ length: attribute ? geometry.drawRange.count : 0 }, (_, k) => [attribute.getX(k), attribute.getY(k), attribute.getZ(k)]);
  }

  // The selected target's gizmo on the page: its centre and its x, y, z arrows' tips.
  gizmoOnPage() {
    if (this.gizmo.node === null) return null;
    const centre = this.gizmo.standIn.position.toArray();
    const reach = this.gizmo.arrowLength();
    const tip = (i) => this.worldToPage(centre.map((v, k) => v + (k === i ? reach : 0)));
    return { node: this.gizmo.node, centre: this.worldToPage(centre), x: tip(0), y: tip(1), z: tip(2) };
  }

  // Every node of the object on the page, and the canvas's box: whether it is all in view.
  objectOnPage() {
    const x = this.objectView.positions, nodes = [];
    for (let i = 0; i < x.length; i += 3) nodes.push(this.worldToPage([x[i], x[i + 1], x[i + 2]]));
    const r = this.renderer.domElement.getBoundingClientRect();
    return { nodes, view: { left: r.left, top: r.top, right: r.right, bottom: r.bottom } };
  }

  // Page coordinates of a world point.
  worldToPage(point) {
    const v = this.scratch.fromArray(point).project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + (v.x + 1) / 2 * rect.width, y: rect.top + (1 - v.y) / 2 * rect.height };
  }
}
