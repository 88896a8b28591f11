// The robot in the 3D view: one group per link (its visuals, in the URDF's colours or else one
// colour per link) posed from each state's link poses, and the collision spheres, shown on
// request. World frame, metres. With `opacity` < 1 and no spheres it draws the ghost robot.
// Mesh visuals arrive later (mesh_loader.js): `group` then dispatches 'meshloaded', or
// 'mesherror' with a `message` naming the file when one cannot be drawn.
import * as THREE from 'three';
import { MeshFormat, ShapeKind } from './protocol.js';
import { loadMesh, triangleVertexCount } from './mesh_loader.js';

const SPHERE_MATERIAL = new THREE.MeshBasicMaterial({ color: 0x66ccff, wireframe: true, transparent: true, opacity: 0.35 });
// The closest checked sphere pair: solid, red when the two overlap, yellow otherwise.
const CLOSEST_MATERIAL = new THREE.MeshBasicMaterial({ color: 0xffd23f, transparent: true, opacity: 0.7 });
const OVERLAP_MATERIAL = new THREE.MeshBasicMaterial({ color: 0xff2a2a, transparent: true, opacity: 0.8 });
// A link whose spheres overlap another's.
export const COLLIDING_COLOR = new THREE.Color(0xff2a2a);
const COLLIDING_EMISSIVE = new THREE.Color(0x550000);
const SHARED_MATERIALS = [SPHERE_MATERIAL, CLOSEST_MATERIAL, OVERLAP_MATERIAL];

function linkColor(index) {
  // Golden-angle hues: neighbouring links get clearly different colours.
  return new THREE.Color().setHSL((index * 0.618034) % 1, 0.45, 0.55);
}

// A visual's material: the URDF's sRGB colour and alpha, else the link's colour; `opacity`
// scales the alpha (the ghost).
function shapeMaterial(shape, index, opacity) {
  const [r, g, b, a] = shape.color ?? [0, 0, 0, 1];
  const color = shape.color ? new THREE.Color().setRGB(r, g, b, THREE.SRGBColorSpace) : linkColor(index);
  const alpha = a * opacity;
  return new THREE.MeshStandardMaterial({
    color, roughness: 0.6, metalness: 0.1, transparent: alpha < 1, opacity: alpha, depthWrite: alpha >= 1,
  });
}

function shapeGeometry(shape) {
  if (shape.kind === ShapeKind.Box) return new THREE.BoxGeometry(...shape.size);
  if (shape.kind === ShapeKind.Cylinder) {
    // three.js cylinders run along y, URDF ones along z.
    return new THREE.CylinderGeometry(shape.radius, shape.radius, shape.length, 24).rotateX(Math.PI / 2);
  }
  return new THREE.SphereGeometry(shape.radius, 24, 16);
}

// Gives the loaded mesh the URDF's colour, else (STL, OBJ) the link's; a DAE without a URDF
// colour keeps its own materials, made translucent for the ghost.
function colourMesh(object, shape, index, opacity) {
  object.traverse((o) => {
    if (!o.isMesh) return;
    if (shape.color || shape.format !== MeshFormat.Dae) {
      o.material = shapeMaterial(shape, index, opacity);
      return;
    }
    for (const m of Array.isArray(o.material) ? o.material : [o.material]) {
      m.opacity *= opacity;
      m.transparent = m.opacity < 1;
      m.depthWrite = m.opacity >= 1;
    }
  });
}

// A visual's material red while its link collides, its own colour (kept at the first call) after.
function paintCollision(material, red) {
  if (!material?.color) return;
  material.userData.color ??= material.color.clone();
  material.userData.emissive ??= material.emissive?.clone();
  material.color.copy(red ? COLLIDING_COLOR : material.userData.color);
  if (material.emissive) material.emissive.copy(red ? COLLIDING_EMISSIVE : material.userData.emissive);
}

// What a faded material draws with: transparent, no depth written (what is behind shows), and
// the first faded surface at a pixel marks the stencil so the others leave that pixel alone: one
// veil over the object however many links (or sides of one) line up in front of it.
const FADED = {
  transparent: true, depthWrite: false,
  stencilWrite: true, stencilRef: 1, stencilFunc: THREE.NotEqualStencilFunc, stencilZPass: THREE.ReplaceStencilOp,
};

