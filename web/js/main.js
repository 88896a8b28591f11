// The shapectl page: connects to /ws, shows the session in 3D and in the side panel, and turns
// clicks, drags, sketches, buttons and sliders into protocol commands (docs/gui.md).
import { Connection } from './connection.js';
import { View3D } from './view3d.js';
import { ConvergencePlot } from './plot.js';
import { CalibrationPanel } from './calibration_panel.js';
import { ObservationRate, activityLines } from './real_object_activity.js';
import { TargetEditor } from './target_editing.js';
import { ViewTools } from './view_tools.js';
import { Command, ControllerStatus } from './protocol.js';
import { statusBadge } from './status_badge.js';
import { typingIn } from './keys.js';
import { JointPanel } from './joint_panel.js';

const $ = (id) => document.getElementById(id);
// Metres as mm for the panel; '–' for none.
const mm = (v) => (v === null || v === undefined ? '–' : (1000 * v).toFixed(2));

const page = {
  scene: null,       // the last "scene" message
  state: null,       // the last "state" message
  robotWarnings: [], // robot meshes not drawn, as shown in the panel
  stats: { states: 0, positions: 0, errors: [], editingStates: 0, stateTimes: [] },
};

const view = new View3D($('view'), {
  addTarget: (node, position) => command(Command.SetTarget, { node, position }),
  moveTarget: (node, position) => command(Command.SetTarget, { node, position }),
  sketch: (points) => command(Command.SetCenterline, { points }).then(() => setSketchMode(false)),
  select: (node) => { $('delete').disabled = node === null; if (page.state) editor.update(page.state); },
  beginEdit: () => editor.beginEdit(),
});
const editor = new TargetEditor({
  x: $('target-x'), y: $('target-y'), z: $('target-z'), node: $('target-node'), undo: $('undo'), redo: $('redo'),
  saveTargets: $('save-targets'), saveJoints: $('save-joints'), load: $('load-file'),
}, { command, state: () => page.state, scene: () => page.scene, view, notify: (text) => toast(text) });
const plot = new ConvergencePlot($('plot'), $('plot-legend'), { readout: $('plot-readout'), logScale: $('plot-log') });
const tools = new ViewTools(view, {
  frames: $('show-frames'), screenshot: $('screenshot'), helpButton: $('help-button'), help: $('help'), scaleBar: $('scale-bar'),
  hover: $('hover-readout'), notice: $('notice'), deleteButton: $('delete'),
});
const calibration = new CalibrationPanel({
  button: $('calibrate'), auto: $('auto-calibration'), status: $('calibration-status'), model: $('model'),
  table: $('calibration-result'), summary: $('calibration-summary'), error: $('calibration-error'),
}, {
  calibrate: () => command(Command.Calibrate),
  setAutomatic: (on) => command(Command.SetAutoCalibration, { on }),
});

const connection = new Connection(`ws://${location.host}/ws`, {
  open: () => setBadge('connection', 'connected', 'ok'),
  close: () => setBadge('connection', 'disconnected — retrying', 'bad'),
  scene: onScene,
  state: onState,
  positions: (frame) => {
    page.stats.positions++;
    if (page.scene && frame.positions.length === 3 * page.scene.node_count) view.setPositions(frame.positions);
  },
  error: (message) => { page.stats.errors.push(message.message); toast(message.message); },
});

// Resolves with the reply, rejects with an error reply (which shows as a toast anyway).
function send(type, fields) {
  tools.sent(type);
  return connection.send(type, fields);
}

// Fire and forget.
function command(type, fields) {
  return send(type, fields).catch(() => {});
}
const jointPanel = new JointPanel($('joints'), (joint, value) => send(Command.SetJoint, { joint, value }));

function toast(text) {
  const t = $('toast');
  t.textContent = text;
  t.classList.add('shown');
  clearTimeout(toast.timer);
  toast.timer = setTimeout(() => t.classList.remove('shown'), 4000);
}

