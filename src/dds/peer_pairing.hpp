// Which writers a node takes its inputs from: the peer it paired with. Anyone on a DDS domain may
// publish on /drone/motor_commands or /drone/Pose; without pairing, one stranger's sample (a stale
// controller left over from a killed run, a mistyped launch, a hostile participant) would be taken as
// the peer's. A plant pairs with its controller's writers, a controller with its plant's, either by
// a token both were given (quadcosim's own `run --transport dds`: a fresh random token per run, put in
// every endpoint's USER_DATA as quadcosim_pair=<token>) or by the participant found to host the peer
// (a foreign ROS 2 node, found by discovery). Samples of any other writer are foreign: counted and
// ignored by the node. Pairing keeps strays out; it is not authentication (discovery data is public,
// so a determined participant can copy a token): DDS Security keeps hostile participants out
// (docs/security.md).
#pragma once

#include <array>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dds/dds_transport.hpp"

namespace quadcosim::dds {

/// The environment variable through which `run --transport dds` hands its plant and controller
/// their run's pairing token.
inline constexpr const char* kPairTokenEnv = "QUADCOSIM_PAIR_TOKEN";

/// A fresh token: 16 hex digits from std::random_device.
std::string new_pair_token();

/// The token in $QUADCOSIM_PAIR_TOKEN, "" when unset. Throws std::invalid_argument when it is not 1
/// to 64 characters of [0-9A-Za-z_-] (it goes into USER_DATA's "key=value;" list).
std::string pair_token_from_environment();

/// The decision, per sender, whether a sample comes from the paired peer. Open (every sender is
/// the peer) until paired. Looked up once per writer through discovery (DdsTransport::sender_info),
/// then remembered. Thread-safe: deliveries may come on Cyclone's threads.
class PeerFilter {
 public:
  explicit PeerFilter(const DdsTransport& transport) : transport_(&transport) {}

  /// Writers whose USER_DATA carries quadcosim_pair=`token`.
  void pair_by_token(std::string token);
  /// Writers of the participant with this GUID.
  void pair_by_participant(const std::array<std::uint8_t, 16>& participant);
  bool paired() const;
  /// What the peer is, for messages: "token 1a2b..." or "participant 0110...".
  std::string describe() const;

  /// True when a sample on `ros_topic` from `sender` is the peer's (always, while unpaired). A sender
  /// discovery cannot describe (gone already) is not the peer's.
  bool accepts(const std::string& ros_topic, sim::SenderId sender);

 private:
  const DdsTransport* transport_;
  mutable std::mutex mutex_;
  std::string token_;
  std::optional<std::array<std::uint8_t, 16>> participant_;
  std::vector<std::pair<sim::SenderId, bool>> known_;  ///< decisions so far (a handful of writers)
};

}  // namespace quadcosim::dds
