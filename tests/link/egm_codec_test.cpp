// EGM wire format against the reference bytes (shared/reference/egm/protocol.md §6), the 7th
// joint as external axis, and a long randomized (fuzz) run of the decoder.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <numbers>
#include <random>

#include <shapectl/link/egm_codec.hpp>

namespace shapectl {
namespace {

constexpr double deg = std::numbers::pi / 180;

std::string from_hex(const std::string& hex) {
  std::string bytes;
  for (std::size_t i = 0; i + 1 < hex.size();) {
    if (hex[i] == ' ' || hex[i] == '\n') {
      ++i;
      continue;
    }
    bytes.push_back(static_cast<char>(std::stoi(hex.substr(i, 2), nullptr, 16)));
    i += 2;
  }
  return bytes;
}

// EgmRobot: seqno 5, tm 1234, DATA; feedBack joints 1…6 deg, external 7 deg, time; motors on,
// MCI running, RAPID running (96 bytes).
const std::string kRobotExample = from_hex(
    "0a 07 08 05 10 d2 09 18 02 12 49 0a 36 09 00 00 00 00 00 00 f0 3f 09 00 00 00 00 00 00 00 40"
    "09 00 00 00 00 00 00 08 40 09 00 00 00 00 00 00 10 40 09 00 00 00 00 00 00 14 40 09 00 00 00"
    "00 00 00 18 40 1a 09 09 00 00 00 00 00 00 1c 40 22 04 08 01 10 02 22 02 08 01 2a 02 08 03 42"
    "02 08 02");

// EgmSensor: seqno 1, tm 0, CORRECTION, joints (0, −130, 30, 0, 40, 0), external 135 (77 bytes).
const std::string kSensorExample = from_hex(
    "0a 06 08 01 10 00 18 03 12 43 0a 36"
    "09 00 00 00 00 00 00 00 00 09 00 00 00 00 00 40 60 c0 09 00 00 00 00 00 00 3e 40"
    "09 00 00 00 00 00 00 00 00 09 00 00 00 00 00 00 44 40 09 00 00 00 00 00 00 00 00"
    "1a 09 09 00 00 00 00 00 e0 60 40");

ArmJoints chain(double j1, double j2, double j7, double j3, double j4, double j5, double j6) {
  return (ArmJoints() << j1, j2, j7, j3, j4, j5, j6).finished() * deg;
}

TEST(EgmCodec, DecodesTheControllersExampleWithAxis7FromTheExternalAxis) {
  ASSERT_EQ(kRobotExample.size(), 96u);
  EgmCodec codec;
  EgmFeedback f;
  std::string_view why;
  ASSERT_TRUE(codec.decode_robot(kRobotExample, f, &why)) << why;
  EXPECT_EQ(f.seqno, 5u);
  EXPECT_EQ(f.tm, 1234u);
  // joints[0..5] = ABB axes 1..6, externalJoints[0] = axis 7 → chain order 1, 2, 7, 3, 4, 5, 6.
  EXPECT_TRUE(f.joints.isApprox(chain(1, 2, 7, 3, 4, 5, 6), 1e-15));
  EXPECT_EQ(f.fault(), "");
}

TEST(EgmCodec, EncodesTheReferenceSensorBytesThenSpeedRef) {
  EgmCodec codec;
  EgmCommand c;
  c.seqno = 1;
  c.tm = 0;
  c.joints = chain(0, -130, 135, 30, 0, 40, 0);
  std::string bytes(codec.encode_sensor(c));
  // Header and planned are the reference bytes; speedRef with 6 + 1 zero speeds follows.
  ASSERT_EQ(bytes.size(), 146u);
  std::string expected = kSensorExample;
  // Degrees computed from radians may differ in the last bits: compare those numerically.
  for (std::size_t at : {13, 22, 31, 40, 49, 58, 69}) {
    double ours, theirs;
    std::memcpy(&ours, bytes.data() + at, 8);
    std::memcpy(&theirs, expected.data() + at, 8);
    EXPECT_NEAR(ours, theirs, 1e-12) << "double at byte " << at;
    std::memset(bytes.data() + at, 0, 8);
    std::memset(expected.data() + at, 0, 8);
  }
  EXPECT_EQ(bytes.substr(0, 77), expected);
}

TEST(EgmCodec, RoundTripsBothDirections) {
  EgmCodec codec;
  EgmFeedback f;
  f.seqno = 77;
  f.tm = 308;
  f.joints = chain(10, -20, 30, -40, 50, -60, 70);
  f.motors_on = f.egm_running = f.rapid_running = true;
  const std::string robot(codec.encode_robot(f));
  EgmFeedback back;
  ASSERT_TRUE(codec.decode_robot(robot, back, nullptr));
  EXPECT_EQ(back.seqno, 77u);
  EXPECT_TRUE(back.joints.isApprox(f.joints, 1e-14));

  EgmCommand c;
  c.seqno = 9;
  c.joints = f.joints;
  c.velocity = chain(1, 2, 3, 4, 5, 6, 7);
  const std::string sensor(codec.encode_sensor(c));
  EgmCommand cb;
  ASSERT_TRUE(codec.decode_sensor(sensor, cb, nullptr));
  EXPECT_EQ(cb.seqno, 9u);
  EXPECT_TRUE(cb.joints.isApprox(c.joints, 1e-14));
  EXPECT_TRUE(cb.velocity.isApprox(c.velocity, 1e-14));
}

TEST(EgmCodec, ReportsWhyTheArmWillNotFollow) {
  EgmCodec codec;
  EgmFeedback f;
  f.motors_on = false, f.egm_running = true, f.rapid_running = true;
  EgmFeedback back;
  ASSERT_TRUE(codec.decode_robot(std::string(codec.encode_robot(f)), back, nullptr));
  EXPECT_EQ(back.fault(), "motors off");
  f.motors_on = true, f.egm_running = false;
  ASSERT_TRUE(codec.decode_robot(std::string(codec.encode_robot(f)), back, nullptr));
  EXPECT_EQ(back.fault(), "EGM not running");
}

TEST(EgmCodec, NeverEncodesNonFiniteValues) {
  EgmCodec codec;
  EgmCommand c;
  c.joints[3] = NAN;
  EXPECT_TRUE(codec.encode_sensor(c).empty());
  c.joints[3] = 0;
  c.velocity[0] = INFINITY;
  EXPECT_TRUE(codec.encode_sensor(c).empty());
}

TEST(EgmCodec, RefusesMalformedDatagramsWithAReason) {
  EgmCodec codec;
  EgmFeedback f;
  std::string_view why;
  // Our own reply is a valid message of the wrong type.
  EXPECT_FALSE(codec.decode_robot(kSensorExample, f, &why));
  EXPECT_EQ(why, "not a DATA message");
  EXPECT_FALSE(codec.decode_robot(std::string(2000, '\0'), f, &why));
  EXPECT_EQ(why, "oversized");
  EXPECT_FALSE(codec.decode_robot("\xff\xff\xff", f, &why));
  EXPECT_EQ(why, "not an EgmRobot message");
  EXPECT_FALSE(codec.decode_robot("", f, &why));  // empty: parses, but has no header
  // A NaN joint: byte 15..22 hold joints[0].
  std::string nan = kRobotExample;
  const double q = NAN;
  std::memcpy(nan.data() + 14, &q, 8);
  EXPECT_FALSE(codec.decode_robot(nan, f, &why));
  EXPECT_EQ(why, "joint value not finite");
}

// A cut at a field boundary is a valid, shorter message (protobuf cannot tell); the joints it
// yields are then the right ones and the missing robot states show as a fault.
TEST(EgmCodec, TruncatedMessagesAreRefusedOrLoseOnlyTrailingFields) {
  EgmCodec codec;
  EgmFeedback full;
  ASSERT_TRUE(codec.decode_robot(kRobotExample, full, nullptr));
  int refused = 0;
  for (std::size_t n = 0; n < kRobotExample.size(); ++n) {
    EgmFeedback f;
    if (!codec.decode_robot(kRobotExample.substr(0, n), f, nullptr)) {
      ++refused;
      continue;
    }
    EXPECT_EQ(f.joints, full.joints) << n << " bytes";
    EXPECT_FALSE(f.fault().empty()) << n << " bytes";
  }
  EXPECT_GE(refused, static_cast<int>(kRobotExample.size()) - 3);
}

// Fuzz: mutated valid messages and random bytes. Nothing may crash, and whatever is accepted
// must carry 7 finite, plausible joint values (the only thing the link takes from it).
TEST(EgmCodec, RandomizedDatagramsNeverYieldBadJoints) {
  std::mt19937 rng(7);
  EgmCodec codec;
  std::uniform_int_distribution<int> byte(0, 255);
  int accepted = 0;
  constexpr int trials = 300000;
  for (int trial = 0; trial < trials; ++trial) {
    std::string d;
    switch (trial % 4) {
      case 0:  // random bytes
        d.resize(rng() % 200);
        for (auto& c : d) c = static_cast<char>(byte(rng));
        break;
      case 1:  // bit flips
        d = kRobotExample;
        for (int k = 1 + static_cast<int>(rng() % 4); k > 0; --k)
          d[rng() % d.size()] ^= static_cast<char>(1 << (rng() % 8));
        break;
      case 2:  // byte overwrites and truncation
        d = kRobotExample;
        for (int k = 1 + static_cast<int>(rng() % 3); k > 0; --k)
          d[rng() % d.size()] = static_cast<char>(byte(rng));
        d.resize(rng() % (d.size() + 1));
        break;
      default:  // splices: a chunk of the message repeated or inserted
        d = kRobotExample;
        const std::size_t from = rng() % d.size(), len = rng() % 40;
        d.insert(rng() % d.size(), d.substr(from, len));
        break;
    }
    EgmFeedback f;
    f.joints.setConstant(NAN);
    std::string_view why;
    if (codec.decode_robot(d, f, &why)) {
      ++accepted;
      ASSERT_TRUE(f.joints.allFinite()) << "trial " << trial;
      ASSERT_LE(f.joints.cwiseAbs().maxCoeff(), 2 * std::numbers::pi) << "trial " << trial;
    } else {
      ASSERT_FALSE(why.empty());
    }
  }
  // Bit flips inside a double's mantissa still decode: the fuzzer does reach the accept path.
  EXPECT_GT(accepted, 1000);
}

}  // namespace
}  // namespace shapectl
