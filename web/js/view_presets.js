// Camera presets, as Blender's numpad: 1 front (from +x, where the robot faces the object),
// 3 side (from −y), 7 top (from +z), 0 iso. The camera keeps its distance to the orbit centre.
import { Vector3 } from 'three';

export const PRESETS = Object.freeze({
  1: { name: 'front', direction: new Vector3(1, 0, 0) },
  3: { name: 'side', direction: new Vector3(0, -1, 0) },
  // Not exactly overhead: with z up, a camera looking straight down has no defined "up".
  7: { name: 'top', direction: new Vector3(-1e-3, 0, 1).normalize() },
  0: { name: 'iso', direction: new Vector3(1, -1, 1).normalize() },
});

// Puts `view`'s camera on the preset for `key` ('1', '3', '7', '0'); false for another key.
export function applyPreset(view, key) {
  const preset = PRESETS[key];
  if (!preset) return false;
  const distance = view.camera.position.distanceTo(view.orbit.target);
  view.camera.position.copy(view.orbit.target).addScaledVector(preset.direction, distance);
  view.orbit.update();
  view.camera.updateMatrixWorld();  // projections before the next frame see the new view
  view.requestRender();
  return true;
}
