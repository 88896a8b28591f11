#pragma once
// An observed frame as the controller's closed loop takes it: the joints, the markers (node,
// position) and the time. The live loop uses markers only; a frame's points feed calibration.
#include <shapectl/calib/observations.hpp>
#include <shapectl/control/controller.hpp>

namespace shapectl {

inline ShapeObservation live_observation(const ObservationFrame& frame) {
  ShapeObservation o;
  o.joints = frame.joints;
  o.sigma = frame.sigma;
  o.time = frame.time.value_or(0);
  for (const ObservedMarker& m : frame.markers) o.markers.emplace_back(m.node, m.position);
  return o;
}

}  // namespace shapectl
