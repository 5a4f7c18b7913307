// Transport over Cyclone DDS speaking the ROS 2 wire format: topic "/drone/Pose" travels as DDS
// topic "rt/drone/Pose" with type "geometry_msgs::msg::dds_::PoseStamped_", XCDR1, and the ROS QoS
// set explicitly. A plain waitset transport: subscriptions are delivered by spin_once() on the
// caller's thread. Delivery on arrival, on Cyclone's receive thread, is dds::ArrivalExecutor's
// (dds/arrival_executor.hpp), which states its threading rule.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dds/participant.hpp"
#include "dds/ros_types.hpp"
#include "sim/topic_qos.hpp"
#include "sim/transport.hpp"

struct ddsi_serdata;

namespace quadcosim::dds {

/// The topics' QoS table (sim/topic_qos.hpp).
using QosProfile = sim::TopicQos;

/// The USER_DATA key of a pairing token (dds/peer_pairing.hpp).
inline constexpr const char* kPairTokenKey = "quadcosim_pair";

/// "/drone/Pose" -> "rt/drone/Pose".
std::string dds_topic_name(const std::string& ros_topic);

class DdsTransport final : public sim::Transport {
 public:
  explicit DdsTransport(const RosEnvironment& env);
  ~DdsTransport() override;

  /// QoS for endpoints created later on `ros_topic` without a QoS of their own (advertise and subscribe
  /// given none: sim::QosChoice; default: QosProfile::for_topic).
  void set_qos(const std::string& ros_topic, QosProfile qos) { qos_[ros_topic] = qos; }

  /// Waits up to timeout_ns for data on any subscription, then delivers the samples of every
  /// subscription the wait found with data, reader by reader in subscription order (the waitset
  /// names them, so a wake costs what arrived, not the number of subscriptions), on the caller's
  /// thread, then serves the extra work. Returns how many messages were delivered. While an
  /// ArrivalExecutor delivers this transport's samples, use its wait() instead (std::logic_error).
  int spin_once(std::int64_t timeout_ns);

  /// Spins until `done()` holds or timeout_ns passes; returns done(). `done` runs between waits.
  bool spin_until(const std::function<bool()>& done, std::int64_t timeout_ns);

  /// Writers matched by our readers of `ros_topic` / readers matched by our writers of it.
  int matched_writers(const std::string& ros_topic) const;
  int matched_readers(const std::string& ros_topic) const;

  /// Waits until every reliable reader matched by our writers of `ros_topic` has acknowledged what
  /// they wrote (dds_wait_for_acks), at most timeout_ns; true when they all have. A reader that has
  /// not discovered the writer yet acknowledges only after it has (and has the samples): what a
  /// writer's own matched count cannot tell.
  bool wait_for_acks(const std::string& ros_topic, std::int64_t timeout_ns);

  const Participant& participant() const { return participant_; }

  /// While held, what the writers of this transport write is packed into their next datagram
  /// instead of sent at once (Cyclone's write batching); release sends every writer's pack. Lockstep
  /// plants hold the outputs of the ticks between control ticks, so the controller gets a writer's
  /// samples of two ticks in one datagram (docs/performance.md). Off, every write is sent at once.
  /// Nothing is held while a reader of this transport's /clock is matched (a node on ROS time sees
  /// every topic in publication order).
  void hold_sends(bool on);

  /// What discovery says of `sender`, a writer matched by our reader of `ros_topic` (the SenderId of
  /// a delivery on that topic): nullopt when it is not (or no longer) matched.
  struct SenderInfo {
    std::array<std::uint8_t, 16> participant{};  ///< the GUID of its participant
    std::string pair_token;                      ///< its USER_DATA's quadcosim_pair value ("" when none)
  };
  std::optional<SenderInfo> sender_info(const std::string& ros_topic, sim::SenderId sender) const;
  /// The writers matched by our readers of `ros_topic`, as the SenderIds their samples come with.
  std::vector<sim::SenderId> matched_senders(const std::string& ros_topic) const;
  /// The participants (GUIDs) of the readers matched by our writers of `ros_topic`, one entry per reader.
  std::vector<std::array<std::uint8_t, 16>> matched_reader_participants(const std::string& ros_topic) const;

