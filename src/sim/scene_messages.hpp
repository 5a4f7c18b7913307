// foxglove_msgs/msg/SceneUpdate and the types it contains, for recordings that Foxglove's 3D panel
// draws. Written in the style of sim/messages.hpp (fields in wire order, from which io/ros2_cdr.cpp
// derives the CDR and the ros2msg schema text) from the published ROS 2 definitions of the
// foxglove_msgs package (schemas/ros2/*.msg of Foxglove's schemas): every field, in the order and with
// the types stated there. The named constants of those files (SceneEntityDeletion.MATCHING_ID = 0,
// ALL = 1; LinePrimitive.LINE_STRIP = 0, LINE_LOOP = 1, LINE_LIST = 2) are not fields and are not
// repeated in the schema text; they are given here as C++ constants. Recorded only: these types are
// never sent over DDS.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "sim/messages.hpp"

namespace quadcosim::msg {

/// builtin_interfaces/msg/Duration
struct Duration {
  static constexpr std::string_view kRosType = "builtin_interfaces/msg/Duration";
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("sec", m.sec);
    v.field("nanosec", m.nanosec);
  }
};

/// geometry_msgs/msg/Pose
struct Pose {
  static constexpr std::string_view kRosType = "geometry_msgs/msg/Pose";
  Vector3 position;  // geometry_msgs/Point
  Quaternion orientation;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("position", m.position, kPoint);
    v.field("orientation", m.orientation);
  }
};

/// foxglove_msgs/msg/Color: RGBA, each in [0, 1].
struct Color {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/Color";
  double r = 1, g = 1, b = 1, a = 1;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("r", m.r);
    v.field("g", m.g);
    v.field("b", m.b);
    v.field("a", m.a);
  }
};

/// foxglove_msgs/msg/KeyValuePair
struct KeyValuePair {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/KeyValuePair";
  std::string key, value;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("key", m.key);
    v.field("value", m.value);
  }
};

/// foxglove_msgs/msg/ArrowPrimitive: an arrow along +x of its pose.
struct ArrowPrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/ArrowPrimitive";
  Pose pose;
  double shaft_length = 0, shaft_diameter = 0, head_length = 0, head_diameter = 0;
  Color color;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("shaft_length", m.shaft_length);
    v.field("shaft_diameter", m.shaft_diameter);
    v.field("head_length", m.head_length);
    v.field("head_diameter", m.head_diameter);
    v.field("color", m.color);
  }
};

/// foxglove_msgs/msg/CubePrimitive: a box centred on its pose, `size` along its axes.
struct CubePrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/CubePrimitive";
  Pose pose;
  Vector3 size;
  Color color;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("size", m.size);
    v.field("color", m.color);
  }
};

/// foxglove_msgs/msg/SpherePrimitive
struct SpherePrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/SpherePrimitive";
  Pose pose;
  Vector3 size;
  Color color;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("size", m.size);
    v.field("color", m.color);
  }
};

/// foxglove_msgs/msg/CylinderPrimitive: axis along z of its pose; size.x, size.y the diameters at
/// the widest end, size.z the height; bottom_scale and top_scale scale the two ends.
struct CylinderPrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/CylinderPrimitive";
  Pose pose;
  Vector3 size;
  double bottom_scale = 1, top_scale = 1;
  Color color;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("size", m.size);
    v.field("bottom_scale", m.bottom_scale);
    v.field("top_scale", m.top_scale);
    v.field("color", m.color);
  }
};

/// foxglove_msgs/msg/LinePrimitive
struct LinePrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/LinePrimitive";
  static constexpr std::uint8_t kLineStrip = 0, kLineLoop = 1, kLineList = 2;
  std::uint8_t type = kLineStrip;
  Pose pose;
  double thickness = 0;
  bool scale_invariant = false;
  std::vector<Vector3> points;  // geometry_msgs/Point[]
  Color color;
  std::vector<Color> colors;
  std::vector<std::uint32_t> indices;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("type", m.type);
    v.field("pose", m.pose);
    v.field("thickness", m.thickness);
    v.field("scale_invariant", m.scale_invariant);
    v.field("points", m.points, kPoint);
    v.field("color", m.color);
    v.field("colors", m.colors);
    v.field("indices", m.indices);
  }
};

