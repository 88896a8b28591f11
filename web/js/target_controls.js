// Mouse interaction with the object, in the style of three.js' DragControls: a left press on
// a target handle or on the surface drags that node's target in the plane facing the camera;
// in sketch mode a left drag draws a centre-line in the plane through the object facing the
// camera. Holding x, y or z while dragging moves the target along that world axis only. A press
// off the handles that `yieldsTo(event)` claims (the gizmo's) is left alone. It changes nothing itself: it dispatches events and its owner acts on them.
//   dragstart {node, position, added}  added: the node had no target, position is where it starts
//   drag      {node, position}         position: scratch vector, copy it to keep it
//   dragend   {node, position, moved}
//   sketchstart, sketch {points}, sketchend {points}  (sketchend: evenly resampled, at most 64)
// The owner disables its camera controls from dragstart/sketchstart to the matching end event.
import { Controls, Plane, Raycaster, Vector2, Vector3 } from 'three';
import { typingIn } from './keys.js';

const SKETCH_SPACING = 0.002;  // m; closer pointer samples are dropped
const SKETCH_POINTS = 64;      // points in a finished sketch
const AXES = { x: new Vector3(1, 0, 0), y: new Vector3(0, 1, 0), z: new Vector3(0, 0, 1) };
const AXIS_REACH = 10;         // m; the axis line is a segment this far each way

export class TargetControls extends Controls {
  constructor(camera, objectView, domElement = null) {
    super(camera, domElement);
    this.objectView = objectView;
    this.sketchMode = false;   // presses sketch instead of picking
    this.dragNode = null;      // node whose target is being dragged
    this.moved = false;        // the dragged target moved since the press
    this.sketchPoints = null;  // Vector3s of the stroke while sketching
    this.axis = null;          // 'x', 'y' or 'z' while that key is held: drags follow that axis
    this.yieldsTo = () => false;  // (pointerdown event) → true when another control takes it
    this.raycaster = new Raycaster();
    // Scratch objects, reused by every pointer event.
    this._pointer = new Vector2();
    this._plane = new Plane();
    this._offset = new Vector3();  // dragged target minus the grabbed point
    this._point = new Vector3();
    this._target = new Vector3();  // where the dragged target is
    this._dragAxis = null;         // the axis the drag follows now (null: the view plane)
    this._anchor = new Vector3();  // axis drags: the target when the axis was taken
    this._anchorParameter = 0;     // axis drags: the pointer's place along the axis then
    this._segment = [new Vector3(), new Vector3(), new Vector3()];  // axis ends, nearest point
    this._onAxisKey = this.onAxisKey.bind(this);
    this._onBlur = () => { this.axis = null; };
    this._onPointerDown = this.onPointerDown.bind(this);
    this._onPointerMove = this.onPointerMove.bind(this);
    this._onPointerUp = this.onPointerUp.bind(this);
    if (domElement !== null) this.connect(domElement);
  }

  connect(element) {
    super.connect(element);
    // Capture phase: decide before OrbitControls whether this press is ours.
    element.addEventListener('pointerdown', this._onPointerDown, { capture: true });
    element.addEventListener('pointermove', this._onPointerMove);
    element.addEventListener('pointerup', this._onPointerUp);
    element.addEventListener('pointercancel', this._onPointerUp);
    window.addEventListener('keydown', this._onAxisKey);
    window.addEventListener('keyup', this._onAxisKey);
    window.addEventListener('blur', this._onBlur);
  }

  disconnect() {
    this.domElement.removeEventListener('pointerdown', this._onPointerDown, { capture: true });
    this.domElement.removeEventListener('pointermove', this._onPointerMove);
    this.domElement.removeEventListener('pointerup', this._onPointerUp);
    this.domElement.removeEventListener('pointercancel', this._onPointerUp);
    window.removeEventListener('keydown', this._onAxisKey);
    window.removeEventListener('keyup', this._onAxisKey);
    window.removeEventListener('blur', this._onBlur);
  }

  // x, y, z held (not while typing in a field) constrain drags to that axis.
  onAxisKey(event) {
    const key = event.key.toLowerCase();
    if (!(key in AXES) || event.ctrlKey || event.metaKey || event.altKey) return;
    if (event.type === 'keyup') { if (this.axis === key) this.axis = null; return; }
    if (typingIn(event.target)) return;
    this.axis = key;
    event.preventDefault();  // a focused list does not pick an item by the letter
  }

  dispose() {
    this.disconnect();
  }

  get dragging() { return this.dragNode !== null; }

