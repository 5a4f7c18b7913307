#include "dds/peer_pairing.hpp"

#include <cstdlib>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

namespace quadcosim::dds {

std::string new_pair_token() {
  std::random_device rd;
  const std::uint64_t v = (static_cast<std::uint64_t>(rd()) << 32) ^ rd();
  return fmt::format("{:016x}", v);
}

std::string pair_token_from_environment() {
  const char* v = std::getenv(kPairTokenEnv);
  if (v == nullptr) return {};
  const std::string token(v);
  bool ok = !token.empty() && token.size() <= 64;
  for (char c : token) {
    ok = ok && ((c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_' || c == '-');
  }
  if (!ok) {
    throw std::invalid_argument(
        fmt::format("{}='{}': expected 1 to 64 characters of 0-9, A-Z, a-z, _ and -", kPairTokenEnv, token));
  }
  return token;
}

void PeerFilter::pair_by_token(std::string token) {
  const std::lock_guard lock(mutex_);
  token_ = std::move(token);
  participant_.reset();
  known_.clear();
}

void PeerFilter::pair_by_participant(const std::array<std::uint8_t, 16>& participant) {
  const std::lock_guard lock(mutex_);
  token_.clear();
  participant_ = participant;
  known_.clear();
}

bool PeerFilter::paired() const {
  const std::lock_guard lock(mutex_);
  return !token_.empty() || participant_.has_value();
}

std::string PeerFilter::describe() const {
  const std::lock_guard lock(mutex_);
  if (!token_.empty()) return "the writers with pairing token " + token_;
  if (!participant_) return "any writer";
  std::string hex;
  for (std::uint8_t b : *participant_) hex += fmt::format("{:02x}", b);
  return "the writers of participant " + hex;
}

bool PeerFilter::accepts(const std::string& ros_topic, sim::SenderId sender) {
  const std::lock_guard lock(mutex_);
  if (token_.empty() && !participant_) return true;
  for (const auto& [s, ok] : known_) {
    if (s == sender) return ok;
  }
  const std::optional<DdsTransport::SenderInfo> info = transport_->sender_info(ros_topic, sender);
  if (!info) return false;  // not remembered: it may be described once discovery has it
  const bool ok = !token_.empty() ? info->pair_token == token_ : info->participant == *participant_;
  if (known_.size() >= 256) known_.erase(known_.begin());  // a participant making writer after writer
  known_.emplace_back(sender, ok);
  return ok;
}

}  // namespace quadcosim::dds
