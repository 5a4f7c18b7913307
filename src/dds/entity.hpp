// Unique owners of Cyclone DDS handles: an entity (participant, domain, reader, writer, topic, waitset,
// condition) is deleted when its owner goes, on every path out of the code that created it, an
// exception included. An entity's children go with it in Cyclone, so owners of children are declared
// after their parent's owner (destroyed first); deleting a handle its parent already took is a
// harmless error return.
#pragma once

#include <dds/dds.h>

#include <memory>
#include <utility>

namespace quadcosim::dds {

class Entity {
 public:
  Entity() = default;
  /// Takes `handle` (a Cyclone return value: an error code, <= 0, owns nothing).
  explicit Entity(dds_entity_t handle) : handle_(handle) {}
  ~Entity() { reset(); }
  Entity(Entity&& other) noexcept : handle_(std::exchange(other.handle_, 0)) {}
  Entity& operator=(Entity&& other) noexcept {
    if (this != &other) {
      reset();
      handle_ = std::exchange(other.handle_, 0);
    }
    return *this;
  }
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;

  /// The handle, for Cyclone's calls (0 when it owns nothing).
  dds_entity_t get() const { return handle_; }
  operator dds_entity_t() const { return handle_; }  // NOLINT: a handle wherever Cyclone takes one
  /// Deletes the entity now (and its children); then owns nothing.
  void reset() {
    if (handle_ > 0) dds_delete(handle_);
    handle_ = 0;
  }

 private:
  dds_entity_t handle_ = 0;
};

/// A QoS object, freed with dds_delete_qos.
struct QosDeleter {
  void operator()(dds_qos_t* qos) const { dds_delete_qos(qos); }
};
using Qos = std::unique_ptr<dds_qos_t, QosDeleter>;

}  // namespace quadcosim::dds
