// libFuzzer target: raw CDR bytes from the network into the plant and the controller.
//
// Input: records, each [kind: 1 byte][length: 2 bytes, little-endian][length bytes of serialized
// sample: 4-byte encapsulation header + CDR]; a short last record takes what is left. kind % 4 picks
// the topic: 0 motor_commands (std_msgs/Float64MultiArray), 1 Pose, 2 Velocity, 3 Imu.
//
// Each record goes the way a sample from another participant goes: Cyclone DDS turns the bytes into
// the idlc-generated C type through the topic's sertype (ddsi_serdata_from_ser_iov, which checks the
// CDR and refuses what does not fit the type, then ddsi_serdata_to_sample), our DDS type adapter
// (dds::type_ops) turns that into the message struct, and the message is published on an in-process
// bus where a PlantNode and a ControllerNode run closed loop, so the injected message competes with
// the real traffic. After every record the loop advances one plant tick (the controller every
// second). Checked after every tick: the plant state is finite, and every motor command the
// controller sends is four finite speeds.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "dds/participant.hpp"
#include "dds/ros_types.hpp"
#include "sim/controller_node.hpp"
#include "sim/inprocess_transport.hpp"
#include "sim/plant_node.hpp"

namespace {

using namespace quadcosim;

// One incoming type: a topic on a participant without discovery, and the sertype Cyclone uses to
// read samples of it.
struct IncomingType {
  const dds::TypeOps* ops = nullptr;
  const ddsi_sertype* sertype = nullptr;
  ddsi_serdata* keep = nullptr;  // holds a reference on the sertype for the life of the process
};

template <class T>
IncomingType incoming(const dds::Participant& p, const char* topic_name) {
  IncomingType t;
  t.ops = dds::type_ops(typeid(T));
  const dds_entity_t topic =
      dds::check(dds_create_topic(p.handle(), t.ops->descriptor, topic_name, nullptr, nullptr), "dds_create_topic");
  dds_qos_t* qos = dds::ros_qos(10, true);
  const dds_entity_t reader = dds::check(dds_create_reader(p.handle(), topic, qos, nullptr), "dds_create_reader");
  const dds_entity_t writer = dds::check(dds_create_writer(p.handle(), topic, qos, nullptr), "dds_create_writer");
  dds_delete_qos(qos);
  // One sample written and taken as serialized data gives the sertype (the public way in 0.10).
  const T sample{};
  dds::check(t.ops->write(writer, &sample), "dds_write");
  dds_sample_info_t info;
  if (dds_takecdr(reader, &t.keep, 1, &info, DDS_ANY_STATE) != 1) {
    std::fprintf(stderr, "fuzz_messages: no local sample on %s\n", topic_name);
    std::abort();
  }
  t.sertype = t.keep->type;
  return t;
}

struct Setup {
  std::unique_ptr<dds::Participant> participant;
  IncomingType types[4];

  Setup() {
    dds::RosEnvironment env;
    env.range = dds::DiscoveryRange::kOff;  // nothing leaves the process
    if (const char* id = std::getenv("ROS_DOMAIN_ID")) env.domain_id = static_cast<std::uint32_t>(std::atoi(id));
    participant = std::make_unique<dds::Participant>(env);
    types[0] = incoming<msg::Float64MultiArray>(*participant, "rt/fuzz/motor_commands");
    types[1] = incoming<msg::PoseStamped>(*participant, "rt/fuzz/Pose");
    types[2] = incoming<msg::TwistStamped>(*participant, "rt/fuzz/Velocity");
    types[3] = incoming<msg::Imu>(*participant, "rt/fuzz/Imu");
  }
};

const Setup& setup() {
  static const Setup s;  // process-wide, created on the first input
  return s;
}

// Decodes `bytes` as Cyclone would and hands the message (as a pointer to the C++ struct) to `to`;
// false when Cyclone refuses the bytes.
bool decode(const IncomingType& t, const std::uint8_t* bytes, std::size_t size,
            const std::function<void(const void*)>& to) {
  ddsrt_iovec_t iov;
  iov.iov_base = const_cast<std::uint8_t*>(bytes);
  iov.iov_len = static_cast<ddsrt_iov_len_t>(size);
  ddsi_serdata* sd = ddsi_serdata_from_ser_iov(t.sertype, SDK_DATA, 1, &iov, size);
  if (!sd) return false;
  std::vector<std::max_align_t> storage(t.ops->descriptor->m_size / sizeof(std::max_align_t) + 1);
  void* sample = storage.data();
  ddsi_sertype_zero_sample(t.sertype, sample);
  const bool ok = ddsi_serdata_to_sample(sd, sample, nullptr, nullptr);
  if (ok) t.ops->deliver(sample, to);
  ddsi_sertype_free_sample(t.sertype, sample, DDS_FREE_CONTENTS);
  ddsi_serdata_unref(sd);
  return ok;
}

bool finite(const model::State& x) {
  return x.p_W.allFinite() && x.v_W.allFinite() && x.q_WB.coeffs().allFinite() && x.w_B.allFinite() &&
         x.omega_rad_s.allFinite();
}

[[noreturn]] void fail(const char* what, sim::Tick k) {
  std::fprintf(stderr, "fuzz_messages: %s at tick %lld\n", what, static_cast<long long>(k));
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Setup& s = setup();

  sim::InProcessTransport bus;
  const sim::Topics topics = sim::Topics::for_namespace("/drone");
  control::ControllerConfig config;
  config.setpoint.p_des_W.z() = 1.0;
  sim::ControllerNode controller(bus, topics, config);
  controller.set_log([](const std::string&) {});
  model::State x0;
  x0.p_W.z() = 1.0;
  x0.omega_rad_s.setConstant(4830.0);
  sim::PlantNode plant(bus, topics, config.params.vehicle, {}, x0);
  plant.set_log([](const std::string&) {});

  bool bad_command = false;
  auto inject_command = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);
  auto inject_pose = bus.advertise<msg::PoseStamped>(topics.pose);
  auto inject_velocity = bus.advertise<msg::TwistStamped>(topics.velocity);
  auto inject_imu = bus.advertise<msg::Imu>(topics.imu);

  const double period_s = 0.01;
  sim::Tick k = 0;
  std::size_t at = 0;
  while (at < size && k < 256) {
    const int kind = data[at] % 4;
    std::size_t len = 0;
    if (at + 3 <= size) len = data[at + 1] | (std::size_t{data[at + 2]} << 8);
    at = std::min(size, at + 3);
    len = std::min(len, size - at);
    const std::uint8_t* bytes = data + at;
    at += len;

    plant.publish_outputs(k);  // the real sensor data of tick k
    decode(s.types[kind], bytes, len, [&](const void* m) {
      switch (kind) {
        case 0: inject_command.publish(*static_cast<const msg::Float64MultiArray*>(m)); break;
        case 1: inject_pose.publish(*static_cast<const msg::PoseStamped*>(m)); break;
        case 2: inject_velocity.publish(*static_cast<const msg::TwistStamped*>(m)); break;
        case 3: inject_imu.publish(*static_cast<const msg::Imu*>(m)); break;
      }
    });
    if (k % 2 == 0) {
      const control::Command& c = controller.step(k * 10'000'000, 2 * period_s);
      for (int i = 0; i < 4; ++i) bad_command = bad_command || !std::isfinite(c.omega_rad_s[i]);
      if (bad_command) fail("the controller sent a non-finite rotor speed", k);
    }
    plant.latch_command(k);
    plant.integrate(k);
    if (!finite(plant.state())) fail("the plant state is not finite", k);
    ++k;
  }
  return 0;
}
