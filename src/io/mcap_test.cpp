// MCAP writer and ROS 2 CDR tests. The CDR bytes are checked against Cyclone DDS's own serialiser
// (an independent implementation, the one rmw_cyclonedds uses); the MCAP files against the MCAP
// reference reader in mcap_interop_test.sh. Here: the writer's structure, errors and crash safety.
#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "dds/dds_test_support.hpp"
#include "dds/entity.hpp"
#include "dds/participant.hpp"
#include "dds/ros_types.hpp"
#include "io/mcap_test_messages.hpp"
#include "io/mcap_writer.hpp"
#include "io/ros2_cdr.hpp"

namespace quadcosim::io {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// CDR against Cyclone DDS

// Writes `m` through a Cyclone DDS writer (the generated C type, via the transport's conversion) and
// returns the serialized sample a reader of the same participant takes with dds_takecdr: Cyclone's
// own CDR, with its 4-byte encapsulation header.
template <class T>
std::vector<std::uint8_t> cyclone_cdr(const dds::Participant& p, const T& m) {
  static int topic_count = 0;  // test-local: unique topic per sample
  const dds::TypeOps* ops = dds::type_ops(typeid(T));
  EXPECT_NE(ops, nullptr);
  const std::string name = "rt/mcap_test/cdr" + std::to_string(++topic_count);
  // Owned (dds/entity.hpp): deleted on every way out, a failed check's exception included.
  const dds::Entity topic(
      dds::check(dds_create_topic(p.handle(), ops->descriptor, name.c_str(), nullptr, nullptr), "dds_create_topic"));
  const dds::Qos qos(dds::ros_qos(10, true));
  const dds::Entity reader(dds::check(dds_create_reader(p.handle(), topic, qos.get(), nullptr), "dds_create_reader"));
  const dds::Entity writer(dds::check(dds_create_writer(p.handle(), topic, qos.get(), nullptr), "dds_create_writer"));
  dds::check(ops->write(writer, &m), "dds_write");

  const dds::Entity ws(dds::check(dds_create_waitset(p.handle()), "dds_create_waitset"));
  const dds_entity_t cond = dds::check(dds_create_readcondition(reader, DDS_ANY_STATE), "dds_create_readcondition");
  dds::check(dds_waitset_attach(ws, cond, 0), "dds_waitset_attach");
  EXPECT_GT(dds_waitset_wait(ws, nullptr, 0, DDS_SECS(5)), 0) << "no sample arrived on " << name;

  std::vector<std::uint8_t> bytes;
  ddsi_serdata* sd = nullptr;
  dds_sample_info_t info;
  if (dds_takecdr(reader, &sd, 1, &info, DDS_ANY_STATE) == 1) {
    bytes.resize(ddsi_serdata_size(sd));
    ddsi_serdata_to_ser(sd, 0, bytes.size(), bytes.data());
    ddsi_serdata_unref(sd);
  }
  return bytes;
}

std::string hex(const std::vector<std::uint8_t>& b) {
  std::string s;
  char buf[4];
  for (std::size_t i = 0; i < b.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%02x", b[i]);
    s += buf;
    s += (i % 16 == 15) ? "\n" : " ";
  }
  return s;
}

// Compares ours with Cyclone's. Cyclone (0.10.2 here) pads the serialized sample to a multiple of 4
// bytes with zeros and puts the pad count in the low two bits of the encapsulation options (XTypes
// 1.3, 7.4.3.5.3): e.g. a PlantStatus whose last_problem string leaves it 2 bytes short comes out
// as 00 01 00 02 + payload + 00 00. to_cdr keeps the options 00 00 and adds no
// padding (what the brief asks for; CDR readers ignore trailing bytes either way, and the options
// carry no meaning for XCDR1 decoding). So: the representation identifier 00 01 (CDR_LE) must match;
// Cyclone's options must be 00 0p with p exactly the padding a 4-byte multiple needs; the payloads
// must match byte for byte; the p pad bytes must be zero.
void expect_same_cdr(const std::vector<std::uint8_t>& ours, const std::vector<std::uint8_t>& cyclone,
                     const std::string& what) {
  ASSERT_GE(cyclone.size(), 4u) << what;
  ASSERT_GE(ours.size(), 4u) << what;
  EXPECT_EQ(ours[0], 0x00) << what;
  EXPECT_EQ(ours[1], 0x01) << what;
  EXPECT_EQ(ours[2], 0x00) << what;
  EXPECT_EQ(ours[3], 0x00) << what;
  EXPECT_EQ(cyclone[0], 0x00) << what;
  EXPECT_EQ(cyclone[1], 0x01) << what << ": Cyclone did not use CDR_LE";
  EXPECT_EQ(cyclone[2], 0x00) << what;
  const std::size_t pad = cyclone[3] & 0x3;
  EXPECT_EQ(cyclone[3] & ~0x3, 0) << what;
  EXPECT_EQ(pad, (4 - ours.size() % 4) % 4) << what << ": Cyclone's pad count";
  ASSERT_EQ(ours.size() + pad, cyclone.size()) << what << "\nours:\n" << hex(ours) << "\ncyclone:\n" << hex(cyclone);
  EXPECT_TRUE(std::equal(ours.begin() + 4, ours.end(), cyclone.begin() + 4)) << what << "\nours:\n"
                                                                             << hex(ours) << "\ncyclone:\n"
                                                                             << hex(cyclone);
  for (std::size_t i = ours.size(); i < cyclone.size(); ++i) EXPECT_EQ(cyclone[i], 0) << what << " pad byte " << i;
}

class CdrTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { participant_ = new dds::Participant(dds::test::private_env()); }
  static void TearDownTestSuite() {
    delete participant_;
    participant_ = nullptr;
  }
  template <class T>
  void check(const T& m, const std::string& what) {
    expect_same_cdr(to_cdr(m), cyclone_cdr(*participant_, m), std::string(T::kRosType) + " " + what);
  }
  static dds::Participant* participant_;
};
dds::Participant* CdrTest::participant_ = nullptr;