  /// Put in the USER_DATA of every endpoint made after this call ("key=value;" pairs, before the type
  /// hash ROS 2 puts there): e.g. the pairing token by which a plant and its controller know each
  /// other's writers (dds/peer_pairing.hpp).
  void set_user_data_keys(std::string keys) { user_data_keys_ = std::move(keys); }

  /// Delivers the samples of `reader` (made elsewhere on this participant, e.g. a service's reply
  /// reader; it must outlive the deliveries) as the C samples idlc generates, in turn with the
  /// subscriptions: by spin_once, or on arrival under an ArrivalExecutor. `label` names it in errors.
  void subscribe_raw(dds_entity_t reader, std::string label, std::function<void(const void*)> deliver);
  /// subscribe_raw, with each sample's writer (its publication handle on `reader`).
  void subscribe_raw_with_sender(dds_entity_t reader, std::string label,
                                 std::function<void(const void*, sim::SenderId)> deliver);

  /// Extra DDS work served by spin_once beside the subscriptions, e.g. ROS 2 services on this
  /// participant. Each entity in `wake_on` (a read condition, or a reader/writer whose status mask is
  /// set) joins the waitset, so it wakes spin_once; `serve` runs after every wait, after the
  /// subscriptions are delivered, on the caller's thread. `serve` must clear what woke it (take the
  /// samples, dds_take_status) or spin_once stops blocking. What it handles is not counted in
  /// spin_once's result. Returns an id for remove_extra_work.
  int add_extra_work(const std::vector<dds_entity_t>& wake_on, std::function<void()> serve);
  /// Detaches the entities and forgets `serve` (call before deleting the entities).
  void remove_extra_work(int id);

 protected:
  std::function<void(const void*)> make_sink(const std::string& topic, const sim::TopicType& type,
                                             const sim::QosChoice& qos) override;
  void add_subscription(const std::string& topic, const sim::TopicType& type, const sim::QosChoice& qos,
                        std::function<void(const void*)> deliver) override;
  /// The sender is the publication handle of the sample's writer (dds_sample_info_t).
  void add_subscription_with_sender(const std::string& topic, const sim::TopicType& type, const sim::QosChoice& qos,
                                    std::function<void(const void*, sim::SenderId)> deliver) override;
  /// The wire bytes are the serialised sample the reader holds (dds_takecdr: what the writer's
  /// serialiser made, not encoded again), with Cyclone's trailing pad taken off and its pad count
  /// cleared from the encapsulation options, so they are io::to_cdr's bytes (io_mcap_test checks
  /// the two serialisers agree); the message is decoded from the same bytes.
  void add_tap(const std::string& topic, const sim::TopicType& type, const sim::QosChoice& qos,
               std::function<void(const void*, sim::SenderId, sim::WireBytes)> deliver) override;

 private:
  friend class ArrivalExecutor;  // delivery on arrival (dds/arrival_executor.hpp): the calls below
  /// With `sink`, every subscription's samples (also of later subscriptions) are announced to
  /// sink(subscription index) on the Cyclone thread that received them (a DATA_AVAILABLE listener)
  /// and no longer delivered by spin_once; empty: back to spin_once (waits for a listener call in
  /// progress). A later subscription's sink is called at once for what came before its listener.
  void set_arrival_sink(std::function<void(std::size_t)> sink);
  /// A reader is matched by one of our /clock writers.
  bool clock_is_read() const;
  /// Delivers what subscription `index` holds on the calling thread; returns how many.
  int take(std::size_t index) { return drain(*readers_[index]); }
  /// Samples taken out of a subscription's reader, undelivered (their memory lent by Cyclone until
  /// deliver_held or drop_held gives it back).
  struct Held {
    static constexpr int kBatch = 16;
    std::size_t index = 0;
    int n = 0;
    void* samples[kBatch] = {nullptr};
    ddsi_serdata* serdata[kBatch] = {nullptr};  ///< a tap's samples (dds_takecdr) instead of samples
    dds_sample_info_t infos[kBatch];
  };
  /// Takes what subscription `index` holds into `into` (appended, in order) without delivering it:
  /// out of the reader, so its history depth cannot drop what waits.
  void hold(std::size_t index, std::vector<Held>& into);
  /// Delivers held samples on the calling thread (then gives their memory back, whatever a delivery
  /// throws); returns how many.
  int deliver_held(Held& held);
  void drop_held(Held& held);
  std::size_t subscription_count() const { return readers_.size(); }
  /// spin_once in two halves: the wait (its result kept for serve_wait), then the deliveries and
  /// the extra work.
  dds_return_t wait_waitset(std::int64_t timeout_ns);
  int serve_wait(dds_return_t rc);

