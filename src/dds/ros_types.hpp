// The link between the ROS-shaped message structs (sim/messages.hpp) and the C types idlc generates
// from the ROS 2 IDL: per message type, its topic descriptor and the conversions both ways.
#pragma once

#include <dds/dds.h>

#include <functional>
#include <typeindex>

namespace quadcosim::dds {

/// Type-erased operations on one message type T.
struct TypeOps {
  const dds_topic_descriptor_t* descriptor;
  /// Writes `*static_cast<const T*>(message)` with `writer`.
  dds_return_t (*write)(dds_entity_t writer, const void* message);
  /// Converts one received sample (a pointer to the generated C struct) into a T and passes it on.
  void (*deliver)(const void* sample, const std::function<void(const void*)>& to);
};

/// The operations for a C++ message type, or nullptr when it has no DDS mapping.
const TypeOps* type_ops(std::type_index type);

}  // namespace quadcosim::dds
