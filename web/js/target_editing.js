// Target editing in the side panel: typed x/y/z (mm) for the selected target, undo/redo of target
// edits (Ctrl+Z, Ctrl+Shift+Z or Ctrl+Y, and buttons), and saving/loading targets and joints as
// the CLI's JSON files (targets_file.js). Edits go out as protocol commands; the server decides.
import { Command } from './protocol.js';
import { TargetHistory, targetsSnapshot } from './target_history.js';
import { jointsFileBody, readTargetsOrJoints, targetsFileBody } from './targets_file.js';
import { typingIn } from './keys.js';

const MM = 1000;
const TYPED_HOLD_MS = 1000;  // an edit not in a state by then: trust the state's again

export class TargetEditor {
  // `elements`: {x, y, z, node, undo, redo, saveTargets, saveJoints, load}; `page`: {command(type,
  // fields) → Promise, state(), scene(), view, notify(text)}.
  constructor(elements, page) {
    this.el = elements;
    this.page = page;
    this.history = new TargetHistory();
    this.asked = null;  // {snapshot, at}: what the page last asked for, until a state shows it
    this.shownNode = null;  // whose coordinates the fields show
    this.position = null;   // their exact values (m), the fields round them to 0.1 mm
    this.typed = null;      // {position, at}: typed and sent, not yet in a state
    this.fields = [elements.x, elements.y, elements.z];
    for (const field of this.fields) {
      field.addEventListener('input', () => { field.edited = true; });
      field.addEventListener('change', () => this.typeCoordinates());
    }
    elements.undo.onclick = () => this.undo();
    elements.redo.onclick = () => this.redo();
    elements.saveTargets.onclick = () => this.saveTargets();
    elements.saveJoints.onclick = () => this.saveJoints();
    elements.load.addEventListener('change', () => this.loadFiles());
    window.addEventListener('keydown', (e) => this.onKey(e));
    this.updateButtons();
  }

  // A new scene: its nodes differ, so nothing to undo.
  reset() {
    this.history.clear();
    this.asked = null;
    this.updateButtons();
  }

  // Before any edit of the targets (drag, sketch, typed, delete, clear, load).
  beginEdit() {
    if (!this.page.state()) return;
    this.history.record(this.current());
    this.asked = null;
    this.updateButtons();
  }

  // Shows the selected target's coordinates (not while one is being typed).
  update(state) {
    if (this.asked && (JSON.stringify(targetsSnapshot(state)) === JSON.stringify(this.asked.snapshot) ||
                       performance.now() - this.asked.at > TYPED_HOLD_MS)) this.asked = null;
    const node = this.page.view.selected;
    const target = node === null ? null : state.targets.find((t) => t.node === node);
    if (node !== this.shownNode) {  // typed for another target
      for (const f of this.fields) f.edited = false;
      this.typed = null;
    }
    this.shownNode = node;
    // What was typed shows until a state has it (a second field may be typed before that).
    if (this.typed && (!target || target.position.every((v, i) => v === this.typed.position[i]) ||
                       performance.now() - this.typed.at > TYPED_HOLD_MS)) this.typed = null;
    if (target && !this.typed) this.position = [...target.position];
    this.el.node.textContent = target ? `node ${node}` : 'none selected';
    this.fields.forEach((field, i) => {
      field.disabled = !target;
      if (!target) field.value = '';
      else if (document.activeElement !== field && !field.edited) field.value = shownMillimetres(this.position[i]);
    });
  }

  // The typed fields' values, the untouched ones exactly where the target is (the fields show
  // them rounded to 0.1 mm).
  typeCoordinates() {
    const node = this.page.view.selected;
    if (node === null || node !== this.shownNode || !this.position) return;
    const position = this.fields.map((f, i) => (f.edited ? Number(f.value) / MM : this.position[i]));
    if (this.fields.some((f) => f.edited && f.value.trim() === '') || !position.every(Number.isFinite)) return;
    for (const f of this.fields) f.edited = false;
    this.position = position;
    this.typed = { position, at: performance.now() };
    const before = this.current();
    this.beginEdit();
    this.expect({ ...before, targets: before.targets.map((t) => (t.node === node ? { node, position } : t)) });
    this.page.command(Command.SetTarget, { node, position });
  }

