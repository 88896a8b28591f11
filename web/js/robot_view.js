// The robot in the 3D view: one group per link (its visuals, one colour per link) posed from
// each state's link poses, and the collision spheres, shown on request. World frame, metres.
import * as THREE from 'three';
import { ShapeKind } from './protocol.js';

const SPHERE_MATERIAL = new THREE.MeshBasicMaterial({ color: 0x66ccff, wireframe: true, transparent: true, opacity: 0.35 });

function linkColor(index) {
  // Golden-angle hues: neighbouring links get clearly different colours.
  return new THREE.Color().setHSL((index * 0.618034) % 1, 0.45, 0.55);
}

function shapeGeometry(shape) {
  if (shape.kind === ShapeKind.Box) return new THREE.BoxGeometry(...shape.size);
  if (shape.kind === ShapeKind.Cylinder) {
    // three.js cylinders run along y, URDF ones along z.
    return new THREE.CylinderGeometry(shape.radius, shape.radius, shape.length, 24).rotateX(Math.PI / 2);
  }
  return new THREE.SphereGeometry(shape.radius, 24, 16);
}

export class RobotView {
  constructor() {
    this.group = new THREE.Group();
    this.linkGroups = [];     // per link, posed by T_world_link
    this.visualMeshes = [];   // the link shapes (hidden by the robot toggle)
    this.sphereMeshes = [];   // collision spheres (their own toggle)
    this.robotVisible = true;
    this.spheresVisible = false;
  }

  // Rebuilds the links from a scene message's "robot" (null: no robot).
  setRobot(robot) {
    this.group.traverse((o) => {
      o.geometry?.dispose();
      if (o.material !== SPHERE_MATERIAL) o.material?.dispose();
    });
    this.group.clear();
    this.linkGroups = [];
    this.visualMeshes = [];
    this.sphereMeshes = [];
    if (!robot) return;
    robot.links.forEach((link, index) => {
      const group = new THREE.Group();
      group.matrixAutoUpdate = false;
      group.name = link.name;
      const material = new THREE.MeshStandardMaterial({ color: linkColor(index), roughness: 0.6, metalness: 0.1 });
      for (const shape of link.visuals) {
        const mesh = new THREE.Mesh(shapeGeometry(shape), material);
        mesh.matrixAutoUpdate = false;
        mesh.matrix.fromArray(shape.pose);
        mesh.visible = this.robotVisible;
        group.add(mesh);
        this.visualMeshes.push(mesh);
      }
      this.group.add(group);
      this.linkGroups.push(group);
    });
    for (const s of robot.collision_spheres) {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(s.radius, 12, 8), SPHERE_MATERIAL);
      mesh.position.set(...s.center);
      mesh.visible = this.spheresVisible;
      this.linkGroups[s.link]?.add(mesh);
      this.sphereMeshes.push(mesh);
    }
  }

  // `poses`: a state's "links", 16 numbers (column-major T_world_link) per link.
  setLinkPoses(poses) {
    poses.forEach((pose, k) => {
      const group = this.linkGroups[k];
      if (group) { group.matrix.fromArray(pose); group.matrixWorldNeedsUpdate = true; }
    });
  }

  setVisible(on) {
    this.robotVisible = on;
    for (const m of this.visualMeshes) m.visible = on;
  }

  setSpheresVisible(on) {
    this.spheresVisible = on;
    for (const m of this.sphereMeshes) m.visible = on;
  }
}
