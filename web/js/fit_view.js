// Fit-view: the camera looks at a box's centre from a direction, just far enough back that the
// box's bounding sphere fills the narrower of the view's two angles (with a margin).
import { MathUtils, Sphere, Vector3 } from 'three';

const MARGIN = 1.1;  // sphere radius × this fits the view
const _sphere = new Sphere();
const _offset = new Vector3();

// `camera`: a PerspectiveCamera; `orbit`: its OrbitControls; `direction`: from the centre to the camera.
export function fitCamera(camera, orbit, box, direction) {
  box.getBoundingSphere(_sphere);
  const halfVertical = MathUtils.degToRad(camera.fov) / 2;
  const halfHorizontal = Math.atan(Math.tan(halfVertical) * camera.aspect);
  const distance = MARGIN * _sphere.radius / Math.sin(Math.min(halfVertical, halfHorizontal));
  orbit.target.copy(_sphere.center);
  camera.position.copy(_sphere.center).add(_offset.copy(direction).normalize().multiplyScalar(distance));
  camera.near = Math.max(0.001, distance / 1000);
  camera.far = Math.max(50, 4 * distance);
  camera.updateProjectionMatrix();
  orbit.update();
  camera.updateMatrixWorld();  // picks and projections before the next render see the new view
}