// Frame ids of every length mod 8 move the doubles after the string through each alignment case.
const std::vector<std::string> kFrames = {"", "a", "ab", "abc", "abcd", "world", "odom_xy", "base_lnk", "base_link"};

TEST_F(CdrTest, PoseStampedMatchesCyclone) {
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::PoseStamped m = testing::sample_pose(static_cast<int>(k) * 37 + 1);
    m.header.frame_id = kFrames[k];
    check(m, "frame '" + kFrames[k] + "'");
  }
  msg::PoseStamped odd;
  odd.header.stamp = {-3, 999'999'999};
  odd.position = {-0.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()};
  odd.orientation = {std::numeric_limits<double>::denorm_min(), 1e-300, -1e300, 1.0};
  check(odd, "special values");
}

TEST_F(CdrTest, TwistStampedMatchesCyclone) {
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::TwistStamped m = testing::sample_twist(static_cast<int>(k) + 5);
    m.header.frame_id = kFrames[k];
    check(m, "frame '" + kFrames[k] + "'");
  }
}

TEST_F(CdrTest, ImuMatchesCyclone) {
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::Imu m = testing::sample_imu(static_cast<int>(k) + 11);
    m.header.frame_id = kFrames[k];
    for (std::size_t j = 0; j < 9; ++j) m.linear_acceleration_covariance[j] = 0.5 * static_cast<double>(j + k);
    check(m, "frame '" + kFrames[k] + "'");
  }
}

TEST_F(CdrTest, Float64MultiArrayMatchesCyclone) {
  check(msg::Float64MultiArray{}, "empty");
  check(testing::sample_command(123), "command");
  msg::Float64MultiArray m;
  m.data = {1.0 / 3.0, -0.0, 1e9};
  m.dim = {{"x", 3, 3}, {"", 1, 1}, {"rotor_group_label", 7, 2}};
  m.data_offset = 5;
  check(m, "three dims");
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::Float64MultiArray one;
    one.dim = {{kFrames[k], static_cast<std::uint32_t>(k), 1}};
    one.data.assign(k, 0.25 * static_cast<double>(k));
    check(one, "label '" + kFrames[k] + "'");
  }
}

TEST_F(CdrTest, ClockMatchesCyclone) {
  check(testing::sample_clock(0), "zero");
  check(testing::sample_clock(123456), "t");
  check(msg::Clock{{-1, 5}}, "negative");
}

TEST_F(CdrTest, ControllerStatusMatchesCyclone) {
  const std::vector<std::string> modes = {"", "attitude", "position", "pos"};
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::ControllerStatus m = testing::sample_status(static_cast<int>(k) * 13);
    m.header.frame_id = kFrames[k];
    m.mode = modes[k % modes.size()];
    check(m, "frame '" + kFrames[k] + "' mode '" + m.mode + "'");
  }
}

TEST_F(CdrTest, PlantStatusMatchesCyclone) {
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::PlantStatus m = testing::sample_plant_status(static_cast<int>(k) * 11 + 1);
    m.header.frame_id = kFrames[k];
    check(m, "frame '" + kFrames[k] + "' problem '" + m.last_problem + "'");
    m.last_problem = kFrames[k];  // strings of every length mod 4: Cyclone's trailing pad
    check(m, "problem '" + m.last_problem + "'");
  }
}