  struct Reader {
    DdsTransport* owner;
    std::size_t index;  ///< in readers_ (its waitset attachment argument)
    std::string topic;
    dds_entity_t reader;
    dds_entity_t condition;
    const TypeOps* ops;  ///< nullptr: a raw reader (subscribe_raw), its C samples delivered as they are
    std::function<void(const void*)> deliver;
    sim::SenderId sender = 0;  ///< the writer of the sample being delivered (its publication handle)
    bool tap = false;          ///< taken serialised (dds_takecdr): delivered with its wire bytes
    sim::WireBytes wire;       ///< a tap's sample being delivered: its bytes (into wire_buffer)
    std::vector<std::uint8_t> wire_buffer;
  };
  void add_reader(dds_entity_t reader, std::string topic, const TypeOps* ops, std::function<void(const void*)> deliver,
                  bool tap = false);
  /// Takes up to Held::kBatch samples of `r` into `samples` (loaned) or, for a tap, `serdata`.
  dds_return_t take_batch(Reader& r, void** samples, ddsi_serdata** serdata, dds_sample_info_t* infos);
  /// Gives back what take_batch took.
  static void give_back(const Reader& r, void** samples, ddsi_serdata** serdata, int n);
  /// Delivers one serialised sample of a tap: its bytes, and the message decoded from them.
  void deliver_serialised(Reader& r, ddsi_serdata* sd);
  static void on_data_available(dds_entity_t reader, void* arg);
  /// Delivery on arrival for one reader: its listener set, its read condition off the waitset.
  void listen(Reader& r, bool on);
  /// A writer or reader on `ros_topic` with its QoS, attached to the waitset for matching changes.
  dds_entity_t create_endpoint(const std::string& ros_topic, const sim::TopicType& type, bool writer,
                               const TypeOps*& ops, const sim::QosChoice& qos);
  /// Attaches `e` to the waitset with `arg`, keeping room in triggered_ for every attachment.
  void attach(dds_entity_t e, dds_attach_t arg);
  dds_entity_t topic_for(const std::string& ros_topic, const sim::TopicType& type, const TypeOps*& ops);
  QosProfile qos_for(const std::string& ros_topic) const;
  int drain(Reader& r);
  /// Delivers n taken samples of `r` (the loan stays the caller's to return).
  int deliver_taken(Reader& r, void* const* samples, ddsi_serdata* const* serdata, const dds_sample_info_t* infos,
                    int n);

  Participant participant_;
  dds_entity_t waitset_ = 0;
  // Waitset attachment arguments: a reader's read condition has its index in readers_ (>= 0); a
  // writer or reader woken by matching changes has -1 - its index in matched_; extra work has kExtra.
  static constexpr dds_attach_t kExtra = std::numeric_limits<dds_attach_t>::min();
  struct Matched {
    dds_entity_t entity;
    std::uint32_t status;  ///< DDS_PUBLICATION_MATCHED_STATUS or DDS_SUBSCRIPTION_MATCHED_STATUS
  };
  std::vector<Matched> matched_;
  std::vector<dds_attach_t> triggered_;  ///< what one wait found, one slot per attachment
  std::vector<std::size_t> ready_;       ///< readers with data, in subscription order
  std::map<std::string, dds_entity_t> topics_;
  std::vector<std::unique_ptr<Reader>> readers_;
  std::map<std::string, std::vector<dds_entity_t>> writers_;
  std::map<std::string, QosProfile> qos_;
  struct ExtraWork {
    std::vector<dds_entity_t> wake_on;
    std::function<void()> serve;
  };
  std::map<int, ExtraWork> extra_;
  std::vector<std::function<void()>> serving_;  ///< spin_once's copy of the extra work's callbacks
  int next_extra_id_ = 1;
  std::function<void(std::size_t)> arrival_sink_;  ///< set_arrival_sink's (empty: delivery by spin_once)
  std::string user_data_keys_;
  bool holding_ = false;
  std::vector<dds_entity_t> held_writers_;  ///< written while holding, in first-write order
};

}  // namespace quadcosim::dds
