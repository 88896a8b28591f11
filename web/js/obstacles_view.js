// The scene's obstacles in the 3D view (the scene message's "obstacles", docs/contact.md):
// a plane as a translucent square with a grid, centred under the object; a box or a mesh from its
// triangles; a sphere; a capsule as a cylinder with two spheres (in general: a sphere of the
// radius at every point and a cylinder along every edge, the inflated shape the contact sees).
// World frame, metres; an obstacle on a robot link at that link's pose.
import * as THREE from 'three';

const PLANE_SIZE_M = 1.2;         // the plane's square: wider than the object and the robot's reach
const PLANE_GRID_CELLS = 24;      // 5 cm cells
const OBSTACLE_COLOR = 0x8a7f6e;  // wood-ish, apart from the object's blue and the robot's greys
const OBSTACLE_OPACITY = 0.55;    // the object's underside shows through
const Z = new THREE.Vector3(0, 0, 1);
const Y = new THREE.Vector3(0, 1, 0);

const material = () => new THREE.MeshStandardMaterial({
  color: OBSTACLE_COLOR, roughness: 0.9, transparent: true, opacity: OBSTACLE_OPACITY, depthWrite: false, side: THREE.DoubleSide,
});

// A plane obstacle: the square and its grid in the plane, its normal along the group's z.
function planeObject(plane) {
  const group = new THREE.Group();
  const square = new THREE.Mesh(new THREE.PlaneGeometry(PLANE_SIZE_M, PLANE_SIZE_M), material());
  const grid = new THREE.GridHelper(PLANE_SIZE_M, PLANE_GRID_CELLS, 0x6b6255, 0x6b6255);
  grid.rotateX(Math.PI / 2);  // GridHelper lies in x–z; the square in x–y
  grid.position.z = 1e-4;     // on the free side, not fighting the square's depth
  group.add(square, grid);
  group.quaternion.setFromUnitVectors(Z, new THREE.Vector3().fromArray(plane.normal).normalize());
  group.position.fromArray(plane.point);
  group.userData.plane = { point: new THREE.Vector3().fromArray(plane.point), normal: new THREE.Vector3().fromArray(plane.normal).normalize() };
  return group;
}

// Points, edges and triangles inflated by `radius`.
function shapeObject(obstacle) {
  const group = new THREE.Group();
  const points = obstacle.points.map((p) => new THREE.Vector3().fromArray(p));
  if (obstacle.triangles.length) {
    const geometry = new THREE.BufferGeometry().setFromPoints(points);
    geometry.setIndex(obstacle.triangles.flat());
    geometry.computeVertexNormals();
    group.add(new THREE.Mesh(geometry, material()));
  }
  if (obstacle.radius > 0) {
    const r = obstacle.radius;
    for (const p of points) {
      const ball = new THREE.Mesh(new THREE.SphereGeometry(r, 24, 16), material());
      ball.position.copy(p);
      group.add(ball);
    }
    for (const [i, j] of obstacle.edges) {
      const axis = new THREE.Vector3().subVectors(points[j], points[i]);
      const rod = new THREE.Mesh(new THREE.CylinderGeometry(r, r, axis.length(), 24, 1, true), material());
      rod.position.addVectors(points[i], points[j]).multiplyScalar(0.5);
      rod.quaternion.setFromUnitVectors(Y, axis.normalize());
      group.add(rod);
    }
  }
  return group;
}

export class ObstaclesView {
  constructor() {
    this.group = new THREE.Group();
    this.group.name = 'obstacles';
    this.obstacles = [];  // {name, shape, object}
  }

  // A scene message's "obstacles" (absent or []: none).
  setObstacles(obstacles = []) {
    this.group.traverse((o) => { o.geometry?.dispose(); o.material?.dispose(); });
    this.group.clear();
    this.obstacles = obstacles.map((o) => {
      const object = o.plane ? planeObject(o.plane) : shapeObject(o);
      object.name = `obstacle ${o.name}`;
      // On a robot link: its points are in the link's frame, the link's pose its matrix.
      if (o.link) object.matrixAutoUpdate = false;
      this.group.add(object);
      return { name: o.name, shape: o.shape, link: o.link ?? null, object };
    });
  }

  // `poses` (a state's "links", column-major T_world_link) for the links named `linkNames`:
  // obstacles on a link move with it.
  setLinkPoses(poses, linkNames) {
    for (const { link, object } of this.obstacles) {
      const k = link ? linkNames.indexOf(link) : -1;
      if (k < 0 || !poses[k]) continue;
      object.matrix.fromArray(poses[k]);
      object.matrixWorldNeedsUpdate = true;
    }
  }

  // Moves each plane's square under `point` (the object's centroid): its foot on the plane.
  centreUnder(point) {
    for (const { object } of this.obstacles) {
      const plane = object.userData.plane;
      if (!plane) continue;
      const height = object.position.copy(point).sub(plane.point).dot(plane.normal);
      object.position.copy(point).addScaledVector(plane.normal, -height);
    }
  }

  // For tests: each obstacle as drawn, {name, shape, link, visible, meshes, centre: [x, y, z] of
  // its box}.
  describe() {
    return this.obstacles.map(({ name, shape, link, object }) => {
      let meshes = 0;
      object.traverse((o) => { if (o.isMesh) meshes++; });
      object.updateMatrixWorld(true);
      const centre = new THREE.Box3().setFromObject(object).getCenter(new THREE.Vector3()).toArray();
      return { name, shape, link, visible: object.visible && this.group.visible, meshes, centre };
    });
  }
}