TEST_F(CdrTest, TFMessageMatchesCyclone) {
  check(msg::TFMessage{}, "empty");
  msg::TFMessage m;
  for (std::size_t k = 0; k < kFrames.size(); ++k) {  // parent and child of every length mod 8
    msg::TransformStamped t;
    t.header = {{static_cast<std::int32_t>(k), static_cast<std::uint32_t>(k * 1000)}, kFrames[k]};
    t.child_frame_id = kFrames[kFrames.size() - 1 - k] + "/base_link";
    t.translation = {1.0 / 3.0 + static_cast<double>(k), -2.5, 1e-7};
    t.rotation = {0.1, -0.2, 0.3, std::sqrt(1.0 - 0.14)};
    m.transforms.push_back(t);
    check(m, std::to_string(k + 1) + " transforms");
  }
}

TEST_F(CdrTest, StringMatchesCyclone) {
  for (const std::string& s : kFrames) check(msg::String{s}, "'" + s + "'");
  check(msg::String{std::string(5000, 'u') + "<robot/>\n"}, "long");
}

// The sensor types with magnitudes a plant puts in them (Earth's field in tesla, sea-level pressure,
// a fix in degrees), stamps and frames of every length mod 8.
TEST_F(CdrTest, MagneticFieldMatchesCyclone) {
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::MagneticField m;
    m.header = {{static_cast<std::int32_t>(k), static_cast<std::uint32_t>(k * 999)}, kFrames[k]};
    m.magnetic_field = {2.1e-5, -1.3e-6 * static_cast<double>(k), 4.4e-5};
    for (std::size_t j = 0; j < 9; j += 4) m.magnetic_field_covariance[j] = 1e-14 * static_cast<double>(j + k + 1);
    check(m, "frame '" + kFrames[k] + "'");
  }
}

TEST_F(CdrTest, FluidPressureMatchesCyclone) {
  for (std::size_t k = 0; k < kFrames.size(); ++k) {
    msg::FluidPressure m;
    m.header = {{7, static_cast<std::uint32_t>(k)}, kFrames[k]};
    m.fluid_pressure = 101325.0 - 12.0 * static_cast<double>(k);
    m.variance = 0.25 * static_cast<double>(k);
    check(m, "frame '" + kFrames[k] + "'");
  }
}

TEST_F(CdrTest, NavSatFixMatchesCyclone) {
  const std::vector<std::int8_t> statuses = {msg::NavSatStatus::kStatusUnknown, msg::NavSatStatus::kStatusNoFix,
                                             msg::NavSatStatus::kStatusFix, msg::NavSatStatus::kStatusGbasFix};
  for (std::size_t k = 0; k < kFrames.size(); ++k) {  // int8 and uint16 after strings of each length mod 8
    msg::NavSatFix m;
    m.header = {{1700000000, static_cast<std::uint32_t>(k * 12345)}, kFrames[k]};
    m.status.status = statuses[k % statuses.size()];
    m.status.service = static_cast<std::uint16_t>(msg::NavSatStatus::kServiceGps | (k << 1));
    m.latitude = 47.3977419 + 1e-7 * static_cast<double>(k);
    m.longitude = 8.5455938;
    m.altitude = k == 3 ? std::numeric_limits<double>::quiet_NaN() : 488.1;
    for (std::size_t j = 0; j < 9; j += 4) m.position_covariance[j] = j == 8 ? 2.25 : 0.5625;
    m.position_covariance_type = static_cast<std::uint8_t>(k % 4);
    check(m, "frame '" + kFrames[k] + "'");
  }
}

TEST(CdrLayoutTest, ClockIsTheHeaderAndTwoIntegers) {
  const std::vector<std::uint8_t> want = {0x00, 0x01, 0x00, 0x00, 0x02, 0, 0, 0, 0x03, 0, 0, 0};
  EXPECT_EQ(to_cdr(msg::Clock{{2, 3}}), want);
}

TEST(CdrLayoutTest, StringsCountTheirNulAndDoublesAlignAfterTheHeader) {
  msg::PoseStamped m;
  m.header.frame_id = "w";
  const auto b = to_cdr(m);
  // header 4 | sec 4 | nanosec 4 | len=2 4 | 'w' 0 | pad to 8 (2 + 4 bytes: offset 14 -> 16) | 7 doubles
  ASSERT_EQ(b.size(), 4u + 16u + 56u);
  EXPECT_EQ(b[12], 2);
  EXPECT_EQ(b[16], 'w');
  EXPECT_EQ(b[17], 0);
}

