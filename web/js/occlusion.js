// Keeps the object in sight: the robot links between the camera and the object fade to
// see-through, and back to solid once they no longer hide it. At every frame the view draws (it
// draws only when something moved), a few dozen points of the object are raycast from the camera
// against the links' visuals: the targets' nodes first, then surface nodes spread over the object.
// Gripped nodes are left out: the fingers holding them always hide them. Picking is not affected:
// handles, gizmo and surface picks ray-cast the object only, never the robot. The `t` key makes
// the whole robot see-through at once.
import { Raycaster, Vector3 } from 'three';

const SURFACE_SAMPLES = 40;  // surface nodes checked per frame (besides the targets' nodes)
const HIDING_OPACITY = 0.3;  // a link that hides the object
const ALL_OPACITY = 0.2;     // the whole robot (`t`)
const FADE_MS = 150;         // solid ↔ see-through: smooth, not laggy
const FRAME_MS = 16;         // the first fade step after an idle view
const SURFACE_GAP = 1e-4;    // m; rays stop this short of the object's point

const _eye = new Vector3();
const _point = new Vector3();
const _direction = new Vector3();

export class Occlusion {
  constructor(robotView, objectView) {
    this.robotView = robotView;
    this.objectView = objectView;
    this.enabled = true;         // the Display toggle "see-through arms"
    this.all = false;            // the whole robot see-through (`t`)
    this.jump = false;           // the next update sets the fades at once (`t` is instant)
    this.surfaceSamples = [];    // surface nodes checked
    this.levels = [];            // per link as drawn: 0 solid … 1 see-through
    this.hiding = new Set();     // links hiding the object at the last check
    this.fading = false;         // a fade was under way at the last update
    this.lastUpdate = 0;
    this.raycaster = new Raycaster();
  }

  // A scene message: its surface nodes to sample and its links, all solid.
  setScene(description) {
    const gripped = new Set(description.grips.flatMap((g) => g.nodes));
    const surface = [...new Set(description.triangles)].filter((n) => !gripped.has(n)).sort((a, b) => a - b);
    const step = Math.max(1, surface.length / SURFACE_SAMPLES);
    this.surfaceSamples = Array.from({ length: Math.min(SURFACE_SAMPLES, surface.length) }, (_, k) => surface[Math.floor(k * step)]);
    this.levels = (description.robot?.links ?? []).map(() => 0);
    this.hiding = new Set();
    this.jump = true;
  }

  setEnabled(on) { this.enabled = on; }
  setAll(on) { this.all = on; this.jump = true; }

  // Checks which links hide the object from `camera` and steps their fades; `now`: ms. Returns
  // whether a fade is still under way (the view then draws another frame).
  update(camera, now) {
    this.hiding = this.hidingLinks(camera);
    const step = this.jump ? 1 : (this.fading ? now - this.lastUpdate : FRAME_MS) / FADE_MS;
    this.jump = false;
    this.lastUpdate = now;
    const opacity = this.all ? ALL_OPACITY : HIDING_OPACITY;
    this.fading = false;
    this.levels.forEach((level, k) => {
      const goal = this.all || this.hiding.has(k) ? 1 : 0;
      const next = goal > level ? Math.min(goal, level + step) : Math.max(goal, level - step);
      if (next !== goal) this.fading = true;
      this.levels[k] = next;
      this.robotView.fadeLink(k, next, opacity);  // every frame: mesh visuals may have loaded since
    });
    return this.fading;
  }

  // Indices of the links that a ray from the camera to a sample of the object passes through.
  hidingLinks(camera) {
    const hiding = new Set();
    if (!this.enabled || this.all || !this.robotView.robotVisible || !this.objectView.positions) return hiding;
    this.robotView.group.updateMatrixWorld();  // link poses set since the last frame
    camera.getWorldPosition(_eye);
    const nodes = [...this.objectView.targets.map((t) => t.node), ...this.surfaceSamples];
    for (const node of nodes) {
      _direction.subVectors(this.objectView.nodePosition(node, _point), _eye);
      const distance = _direction.length();
      this.raycaster.set(_eye, _direction.divideScalar(distance));
      this.raycaster.far = distance - SURFACE_GAP;
      for (const hit of this.raycaster.intersectObjects(this.robotView.visualMeshes, true)) hiding.add(this.linkOf(hit.object));
    }
    return hiding;
  }

  // The index of the link whose group holds `object`.
  linkOf(object) {
    let o = object;
    while (o.parent && o.parent !== this.robotView.group) o = o.parent;
    return this.robotView.linkGroups.indexOf(o);
  }

  // For tests: the names of the links hiding the object at the last frame.
  hidingNames() {
    return [...this.hiding].map((k) => this.robotView.linkGroups[k].name);
  }
}