  // Forgets a gesture in progress without end events (its scene is gone).
  cancel() {
    this.dragNode = null;
    this.sketchPoints = null;
  }

  onPointerDown(event) {
    if (!this.enabled || event.button !== 0 || !this.objectView.positions) return;
    this.updateRay(event);
    if (this.sketchMode) {
      this.setViewPlane(this.objectView.centroid(this._point));
      this.sketchPoints = [];
      this.beginGesture(event);
      this.dispatchEvent({ type: 'sketchstart' });
      this.addSketchPoint();
      return;
    }
    const handle = this.objectView.pickHandle(this.raycaster);
    if (handle) {
      this.startDrag(handle.node, handle.target, handle.point, false, event);
      return;
    }
    if (this.yieldsTo(event)) return;  // the gizmo's arrows reach over the surface, not over handles
    const picked = this.objectView.pickNode(this.raycaster);
    if (!picked) return;
    const existing = this.objectView.targetPosition(picked.node, this._target);
    const start = existing ?? this.objectView.nodePosition(picked.node, this._target);
    this.startDrag(picked.node, start, picked.point, !existing, event);
  }

  onPointerMove(event) {
    if (!this.enabled) return;
    if (this.sketchPoints) {
      this.updateRay(event);
      this.addSketchPoint();
      return;
    }
    if (this.dragNode === null) return;
    this.updateRay(event);
    if (this.axis !== this._dragAxis) this.rebase();
    if (this._dragAxis) {
      this._target.copy(this._anchor).addScaledVector(AXES[this._dragAxis], this.axisParameter() - this._anchorParameter);
    } else {
      if (!this.raycaster.ray.intersectPlane(this._plane, this._point)) return;
      this._target.addVectors(this._point, this._offset);
    }
    this.moved = true;
    this.dispatchEvent({ type: 'drag', node: this.dragNode, position: this._target });
  }

  onPointerUp() {
    if (this.sketchPoints) {
      const points = this.sketchPoints;
      this.sketchPoints = null;
      this.dispatchEvent({ type: 'sketchend', points: resample(points, SKETCH_POINTS) });
      return;
    }
    if (this.dragNode === null) return;
    const node = this.dragNode;
    this.dragNode = null;
    this.dispatchEvent({ type: 'dragend', node, position: this._target, moved: this.moved });
  }

  // `start` may be this._target itself.
  startDrag(node, start, grabPoint, added, event) {
    this._offset.subVectors(start, grabPoint);
    this._target.copy(start);
    this.setViewPlane(grabPoint);
    this.dragNode = node;
    this.moved = false;
    this._dragAxis = null;
    if (this.axis) this.rebase();
    this.beginGesture(event);
    this.dispatchEvent({ type: 'dragstart', node, position: this._target, added });
  }

  beginGesture(event) {
    this.domElement.setPointerCapture(event.pointerId);
    event.stopPropagation();
    event.preventDefault();
  }

  // The drag switches between the view plane and an axis: it goes on from where the target is.
  rebase() {
    this._dragAxis = this.axis;
    if (this._dragAxis) {
      this._anchor.copy(this._target);
      this._anchorParameter = this.axisParameter();
      return;
    }
    this.setViewPlane(this._target);
    if (this.raycaster.ray.intersectPlane(this._plane, this._point)) this._offset.subVectors(this._target, this._point);
    else this._offset.set(0, 0, 0);
  }

  // Where the pointer's ray passes nearest the drag axis through the anchor, as a coordinate
  // along that axis (m from the anchor).
  axisParameter() {
    const axis = AXES[this._dragAxis];
    const [a, b, onAxis] = this._segment;
    a.copy(this._anchor).addScaledVector(axis, -AXIS_REACH);
    b.copy(this._anchor).addScaledVector(axis, AXIS_REACH);
    this.raycaster.ray.distanceSqToSegment(a, b, null, onAxis);
    return onAxis.sub(this._anchor).dot(axis);
  }

  updateRay(event) {
    const rect = this.domElement.getBoundingClientRect();
    this._pointer.set(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    this.raycaster.setFromCamera(this._pointer, this.object);
  }

  setViewPlane(point) {
    this._plane.setFromNormalAndCoplanarPoint(this.object.getWorldDirection(this._plane.normal), point);
  }

  addSketchPoint() {
    if (!this.raycaster.ray.intersectPlane(this._plane, this._point)) return;
    const last = this.sketchPoints[this.sketchPoints.length - 1];
    if (last && last.distanceTo(this._point) < SKETCH_SPACING) return;
    this.sketchPoints.push(this._point.clone());
    this.dispatchEvent({ type: 'sketch', points: this.sketchPoints });
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