function setBadge(id, text, kind, title = '') {
  const b = $(id);
  b.textContent = text;
  b.className = `badge ${kind ?? ''}`;
  b.title = title;
}

// ---- scene ----
function onScene(scene) {
  page.scene = scene;
  page.state = null;
  view.setScene(scene);
  editor.reset();
  tools.setScene(scene);
  plot.reset(scene.history);
  const select = $('scene-select');
  select.replaceChildren(...scene.scenes.map((name) => new Option(name, name, false, name === scene.scene)));
  $('sketch').disabled = !scene.bar;
  $('face-bar').disabled = !scene.bar;
  $('sketch').title = scene.bar ? 'Sketch a centre-line with the mouse (C)' : 'Only for bar-like objects';
  $('link-section').hidden = !scene.link;
  $('contacts-toggle').hidden = !scene.obstacles?.length && !scene.contact?.self;
  $('contact-scale').textContent = '';
  jointPanel.setRobot(scene.robot);
  showRobotWarnings(scene.warnings ?? []);
}

// Robot meshes the server could not find (the scene's "warnings") or the page could not draw:
// a line each in the panel, and a toast.
function showRobotWarnings(lines) {
  page.robotWarnings = lines;
  const box = $('robot-warnings');
  box.textContent = lines.join('\n');
  box.hidden = lines.length === 0;
  if (lines.length) toast(lines.length === 1 ? lines[0] : `${lines.length} robot meshes are not drawn: see the panel`);
}
view.robotView.group.addEventListener('meshloaded', () => view.requestRender());
view.ghostView.group.addEventListener('meshloaded', () => view.requestRender());
view.robotView.group.addEventListener('mesherror', (e) => showRobotWarnings([...page.robotWarnings, e.message]));

// ---- state ----
function onState(state) {
  page.state = state;
  page.stats.states++;
  if (state.editing) page.stats.editingStates++;
  page.stats.stateTimes.push(performance.now());
  if (page.stats.stateTimes.length > 200) page.stats.stateTimes.shift();
  // Red: links that overlap, and those a refused jog would have made overlap.
  view.robotView.setCollisions([...state.colliding_links, ...state.jog_refused_links], state.closest_pair);
  view.setState(state);
  $('contact-scale').textContent = view.contactsView.scaleLabel && `(${view.contactsView.scaleLabel})`;
  editor.update(state);
  tools.setState(state);
  plot.add(state.time, plotValues(state), state.editing);
  drawPlot();

  const badge = statusBadge(state);
  setBadge('status', badge.text, badge.kind, badge.title);
  $('status-reason').textContent = badge.title;
  $('error-mean').textContent = state.targets.length ? mm(state.error.mean) : '–';
  $('error-max').textContent = state.targets.length ? mm(state.error.max) : '–';
  // Only while it iterates: a paused or stopped optimizer has no rate, not the last one.
  const running = state.status === ControllerStatus.Optimizing && state.iterations_per_second !== null;
  $('rate').textContent = running ? state.iterations_per_second.toFixed(0) : '–';
  // Wrapped between its parts, never inside one ("53" and "mm" on separate lines).
  const whole = (part) => part.replaceAll(' ', '\u00a0');
  const count = (n, one, many) => `${n} ${n === 1 ? one : many}`;
  const parts = [count(state.targets.length, 'target', 'targets'), count(state.iterations, 'iteration', 'iterations'),
    count(state.clients, 'page', 'pages')];
  if (state.min_clearance !== null) parts.push(`clearance ${(1000 * state.min_clearance).toFixed(0)} mm`);
  if (state.contacts) parts.push(...contactSummary(state.contacts));
  if (!state.safe) parts.push('UNSAFE');
  $('status-detail').textContent = parts.map(whole).join(' · ') + (state.last_error ? ` · ${state.last_error}` : '');
  $('pause').textContent = state.paused ? 'Resume' : 'Pause';
  $('pause').classList.toggle('active', state.paused);
  $('jog-hint').textContent = state.paused ? '(drag to jog)' : '(pause to jog)';

  jointPanel.update(state);

  $('feedback').checked = !!state.feedback;
  $('observed').textContent = observedLine(state);
  const activity = activityLines(state, observationRate.update(state.observations ?? 0)).join('\n');
  if ($('activity').textContent !== activity) $('activity').textContent = activity;

  calibration.update(state);

  if (state.link) {
    const l = state.link;
    $('link-status').textContent = `${l.kind}: ${l.connected ? 'connected' : 'no feedback'}, ${l.armed ? 'ARMED' : 'disarmed'}` +
      (l.reason ? ` — ${l.reason}` : '');
  }
}