// Bytes laid out by hand (XCDR1 little endian, alignment counted after the 4-byte encapsulation
// header; doubles written as their IEEE 754 bit patterns).
class Bytes {
 public:
  Bytes& raw(std::initializer_list<std::uint8_t> b) {
    v_.insert(v_.end(), b);
    return *this;
  }
  Bytes& u32(std::uint32_t x) {
    return raw({std::uint8_t(x), std::uint8_t(x >> 8), std::uint8_t(x >> 16), std::uint8_t(x >> 24)});
  }
  Bytes& f64(std::uint64_t bits) {
    for (int i = 0; i < 8; ++i) v_.push_back(static_cast<std::uint8_t>(bits >> (8 * i)));
    return *this;
  }
  Bytes& zeros(std::size_t n) {
    v_.insert(v_.end(), n, 0);
    return *this;
  }
  const std::vector<std::uint8_t>& get() const { return v_; }

 private:
  std::vector<std::uint8_t> v_{0x00, 0x01, 0x00, 0x00};
};
constexpr std::uint64_t kOne = 0x3ff0000000000000;           // 1.0
constexpr std::uint64_t kHalf = 0x3fe0000000000000;          // 0.5
constexpr std::uint64_t kMinusQuarter = 0xbfd0000000000000;  // -0.25
constexpr std::uint64_t kTwo = 0x4000000000000000;           // 2.0
constexpr std::uint64_t kFour = 0x4010000000000000;          // 4.0

TEST(CdrLayoutTest, MagneticFieldIsHeaderVectorAndNineDoubles) {
  msg::MagneticField m;
  m.header = {{1, 2}, "xyz"};
  m.magnetic_field = {0.5, -0.25, 1.0};
  m.magnetic_field_covariance[0] = 2.0;
  m.magnetic_field_covariance[8] = 4.0;
  // sec 0..3 | nanosec 4..7 | length 4 at 8..11 | "xyz\0" 12..15 | the vector from 16 (aligned) | covariance
  Bytes want;
  want.u32(1)
      .u32(2)
      .u32(4)
      .raw({'x', 'y', 'z', 0})
      .f64(kHalf)
      .f64(kMinusQuarter)
      .f64(kOne)
      .f64(kTwo)
      .zeros(7 * 8)
      .f64(kFour);
  EXPECT_EQ(to_cdr(m), want.get());
  EXPECT_EQ(want.get().size(), 4u + 16u + 24u + 72u);
}

TEST(CdrLayoutTest, FluidPressureAlignsItsDoublesAfterTheFrame) {
  msg::FluidPressure m;
  m.header = {{3, 4}, "b"};
  m.fluid_pressure = 101325.0;
  m.variance = 4.0;
  // ... length 2 at 8..11 | 'b' 0 at 12..13 | 2 pad bytes | pressure at 16 | variance at 24
  Bytes want;
  want.u32(3).u32(4).u32(2).raw({'b', 0}).zeros(2).f64(0x40f8bcd000000000).f64(kFour);
  EXPECT_EQ(to_cdr(m), want.get());
}

TEST(CdrLayoutTest, NavSatFixPacksStatusServiceAndTheCovarianceType) {
  msg::NavSatFix m;
  m.header = {{5, 6}, "ab"};
  m.status.status = msg::NavSatStatus::kStatusNoFix;                                       // -1: 0xff
  m.status.service = msg::NavSatStatus::kServiceGps | msg::NavSatStatus::kServiceGalileo;  // 9
  m.latitude = 52.5;
  m.longitude = 13.25;
  m.altitude = 480.0;
  m.position_covariance[0] = 0.5;
  m.position_covariance[4] = 0.5;
  m.position_covariance[8] = 2.0;
  m.position_covariance_type = msg::NavSatFix::kCovarianceTypeDiagonalKnown;  // 2
  // length 3 at 8..11 | "ab\0" 12..14 | status (int8) at 15 | service (uint16) at 16..17 | 6 pad bytes |
  // latitude at 24, longitude 32, altitude 40 | covariance 48..119 | covariance type at 120, nothing after
  Bytes want;
  want.u32(5).u32(6).u32(3).raw({'a', 'b', 0, 0xff, 0x09, 0x00}).zeros(6);
  want.f64(0x404a400000000000).f64(0x402a800000000000).f64(0x407e000000000000);
  want.f64(kHalf).zeros(3 * 8).f64(kHalf).zeros(3 * 8).f64(kTwo).raw({0x02});
  EXPECT_EQ(to_cdr(m), want.get());
  EXPECT_EQ(want.get().size(), 4u + 121u);
}

// ---------------------------------------------------------------------------------------------
// ros2msg schema text

