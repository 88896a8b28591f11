// The object's contacts with the obstacles (a state's "contacts", docs/contact.md): each contact
// point as a small dot and the obstacle's force on the object there as an arrow from the point
// along the force, drawn over everything (the points lie between the object and the obstacle).
// Arrow lengths are to one scale per state, a round number of newtons per centimetre chosen so
// the largest force is at most MAX_ARROW_CM long; the page shows it ("1 cm = 0.05 N").
// The object's contacts with itself ("contacts.self") as dots of their own colour, no arrows: a
// pair pushes its two sides apart with equal and opposite forces.
import * as THREE from 'three';

const COLOR = 0xffe14d;        // yellow: apart from targets (orange), grips (red), observations
const SELF_COLOR = 0x5cff6e;   // green: self-contact, apart from the obstacles' yellow
const POINT_PIXELS = 5;
const MAX_ARROW_CM = 3;        // the largest force's arrow, at most
const HEAD_FRACTION = 0.25;    // head length / arrow length
const HEAD_WIDTH = 0.4;        // head radius / head length
const RENDER_ORDER = 15;       // over the object and the obstacles, under the target glyphs

const overlay = { color: COLOR, depthTest: false, depthWrite: false, transparent: true };
const HEAD = new THREE.ConeGeometry(1, 1, 10).translate(0, -0.5, 0);  // tip at the origin, along +y
const Y = new THREE.Vector3(0, 1, 0);

// The smallest 1, 2 or 5 × 10^k at least `value` (> 0).
function roundUp(value) {
  const decade = 10 ** Math.floor(Math.log10(value));
  return [1, 2, 5, 10].map((m) => m * decade).find((m) => m >= value * (1 - 1e-12));
}

// "0.05 N", "2 N", "1e-6 N".
export function forceLabel(newtons) { return `${+newtons.toPrecision(3)} N`; }

export class ContactsView {
  constructor() {
    this.group = new THREE.Group();
    this.group.name = 'contacts';
    this.capacity = 0;
    this.count = 0;             // points drawn
    this.newtonsPerCm = null;   // the arrows' scale; null without a force
    this.enabled = true;        // the page's checkbox
    this.pointGeometry = new THREE.BufferGeometry();
    this.points = new THREE.Points(this.pointGeometry, new THREE.PointsMaterial({ ...overlay, size: POINT_PIXELS, sizeAttenuation: false }));
    this.shaftGeometry = new THREE.BufferGeometry();
    this.shafts = new THREE.LineSegments(this.shaftGeometry, new THREE.LineBasicMaterial(overlay));
    this.heads = null;  // InstancedMesh, regrown with the capacity
    this.headMaterial = new THREE.MeshBasicMaterial(overlay);
    this.selfGeometry = new THREE.BufferGeometry();
    this.selfPoints = new THREE.Points(this.selfGeometry, new THREE.PointsMaterial({ ...overlay, color: SELF_COLOR, size: POINT_PIXELS, sizeAttenuation: false }));
    this.selfCount = 0;
    for (const o of [this.points, this.shafts, this.selfPoints]) { o.frustumCulled = false; o.renderOrder = RENDER_ORDER; }
    this.group.add(this.points, this.shafts, this.selfPoints);
    this.grow(64);
    this.set(null);
  }

  grow(capacity) {
    this.capacity = capacity;
    this.pointGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * capacity), 3));
    this.shaftGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * capacity), 3));
    if (this.heads) { this.group.remove(this.heads); this.heads.dispose(); }
    this.heads = new THREE.InstancedMesh(HEAD, this.headMaterial, capacity);
    this.heads.frustumCulled = false;
    this.heads.renderOrder = RENDER_ORDER;
    this.group.add(this.heads);
  }

  // A state's "contacts" (undefined or null: the scene has no obstacles and no self-contact).
  set(contacts) {
    this.setSelf(contacts?.self?.points ?? []);
    const list = contacts?.points ?? [];
    if (list.length > this.capacity) this.grow(Math.max(list.length, 2 * this.capacity));
    let largest = 0;
    for (const c of list) largest = Math.max(largest, Math.hypot(c[3], c[4], c[5]));
    this.newtonsPerCm = largest > 0 ? roundUp(largest / MAX_ARROW_CM) : null;
    const metresPerNewton = largest > 0 ? 0.01 / this.newtonsPerCm : 0;
    const at = this.pointGeometry.getAttribute('position'), shaft = this.shaftGeometry.getAttribute('position');
    const tail = new THREE.Vector3(), force = new THREE.Vector3(), tip = new THREE.Vector3(), m = new THREE.Matrix4();
    const q = new THREE.Quaternion(), s = new THREE.Vector3();
    let arrows = 0;
    list.forEach((c, k) => {
      tail.fromArray(c, 0);
      at.setXYZ(k, tail.x, tail.y, tail.z);
      force.fromArray(c, 3).multiplyScalar(metresPerNewton);
      const length = force.length();
      if (!(length > 0)) return;
      tip.addVectors(tail, force);
      const head = HEAD_FRACTION * length;
      shaft.setXYZ(2 * arrows, tail.x, tail.y, tail.z);
      shaft.setXYZ(2 * arrows + 1, tip.x - force.x * HEAD_FRACTION, tip.y - force.y * HEAD_FRACTION, tip.z - force.z * HEAD_FRACTION);
      // The cone's tip at the arrow's tip, opening back towards the tail.
      q.setFromUnitVectors(Y, force.divideScalar(length));
      this.heads.setMatrixAt(arrows, m.compose(tip, q, s.set(HEAD_WIDTH * head, head, HEAD_WIDTH * head)));
      arrows++;
    });
    at.needsUpdate = shaft.needsUpdate = true;
    this.heads.instanceMatrix.needsUpdate = true;
    this.pointGeometry.setDrawRange(0, list.length);
    this.shaftGeometry.setDrawRange(0, 2 * arrows);
    this.heads.count = arrows;
    this.count = list.length;
    this.arrowCount = arrows;
    this.group.visible = this.enabled && this.count + this.selfCount > 0;
  }

  // The self-contact points, [[x, y, z], ...].
  setSelf(list) {
    this.selfGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(list.flat()), 3));
    this.selfCount = list.length;
  }

  setEnabled(on) {
    this.enabled = on;
    this.group.visible = on && this.count + this.selfCount > 0;
  }

  get scaleLabel() { return this.newtonsPerCm === null ? '' : `1 cm = ${forceLabel(this.newtonsPerCm)}`; }

  // For tests: what is drawn, the arrows as [tail, tip] world points.
  describe() {
    const shaft = this.shaftGeometry.getAttribute('position'), m = new THREE.Matrix4(), tip = new THREE.Vector3();
    const arrows = [];
    for (let k = 0; k < this.arrowCount; k++) {
      this.heads.getMatrixAt(k, m);
      arrows.push([[shaft.getX(2 * k), shaft.getY(2 * k), shaft.getZ(2 * k)], tip.setFromMatrixPosition(m).toArray()]);
    }
    const at = this.selfGeometry.getAttribute('position');
    const selfPoints = [];
    for (let k = 0; k < this.selfCount; k++) selfPoints.push([at.getX(k), at.getY(k), at.getZ(k)]);
    return { visible: this.group.visible && !!this.group.parent?.visible, points: this.count, arrows, newtonsPerCm: this.newtonsPerCm, scale: this.scaleLabel, selfPoints };
  }
}
