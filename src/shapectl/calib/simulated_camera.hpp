#pragma once
// Observations of a known shape, as a tracker or a depth camera would make them: markers at
// chosen nodes and/or points on the surface, each with Gaussian noise, plus a fraction of
// outliers spread over the shape's bounding box grown by a margin (background, flying pixels).
// Or, as a depth camera writes them, depth images of the shape (calib/depth_render.hpp) with
// the same noise along each pixel's ray and the same fraction of flying pixels.
// For tests, benchmarks and the simulated world; the truth is whatever `positions` say.
#include <random>
#include <vector>

#include <shapectl/calib/depth_image.hpp>
#include <shapectl/calib/observations.hpp>
#include <shapectl/mesh/tet_mesh.hpp>

namespace shapectl {

struct SimulatedCamera {
  std::vector<int> marker_nodes;  // a marker on each of these nodes
  int surface_points = 0;         // points sampled uniformly (by area) on the surface
  double outlier_fraction = 0;    // of the cloud: points anywhere in the grown bounding box
  double outlier_margin = 0.03;   // m
  double sigma = 0.0003;          // m, per axis

  // One frame of the shape `positions` (3n, world) of `mesh`, taken at `joints`.
  ObservationFrame observe(const TetMesh& mesh, const Positions& positions,
                           const Eigen::VectorXd& joints, std::mt19937& rng) const;
  // The shape as a width × height depth image of a camera at T_world_camera: each depth with
  // noise σ along its ray, outlier_fraction of the pixels on the object flying anywhere from
  // half to 1.5 times their depth (mixed edge pixels, multipath). Write it with
  // depth_png_bytes (pixels_from_depth) or depth_npy_bytes.
  DepthImage depth_image(const TetMesh& mesh, const Positions& positions,
                         const PinholeIntrinsics& intrinsics,
                         const Eigen::Isometry3d& T_world_camera, int width, int height,
                         std::mt19937& rng) const;
};

}  // namespace shapectl
