#pragma once
// A frame's "depth_image" (docs/calibration.md, "Depth images"): a depth camera's image as the
// frame's points, back-projected, placed in the world and cropped:
//   "depth_image": {"file": "d.png", "scale": 0.001,
//                   "intrinsics": {"fx": 600, "fy": 600, "cx": 319.5, "cy": 239.5},
//                   "camera_pose": {"position": [x, y, z], "rpy": [r, p, y]},
//                   "crop": {"box": {"min": [..], "max": [..]}}, "stride": 2, "camera": 0}
// file: .png (16-bit grayscale, value × scale = depth in m, 0: no reading; scale required) or
//   .npy (2-D float32/float64, value × scale, scale 1 if not given; NaN or 0: no reading),
//   relative to the JSON file's directory. intrinsics: pinhole, pixels (fx, fy > 0).
//   camera_pose: T_world_camera, the scene's pose schema, camera axes OpenCV's (x right, y down,
//   z forward). crop (optional): only points inside this world-frame box are kept. stride
//   (optional, default 1): every stride-th pixel of every stride-th row. camera (optional,
//   default 0): which camera took it, 0 to max_cameras − 1: frames of one camera share its
//   fitted pose correction (--fit camera_poses).
#include <vector>

#include <shapectl/calib/observations.hpp>

namespace shapectl {

struct DepthImageObservation {
  std::vector<Vec3> points;  // world frame, m
  FrameCamera camera;
};

// Throws InputError naming the observations file and the field: a missing or bad key, a file
// that cannot be read (the message names it and the problem: not 16-bit grayscale, a wrong
// dtype or shape, too many pixels), more than max_point_cloud_points points after the crop, a
// point beyond max_observation_distance.
DepthImageObservation read_depth_image(const JsonInput& field);

}  // namespace shapectl
