// Undo and redo of target edits: snapshots of the session's targets ({targets, centerline}, as
// in a state) taken just before each edit. Undo returns the snapshot to restore and keeps the
// current one for redo; a new edit forgets what could be redone.
const MAX_STEPS = 100;

export function targetsSnapshot(state) {
  return {
    targets: state.targets.map((t) => ({ node: t.node, position: [...t.position] })),
    centerline: state.centerline.map((p) => [...p]),
  };
}

export class TargetHistory {
  constructor() {
    this.undoStack = [];
    this.redoStack = [];
  }

  clear() {
    this.undoStack = [];
    this.redoStack = [];
  }

  // Before an edit: `snapshot` is what undo goes back to.
  record(snapshot) {
    this.undoStack.push(snapshot);
    if (this.undoStack.length > MAX_STEPS) this.undoStack.shift();
    this.redoStack = [];
  }

  get canUndo() { return this.undoStack.length > 0; }
  get canRedo() { return this.redoStack.length > 0; }

  // The snapshot to restore (null: nothing to undo); `current` goes to the redo stack.
  undo(current) {
    if (!this.canUndo) return null;
    this.redoStack.push(current);
    return this.undoStack.pop();
  }

  redo(current) {
    if (!this.canRedo) return null;
    this.undoStack.push(current);
    return this.redoStack.pop();
  }
}
