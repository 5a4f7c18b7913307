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
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>

#include "closed_loop.hpp"
#include "cyclone_bytes.hpp"
#include "dds/ros_types.hpp"

namespace {

using namespace quadcosim;

// The four incoming types, each with the topic Cyclone reads it on and our type adapter.
struct Setup {
  std::unique_ptr<dds::Participant> participant = fuzz::isolated_participant();
  const dds::TypeOps* ops[4] = {dds::type_ops(typeid(msg::Float64MultiArray)), dds::type_ops(typeid(msg::PoseStamped)),
                                dds::type_ops(typeid(msg::TwistStamped)), dds::type_ops(typeid(msg::Imu))};
  fuzz::LocalTopic topics[4] = {{*participant, ops[0]->descriptor, "rt/fuzz/motor_commands"},
                                {*participant, ops[1]->descriptor, "rt/fuzz/Pose"},
                                {*participant, ops[2]->descriptor, "rt/fuzz/Velocity"},
                                {*participant, ops[3]->descriptor, "rt/fuzz/Imu"}};
};

const Setup& setup() {
  static const Setup s;  // process-wide, made on the first input
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const Setup& s = setup();

  fuzz::ClosedLoop loop("fuzz_messages", 4830.0);  // rotors near hover speed
  sim::InProcessTransport& bus = loop.bus();
  const sim::Topics& topics = loop.topics();
  auto inject_command = bus.advertise<msg::Float64MultiArray>(topics.motor_commands);
  auto inject_pose = bus.advertise<msg::PoseStamped>(topics.pose);
  auto inject_velocity = bus.advertise<msg::TwistStamped>(topics.velocity);
  auto inject_imu = bus.advertise<msg::Imu>(topics.imu);

  sim::Tick k = 0;
  fuzz::for_each_record(data, size, 256, [&](int record_kind, const std::uint8_t* bytes, std::size_t len) {
    const int kind = record_kind % 4;
    loop.begin(k);  // the real sensor data of tick k, then the injected sample
    s.topics[kind].with_sample(bytes, len, [&](const void* c_sample) {
      s.ops[kind]->deliver(c_sample, [&](const void* m) {
        switch (kind) {
          case 0: inject_command.publish(*static_cast<const msg::Float64MultiArray*>(m)); break;
          case 1: inject_pose.publish(*static_cast<const msg::PoseStamped*>(m)); break;
          case 2: inject_velocity.publish(*static_cast<const msg::TwistStamped*>(m)); break;
          case 3: inject_imu.publish(*static_cast<const msg::Imu*>(m)); break;
        }
      });
    });
    loop.end(k);
    ++k;
  });
  return 0;
}
