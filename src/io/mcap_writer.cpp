#include "io/mcap_writer.hpp"

#include <zstd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include <fcntl.h>
#include <unistd.h>

#include "io/output_folder.hpp"

#ifndef QUADCOSIM_VERSION
#define QUADCOSIM_VERSION "unknown"
#endif

namespace quadcosim::io {

namespace {

// Record opcodes (spec: Records).
enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), as zlib's crc32 and the spec use, eight
// bytes a step ("slicing by 8": table k is the CRC of a byte followed by k zero bytes): the same
// values as a byte at a time, several times faster (a run's recording passes every byte through it
// twice: the chunk's CRC and the data section's).
constexpr std::array<std::array<std::uint32_t, 256>, 8> make_crc_tables() {
  std::array<std::array<std::uint32_t, 256>, 8> t{};
  for (std::uint32_t i = 0; i < 256; ++i) {
    std::uint32_t c = i;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
    t[0][i] = c;
  }
  for (std::size_t k = 1; k < 8; ++k) {
    for (std::size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xFF];
  }
  return t;
}
constexpr auto kCrcTables = make_crc_tables();
constexpr std::uint32_t kCrcInit = 0xFFFFFFFFu;
std::uint32_t crc_update(std::uint32_t state, const std::uint8_t* p, std::size_t n) {
  const auto& t = kCrcTables;
  for (; n >= 8; p += 8, n -= 8) {
    const std::uint32_t lo = state ^ (static_cast<std::uint32_t>(p[0]) | static_cast<std::uint32_t>(p[1]) << 8 |
                                      static_cast<std::uint32_t>(p[2]) << 16 | static_cast<std::uint32_t>(p[3]) << 24);
    state = t[7][lo & 0xFF] ^ t[6][(lo >> 8) & 0xFF] ^ t[5][(lo >> 16) & 0xFF] ^ t[4][lo >> 24] ^ t[3][p[4]] ^
            t[2][p[5]] ^ t[1][p[6]] ^ t[0][p[7]];
  }
  for (; n > 0; ++p, --n) state = t[0][(state ^ *p) & 0xFF] ^ (state >> 8);
  return state;
}
std::uint32_t crc_final(std::uint32_t state) { return state ^ 0xFFFFFFFFu; }

// Little-endian field serialisation (spec: Serialization) into a byte vector.
class Fields {
 public:
  explicit Fields(std::vector<std::uint8_t>& out) : out_(out) {}
  Fields& u8(std::uint8_t v) {
    out_.push_back(v);
    return *this;
  }
  Fields& u16(std::uint16_t v) { return le(v, 2); }
  Fields& u32(std::uint32_t v) { return le(v, 4); }
  Fields& u64(std::uint64_t v) { return le(v, 8); }
  Fields& bytes(const void* p, std::size_t n) {
    if (n == 0) return *this;
    const std::size_t at = out_.size();
    out_.resize(at + n);
    std::memcpy(out_.data() + at, p, n);
    return *this;
  }
  Fields& str(const std::string& s) { return u32(static_cast<std::uint32_t>(s.size())).bytes(s.data(), s.size()); }
  /// Map<string, string>: uint32 byte length, then key/value strings.
  Fields& string_map(const std::map<std::string, std::string>& m) {
    const std::size_t at = begin_length();
    for (const auto& [k, v] : m) str(k).str(v);
    return end_length(at);
  }
  /// Map<uint16, uint64>.
  Fields& id_map(const std::map<std::uint16_t, std::uint64_t>& m) {
    const std::size_t at = begin_length();
    for (const auto& [k, v] : m) u16(k).u64(v);
    return end_length(at);
  }

  std::size_t begin_length() {
    u32(0);
    return out_.size();
  }
  Fields& end_length(std::size_t at) {
    const auto n = static_cast<std::uint32_t>(out_.size() - at);
    for (int i = 0; i < 4; ++i) out_[at - 4 + i] = static_cast<std::uint8_t>(n >> (8 * i));
    return *this;
  }

 private:
  Fields& le(std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out_.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
    return *this;
  }
  std::vector<std::uint8_t>& out_;
};

// opcode + uint64 content length
std::array<std::uint8_t, 9> record_prefix(std::uint8_t opcode, std::uint64_t length) {
  std::array<std::uint8_t, 9> p{};
  p[0] = opcode;
  for (int i = 0; i < 8; ++i) p[1 + i] = static_cast<std::uint8_t>(length >> (8 * i));
  return p;
}

}  // namespace

std::uint32_t mcap_crc32(std::span<const std::uint8_t> bytes) {
  return crc_final(crc_update(kCrcInit, bytes.data(), bytes.size()));
}

