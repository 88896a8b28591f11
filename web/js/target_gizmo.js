// three.js' TransformControls translate gizmo on the selected target: dragging one of its arrows
// moves the target along that world axis only, a plane square along two. It moves a stand-in
// object at the target and reports; its owner sends the edits.
//   dragstart {node}, drag {node, position}, dragend {node, position}   (position: scratch)
import { EventDispatcher, Object3D, Vector2 } from 'three';
import { TransformControls } from 'three/addons/controls/TransformControls.js';

const GIZMO_SIZE = 0.7;  // TransformControls' own screen-relative size

// Removes the translate gizmo's centre (a translucent white blob for free moves in the view
// plane): it would sit on the target's handle and wash its orange out, and the handle's own drag
// does that move (and knows the axis keys). Reaches into TransformControls' gizmo by name.
function withoutCentre(controls) {
  const gizmo = controls.getHelper().children.find((c) => c.gizmo && c.picker);
  for (const group of [gizmo?.gizmo.translate, gizmo?.picker.translate]) {
    for (const centre of group?.children.filter((c) => c.name === 'XYZ') ?? []) group.remove(centre);
  }
}

export class TargetGizmo extends EventDispatcher {
  constructor(camera, domElement, scene) {
    super();
    this.camera = camera;
    this.domElement = domElement;
    this.standIn = new Object3D();  // where the selected target is; the gizmo moves it
    scene.add(this.standIn);
    this.controls = new TransformControls(camera, domElement);
    this.controls.setMode('translate');
    this.controls.setSpace('world');
    this.controls.setSize(GIZMO_SIZE);
    scene.add(this.controls.getHelper());
    withoutCentre(this.controls);
    this.node = null;  // the target it is on, null when detached
    this._pointer = new Vector2();
    this.controls.addEventListener('dragging-changed', ({ value }) => {
      if (this.node === null) return;
      this.dispatchEvent({ type: value ? 'dragstart' : 'dragend', node: this.node, position: this.standIn.position });
    });
    this.controls.addEventListener('objectChange', () => {
      if (this.node !== null) this.dispatchEvent({ type: 'drag', node: this.node, position: this.standIn.position });
    });
  }

  get dragging() { return this.controls.dragging; }

  // On the target of `node` at `position` (Vector3); null `node` detaches it.
  attach(node, position) {
    if (node === null || !position) {
      this.node = null;
      this.controls.detach();
      return;
    }
    if (this.controls.dragging && this.node === node) return;  // the hand moves it
    this.node = node;
    this.standIn.position.copy(position);
    this.standIn.updateMatrixWorld();
    if (this.controls.object !== this.standIn) this.controls.attach(this.standIn);
  }

  // Whether a press at `event` would grab the gizmo (an axis arrow or plane square under it).
  hits(event) {
    const rect = this.domElement.getBoundingClientRect();
    this._pointer.set(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    return this.hitsAt(this._pointer, event.button);
  }

  // The same at `pointer` (normalized device coordinates); it also highlights that arrow.
  hitsAt(pointer, button = 0) {
    if (this.node === null) return false;
    this.controls.getHelper().updateMatrixWorld(true);
    this.controls.pointerHover({ x: pointer.x, y: pointer.y, button });
    return this.controls.axis !== null;
  }

  // Metres from the centre to an arrow's tip now (0.6 gizmo units, scaled as TransformControls
  // scales them: by the camera distance, so they keep their size on screen).
  arrowLength() {
    const camera = this.camera, distance = this.standIn.position.distanceTo(camera.position);
    const factor = distance * Math.min(1.9 * Math.tan(Math.PI * camera.fov / 360) / camera.zoom, 7);
    return 0.6 * factor * GIZMO_SIZE / 4;
  }

  // Off while another control drags the target: no hover highlight, no grab.
  setEnabled(on) {
    this.controls.enabled = on;
    if (!on) this.controls.axis = null;
  }

  setVisible(on) { this.controls.getHelper().visible = on; }

  addChangeListener(listener) { this.controls.addEventListener('change', listener); }
}
