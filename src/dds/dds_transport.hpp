// Transport over Cyclone DDS speaking the ROS 2 wire format: topic "/drone/Pose" travels as DDS
// topic "rt/drone/Pose" with type "geometry_msgs::msg::dds_::PoseStamped_", XCDR1, and the ROS QoS
// set explicitly. Subscriptions are delivered by spin_once() on the caller's thread, or on arrival on
// Cyclone's receive thread while the caller waits in spin_once; either way a node never sees a
// callback while it is in the middle of a step.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "dds/participant.hpp"
#include "dds/ros_types.hpp"
#include "sim/transport.hpp"

namespace quadcosim::dds {

struct QosProfile {
  int depth = 10;         ///< KEEP_LAST depth
  bool reliable = true;   ///< RELIABLE (ROS default) or BEST_EFFORT (ROS sensor data)
  static QosProfile ros_default() { return {10, true}; }
  static QosProfile sensor_data() { return {5, false}; }
};

/// "/drone/Pose" -> "rt/drone/Pose".
std::string dds_topic_name(const std::string& ros_topic);

class DdsTransport final : public sim::Transport {
 public:
  explicit DdsTransport(const RosEnvironment& env);
  ~DdsTransport() override;

  /// QoS for endpoints created later on `ros_topic` (default: ROS default QoS).
  void set_qos(const std::string& ros_topic, QosProfile qos) { qos_[ros_topic] = qos; }

  /// Waits up to timeout_ns for data on any subscription, then delivers the samples of every
  /// subscription the wait found with data, reader by reader in subscription order (the waitset
  /// names them, so a wake costs what arrived, not the number of subscriptions). Returns how many
  /// messages were delivered. With delivery on arrival (below), waits for matching changes, extra
  /// work or the wake condition only, serves the extra work, and returns the messages delivered on
  /// arrival since the last call; it rethrows what a delivery on arrival threw.
  int spin_once(std::int64_t timeout_ns);

  /// Delivery on arrival (on) or by spin_once (off, the default). On arrival, each subscription's
  /// samples are taken and delivered on the Cyclone thread that received them (a DATA_AVAILABLE
  /// listener), so a node that reacts to data where it is delivered (a lockstep controller stepping
  /// on a complete sample) answers without waking another thread. A node still never sees a
  /// callback while its own thread is busy with it: the thread that turns delivery on arrival on
  /// holds the deliveries' (recursive) lock from then on, except while spin_once waits, so a
  /// delivery runs only while that thread waits in spin_once, and never beside another delivery.
  /// Call it, spin_once and the switch off from that one thread (another gets std::logic_error),
  /// never from inside a delivery. A delivery may publish (also to this transport's own readers).
  /// An exception a delivery throws is kept (later deliveries are dropped), wakes spin_once and is
  /// rethrown by it. Turning it off waits for a delivery in progress; do so (or let
  /// ArrivalDelivery do it) before anything a delivery uses is destroyed.
  void deliver_on_arrival(bool on);

  /// Runs `blocking()` on the owning thread with deliveries let through, as in spin_once's wait:
  /// for a blocking call that needs Cyclone's receive thread (e.g. waiting for a service reply on
  /// another reader), which a delivery waiting for the lock would otherwise hold up. `blocking`
  /// must not touch what deliveries touch. Without delivery on arrival it just runs `blocking`.
  template <class F>
  auto with_deliveries(F blocking) {
    if (!arrival_) return blocking();
    check_owner("with_deliveries");
    struct Relock {
      std::recursive_mutex& m;
      ~Relock() { m.lock(); }
    };
    mutex_.unlock();
    const Relock relock{mutex_};
    return blocking();
  }

  /// With delivery on arrival: `after()` runs after each delivery, on the delivering thread under
  /// the deliveries' lock, and spin_once is woken when it returns true. A node may react there (a
  /// lockstep plant runs its next ticks once the command it waits for is in) and wake its own
  /// thread only when that thread has work. Without one, deliveries on arrival do not wake
  /// spin_once. Empty to clear.
  void on_arrival(std::function<bool()> after) { after_arrival_ = std::move(after); }

  /// Spins until `done()` holds or timeout_ns passes; returns done(). `done` runs on the caller's
  /// thread between waits; with delivery on arrival also after each delivery (under the
  /// deliveries' lock), so a delivery that makes it hold ends the wait.
  bool spin_until(const std::function<bool()>& done, std::int64_t timeout_ns);

  /// Writers matched by our readers of `ros_topic` / readers matched by our writers of it.
  int matched_writers(const std::string& ros_topic) const;
  int matched_readers(const std::string& ros_topic) const;

  const Participant& participant() const { return participant_; }

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
  std::function<void(const void*)> make_sink(const std::string& topic, const sim::TopicType& type) override;
  void add_subscription(const std::string& topic, const sim::TopicType& type,
                        std::function<void(const void*)> deliver) override;

 private:
  struct Reader {
    DdsTransport* owner;
    std::size_t index;  ///< in readers_ (its waitset attachment argument)
    std::string topic;
    dds_entity_t reader;
    dds_entity_t condition;
    const TypeOps* ops;
    std::function<void(const void*)> deliver;
  };
  static void on_data_available(dds_entity_t reader, void* arg);
  /// Delivery on arrival for one reader: its listener set, its read condition off the waitset.
  void listen(Reader& r, bool on);
  /// A writer or reader on `ros_topic` with its QoS, attached to the waitset for matching changes.
  dds_entity_t create_endpoint(const std::string& ros_topic, const sim::TopicType& type, bool writer,
                               const TypeOps*& ops);
  /// Attaches `e` to the waitset with `arg`, keeping room in triggered_ for every attachment.
  void attach(dds_entity_t e, dds_attach_t arg);
  dds_entity_t topic_for(const std::string& ros_topic, const sim::TopicType& type, const TypeOps*& ops);
  QosProfile qos_for(const std::string& ros_topic) const;
  int drain(Reader& r);

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
  bool arrival_ = false;
  std::thread::id owner_;  ///< the thread that turned delivery on arrival on
  /// Throws std::logic_error naming `what` when delivery is on arrival and this is not owner_'s thread.
  void check_owner(const char* what) const;
  /// Deliveries on arrival take it; the thread that switched arrival on holds it but in spin_once's wait.
  std::recursive_mutex mutex_;
  int delivered_on_arrival_ = 0;    ///< since the last spin_once (under mutex_)
  std::exception_ptr failure_;      ///< the first exception of a delivery on arrival (under mutex_)
  std::function<bool()> after_arrival_;  ///< on_arrival's hook (under mutex_)
  const std::function<bool()>* until_ = nullptr;  ///< spin_until's condition while it runs (under mutex_)
  dds_entity_t wake_ = 0;            ///< guard condition on the waitset: a delivery on arrival wakes spin_once
  /// After a delivery on arrival (under mutex_): runs after_arrival_, then spin_until's condition;
  /// wakes spin_once on a failure or when either holds.
  void after_arrival();
};

/// Delivery on arrival for a scope, on the thread that creates it: on in the constructor, off
/// (waiting for a delivery in progress) in the destructor. Declare it after what the deliveries use.
class ArrivalDelivery {
 public:
  explicit ArrivalDelivery(DdsTransport& t) : t_(t) { t_.deliver_on_arrival(true); }
  ~ArrivalDelivery() { t_.deliver_on_arrival(false); }
  ArrivalDelivery(const ArrivalDelivery&) = delete;
  ArrivalDelivery& operator=(const ArrivalDelivery&) = delete;

 private:
  DdsTransport& t_;
};

}  // namespace quadcosim::dds
