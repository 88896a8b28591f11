// What is under the pointer in the 3D view, in an overlay: the surface node (id and position,
// mm) and, when the node has a target, the target's position and the node's distance from it
// (its error). And the pointer says what a press would do: a hand over a handle (which grows)
// or a gizmo arrow (which lights up), a closed hand while dragging one, a pointing finger over
// the object (a click adds a target). One raycast per animation frame at most; none while a
// mouse button is down. The object and the targets change under a still pointer (the optimizer
// moves the object, a drag or another page moves a target): refresh() reads it anew.
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
    this.buttons = 0;
    this.inside = false;  // the pointer is over the view
    canvas.addEventListener('pointermove', (e) => {
      this.buttons = e.buttons;
      this.inside = true;
      if (e.buttons !== 0) return;
      const rect = canvas.getBoundingClientRect();
      this.pointer.set((e.clientX - rect.left) / rect.width * 2 - 1, -(e.clientY - rect.top) / rect.height * 2 + 1);
      this.schedule();
    });
    // Capture: a target drag stops the press's propagation (target_controls.js).
    canvas.addEventListener('pointerdown', (e) => {
      this.buttons = e.buttons;
      if (canvas.style.cursor) canvas.style.cursor = 'grabbing';  // a handle, the gizmo or a new target
    }, { capture: true });
    // A drag ends with the pointer still: its new target shows without a move.
    window.addEventListener('pointerup', (e) => { this.buttons = e.buttons; this.refresh(); });
    canvas.addEventListener('pointerleave', () => { this.inside = false; this.show(null); this.point(null, false, false); });
  }

  // Reads what is under the pointer again, if it is over the view.
  refresh() {
    if (this.inside) this.schedule();
  }

  schedule() {
    if (this.pending || this.buttons !== 0) return;
    this.pending = true;
    requestAnimationFrame(() => { this.pending = false; if (this.buttons === 0) this.update(); });
  }

  update() {
    if (!this.view.positions) return this.show(null);
    this.raycaster.setFromCamera(this.pointer, this.view.camera);
    const handle = this.view.objectView.pickHandle(this.raycaster);
    const node = handle ? handle.node : this.view.objectView.pickNode(this.raycaster)?.node ?? null;
    this.point(handle, node !== null, !handle && this.view.gizmo.hitsAt(this.pointer));
    if (node === null) return this.show(null);
    this.view.objectView.nodePosition(node, this.position);
    const target = this.targets().find((t) => t.node === node);
    if (target) this.target.fromArray(target.position);
    this.show({ node, position: this.position.toArray(), target: target ? target.position.slice() : null,
      error: target ? this.position.distanceTo(this.target) : null });
  }

  // The cursor and the hovered handle for a press on `handle` (a pick or null), on the gizmo, on
  // the object or on nothing. Sketching keeps its crosshair (style.css).
  point(handle, onObject, onGizmo) {
    const cursor = this.view.sketchMode ? '' : handle || onGizmo ? 'grab' : onObject ? 'pointer' : '';
    this.view.renderer.domElement.style.cursor = cursor;
    if (this.view.objectView.setHovered(handle?.node ?? null)) this.view.requestRender();
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