// Fades a material towards `opacity` by `amount` (0: its own opacity, kept at the first fade,
// 1: `opacity`, if that is lower). The view's renderer needs a stencil buffer.
function fade(material, amount, opacity) {
  const solid = material.userData.solid;
  if (amount <= 0) {
    if (!solid) return;
    Object.assign(material, solid);
    delete material.userData.solid;
    material.needsUpdate = true;
    return;
  }
  if (!solid) {
    material.userData.solid = Object.fromEntries(['opacity', ...Object.keys(FADED)].map((key) => [key, material[key]]));
    Object.assign(material, FADED);
    material.needsUpdate = true;
  }
  const own = material.userData.solid.opacity;
  material.opacity = own + (Math.min(own, opacity) - own) * Math.min(1, amount);
}

export class RobotView {
  // `opacity` scales every visual's alpha; `spheres`: whether to draw the collision spheres.
  constructor({ opacity = 1, spheres = true } = {}) {
    this.opacity = opacity;
    this.drawSpheres = spheres;
    this.group = new THREE.Group();
    this.linkGroups = [];     // per link, posed by T_world_link
    this.visualMeshes = [];   // the link shapes (hidden by the robot toggle)
    this.sphereMeshes = [];   // collision spheres (their own toggle)
    this.robotVisible = true;
    this.spheresVisible = false;
    this.meshes = [];         // per mesh visual: {link, url, format, holder, state, vertices, problem}
    this.generation = 0;      // loads for an older robot are dropped
    this.collidingLinks = new Set();  // link indices drawn red
    this.closestPair = null;          // the state's closest_pair
  }

  // Rebuilds the links from a scene message's "robot" (null: no robot).
  setRobot(robot) {
    this.group.traverse((o) => {
      o.geometry?.dispose();
      if (!SHARED_MATERIALS.includes(o.material)) o.material?.dispose();
    });
    this.group.clear();
    this.linkGroups = [];
    this.visualMeshes = [];
    this.sphereMeshes = [];
    this.meshes = [];
    this.generation++;
    this.collidingLinks = new Set();
    this.closestPair = null;
    if (!robot) return;
    robot.links.forEach((link, index) => {
      const group = new THREE.Group();
      group.matrixAutoUpdate = false;
      group.name = link.name;
      for (const shape of link.visuals) {
        if (shape.kind === ShapeKind.Mesh) {
          this.addMeshVisual(group, shape, index);
          continue;
        }
        const mesh = new THREE.Mesh(shapeGeometry(shape), shapeMaterial(shape, index, this.opacity));
        mesh.matrixAutoUpdate = false;
        mesh.matrix.fromArray(shape.pose);
        mesh.visible = this.robotVisible;
        group.add(mesh);
        this.visualMeshes.push(mesh);
      }
      this.group.add(group);
      this.linkGroups.push(group);
    });
    if (!this.drawSpheres) return;
    for (const s of robot.collision_spheres) {
      const mesh = new THREE.Mesh(new THREE.SphereGeometry(s.radius, 12, 8), SPHERE_MATERIAL);
      mesh.position.set(...s.center);
      mesh.visible = this.spheresVisible;
      this.linkGroups[s.link]?.add(mesh);
      this.sphereMeshes.push(mesh);
    }
  }

  // A placeholder at the visual's pose that the mesh fills once loaded. Missing on the server
  // (no url): nothing to draw, the scene message's warnings say so.
  addMeshVisual(group, shape, index) {
    const entry = { link: group.name, file: shape.file, url: shape.url, format: shape.format, holder: null,
      state: shape.url ? 'loading' : 'missing', vertices: 0, problem: shape.url ? null : shape.missing };
    this.meshes.push(entry);
    if (!shape.url) return;
    const holder = new THREE.Group();
    holder.matrixAutoUpdate = false;
    holder.matrix.fromArray(shape.pose);
    holder.visible = this.robotVisible;
    group.add(holder);
    this.visualMeshes.push(holder);
    entry.holder = holder;
    const generation = this.generation;
    loadMesh(shape.url, shape.format).then((object) => {
      if (generation !== this.generation) return;
      object.scale.multiply(new THREE.Vector3(...shape.scale));
      colourMesh(object, shape, index, this.opacity);
      holder.add(object);
      Object.assign(entry, { state: 'loaded', vertices: triangleVertexCount(object) });
      this.group.dispatchEvent({ type: 'meshloaded' });
    }).catch((error) => {
      if (generation !== this.generation) return;
      const problem = `link '${group.name}': mesh '${shape.file}' (${shape.url}) could not be drawn: ${error?.message ?? error}`;
      Object.assign(entry, { state: 'failed', problem });
      this.group.dispatchEvent({ type: 'mesherror', message: problem });
    });
  }

