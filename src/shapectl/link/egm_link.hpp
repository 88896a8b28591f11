#pragma once
// The real robot link: ABB EGM joint streaming to a YuMi, one UDP endpoint per arm. The
// controller sends an EgmRobot every sample; each one is answered with an EgmSensor carrying
// the governor's command for the controller tick the reply lands on (one governor step of
// `egm_period` per tick, MotionPacer). A reply leaves at once, or up to a latency allowance
// later when it could otherwise land on either side of a tick. Nothing is sent unasked:
// without feedback the robot gets nothing, and EGM's own \CommTimeout stops it. Datagrams
// that are not valid EgmRobot messages are counted and ignored.
#include <chrono>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include <shapectl/link/egm_codec.hpp>
#include <shapectl/link/feedback_filter.hpp>
#include <shapectl/link/make_robot_link.hpp>
#include <shapectl/link/supervised_link.hpp>
#include <shapectl/link/udp_socket.hpp>

namespace shapectl {

// The EGM channels of a YuMi-like robot: "left" (joints *_l) and "right" (*_r), each the θ
// indices of yumi_joint_{1,2,7,3,4,5,6}_<arm> (chain order). An arm without active joints
// has no channel. InputError when an active joint is not yumi_joint_<1..7>_<l|r> or an arm
// has only some of its 7 joints active.
std::vector<LinkChannel> egm_arm_channels(const RobotModel& robot);

// Time from a feedback datagram's arrival in our process to its reply leaving, microseconds.
struct LatencyStats {
  std::size_t samples = 0;
  double median_us = 0;
  double p99_us = 0;
  double max_us = 0;
};

class EgmLink : public SupervisedLink {
 public:
  EgmLink(const LinkConfig& config, const RobotModel& robot, PoseCheck check,
          std::shared_ptr<SessionLog> log);  // binds the ports
  ~EgmLink() override;

  LinkStatus status() const override;

  const std::vector<LinkChannel>& channels() const { return supervisor_.channels(); }
  int port(int channel) const { return sockets_[static_cast<std::size_t>(channel)].port(); }
  LatencyStats latency() const;  // over the last 65536 replies

 private:
  void run(std::stop_token stop) override;
  // A reply ready to leave at `due` (s, the link's clock).
  struct Reply {
    sockaddr_in to{};
    std::chrono::steady_clock::time_point arrived;  // its feedback's arrival
    Eigen::VectorXd measured;
    FeedbackStep step;
    std::string bytes;  // empty: the command was not finite
    ArmJoints joints = ArmJoints::Zero();
    std::uint32_t seqno = 0;
    double due = 0;
  };
  // Bursts (one reply per datagram) fit; more means the link thread stalled: drop the newest.
  static constexpr std::size_t max_pending_replies = 64;

  void handle_datagram(int channel, std::string_view datagram, const sockaddr_in& from,
                       std::chrono::steady_clock::time_point arrived);
  void send_due_replies();
  void send_reply(int channel, const Reply& reply);

  std::vector<UdpSocket> sockets_;          // one per channel
  EgmCodec codec_;                          // link thread only
  std::vector<char> buffer_;                // link thread only
  std::vector<std::deque<Reply>> pending_;  // per channel, link thread only

  // Guarded by mutex_:
  std::vector<std::uint32_t> next_seqno_;  // per channel, ours
  std::vector<FeedbackFilter> filters_;    // per channel
  std::uint64_t rejected_ = 0;
  int foreign_logged_ = 0;
  std::vector<float> latency_us_;  // ring buffer
  std::size_t latency_next_ = 0;
};

}  // namespace shapectl