  onKey(e) {
    if (typingIn(e.target) || !(e.ctrlKey || e.metaKey)) return;  // a field keeps its own undo
    const key = e.key.toLowerCase();
    if (key === 'z' && !e.shiftKey) this.undo();
    else if ((key === 'z' && e.shiftKey) || key === 'y') this.redo();
    else return;
    e.preventDefault();
  }

  undo() { this.restore(this.history.undo(this.current())); }
  redo() { this.restore(this.history.redo(this.current())); }

  // The session's targets, or what undo/redo just asked for when the server has not shown it
  // yet (quick repeated Ctrl+Z).
  current() {
    if (this.asked) return this.asked.snapshot;
    const state = this.page.state();
    return state ? targetsSnapshot(state) : { targets: [], centerline: [] };
  }

  restore(snapshot) {
    this.updateButtons();
    if (!snapshot) return;
    this.expect(snapshot);
    const { view } = this.page;
    if (view.selected !== null && !snapshot.targets.some((t) => t.node === view.selected)) view.select(null);
    if (snapshot.centerline.length >= 2) this.page.command(Command.SetCenterline, { points: snapshot.centerline });
    else if (snapshot.targets.length) this.page.command(Command.SetTargets, { targets: snapshot.targets });
    else this.page.command(Command.ClearTargets);
  }

  // The targets the session will have once the server applied what was just sent.
  expect(snapshot) { this.asked = { snapshot, at: performance.now() }; }

  updateButtons() {
    this.el.undo.disabled = !this.history.canUndo;
    this.el.redo.disabled = !this.history.canRedo;
  }

  saveTargets() {
    const state = this.page.state();
    if (state) download('targets.json', targetsFileBody(state));
  }

  saveJoints() {
    const state = this.page.state(), robot = this.page.scene()?.robot;
    if (state && robot) download('joints.json', jointsFileBody(state, robot));
  }

  // Each chosen file: targets (or a centre-line) replace the session's; joints pause the
  // optimizer and jog the robot there. With joints among the files the optimizer is paused
  // before anything lands: new targets would otherwise set it moving, away from the saved
  // joints, and a jog beyond the step limit from where it got to is refused.
  async loadFiles() {
    const files = [...this.el.load.files];
    this.el.load.value = '';  // the same file again is a new choice
    const robot = this.page.scene()?.robot;
    const read = [];
    for (const file of files) {
      try {
        read.push(readTargetsOrJoints(file.name, await file.text(), robot));
      } catch (e) {
        this.page.notify(e.message);
      }
    }
    const steps = read.map((asked) => () => this.apply(asked));
    if (read.some((asked) => asked.joints)) {
      steps.unshift(() => this.page.command(Command.SetPaused, { paused: true }));
    }
    for (const step of steps) {
      try {
        await step();
      } catch (e) {
        this.page.notify(e.message);
      }
    }
  }

  async apply({ targets, centerline, joints }) {
    const { command } = this.page;
    if (centerline || targets) {
      this.beginEdit();
      this.page.view.select(null);
      if (centerline) await command(Command.SetCenterline, { points: centerline });
      else await command(targets.length ? Command.SetTargets : Command.ClearTargets, targets.length ? { targets } : undefined);
    }
    if (joints) {
      await command(Command.SetPaused, { paused: true });
      await command(Command.SetJoints, { joints });
    }
  }
}

// A coordinate in mm, 0.1 mm digits, never "-0.0".
function shownMillimetres(metres) {
  const text = (MM * metres).toFixed(1);
  return text === '-0.0' ? '0.0' : text;
}

// Saves `body` as a JSON file through the browser's download.
function download(name, body) {
  const url = URL.createObjectURL(new Blob([JSON.stringify(body, null, 2) + '\n'], { type: 'application/json' }));
  const link = document.createElement('a');
  link.href = url;
  link.download = name;
  link.click();
  setTimeout(() => URL.revokeObjectURL(url), 1000);
}