McapWriter::McapWriter(const std::string& path, McapOptions options) : path_(path), options_(std::move(options)) {
  try {
    file_ = open_output_file(path);  // never through a link planted at `path`
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string("McapWriter: cannot create '") + path + "': " + e.what());
  }
  if (options_.compress) {
    zstd_ = ZSTD_createCCtx();
    if (!zstd_) {
      std::fclose(file_);
      throw std::runtime_error("McapWriter: '" + path + "': cannot create a zstd context");
    }
  }
  try {
    chunk_indexes_.reserve(kChunkIndexMemoryBytes + 1024);  // the bound and one record beyond it
    crc_ = kCrcInit;
    emit(kMagic.data(), kMagic.size());
    const std::string library = std::string("quadcosim ") + QUADCOSIM_VERSION;
    std::vector<std::uint8_t> body;
    body.reserve(8 + options_.profile.size() + library.size());
    Fields(body).str(options_.profile).str(library);
    emit_record(kHeader, body);
    flush_file();
  } catch (...) {
    std::fclose(file_);
    ZSTD_freeCCtx(zstd_);
    throw;
  }
}

McapWriter::~McapWriter() {
  try {
    close();
  } catch (...) {
    // close() reports errors to callers that ask; a destructor must not throw.
  }
  if (file_) std::fclose(file_);
  if (spill_) std::fclose(spill_);
  ZSTD_freeCCtx(zstd_);
}

void McapWriter::require_open(const char* what) const {
  if (closed_) throw std::logic_error(std::string("McapWriter::") + what + " after close() of '" + path_ + "'");
}

void McapWriter::emit(const void* bytes, std::size_t n) {
  if (n == 0) return;
  if (std::fwrite(bytes, 1, n, file_) != n) {
    throw std::runtime_error("McapWriter: cannot write '" + path_ + "': " + std::strerror(errno));
  }
  offset_ += n;
  crc_ = crc_update(crc_, static_cast<const std::uint8_t*>(bytes), n);
}

void McapWriter::flush_file() {
  if (std::fflush(file_) != 0) {
    throw std::runtime_error("McapWriter: cannot write '" + path_ + "': " + std::strerror(errno));
  }
}

void McapWriter::emit_record(std::uint8_t opcode, const std::vector<std::uint8_t>& body) {
  const auto prefix = record_prefix(opcode, body.size());
  emit(prefix.data(), prefix.size());
  emit(body.data(), body.size());
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  require_open("add_schema");
  if (options_.profile == "ros2" && encoding != "ros2msg" && encoding != "ros2idl") {
    throw std::invalid_argument(
        "McapWriter::add_schema: the ros2 profile needs schema encoding ros2msg or ros2idl, not '" + encoding +
        "' (schema '" + name + "')");
  }
  for (const Schema& s : schemas_) {
    if (s.name == name && s.encoding == encoding && s.data == data) return s.id;
  }
  if (schemas_.size() >= 0xFFFF) throw std::invalid_argument("McapWriter::add_schema: more than 65535 schemas");
  const auto id = static_cast<std::uint16_t>(schemas_.size() + 1);
  schemas_.push_back({id, name, encoding, data});
  std::vector<std::uint8_t> body;
  Fields(body).u16(id).str(name).str(encoding).str(data);  // data: uint32 length-prefixed bytes
  emit_record(kSchema, body);
  flush_file();
  return id;
}

std::uint16_t McapWriter::add_channel(const std::string& topic, std::uint16_t schema_id,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  require_open("add_channel");
  if (schema_id > schemas_.size()) {
    throw std::invalid_argument("McapWriter::add_channel: topic '" + topic + "' names unknown schema id " +
                                std::to_string(schema_id));
  }
  std::map<std::string, std::string> meta = metadata;
  if (options_.profile == "ros2") {
    if (message_encoding != "cdr") {
      throw std::invalid_argument("McapWriter::add_channel: the ros2 profile needs message encoding cdr, not '" +
                                  message_encoding + "' (topic '" + topic + "')");
    }
    meta.try_emplace("offered_qos_profiles", "");  // required by the profile; "" = unknown
  }
  for (const Channel& c : channels_) {
    if (c.topic == topic && c.schema_id == schema_id && c.message_encoding == message_encoding && c.metadata == meta) {
      return c.id;
    }
  }
  if (channels_.size() >= 0xFFFF) throw std::invalid_argument("McapWriter::add_channel: more than 65535 channels");
  const auto id = static_cast<std::uint16_t>(channels_.size() + 1);
  channels_.push_back({id, schema_id, topic, message_encoding, std::move(meta)});
  channel_message_counts_.push_back(0);
  std::vector<std::uint8_t> body;
  const Channel& c = channels_.back();
  Fields(body).u16(c.id).u16(c.schema_id).str(c.topic).str(c.message_encoding).string_map(c.metadata);
  emit_record(kChannel, body);
  flush_file();
  return id;
}