const observationRate = new ObservationRate();

// The status line's contacts: with obstacles how many pairs touch, the smallest gap and the
// obstacles' total force on the object; with self-contact how many of its pairs touch and their
// smallest gap.
function contactSummary(c) {
  const parts = [];
  if (Object.keys(c.by_obstacle).length) {
    const f = Math.hypot(...c.force_total);
    parts.push(c.count ? `${c.count} contacts, gap ${mm(c.min_distance)} mm, ${f.toPrecision(3)} N` : 'no contact');
  }
  if (c.self) parts.push(c.self.count ? `${c.self.count} self-contacts, gap ${mm(c.self.min_distance)} mm` : 'no self-contact');
  return parts;
}

// The Real object panel's line: observations, the errors, what the gate refused and why the
// newest was ignored or gated (docs/calibration.md, Safety).
function observedLine(state) {
  const g = state.gate;
  const gated = g && (g.markers_rejected || g.frames_rejected) ?
    `gate rejected ${g.markers_rejected} of ${g.markers_checked} markers, ${g.frames_rejected} frames · ` +
    `correction ${mm(state.authority.largest)} of at most ${mm(state.authority.max_correction)} mm` : '';
  const problem = state.observation_problem ?
    (state.observations_ignored ? `${state.observations_ignored} ignored · ` : '') + state.observation_problem : '';
  const ignored = [gated, problem].filter(Boolean).join(' · ');
  if (!state.observations) return ignored || 'no observations yet';
  const truth = state.true_error === null || state.true_error === undefined ? '' : ` · true error (simulated world) ${mm(state.true_error)} mm`;
  return `${state.observations} observations · model error ${mm(state.model_error)} mm · observed error ${mm(state.observed_error)} mm` +
    truth + (ignored ? ` · ${ignored}` : '');
}

// The plot's values, in the order of plot.js's SERIES; the real object's errors only once it
// was observed (before, the server sends 0).
function plotValues(state) {
  const observed = state.observations > 0;
  return [state.error.mean, state.true_error ?? null, observed ? state.model_error : null, observed ? state.observed_error : null];
}

let plotPending = false;
function drawPlot() {
  if (plotPending) return;
  plotPending = true;
  requestAnimationFrame(() => { plotPending = false; plot.draw(); });
}

// ---- controls ----
function setSketchMode(on) {
  view.setSketchMode(on);
  $('sketch').classList.toggle('active', on);
}

function deleteSelected() {
  if (view.selected === null) return;
  editor.beginEdit();
  command(Command.RemoveTarget, { node: view.selected });
  view.select(null);
}

