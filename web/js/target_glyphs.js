// Each target's handle (a sphere to grab) and arrow (from its node to the target), sized in
// screen pixels and drawn over the robot and the object: a target must stay visible and
// grabbable wherever it was dragged, and a few-mm error must still show an arrow with a head.
// Pooled: the first `count` handles and arrows are shown. World frame, metres.
import * as THREE from 'three';

export const TARGET_ORANGE = 0xff8c1a;
const HANDLE_PIXELS = 7;           // handle radius on screen
const SELECTED_HANDLE_PIXELS = 10; // the selected one is bigger, same orange (and carries the gizmo)
const HOVERED_GROWTH_PIXELS = 2;   // the one under the pointer grows by this: it can be grabbed
const SHAFT_PIXELS = 1.5;          // arrow shaft radius
const HEAD_PIXELS = 5;             // arrow head radius
const HEAD_FRACTION = 0.3;         // head length / arrow length: the head grows with the error
const RENDER_ORDER = 20;           // after the robot and the object: on top

const overlay = (color) => new THREE.MeshBasicMaterial({ color, depthTest: false, depthWrite: false, transparent: true });
const HANDLE_MATERIAL = overlay(TARGET_ORANGE);
const ARROW_MATERIAL = overlay(TARGET_ORANGE);
const SPHERE = new THREE.SphereGeometry(1, 16, 12);
// Unit shaft and head along +y from the origin, so scale.y is their length.
const SHAFT = new THREE.CylinderGeometry(1, 1, 1, 8).translate(0, 0.5, 0);
const HEAD = new THREE.ConeGeometry(1, 1, 12).translate(0, -0.5, 0);  // tip at the origin
const Y = new THREE.Vector3(0, 1, 0);

const _eye = new THREE.Vector3();
const _view = new THREE.Vector3();
const _delta = new THREE.Vector3();

// Metres per screen pixel at `point` for a perspective `camera` in a `heightPixels` view.
export function metresPerPixel(camera, point, heightPixels) {
  const depth = _eye.subVectors(point, camera.position).dot(camera.getWorldDirection(_view));
  return 2 * Math.max(depth, camera.near) * Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2) / heightPixels;
}

export class TargetGlyphs {
  constructor() {
    this.group = new THREE.Group();
    this.handles = [];
    this.arrows = [];
    this.handleCount = 0;
    this.arrowCount = 0;
  }

  begin() {
    this.handleCount = 0;
    this.arrowCount = 0;
  }

  // Hides the pooled glyphs not used since begin().
  end() {
    this.handles.forEach((h, k) => { h.visible = k < this.handleCount; });
    this.arrows.forEach((a, k) => { a.visible = k < this.arrowCount; });
  }

  addHandle(node, position, selected, hovered) {
    if (this.handleCount === this.handles.length) {
      const mesh = new THREE.Mesh(SPHERE, HANDLE_MATERIAL);
      mesh.renderOrder = RENDER_ORDER + 1;
      this.handles.push(mesh);
      this.group.add(mesh);
    }
    const handle = this.handles[this.handleCount++];
    handle.position.copy(position);
    handle.userData.node = node;
    handle.userData.pixels = (selected ? SELECTED_HANDLE_PIXELS : HANDLE_PIXELS) + (hovered ? HOVERED_GROWTH_PIXELS : 0);
  }

  addArrow(from, to) {
    if (this.arrowCount === this.arrows.length) {
      const arrow = new THREE.Group();
      const shaft = new THREE.Mesh(SHAFT, ARROW_MATERIAL), head = new THREE.Mesh(HEAD, ARROW_MATERIAL);
      shaft.renderOrder = head.renderOrder = RENDER_ORDER;
      arrow.add(shaft, head);
      arrow.userData = { from: new THREE.Vector3(), to: new THREE.Vector3() };
      this.arrows.push(arrow);
      this.group.add(arrow);
    }
    const arrow = this.arrows[this.arrowCount++];
    arrow.userData.from.copy(from);
    arrow.userData.to.copy(to);
  }

  // Sizes every shown glyph for `camera` in a view `heightPixels` high; call before each render.
  fitToScreen(camera, heightPixels) {
    for (let k = 0; k < this.handleCount; k++) {
      const h = this.handles[k];
      h.scale.setScalar(h.userData.pixels * metresPerPixel(camera, h.position, heightPixels));
    }
    for (let k = 0; k < this.arrowCount; k++) {
      const arrow = this.arrows[k], { from, to } = arrow.userData;
      const length = _delta.subVectors(to, from).length();
      const pixel = metresPerPixel(camera, to, heightPixels);
      const head = HEAD_FRACTION * length;
      const [shaft, tip] = arrow.children;
      arrow.position.copy(to);  // the head's tip at the target
      arrow.quaternion.setFromUnitVectors(Y, _delta.divideScalar(length).negate());
      // Built from the tip back to the node: +y points from the target to the node.
      shaft.position.set(0, head, 0);
      shaft.scale.set(SHAFT_PIXELS * pixel, length - head, SHAFT_PIXELS * pixel);
      tip.rotation.set(Math.PI, 0, 0);  // cone tip at the origin, widening towards the node
      tip.scale.set(Math.max(HEAD_PIXELS * pixel, 0.35 * head), head, Math.max(HEAD_PIXELS * pixel, 0.35 * head));
    }
  }

  // The shown handle nearest along `raycaster`: {node, target, point} or null.
  pick(raycaster) {
    const hit = raycaster.intersectObjects(this.handles.slice(0, this.handleCount), false)[0];
    return hit ? { node: hit.object.userData.node, target: hit.object.position.clone(), point: hit.point } : null;
  }
}