void McapWriter::write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                       std::uint64_t publish_time_ns, const std::uint8_t* data, std::size_t size) {
  require_open("write");
  if (channel_id == 0 || channel_id > channels_.size()) {
    throw std::invalid_argument("McapWriter::write: unknown channel id " + std::to_string(channel_id) + " in '" +
                                path_ + "'");
  }
  if (chunk_index_.empty()) {
    chunk_start_time_ = chunk_end_time_ = log_time_ns;
  } else {
    chunk_start_time_ = std::min(chunk_start_time_, log_time_ns);
    chunk_end_time_ = std::max(chunk_end_time_, log_time_ns);
  }
  if (message_count_ == 0) {
    start_time_ = end_time_ = log_time_ns;
  } else {
    start_time_ = std::min(start_time_, log_time_ns);
    end_time_ = std::max(end_time_, log_time_ns);
  }
  chunk_index_[channel_id].emplace_back(log_time_ns, chunk_.size());
  const auto prefix = record_prefix(kMessage, 2 + 4 + 8 + 8 + size);
  Fields(chunk_)
      .bytes(prefix.data(), prefix.size())
      .u16(channel_id)
      .u32(sequence)
      .u64(log_time_ns)
      .u64(publish_time_ns);
  chunk_.insert(chunk_.end(), data, data + size);
  ++message_count_;
  ++channel_message_counts_[channel_id - 1];
  if (chunk_.size() >= options_.chunk_size) write_chunk();
}

void McapWriter::write_chunk() {
  if (chunk_index_.empty()) return;
  const std::uint32_t records_crc = crc_final(crc_update(kCrcInit, chunk_.data(), chunk_.size()));
  const std::uint8_t* records = chunk_.data();
  std::size_t records_size = chunk_.size();
  std::string compression;
  if (zstd_) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n = ZSTD_compressCCtx(zstd_, compressed_.data(), compressed_.size(), chunk_.data(), chunk_.size(),
                                            ZSTD_CLEVEL_DEFAULT);
    if (ZSTD_isError(n)) {
      throw std::runtime_error("McapWriter: '" + path_ + "': zstd: " + ZSTD_getErrorName(n));
    }
    records = compressed_.data();
    records_size = n;
    compression = "zstd";
  }

  const std::uint64_t chunk_offset = offset_;
  std::vector<std::uint8_t> head;
  Fields(head)
      .u64(chunk_start_time_)
      .u64(chunk_end_time_)
      .u64(chunk_.size())
      .u32(records_crc)
      .str(compression)
      .u64(records_size);
  const auto prefix = record_prefix(kChunk, head.size() + records_size);
  emit(prefix.data(), prefix.size());
  emit(head.data(), head.size());
  emit(records, records_size);
  const std::uint64_t chunk_length = offset_ - chunk_offset;

  const std::uint64_t indexes_start = offset_;
  std::map<std::uint16_t, std::uint64_t> message_index_offsets;
  std::vector<std::uint8_t> body;
  for (const auto& [channel, entries] : chunk_index_) {
    body.clear();
    Fields f(body);
    f.u16(channel);
    const std::size_t at = f.begin_length();
    for (const auto& [log_time, offset] : entries) f.u64(log_time).u64(offset);
    f.end_length(at);
    message_index_offsets[channel] = offset_;
    emit_record(kMessageIndex, body);
  }
  // The chunk's Chunk Index record for the summary, serialised now (opcode, length, body).
  body.clear();
  Fields(body)
      .u64(chunk_start_time_)
      .u64(chunk_end_time_)
      .u64(chunk_offset)
      .u64(chunk_length)
      .id_map(message_index_offsets)
      .u64(offset_ - indexes_start)
      .str(compression)
      .u64(records_size)
      .u64(chunk_.size());
  const auto index_prefix = record_prefix(kChunkIndex, body.size());
  chunk_indexes_.insert(chunk_indexes_.end(), index_prefix.begin(), index_prefix.end());
  chunk_indexes_.insert(chunk_indexes_.end(), body.begin(), body.end());
  ++chunk_count_;
  if (chunk_indexes_.size() >= kChunkIndexMemoryBytes) spill_chunk_indexes();

  chunk_.clear();
  chunk_index_.clear();
  flush_file();
}