  // For tests: each mesh visual, its link, url, state ('loading', 'loaded', 'failed',
  // 'missing'), the vertices drawn and the problem if any.
  meshVisuals() {
    return this.meshes.map(({ holder, ...m }) => ({ ...m, visible: !!holder?.visible }));
  }

  // `poses`: a state's "links", 16 numbers (column-major T_world_link) per link.
  setLinkPoses(poses) {
    poses.forEach((pose, k) => {
      const group = this.linkGroups[k];
      if (group) { group.matrix.fromArray(pose); group.matrixWorldNeedsUpdate = true; }
    });
  }

  // A state's colliding_links (red) and closest_pair (highlighted among the spheres).
  setCollisions(collidingLinks, closestPair) {
    this.collidingLinks = new Set(collidingLinks);
    this.linkGroups.forEach((group, k) => {
      const red = this.collidingLinks.has(k);
      // Primitive and loaded mesh visuals alike; the collision spheres keep their own colours.
      group.traverse((o) => {
        if (!o.isMesh || this.sphereMeshes.includes(o)) return;
        for (const material of Array.isArray(o.material) ? o.material : [o.material]) paintCollision(material, red);
      });
    });
    this.closestPair = closestPair;
    const pair = closestPair?.spheres ?? [];
    const highlight = closestPair && closestPair.clearance !== null && closestPair.clearance < 0 ? OVERLAP_MATERIAL : CLOSEST_MATERIAL;
    this.sphereMeshes.forEach((mesh, k) => { mesh.material = pair.includes(k) ? highlight : SPHERE_MATERIAL; });
  }

  // For tests: the highlighted spheres (indices into the scene's collision_spheres) and whether
  // they are shown, red (overlapping) or yellow.
  highlightedSpheres() {
    const spheres = [];
    this.sphereMeshes.forEach((mesh, k) => { if (mesh.material !== SPHERE_MATERIAL) spheres.push(k); });
    const overlap = spheres.length > 0 && this.sphereMeshes[spheres[0]].material === OVERLAP_MATERIAL;
    return { spheres, visible: this.spheresVisible, overlap };
  }

  // For tests: per link in scene order, its name and each drawn visual's sRGB colour and opacity.
  visualColors() {
    const srgb = new THREE.Color();
    return this.linkGroups.map((group) => ({
      name: group.name,
      visuals: group.children.filter((o) => this.visualMeshes.includes(o)).map((m) => {
        // A mesh visual: its first triangle mesh's material (none until loaded).
        let material = m.material;
        m.traverse((o) => { if (!material && o.isMesh) material = [].concat(o.material)[0]; });
        if (!material) return { rgb: null, opacity: null };
        material.color.getRGB(srgb, THREE.SRGBColorSpace);
        return { rgb: [srgb.r, srgb.g, srgb.b], opacity: material.opacity };
      }),
    }));
  }

  // Fades link `k`'s visuals (not its collision spheres) towards `opacity` by `amount` (0: solid).
  fadeLink(k, amount, opacity) {
    this.linkGroups[k]?.traverse((o) => {
      if (!o.isMesh || this.sphereMeshes.includes(o)) return;
      for (const material of Array.isArray(o.material) ? o.material : [o.material]) fade(material, amount, opacity);
    });
  }

  // For tests: each link's pose as drawn, 16 numbers (column-major T_world_link).
  linkPoses() {
    return this.linkGroups.map((group) => group.matrix.toArray());
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
