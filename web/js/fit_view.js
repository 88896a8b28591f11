// Fit-view: the camera looks at a centre from a direction, just far enough back that every given
// point is inside both of the view's angles (with a margin). Fitting the points themselves, not
// their box or sphere: a robot's bounding box seen from the side is far wider than the robot.
import { MathUtils, Vector3 } from 'three';

const MARGIN = 1.08;  // distance × this: a little room around what is framed
const _forward = new Vector3();
const _right = new Vector3();
const _up = new Vector3();
const _offset = new Vector3();

// `camera`: a PerspectiveCamera (its `up` set); `orbit`: its OrbitControls; `direction`: from
// `centre` towards the camera; `forEachPoint(visit)` calls visit(Vector3) for each point to frame.
export function fitCamera(camera, orbit, centre, direction, forEachPoint) {
  _forward.copy(direction).normalize().negate();  // where the camera looks
  _right.crossVectors(_forward, camera.up).normalize();
  _up.crossVectors(_right, _forward);
  const tanVertical = Math.tan(MathUtils.degToRad(camera.fov) / 2);
  const tanHorizontal = tanVertical * camera.aspect;
  let distance = 0;
  forEachPoint((point) => {
    // At depth distance + offset·forward, its sideways offsets must be within the angles.
    _offset.subVectors(point, centre);
    const ahead = _offset.dot(_forward);
    distance = Math.max(distance,
      Math.abs(_offset.dot(_right)) / tanHorizontal - ahead, Math.abs(_offset.dot(_up)) / tanVertical - ahead);
  });
  place(camera, orbit, centre, direction, distance * MARGIN);
}

// The camera looks at a sphere from `direction` (as above), just far enough back that all of it is
// inside the narrower of the view's angles, with the same margin: the sphere fills the view.
export function fitSphere(camera, orbit, centre, radius, direction) {
  const tanVertical = Math.tan(MathUtils.degToRad(camera.fov) / 2);
  const halfAngle = Math.atan(Math.min(tanVertical, tanVertical * camera.aspect));
  place(camera, orbit, centre, direction, MARGIN * radius / Math.sin(halfAngle));
}

// The camera `distance` from `centre` towards `direction`, looking at it, orbiting about it.
function place(camera, orbit, centre, direction, distance) {
  _offset.copy(direction).normalize();
  orbit.target.copy(centre);
  camera.position.copy(centre).addScaledVector(_offset, distance);
  camera.near = Math.max(0.001, distance / 1000);
  camera.far = Math.max(50, 4 * distance);
  camera.updateProjectionMatrix();
  orbit.update();
  camera.updateMatrixWorld();  // picks and projections before the next render see the new view
}
