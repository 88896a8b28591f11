// The broad phase: the hierarchy finds exactly the boxes brute force finds.
#include <shapectl/contact/bvh.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace shapectl {
namespace {

Aabb random_box(std::mt19937& rng, double size) {
  std::uniform_real_distribution<double> u(0, 1), s(0, size);
  const Vec3 corner(u(rng), u(rng), u(rng));
  return {corner, corner + Vec3(s(rng), s(rng), s(rng))};
}

TEST(Bvh, FindsExactlyTheOverlappingBoxes) {
  std::mt19937 rng(21);
  for (int count : {0, 1, 3, 17, 1000}) {
    std::vector<Aabb> boxes;
    for (int i = 0; i < count; ++i) boxes.push_back(random_box(rng, 0.05));
    const Bvh bvh(boxes);
    int found_any = 0;
    for (int q = 0; q < 200; ++q) {
      const Aabb query = random_box(rng, 0.1);
      std::vector<int> found, expected;
      bvh.query(query, [&](int i) { found.push_back(i); });
      for (int i = 0; i < count; ++i)
        if (boxes[i].overlaps(query)) expected.push_back(i);
      std::sort(found.begin(), found.end());
      EXPECT_EQ(found, expected) << count << " boxes, query " << q;
      found_any += !found.empty();
    }
    if (count >= 17) {
      EXPECT_GT(found_any, 0);
    }
  }
}

TEST(SegmentOverlaps, AgreesWithSamplingTheSegment) {
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> u(-0.5, 1.5);
  int hits = 0, misses = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Aabb box = random_box(rng, 0.5);
    const Vec3 a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng));
    bool sampled = false;
    for (int k = 0; k <= 2000 && !sampled; ++k) {
      const Vec3 p = a + (b - a) * (k / 2000.0);
      sampled = (p.array() >= box.min.array()).all() && (p.array() <= box.max.array()).all();
    }
    const bool overlaps = segment_overlaps(a, b, box);
    // Sampling can miss a corner the segment clips: only a sampled hit must be found.
    if (sampled) {
      EXPECT_TRUE(overlaps) << "trial " << trial;
    }
    hits += overlaps;
    misses += !overlaps;
    if (overlaps && !sampled) {  // then it passes within a sample step of the box
      const Aabb grown = box.inflated(1e-3 * (b - a).norm());
      bool near = false;
      for (int k = 0; k <= 2000 && !near; ++k) {
        const Vec3 p = a + (b - a) * (k / 2000.0);
        near = (p.array() >= grown.min.array()).all() && (p.array() <= grown.max.array()).all();
      }
      EXPECT_TRUE(near) << "trial " << trial;
    }
  }
  EXPECT_GT(hits, 50);
  EXPECT_GT(misses, 100);
}

}  // namespace
}  // namespace shapectl
