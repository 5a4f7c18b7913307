// Serialized samples in and out of Cyclone DDS for the fuzz targets and their seed maker, without a
// network: topics on a participant whose discovery is off. The sertype that Cyclone uses to read a
// topic's samples is obtained the public way of Cyclone 0.10: write one sample and take it back as
// serialized data (dds_takecdr), whose serdata names its type.
#pragma once

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "dds/participant.hpp"

namespace quadcosim::fuzz {

/// A participant that talks to nobody (ROS_DOMAIN_ID from the environment, discovery off).
inline std::unique_ptr<dds::Participant> isolated_participant() {
  dds::RosEnvironment env;
  env.range = dds::DiscoveryRange::kOff;
  if (const char* id = std::getenv("ROS_DOMAIN_ID")) env.domain_id = static_cast<std::uint32_t>(std::atoi(id));
  return std::make_unique<dds::Participant>(env);
}

/// One topic of a generated type: a reliable writer on it, and the sertype of its samples.
struct LocalTopic {
  const dds_topic_descriptor_t* descriptor = nullptr;
  dds_entity_t topic = 0, writer = 0;
  const ddsi_sertype* sertype = nullptr;
  ddsi_serdata* keep = nullptr;  ///< holds a reference on the sertype while this object lives

  LocalTopic(const dds::Participant& p, const dds_topic_descriptor_t* desc, const std::string& name)
      : descriptor(desc) {
    topic = dds::check(dds_create_topic(p.handle(), desc, name.c_str(), nullptr, nullptr), "dds_create_topic");
    dds_qos_t* qos = dds::ros_qos(10, true);
    const dds_entity_t reader = dds::check(dds_create_reader(p.handle(), topic, qos, nullptr), "dds_create_reader");
    writer = dds::check(dds_create_writer(p.handle(), topic, qos, nullptr), "dds_create_writer");
    dds_delete_qos(qos);
    void* zero = dds_alloc(desc->m_size);  // zeroed: empty strings and sequences
    dds::check(dds_write(writer, zero), "dds_write");
    dds_write_flush(writer);
    dds_sample_free(zero, desc, DDS_FREE_ALL);
    dds_sample_info_t info;
    if (dds_takecdr(reader, &keep, 1, &info, DDS_ANY_STATE) != 1) {
      std::fprintf(stderr, "fuzz: no local sample on %s\n", name.c_str());
      std::abort();
    }
    sertype = keep->type;
    dds_delete(reader);
  }
  ~LocalTopic() {
    if (keep) ddsi_serdata_unref(keep);
  }
  LocalTopic(const LocalTopic&) = delete;
  LocalTopic& operator=(const LocalTopic&) = delete;
  LocalTopic(LocalTopic&& o) noexcept
      : descriptor(o.descriptor), topic(o.topic), writer(o.writer), sertype(o.sertype), keep(o.keep) {
    o.keep = nullptr;
  }

  /// Cyclone's reading of `bytes` (encapsulation header + CDR), or nullptr when it refuses them.
  ddsi_serdata* from_bytes(const std::uint8_t* bytes, std::size_t size) const {
    ddsrt_iovec_t iov;
    iov.iov_base = const_cast<std::uint8_t*>(bytes);
    iov.iov_len = static_cast<ddsrt_iov_len_t>(size);
    return ddsi_serdata_from_ser_iov(sertype, SDK_DATA, 1, &iov, size);
  }

  /// Decodes `bytes` into a generated C sample and hands it to `use`; false when Cyclone refuses them.
  template <class F>
  bool with_sample(const std::uint8_t* bytes, std::size_t size, F&& use) const {
    ddsi_serdata* sd = from_bytes(bytes, size);
    if (!sd) return false;
    void* sample = dds_alloc(descriptor->m_size);
    ddsi_sertype_zero_sample(sertype, sample);
    const bool ok = ddsi_serdata_to_sample(sd, sample, nullptr, nullptr);
    if (ok) use(static_cast<const void*>(sample));
    ddsi_sertype_free_sample(sertype, sample, DDS_FREE_ALL);
    ddsi_serdata_unref(sd);
    return ok;
  }

  /// Cyclone's serialized form (encapsulation header + CDR) of a generated C sample.
  std::vector<std::uint8_t> to_bytes(const void* sample) const {
    ddsi_serdata* sd = ddsi_serdata_from_sample(sertype, SDK_DATA, sample);
    std::vector<std::uint8_t> out(ddsi_serdata_size(sd));
    ddsi_serdata_to_ser(sd, 0, out.size(), out.data());
    ddsi_serdata_unref(sd);
    return out;
  }
};

/// Appends one record of the fuzz input format: [kind][length, 2 bytes LE][bytes].
inline void append_record(std::vector<std::uint8_t>& out, int kind, const std::vector<std::uint8_t>& bytes) {
  out.push_back(static_cast<std::uint8_t>(kind));
  out.push_back(static_cast<std::uint8_t>(bytes.size() & 0xff));
  out.push_back(static_cast<std::uint8_t>((bytes.size() >> 8) & 0xff));
  out.insert(out.end(), bytes.begin(), bytes.end());
}

/// Splits an input into records: calls `use(kind, bytes, size)` for each, at most `max_records`.
template <class F>
void for_each_record(const std::uint8_t* data, std::size_t size, int max_records, F&& use) {
  std::size_t at = 0;
  for (int n = 0; at < size && n < max_records; ++n) {
    const int kind = data[at];
    std::size_t len = 0;
    if (at + 3 <= size) len = data[at + 1] | (std::size_t{data[at + 2]} << 8);
    at = std::min(size, at + 3);
    len = std::min(len, size - at);
    use(kind, data + at, len);
    at += len;
  }
}

}  // namespace quadcosim::fuzz
