// The view's and panel's tools, wired in one place so main.js only forwards scenes, states and
// sent commands: world and tool frames, the scale bar, the hover read-out, view presets (1 3 7 0),
// the screenshot button, the `?` help, notices when another page changes the session, and
// a Delete button that offers only what can be done (a selected target that exists).
import { FramesView } from './frames_view.js';
import { ScaleBar } from './scale_bar.js';
import { HoverReadout } from './hover_readout.js';
import { HelpOverlay } from './help_overlay.js';
import { SessionNotices } from './session_notices.js';
import { applyPreset } from './view_presets.js';
import { saveScreenshot } from './screenshot.js';
import { typingIn } from './keys.js';

const NOTICE_MS = 6000;

export class ViewTools {
  // `elements`: {frames, screenshot, helpButton, help, scaleBar, hover, notice, deleteButton}
  constructor(view, elements) {
    this.view = view;
    this.elements = elements;
    this.scene = null;
    this.state = null;
    this.frames = new FramesView();
    view.scene.add(this.frames.group);
    this.scaleBar = new ScaleBar(elements.scaleBar, view);
    this.hover = new HoverReadout(elements.hover, view, () => this.state?.targets ?? []);
    this.help = new HelpOverlay(elements.help, elements.helpButton);
    this.notices = new SessionNotices((text) => this.notify(text));
    elements.frames.addEventListener('change', () => { this.frames.setVisible(elements.frames.checked); view.requestRender(); });
    elements.screenshot.addEventListener('click', () => saveScreenshot(view, this.scene?.scene));
    window.addEventListener('keydown', (e) => this.onKey(e));
  }

  onKey(e) {
    if (typingIn(e.target) || e.ctrlKey || e.metaKey || e.altKey) return;
    if (e.key === '?') this.help.toggle();
    else if (e.key === 'Escape') this.help.toggle(false);
    else if (!applyPreset(this.view, e.key)) return;
    e.preventDefault();
  }

  setScene(scene) {
    this.notices.setScene(scene);
    this.scene = scene;
    this.state = null;
    this.frames.setRobot(scene.robot);
  }

  setState(state) {
    this.notices.setState(state);
    this.state = state;
    this.frames.setLinkPoses(state.links);
    this.hover.refresh();  // the object or a target may have moved under the pointer
    const selected = this.view.selected;
    const exists = selected !== null && (state.targets.some((t) => t.node === selected) || this.view.objectView.localTargets.has(selected));
    this.elements.deleteButton.disabled = !exists;
  }

  // Every command this page sends.
  sent(type) { this.notices.sent(type); }

  notify(text) {
    const n = this.elements.notice;
    n.textContent = text;
    n.hidden = false;
    clearTimeout(this.noticeTimer);
    this.noticeTimer = setTimeout(() => { n.hidden = true; }, NOTICE_MS);
  }

  // For tests.
  get hooks() {
    return {
      scaleBar: () => ({ metres: this.scaleBar.metres, pixels: this.scaleBar.pixels, label: this.scaleBar.label.textContent }),
      orbitTarget: () => this.view.orbit.target.toArray(),
      cameraPosition: () => this.view.camera.position.toArray(),
      hovered: () => this.hover.hovered,
      toolOrigins: () => this.frames.toolOrigins(),
      framesVisible: () => this.frames.group.visible,
    };
  }
}
