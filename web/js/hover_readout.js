// What is under the pointer in the 3D view, in an overlay: the surface node (id and position,
// mm) and, when the node has a target, the target's position and the node's distance from it
// (its error). One raycast per animation frame at most; none while a mouse button is down.
import { Raycaster, Vector2, Vector3 } from 'three';

const mm = (v) => (Math.abs(v) < 5e-5 ? 0 : 1000 * v).toFixed(1);  // no "-0.0"
const point = (p) => `(${mm(p.x)}, ${mm(p.y)}, ${mm(p.z)}) mm`;

export class HoverReadout {
  // `element`: the overlay; `view`: the View3D; `targets()`: the current [{node, position}].
  constructor(element, view, targets) {
    this.element = element;
    this.view = view;
    this.targets = targets;
    this.raycaster = new Raycaster();
    this.pointer = new Vector2();
    this.position = new Vector3();
    this.target = new Vector3();
    this.pending = false;
    this.hovered = null;  // {node, position: [x, y, z], target: [x, y, z] | null, error: m | null}
    const canvas = view.renderer.domElement;
    canvas.addEventListener('pointermove', (e) => {
      if (e.buttons !== 0) return;
      const rect = canvas.getBoundingClientRect();
      this.pointer.set((e.clientX - rect.left) / rect.width * 2 - 1, -(e.clientY - rect.top) / rect.height * 2 + 1);
      if (this.pending) return;
      this.pending = true;
      requestAnimationFrame(() => { this.pending = false; this.update(); });
    });
    canvas.addEventListener('pointerleave', () => this.show(null));
  }

  update() {
    if (!this.view.positions) return this.show(null);
    this.raycaster.setFromCamera(this.pointer, this.view.camera);
    const handle = this.view.objectView.pickHandle(this.raycaster);
    const node = handle ? handle.node : this.view.objectView.pickNode(this.raycaster)?.node;
    if (node === undefined || node === null) return this.show(null);
    this.view.objectView.nodePosition(node, this.position);
    const target = this.targets().find((t) => t.node === node);
    if (target) this.target.fromArray(target.position);
    this.show({ node, position: this.position.toArray(), target: target ? target.position.slice() : null,
      error: target ? this.position.distanceTo(this.target) : null });
  }

  show(hovered) {
    this.hovered = hovered;
    this.element.hidden = !hovered;
    if (!hovered) return;
    const lines = [`node ${hovered.node} at ${point(this.position)}`];
    if (hovered.target) lines.push(`target ${point(this.target)} · error ${mm(hovered.error)} mm`);
    this.element.textContent = lines.join('\n');
  }
}