$('pause').onclick = () => command(Command.SetPaused, { paused: !page.state?.paused });
$('reset').onclick = () => command(Command.Reset);
$('clear').onclick = () => { editor.beginEdit(); command(Command.ClearTargets); view.select(null); };
$('delete').onclick = deleteSelected;
$('sketch').onclick = () => setSketchMode(!view.sketchMode);
$('face-bar').onclick = () => { if (page.scene?.bar) view.faceBar(page.scene.bar.direction); };
$('show-wireframe').onchange = (e) => view.setWireframe(e.target.checked);
$('show-spheres').onchange = (e) => view.setSpheresVisible(e.target.checked);
$('show-robot').onchange = (e) => view.setRobotVisible(e.target.checked);
$('see-through-arms').onchange = (e) => view.setSeeThroughArms(e.target.checked);
$('show-points').onchange = (e) => view.setObservedPointsVisible(e.target.checked);
$('show-contacts').onchange = (e) => view.setContactsVisible(e.target.checked);
$('scene-select').onchange = (e) => command(Command.LoadScene, { scene: e.target.value });
$('feedback').onchange = (e) => command(Command.SetFeedback, { on: e.target.checked });
$('arm').onclick = () => command(Command.Arm);
$('disarm').onclick = () => command(Command.Disarm);
window.addEventListener('keydown', (e) => {
  if (typingIn(e.target) || e.ctrlKey || e.metaKey || e.altKey) return;  // Ctrl+Z and the like: target_editing.js
  if (e.key === 'Delete' || e.key === 'Backspace') deleteSelected();
  else if (e.key === 'c') setSketchMode(!view.sketchMode);
  else if (e.key === 'Escape') setSketchMode(false);
  else if (e.key === 'f') view.fitObject();
  else if (e.key === 't') view.setRobotSeeThrough(!view.robotSeeThrough);
  else if (e.key === ' ') $('pause').click();
  else return;
  e.preventDefault();  // not also the focused control's own use of the key
});

// ---- hooks for tests and scripts (read-only views plus screen projections) ----
window.shapectl = {
  get scene() { return page.scene; },
  get state() { return page.state; },
  get stats() { return page.stats; },
  // Scene, state and positions here and drawn: no render still pending (the view renders on
  // demand, so an idle scene may never draw a third frame).
  get ready() { return !!(page.scene && page.state && view.positions && view.frames > 0 && !view.renderPending); },
  get arrowCount() { return view.arrowCount; },
  get handleCount() { return view.objectView.handleCount; },
  // Page coordinates of the gizmo's centre and of its x, y, z arrows' tips; null without a gizmo.
  gizmo: () => view.gizmoOnPage(),
  // The object's node positions on the page and the view's box: is it all in view?
  objectOnPage: () => view.objectOnPage(),
  get frames() { return view.frames; },
  get observedPointsDrawn() { return view.observedPointsDrawn; },
  get selected() { return view.selected; },
  get tools() { return tools.hooks; },
  plot: () => ({ top: plot.top, clipped: plot.clipped, log: plot.log }),
  nodePosition: (node) => view.nodePosition(node).toArray(),
  positions: () => Array.from(view.positions ?? []),
  worldToPage: (point) => view.worldToPage(point),
  nodeToPage: (node) => view.worldToPage(view.nodePosition(node).toArray()),
  setLayers: ({ robot = true, object = true, targets = true } = {}) => {
    view.setRobotVisible(robot); view.setObjectVisible(object); view.setTargetsVisible(targets); view.render();
  },
  objectCentroid: () => view.objectCentroid().toArray(),
  cameraDirection: () => view.cameraDirection(),
  cameraPosition: () => view.camera.position.toArray(),
  get renderPending() { return view.renderPending; },
  observedPoints: () => view.observedPoints(),
  // The obstacles and contacts as drawn (obstacles_view.js, contacts_view.js).
  obstacles: () => view.obstaclesView.describe(),
  contacts: () => view.contactsView.describe(),
  robotColors: () => view.robotView.visualColors(),
  // Names of the links hiding the object in the last frame drawn (drawn see-through: occlusion.js).
  hidingLinks: () => view.occlusion.hidingNames(),
  robotMeshes: () => view.robotView.meshVisuals(),
  get robotWarnings() { return page.robotWarnings; },
  highlightedSpheres: () => view.robotView.highlightedSpheres(),
  setSpheresVisible: (on) => { $('show-spheres').checked = on; view.setSpheresVisible(on); view.render(); },
  ghost: () => ({ visible: view.ghostView.visible, links: view.ghostView.robotView.linkPoses(),
    colors: view.ghostView.robotView.visualColors(), meshes: view.ghostView.group.children.reduce((n, g) => n + g.children.length, 0),
    meshVisuals: view.ghostView.robotView.meshVisuals() }),
};
