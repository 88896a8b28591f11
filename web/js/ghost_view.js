// The ghost robot: a translucent copy of the robot's visuals at the link's measured joints (a
// state's "measured_links"), shown while the link is connected and armed, so lag and where the
// real robot is can be seen. No collision spheres.
import { RobotView } from './robot_view.js';

const GHOST_OPACITY = 0.3;

export class GhostView {
  constructor() {
    this.robotView = new RobotView({ opacity: GHOST_OPACITY, spheres: false });
    this.group = this.robotView.group;
    this.group.name = 'ghost';
    this.group.visible = false;
  }

  // A scene message's "robot" (null: no robot).
  setRobot(robot) {
    this.robotView.setRobot(robot);
    this.group.visible = false;
  }

  // Shows and poses the ghost from a state; returns whether the drawing may have changed.
  setState(state) {
    const link = state.link;
    const on = !!(link?.connected && link.armed && state.measured_links);
    const changed = on || on !== this.group.visible;
    this.group.visible = on;
    if (on) this.robotView.setLinkPoses(state.measured_links);
    return changed;
  }

  get visible() { return this.group.visible; }
}