void McapWriter::spill_chunk_indexes() {
  if (chunk_indexes_.empty()) return;
  if (!spill_) {
    const std::string spill_path = path_ + ".chunk-indexes";
    // Created new (O_EXCL: never through a link planted there, never another file's bytes).
    const int fd = ::open(spill_path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0600);
    spill_ = fd >= 0 ? ::fdopen(fd, "w+b") : nullptr;
    if (!spill_) {
      if (fd >= 0) ::close(fd);
      throw std::runtime_error("McapWriter: cannot create '" + spill_path + "' (the chunk indexes of '" + path_ +
                               "' beyond " + std::to_string(kChunkIndexMemoryBytes) +
                               " bytes): " + std::strerror(errno));
    }
    ::unlink(spill_path.c_str());  // open, it stays readable; nothing is left behind
  }
  if (std::fwrite(chunk_indexes_.data(), 1, chunk_indexes_.size(), spill_) != chunk_indexes_.size()) {
    throw std::runtime_error("McapWriter: cannot write the chunk indexes of '" + path_ +
                             "' beside it: " + std::strerror(errno));
  }
  spilled_bytes_ += chunk_indexes_.size();
  chunk_indexes_.clear();
}

void McapWriter::flush() {
  require_open("flush");
  write_chunk();
  flush_file();
}

void McapWriter::close() {
  if (closed_) return;
  closed_ = true;  // also when finishing fails: the file is not to be written again
  finish();
  if (spill_) {  // its bytes are in the summary now; closing it frees them on the disk
    std::fclose(spill_);
    spill_ = nullptr;
  }
  const int rc = std::fclose(file_);
  file_ = nullptr;
  if (rc != 0) throw std::runtime_error("McapWriter: cannot write '" + path_ + "': " + std::strerror(errno));
}

void McapWriter::finish() {
  write_chunk();

  std::vector<std::uint8_t> body;
  Fields(body).u32(crc_final(crc_));  // CRC of everything before the Data End record
  emit_record(kDataEnd, body);

  // Summary section, grouped by opcode; each group's extent goes into a Summary Offset record.
  const std::uint64_t summary_start = offset_;
  crc_ = kCrcInit;
  struct Group {
    std::uint8_t opcode;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](std::uint8_t opcode, auto&& emit_all) {
    const std::uint64_t start = offset_;
    emit_all();
    if (offset_ > start) groups.push_back({opcode, start, offset_ - start});
  };
  group(kSchema, [&] {
    for (const Schema& s : schemas_) {
      body.clear();
      Fields(body).u16(s.id).str(s.name).str(s.encoding).str(s.data);
      emit_record(kSchema, body);
    }
  });
  group(kChannel, [&] {
    for (const Channel& c : channels_) {
      body.clear();
      Fields(body).u16(c.id).u16(c.schema_id).str(c.topic).str(c.message_encoding).string_map(c.metadata);
      emit_record(kChannel, body);
    }
  });
  group(kChunkIndex, [&] {
    if (spill_) {  // the records spilled first, in the order they were written, then those in memory
      if (std::fflush(spill_) != 0 || std::fseek(spill_, 0, SEEK_SET) != 0) {
        throw std::runtime_error("McapWriter: cannot read back the chunk indexes of '" + path_ +
                                 "': " + std::strerror(errno));
      }
      std::vector<std::uint8_t> buffer(64 * 1024);
      std::uint64_t left = spilled_bytes_;
      while (left > 0) {
        const std::size_t n = std::fread(buffer.data(), 1, std::min<std::uint64_t>(left, buffer.size()), spill_);
        if (n == 0) {
          throw std::runtime_error("McapWriter: cannot read back the chunk indexes of '" + path_ +
                                   "': " + std::strerror(errno));
        }
        emit(buffer.data(), n);
        left -= n;
      }
    }
    emit(chunk_indexes_.data(), chunk_indexes_.size());
  });
  group(kStatistics, [&] {
    std::map<std::uint16_t, std::uint64_t> counts;
    for (std::size_t i = 0; i < channels_.size(); ++i) counts[channels_[i].id] = channel_message_counts_[i];
    body.clear();
    Fields(body)
        .u64(message_count_)
        .u16(static_cast<std::uint16_t>(schemas_.size()))
        .u32(static_cast<std::uint32_t>(channels_.size()))
        .u32(0)  // attachments
        .u32(0)  // metadata
        .u32(static_cast<std::uint32_t>(chunk_count_))
        .u64(start_time_)
        .u64(end_time_)
        .id_map(counts);
    emit_record(kStatistics, body);
  });

  const std::uint64_t summary_offset_start = offset_;
  for (const Group& g : groups) {
    body.clear();
    Fields(body).u8(g.opcode).u64(g.start).u64(g.length);
    emit_record(kSummaryOffset, body);
  }

  // Footer: its summary CRC covers the summary, the summary offsets and the footer up to the CRC.
  body.clear();
  Fields(body).u64(summary_start).u64(summary_offset_start);
  const auto prefix = record_prefix(kFooter, body.size() + 4);
  emit(prefix.data(), prefix.size());
  emit(body.data(), body.size());
  body.clear();
  Fields(body).u32(crc_final(crc_));
  emit(body.data(), body.size());
  emit(kMagic.data(), kMagic.size());
}

}  // namespace quadcosim::io
