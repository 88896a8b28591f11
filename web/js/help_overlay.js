// The keyboard help: `?` (or the panel's ? button) shows every key the page knows, Esc or ?
// hides it again. The list is the one place the keys are written down for users (docs/gui.md
// has the same table).
export const KEYS = Object.freeze([
  ['c', 'sketch a centre-line (bar-like objects); press again to stop'],
  ['Esc', 'stop sketching; close this help'],
  ['Space', 'pause / resume the optimizer'],
  ['Delete', 'remove the selected target'],
  ['f', 'fit the view to the object'],
  ['x / y / z', 'held while dragging: move the target along that axis only'],
  ['Ctrl+Z', 'undo a target edit'],
  ['Ctrl+Shift+Z, Ctrl+Y', 'redo'],
  ['1 / 3 / 7 / 0', 'view from the front / side / top / iso'],
  ['t', 'see-through robot'],
  ['Shift+← / →', 'on a joint slider: jog by 0.1°'],
  ['?', 'this help'],
]);

export const MOUSE = Object.freeze([
  ['click the object', 'add a target at the nearest node'],
  ['drag a handle', 'move that target in the view plane'],
  ["drag the gizmo's arrows", 'move the selected target along that axis'],
  ['drag a joint slider (paused)', 'the joint follows while held; Shift: a tenth as fast'],
  ['left drag', 'orbit'],
  ['right / middle drag', 'pan'],
  ['wheel', 'zoom'],
]);

export class HelpOverlay {
  // `element`: the overlay (filled here); `button`: toggles it.
  constructor(element, button) {
    this.element = element;
    const rows = (list) => list.map(([key, what]) => `<tr><td><kbd>${key}</kbd></td><td>${what}</td></tr>`).join('');
    element.innerHTML = `<h2>Keys</h2><table class="keys">${rows(KEYS)}</table>
      <h2>Mouse</h2><table class="keys">${rows(MOUSE)}</table>
      <p class="muted">Press ? or Esc to close.</p>`;
    element.hidden = true;
    button?.addEventListener('click', () => this.toggle());
  }

  get shown() { return !this.element.hidden; }
  toggle(on = !this.shown) { this.element.hidden = !on; }
}