/// foxglove_msgs/msg/TriangleListPrimitive
struct TriangleListPrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/TriangleListPrimitive";
  Pose pose;
  std::vector<Vector3> points;  // geometry_msgs/Point[]
  Color color;
  std::vector<Color> colors;
  std::vector<std::uint32_t> indices;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("points", m.points, kPoint);
    v.field("color", m.color);
    v.field("colors", m.colors);
    v.field("indices", m.indices);
  }
};

/// foxglove_msgs/msg/TextPrimitive
struct TextPrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/TextPrimitive";
  Pose pose;
  bool billboard = false;
  double font_size = 0;
  bool scale_invariant = false;
  Color color;
  std::string text;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("billboard", m.billboard);
    v.field("font_size", m.font_size);
    v.field("scale_invariant", m.scale_invariant);
    v.field("color", m.color);
    v.field("text", m.text);
  }
};

/// foxglove_msgs/msg/ModelPrimitive
struct ModelPrimitive {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/ModelPrimitive";
  Pose pose;
  Vector3 scale;
  Color color;
  bool override_color = false;
  std::string url;
  std::string media_type;
  std::vector<std::uint8_t> data;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("pose", m.pose);
    v.field("scale", m.scale);
    v.field("color", m.color);
    v.field("override_color", m.override_color);
    v.field("url", m.url);
    v.field("media_type", m.media_type);
    v.field("data", m.data);
  }
};

/// foxglove_msgs/msg/SceneEntity: primitives sharing one frame. frame_locked: they follow frame_id as
/// it moves; lifetime zero: shown until replaced (same id on the topic) or deleted.
struct SceneEntity {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/SceneEntity";
  Time timestamp;
  std::string frame_id;
  std::string id;
  Duration lifetime;
  bool frame_locked = false;
  std::vector<KeyValuePair> metadata;
  std::vector<ArrowPrimitive> arrows;
  std::vector<CubePrimitive> cubes;
  std::vector<SpherePrimitive> spheres;
  std::vector<CylinderPrimitive> cylinders;
  std::vector<LinePrimitive> lines;
  std::vector<TriangleListPrimitive> triangles;
  std::vector<TextPrimitive> texts;
  std::vector<ModelPrimitive> models;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("timestamp", m.timestamp);
    v.field("frame_id", m.frame_id);
    v.field("id", m.id);
    v.field("lifetime", m.lifetime);
    v.field("frame_locked", m.frame_locked);
    v.field("metadata", m.metadata);
    v.field("arrows", m.arrows);
    v.field("cubes", m.cubes);
    v.field("spheres", m.spheres);
    v.field("cylinders", m.cylinders);
    v.field("lines", m.lines);
    v.field("triangles", m.triangles);
    v.field("texts", m.texts);
    v.field("models", m.models);
  }
};

/// foxglove_msgs/msg/SceneEntityDeletion
struct SceneEntityDeletion {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/SceneEntityDeletion";
  static constexpr std::uint8_t kMatchingId = 0, kAll = 1;
  Time timestamp;
  std::uint8_t type = kMatchingId;
  std::string id;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("timestamp", m.timestamp);
    v.field("type", m.type);
    v.field("id", m.id);
  }
};

/// foxglove_msgs/msg/SceneUpdate
struct SceneUpdate {
  static constexpr std::string_view kRosType = "foxglove_msgs/msg/SceneUpdate";
  std::vector<SceneEntityDeletion> deletions;
  std::vector<SceneEntity> entities;
  template <class M, class V>
  static void fields(M& m, V& v) {
    v.field("deletions", m.deletions);
    v.field("entities", m.entities);
  }
};

}  // namespace quadcosim::msg