// The sensor types' schema texts, written out from the Jazzy .msg files (sensor_msgs/msg/*.msg of
// ros2/common_interfaces, branch jazzy): constants first, then the fields (defaults after them), then
// each dependency once.
TEST(Ros2MsgTest, SensorTypesAsTheirJazzyMsgFilesDeclareThem) {
  const std::string sep = std::string(80, '=') + "\n";
  const std::string header = sep + "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" + sep +
                             "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n";
  EXPECT_EQ(ros2msg_definition("sensor_msgs/msg/MagneticField"),
            "std_msgs/Header header\ngeometry_msgs/Vector3 magnetic_field\nfloat64[9] magnetic_field_covariance\n" +
                header + sep + "MSG: geometry_msgs/Vector3\nfloat64 x\nfloat64 y\nfloat64 z\n");
  EXPECT_EQ(ros2msg_definition("sensor_msgs/msg/FluidPressure"),
            "std_msgs/Header header\nfloat64 fluid_pressure\nfloat64 variance\n" + header);
  const std::string status =
      "int8 STATUS_UNKNOWN=-2\nint8 STATUS_NO_FIX=-1\nint8 STATUS_FIX=0\nint8 STATUS_SBAS_FIX=1\n"
      "int8 STATUS_GBAS_FIX=2\nuint16 SERVICE_UNKNOWN=0\nuint16 SERVICE_GPS=1\nuint16 SERVICE_GLONASS=2\n"
      "uint16 SERVICE_COMPASS=4\nuint16 SERVICE_GALILEO=8\nint8 status -2\nuint16 service\n";
  EXPECT_EQ(ros2msg_definition("sensor_msgs/msg/NavSatStatus"), status);
  EXPECT_EQ(ros2msg_definition("sensor_msgs/msg/NavSatFix"),
            "uint8 COVARIANCE_TYPE_UNKNOWN=0\nuint8 COVARIANCE_TYPE_APPROXIMATED=1\n"
            "uint8 COVARIANCE_TYPE_DIAGONAL_KNOWN=2\nuint8 COVARIANCE_TYPE_KNOWN=3\n"
            "std_msgs/Header header\nNavSatStatus status\nfloat64 latitude\nfloat64 longitude\nfloat64 altitude\n"
            "float64[9] position_covariance\nuint8 position_covariance_type\n" +
                header + sep + "MSG: sensor_msgs/NavSatStatus\n" + status);
}

TEST(Ros2MsgTest, PoseStampedHasItsFieldsThenEachDependencyOnce) {
  const std::string sep = std::string(80, '=') + "\n";
  const std::string want = "std_msgs/Header header\nPose pose\n" + sep +
                           "MSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n" + sep +
                           "MSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n" + sep +
                           "MSG: geometry_msgs/Pose\nPoint position\nQuaternion orientation\n" + sep +
                           "MSG: geometry_msgs/Point\nfloat64 x\nfloat64 y\nfloat64 z\n" + sep +
                           "MSG: geometry_msgs/Quaternion\nfloat64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";
  EXPECT_EQ(ros2msg_definition("geometry_msgs/msg/PoseStamped"), want);
}

std::vector<std::string> msg_blocks(const std::string& text) {
  std::vector<std::string> names;
  for (std::size_t at = text.find("MSG: "); at != std::string::npos; at = text.find("MSG: ", at + 1)) {
    names.push_back(text.substr(at + 5, text.find('\n', at) - at - 5));
  }
  return names;
}

