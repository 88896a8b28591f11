#include <shapectl/control/observation_gate.hpp>

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <shapectl/control/model_error_feedback.hpp>
#include <shapectl/mesh/box_mesh.hpp>

namespace shapectl {
namespace {

TEST(ObservationGate, MarkersOutsideTheGateAreRejectedAndCountedAndAMajorityRejectsTheFrame) {
  const GateOptions options;
  const double radius = gate_radius(0, 0.001, options);
  EXPECT_NEAR(radius, std::sqrt(16.27 * (36e-6 + 1e-6)), 1e-15);  // 24.5 mm
  GateCounts counts;
  GateVerdict v = judge_innovations({Vec3(0.02, 0, 0), Vec3(0, 0.3, 0), Vec3(0, 0, 0.001)},
                                    {0, 0, 0}, 0.001, options, counts);
  EXPECT_EQ(v.inside, (std::vector<bool>{true, false, true}));
  EXPECT_FALSE(v.frame_rejected);
  EXPECT_NE(v.reason.find("1 of 3 markers outside the gate (largest innovation 300.0 mm, gate "
                          "24.5 mm)"),
            std::string::npos)
      << v.reason;
  v = judge_innovations({Vec3(1, 0, 0), Vec3(NAN, 0, 0), Vec3::Zero()}, {0, 0, 0}, 0.001, options,
                        counts);
  EXPECT_EQ(v.inside, (std::vector<bool>{false, false, true}));  // NaN is never inside
  EXPECT_TRUE(v.frame_rejected);
  EXPECT_EQ(counts.markers_checked, 6u);
  EXPECT_EQ(counts.markers_rejected, 3u);
  EXPECT_EQ(counts.frames_checked, 2u);
  EXPECT_EQ(counts.frames_rejected, 1u);
}

TEST(ObservationGate, AFrameCannotWidenTheGateByClaimingMoreNoise) {
  const GateOptions options;
  const double q = options.model_error_allowance;
  const double widest = std::sqrt(16.27 * (1e-4 + 2 * q * q));
  EXPECT_NEAR(gate_radius(1e-4, 1.0, options), widest, 1e-15);
  EXPECT_NEAR(gate_radius(1e-4, 1e6, options), widest, 1e-15);
  GateCounts counts;
  EXPECT_TRUE(judge_innovations({Vec3(0.5, 0, 0)}, {1e-4}, 1e6, options, counts).frame_rejected);
}

class FeedbackAuthorityTest : public ::testing::Test {
 protected:
  std::shared_ptr<const TetMesh> mesh =
      std::make_shared<const TetMesh>(make_box_mesh({0.3, 0.04, 0.04}, {6, 1, 1}));
  Positions predicted = flatten(mesh->rest_positions());
  static Positions flatten(const std::vector<Vec3>& points) {
    Positions x(3 * points.size());
    for (std::size_t i = 0; i < points.size(); ++i) x.segment<3>(3 * i) = points[i];
    return x;
  }
};

// Lies inside the gate (a consistent 35 mm, and one growing by 0.14 mm per frame so the gate never
// sees a jump), flooded at 100 frames a second and repeated at one instant: no correction, at an
// observed node or interpolated at another, moves faster than the rate or farther than the bound.
TEST_F(FeedbackAuthorityTest,
       NoSequenceOfObservationsMovesACorrectionFasterOrFartherThanTheBounds) {
  const FeedbackOptions options;
  ModelErrorFeedback feedback(mesh, options);
  const std::vector<int> nodes = {0, 5, 9};
  std::vector<Vec3> last(mesh->node_count(), Vec3::Zero());
  double last_time = -1;  // the first frame may move a second's worth
  double worst_excess = -1, worst_size = 0;
  for (int k = 0; k < 400; ++k) {
    const double time = 0.01 * (k < 300 ? k : 300);  // the last 100 at one instant
    std::vector<std::pair<int, Vec3>> observed;
    for (int node : nodes) {
      const double lie = node == 0 ? 0.025 : 0.0001 * k;  // 35 mm; 0.14 mm per frame
      observed.emplace_back(node, predicted.segment<3>(3 * node) + Vec3(lie, 0, -lie));
    }
    feedback.observe(observed, predicted, 0.001, time);
    for (int node = 0; node < mesh->node_count(); ++node) {
      const Vec3 e = feedback.estimate(node);
      worst_size = std::max(worst_size, e.norm());
      const double allowed = options.max_correction_rate * (time - last_time);
      worst_excess = std::max(worst_excess, (e - last[node]).norm() - allowed);
      last[node] = e;
    }
    last_time = time;
  }
  EXPECT_LE(worst_size, options.max_correction + 1e-12);
  EXPECT_GT(worst_size, 0.99 * options.max_correction) << "the lies did reach the bound";
  EXPECT_LE(worst_excess, 1e-12);
  const FeedbackAuthority a = feedback.authority();
  EXPECT_NEAR(a.largest, options.max_correction, 1e-12);
  EXPECT_GT(a.rate_limited, 0u);
  EXPECT_GT(a.clamped, 0u);
  EXPECT_EQ(feedback.gate_counts().markers_rejected, 0u);  // all of it inside the gate
  const ShapeTargets t = feedback.corrected({{3}, {Vec3(1, 2, 3)}});
  EXPECT_LE((t.positions[0] - Vec3(1, 2, 3)).norm(), options.max_correction + 1e-12);
}

// A node not yet seen may be off by a model's centimetres (gate 123 mm); once its estimate has
// settled the gate is 40 mm, and a sudden 60 mm jump there is not taken.
TEST_F(FeedbackAuthorityTest, TheGateIsWideForAnUnseenNodeAndNarrowsAsItsEstimateSettles) {
  ModelErrorFeedback feedback(mesh, {.max_correction_rate = INFINITY});
  const auto seen = [&](double error, double time) {
    return feedback.observe({{0, predicted.segment<3>(0) + Vec3(0, 0, error)}}, predicted, 0.0003,
                            time);
  };
  GateVerdict v = seen(0.1, 0);
  EXPECT_FALSE(v.frame_rejected) << v.reason;
  EXPECT_NEAR(v.radius, std::sqrt(16.27 * (9e-4 + 36e-6 + 9e-8)), 1e-12);
  for (int k = 1; k < 40; ++k) seen(0.02, k);  // the model was 2 cm off after all
  v = seen(0.08, 40);
  EXPECT_TRUE(v.frame_rejected);
  EXPECT_NEAR(v.radius, 0.0404, 0.0005);
  EXPECT_FALSE(seen(0.04, 41).frame_rejected);  // 2 cm more: within
}

TEST_F(FeedbackAuthorityTest, ARejectedFrameChangesNothingButTheCounts) {
  ModelErrorFeedback feedback(mesh);
  feedback.observe({{0, predicted.segment<3>(0) + Vec3(0.002, 0, 0)}}, predicted, 0.001, 0);
  const Vec3 before = feedback.estimate(0);
  const GateVerdict v = feedback.observe({{0, predicted.segment<3>(0) + Vec3(0, 0, 1)},
                                          {1, predicted.segment<3>(3) + Vec3(0, 0, 1)}},
                                         predicted, 0.001, 1);
  EXPECT_TRUE(v.frame_rejected);
  EXPECT_EQ(feedback.estimate(0), before);
  EXPECT_EQ(feedback.gate_counts().frames_rejected, 1u);
  EXPECT_EQ(feedback.gate_counts().markers_rejected, 2u);
  EXPECT_GT(feedback.last_model_error(), 0);  // the accepted frame's, not the lie's
  EXPECT_LT(feedback.last_model_error(), 0.01);
}

}  // namespace
}  // namespace shapectl
