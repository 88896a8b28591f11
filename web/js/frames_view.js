// Coordinate frames in the 3D view: the world frame at the origin and a tool frame at each end
// effector's TCP (the link's orientation, at its `tcp` point). Red x, green y, blue z, as
// three.js' AxesHelper (and RViz, MeshCat) draw them.
import * as THREE from 'three';

const WORLD_AXIS_M = 0.1;  // length of the world frame's axes
const TOOL_AXIS_M = 0.05;  // length of a tool frame's axes

function makeAxes(length) {
  const axes = new THREE.AxesHelper(length);
  axes.material.depthTest = false;  // over the gripper boxes that hide the TCP
  axes.renderOrder = 5;
  axes.matrixAutoUpdate = false;
  return axes;
}

export class FramesView {
  constructor() {
    this.group = new THREE.Group();
    this.world = makeAxes(WORLD_AXIS_M);
    this.group.add(this.world);
    this.tools = [];  // {name, link (index into robot.links and the state's links), tcp: Vector3, axes}
    this.scratch = new THREE.Matrix4();
  }

  // The scene message's robot: a tool frame per end effector.
  setRobot(robot) {
    for (const t of this.tools) { this.group.remove(t.axes); t.axes.dispose(); }
    this.tools = (robot?.end_effectors ?? []).map((e) => {
      const axes = makeAxes(TOOL_AXIS_M);
      axes.name = `tool frame ${e.name}`;
      axes.visible = false;  // until a state gives its link's pose
      this.group.add(axes);
      return { name: e.name, link: e.link, tcp: new THREE.Vector3().fromArray(e.tcp), axes };
    });
  }

  // The state's link poses (T_world_link, column-major 16 numbers each).
  setLinkPoses(poses) {
    for (const t of this.tools) {
      const pose = poses?.[t.link];
      t.axes.visible = !!pose;
      if (!pose) continue;
      t.axes.matrix.fromArray(pose);
      // T_world_tool = T_world_link · translation(tcp): the link's axes, moved to the TCP.
      t.axes.matrix.multiply(this.scratch.makeTranslation(t.tcp));
      t.axes.matrixWorldNeedsUpdate = true;
    }
  }

  setVisible(on) { this.group.visible = on; }

  // World origins of the tool frames, for tests: {name: [x, y, z]}.
  toolOrigins() {
    const p = new THREE.Vector3();
    return Object.fromEntries(this.tools.map((t) => [t.name, p.setFromMatrixPosition(t.axes.matrix).toArray()]));
  }
}