TEST(Ros2MsgTest, EveryRecordedTypeListsItsDependencies) {
  using V = std::vector<std::string>;
  EXPECT_EQ(msg_blocks(ros2msg_definition(msg::TwistStamped::kRosType)),
            (V{"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Twist", "geometry_msgs/Vector3"}));
  EXPECT_EQ(msg_blocks(ros2msg_definition(msg::Imu::kRosType)),
            (V{"std_msgs/Header", "builtin_interfaces/Time", "geometry_msgs/Quaternion", "geometry_msgs/Vector3"}));
  EXPECT_EQ(msg_blocks(ros2msg_definition(msg::Float64MultiArray::kRosType)),
            (V{"std_msgs/MultiArrayLayout", "std_msgs/MultiArrayDimension"}));
  EXPECT_EQ(msg_blocks(ros2msg_definition(msg::Clock::kRosType)), (V{"builtin_interfaces/Time"}));
  const std::string& status = ros2msg_definition(msg::ControllerStatus::kRosType);
  EXPECT_EQ(msg_blocks(status), (V{"std_msgs/Header", "builtin_interfaces/Time"}));
  EXPECT_EQ(status.substr(0, status.find("====")),
            "std_msgs/Header header\nstring controller\nstring mode\nfloat64[6] setpoint\nfloat64[4] u\n"
            "float64[3] position_error\nfloat64 yaw_error\nfloat64 attitude_error\n"
            "bool[8] rotor_saturated\nbool tilt_saturated\nbool safety\nuint64 rejected_non_finite\n"
            "uint64 rejected_bad_quaternion\nuint64 rejected_bad_stamp\nuint64 rejected_stamp_backwards\n"
            "uint64 rejected_stamp_ahead\n"
            "string[] output_names\nfloat64[] outputs\n");
  const std::string& plant = ros2msg_definition(msg::PlantStatus::kRosType);
  EXPECT_EQ(msg_blocks(plant), (V{"std_msgs/Header", "builtin_interfaces/Time"}));
  EXPECT_EQ(plant.substr(0, plant.find("====")),
            "std_msgs/Header header\nuint64 commands_accepted\nuint64 commands_clamped\n"
            "uint64 commands_rejected_length\nuint64 commands_rejected_non_finite\nstring last_problem\n"
            "bool watchdog_active\nuint64 watchdog_trips\nuint64 watchdog_ticks\nuint64 commands_stale\n"
            "uint64 commands_foreign\nuint64 commands_rejected_second_topic\n"
            "uint64 commands_rejected_bad_quaternion\n");
  const std::string& tf = ros2msg_definition(msg::TFMessage::kRosType);
  EXPECT_EQ(msg_blocks(tf), (V{"geometry_msgs/TransformStamped", "std_msgs/Header", "builtin_interfaces/Time",
                               "geometry_msgs/Transform", "geometry_msgs/Vector3", "geometry_msgs/Quaternion"}));
  EXPECT_EQ(tf.substr(0, tf.find("====")), "geometry_msgs/TransformStamped[] transforms\n");
  EXPECT_NE(tf.find("MSG: geometry_msgs/TransformStamped\nstd_msgs/Header header\nstring child_frame_id\n"
                    "Transform transform\n"),
            std::string::npos);
  EXPECT_NE(tf.find("MSG: geometry_msgs/Transform\nVector3 translation\nQuaternion rotation\n"), std::string::npos);
  EXPECT_EQ(ros2msg_definition(msg::String::kRosType), "string data\n");
  // foxglove_msgs/SceneUpdate as Foxglove's ROS 2 .msg files state it (field lines, in order; a type
  // of the same package named without it, as .msg files may).
  const std::string& scene = ros2msg_definition(msg::SceneUpdate::kRosType);
  EXPECT_EQ(scene.substr(0, scene.find("====")),
            "SceneEntityDeletion[] deletions\nSceneEntity[] entities\n");  // same package: bare names
  const std::string sep = std::string(80, '=') + "\n";
  for (const std::string block :
       {"MSG: foxglove_msgs/SceneEntityDeletion\nbuiltin_interfaces/Time timestamp\nuint8 type\nstring id\n",
        "MSG: foxglove_msgs/SceneEntity\nbuiltin_interfaces/Time timestamp\nstring frame_id\nstring id\n"
        "builtin_interfaces/Duration lifetime\nbool frame_locked\nKeyValuePair[] metadata\n"
        "ArrowPrimitive[] arrows\nCubePrimitive[] cubes\nSpherePrimitive[] spheres\n"
        "CylinderPrimitive[] cylinders\nLinePrimitive[] lines\nTriangleListPrimitive[] triangles\n"
        "TextPrimitive[] texts\nModelPrimitive[] models\n",
        "MSG: builtin_interfaces/Duration\nint32 sec\nuint32 nanosec\n",
        "MSG: foxglove_msgs/CylinderPrimitive\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 size\n"
        "float64 bottom_scale\nfloat64 top_scale\nColor color\n",
        "MSG: foxglove_msgs/LinePrimitive\nuint8 type\ngeometry_msgs/Pose pose\nfloat64 thickness\n"
        "bool scale_invariant\ngeometry_msgs/Point[] points\nColor color\nColor[] colors\nuint32[] indices\n",
        "MSG: foxglove_msgs/ModelPrimitive\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nColor color\n"
        "bool override_color\nstring url\nstring media_type\nuint8[] data\n",
        "MSG: foxglove_msgs/Color\nfloat64 r\nfloat64 g\nfloat64 b\nfloat64 a\n"}) {
    EXPECT_NE(scene.find(sep + block), std::string::npos) << block;
  }
  EXPECT_EQ(msg_blocks(scene).size(), 18u) << scene;
  EXPECT_THROW(ros2msg_definition("geometry_msgs/msg/PoseWithCovariance"), std::invalid_argument);
  EXPECT_THROW(ros2msg_definition("geometry_msgs/PoseStamped"), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// McapWriter

class McapWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("quadcosim_mcap_test_" + std::to_string(getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::vector<std::uint8_t> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint64_t le64(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + i];
  return v;
}

// Top-level records after the leading magic, as (opcode, offset), up to the footer or the end of the
// complete records.
std::vector<std::pair<int, std::size_t>> top_level_records(const std::vector<std::uint8_t>& b) {
  std::vector<std::pair<int, std::size_t>> r;
  std::size_t at = 8;
  while (at + 9 <= b.size()) {
    const std::uint64_t len = le64(b, at + 1);
    if (at + 9 + len > b.size()) break;
    r.emplace_back(b[at], at);
    if (b[at] == 0x02) break;
    at += 9 + len;
  }
  return r;
}

std::vector<std::uint8_t> pose_bytes(int i) { return to_cdr(testing::sample_pose(i)); }

/// Adds the PoseStamped schema and the channel /drone/Pose (CDR) to `w`; the channel's id.
std::uint16_t add_pose_channel(McapWriter& w) {
  const std::uint16_t s =
      w.add_schema("geometry_msgs/msg/PoseStamped", "ros2msg", ros2msg_definition("geometry_msgs/msg/PoseStamped"));
  return w.add_channel("/drone/Pose", s, "cdr");
}

/// Writes pose_bytes(i) on `channel` as message i + 1, logged and published at tick i.
void write_pose(McapWriter& w, std::uint16_t channel, int i) {
  const auto b = pose_bytes(i);
  w.write(channel, static_cast<std::uint32_t>(i + 1), testing::tick_ns(i), testing::tick_ns(i), b.data(), b.size());
}

TEST_F(McapWriterTest, OpeningFailsWithThePathInTheMessage) {
  const std::string bad = path("no/such/dir/x.mcap");
  try {
    McapWriter w(bad);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
}

TEST_F(McapWriterTest, RejectsUnknownIdsAndEncodingsOutsideTheRos2Profile) {
  McapWriter w(path("bad.mcap"));
  EXPECT_THROW(w.add_schema("x/msg/Y", "jsonschema", "{}"), std::invalid_argument);
  const auto s =
      w.add_schema("geometry_msgs/msg/PoseStamped", "ros2msg", ros2msg_definition("geometry_msgs/msg/PoseStamped"));
  EXPECT_EQ(s, 1);
  EXPECT_EQ(
      w.add_schema("geometry_msgs/msg/PoseStamped", "ros2msg", ros2msg_definition("geometry_msgs/msg/PoseStamped")), s);
  EXPECT_THROW(w.add_channel("/p", 2, "cdr"), std::invalid_argument);
  EXPECT_THROW(w.add_channel("/p", s, "json"), std::invalid_argument);
  const auto c = w.add_channel("/p", s, "cdr");
  EXPECT_EQ(c, 1);
  EXPECT_EQ(w.add_channel("/p", s, "cdr"), c);
  const auto b = pose_bytes(1);
  EXPECT_THROW(w.write(2, 0, 0, 0, b.data(), b.size()), std::invalid_argument);
  EXPECT_THROW(w.write(0, 0, 0, 0, b.data(), b.size()), std::invalid_argument);
  w.write(c, 1, 5, 5, b.data(), b.size());
  EXPECT_EQ(w.messages(), 1u);
  w.close();
  w.close();  // no-op
  EXPECT_THROW(w.write(c, 2, 6, 6, b.data(), b.size()), std::logic_error);
}

TEST_F(McapWriterTest, ChunksReachTheFileAsSoonAsTheyFillAndFlushEndsTheOpenOne) {
  const std::string file = path("safety.mcap");
  McapWriter w(file, {"ros2", 4096, true});
  const auto c = add_pose_channel(w);
  const auto count_chunks = [&] {
    int n = 0;
    for (const auto& [op, at] : top_level_records(read_file(file))) n += op == 0x06;
    return n;
  };
  EXPECT_EQ(count_chunks(), 0);
  const std::uintmax_t before = fs::file_size(file);  // header, schema and channel are on disk
  EXPECT_GT(before, 8u + 9u);
  int i = 0;
  while (count_chunks() == 0) {
    ASSERT_LT(i, 1000) << "no chunk written after 1000 messages of a 4 KiB chunk";
    write_pose(w, c, i);
    ++i;
  }
  EXPECT_GE(static_cast<std::size_t>(i) * (pose_bytes(0).size() + 31), 4096u);  // only once full
  const std::uintmax_t after_chunk = fs::file_size(file);
  write_pose(w, c, i);
  EXPECT_EQ(fs::file_size(file), after_chunk) << "a single message went to disk before its chunk filled";
  w.flush();
  EXPECT_EQ(count_chunks(), 2);
  // Each chunk is followed at once by its message index.
  const auto records = top_level_records(read_file(file));
  for (std::size_t k = 0; k + 1 < records.size(); ++k) {
    if (records[k].first == 0x06) {
      EXPECT_EQ(records[k + 1].first, 0x07);
    }
  }
}

TEST_F(McapWriterTest, ClosedFileHasDataEndSummaryOffsetsFooterAndMagic) {
  const std::string file = path("layout.mcap");
  {
    McapWriter w(file, {"ros2", 2048, false});
    const auto c = add_pose_channel(w);
    for (int i = 0; i < 50; ++i) {
      write_pose(w, c, i);
    }
    // no close(): the destructor finishes the file
  }
  const auto b = read_file(file);
  const std::vector<std::uint8_t> magic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
  ASSERT_GT(b.size(), 16u);
  EXPECT_TRUE(std::equal(magic.begin(), magic.end(), b.begin()));
  EXPECT_TRUE(std::equal(magic.begin(), magic.end(), b.end() - 8));
  std::vector<int> ops;
  for (const auto& [op, at] : top_level_records(b)) ops.push_back(op);
  ASSERT_GE(ops.size(), 6u);
  EXPECT_EQ(ops[0], 0x01);  // Header
  EXPECT_EQ(ops[1], 0x03);  // Schema before its first use
  EXPECT_EQ(ops[2], 0x04);  // Channel before its first use
  EXPECT_EQ(ops[3], 0x06);
  EXPECT_EQ(ops.back(), 0x02);
  // After Data End: Schema, Channel, one Chunk Index per chunk, Statistics, 4 Summary Offsets, Footer.
  const auto data_end = std::find(ops.begin(), ops.end(), 0x0F);
  ASSERT_NE(data_end, ops.end());
  EXPECT_EQ(*(data_end + 1), 0x03);
  EXPECT_EQ(*(data_end + 2), 0x04);
  const long chunks = std::count(ops.begin(), data_end, 0x06);
  EXPECT_GE(chunks, 2);
  EXPECT_EQ(std::count(data_end, ops.end(), 0x08), chunks);
  EXPECT_EQ(std::count(data_end, ops.end(), 0x0B), 1);
  EXPECT_EQ(std::count(data_end, ops.end(), 0x0E), 4);
  // Footer: summary_start is the record after Data End.
  const auto records = top_level_records(b);
  const std::size_t footer_at = records.back().second;
  const std::size_t data_end_at = records[static_cast<std::size_t>(data_end - ops.begin())].second;
  EXPECT_EQ(le64(b, footer_at + 9), data_end_at + 9 + 4);
  EXPECT_EQ(b[le64(b, footer_at + 17)], 0x0E);
}

TEST_F(McapWriterTest, ChunkIndexesBeyondTheMemoryBoundGoToASpillFileAndAllReachTheSummary) {
  // Tiny chunks (one Pose each, uncompressed): 4,000 chunks are 4,000 Chunk Index records of one
  // channel, 83 bytes each (332 kB in all), far more than kChunkIndexMemoryBytes (64 KiB): most spill.
  const std::string file = path("spill.mcap");
  std::uint64_t chunks = 0, spilled = 0;
  {
    McapWriter w(file, {"ros2", 64, false});
    const auto c = add_pose_channel(w);
    for (int i = 0; i < 4000; ++i) {
      write_pose(w, c, i);
    }
    chunks = w.chunks();
    spilled = w.spilled_index_bytes();
    EXPECT_EQ(chunks, 4000u);
    EXPECT_GT(spilled, 0u);
    EXPECT_FALSE(fs::exists(file + ".chunk-indexes")) << "the spill file is unlinked once open";
    w.close();
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), fs::directory_iterator()), 1) << "only the .mcap is left";
  const auto b = read_file(file);
  const auto records = top_level_records(b);
  std::vector<std::size_t> chunk_at, index_to;
  std::uint64_t index_bytes = 0;
  for (const auto& [op, at] : records) {
    if (op == 0x06) chunk_at.push_back(at);
    if (op == 0x08) {
      index_to.push_back(le64(b, at + 9 + 16));  // Chunk Index: chunk_start_offset
      index_bytes = 9 + le64(b, at + 1);
    }
  }
  EXPECT_EQ(index_bytes, 83u);  // 9 + 32 (times, offset, length) + 14 (one channel) + 8 + 4 ("") + 16
  EXPECT_EQ(spilled % index_bytes, 0u) << "whole records only";
  EXPECT_GT(spilled, chunks * index_bytes - McapWriter::kChunkIndexMemoryBytes - index_bytes);
  ASSERT_EQ(chunk_at.size(), chunks);
  EXPECT_EQ(index_to, chunk_at) << "one Chunk Index per chunk, in order, each at its chunk";
}

}  // namespace
}  // namespace quadcosim::io
