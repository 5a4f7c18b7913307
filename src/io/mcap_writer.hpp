// An MCAP file writer (https://mcap.dev/spec, major version 0), written from the specification:
// the format Foxglove, rosbag2's default storage and the `mcap` CLI read.
//
// Layout it produces:
//   magic, Header(profile, "quadcosim <version>"),
//   data section: Schema and Channel records as they are added (outside chunks, flushed at once, so a
//     reader that recovers a file without summary can decode every later message), then Chunk records
//     (messages only; zstd or uncompressed; CRC32 of the uncompressed records), each followed by one
//     Message Index record per channel in it; Data End (CRC32 of the data section);
//   summary: Schema, Channel, Chunk Index (with the message index offsets) and Statistics groups;
//   Summary Offset records for each group; Footer (summary CRC32); magic.
//
// Crash safety: a chunk is written and fflush-ed to the OS as soon as its uncompressed records reach
// `chunk_size` (and on flush()), so after a SIGKILL only the messages of the open chunk are lost; the
// rest is readable by a reader that tolerates a missing summary and footer (McapStreamReader of
// @mcap/core, tested in mcap_interop_test.sh; the mcap CLI's `recover` works the same way). No
// fsync: a power cut may lose what the OS had not written yet.
//
// Memory: what the summary needs of each chunk (its Chunk Index record, 77 + 10 bytes per channel in
// the chunk: 157 bytes for a chunk of 8 channels) is serialised as the chunk is written and kept in
// memory up to kChunkIndexMemoryBytes; beyond that it is appended to a spill file beside the output
// (`<path>.chunk-indexes`, unlinked as soon as it is opened, so nothing is left behind even after a
// SIGKILL) and copied into the summary at close. The writer's memory is so bounded whatever the run's
// length; the spill file grows by those bytes per chunk on the output's disk.
//
// Not thread-safe: one thread writes (the recorder).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <map>
#include <span>
#include <string>
#include <vector>

struct ZSTD_CCtx_s;

namespace quadcosim::io {

/// CRC-32 (IEEE 802.3, zlib's crc32) of `bytes`: the checksum of MCAP's chunks and data section.
std::uint32_t mcap_crc32(std::span<const std::uint8_t> bytes);

struct McapOptions {
  /// Header profile. "ros2" (the MCAP registry's ROS 2 profile) makes add_schema accept only the
  /// encodings "ros2msg"/"ros2idl", add_channel only message encoding "cdr", and fills in an empty
  /// `offered_qos_profiles` channel metadata entry when the caller gives none.
  std::string profile = "ros2";
  /// A chunk is written once its uncompressed records reach this many bytes [bytes]. Smaller chunks
  /// lose less on a crash and compress less well.
  std::size_t chunk_size = 1 << 20;
  /// zstd-compress chunks (otherwise they are stored uncompressed).
  bool compress = true;
};

class McapWriter {
 public:
  /// Creates (truncates) `path` and writes the magic and Header. Throws std::runtime_error naming the
  /// path when it cannot be opened or written.
  McapWriter(const std::string& path, McapOptions options = {});
  /// Finishes the file as close() does if close() was not called; errors are swallowed (call close()
  /// to see them).
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Registers a schema and writes its record to the data section; returns its id (1, 2, ...). An
  /// identical schema (name, encoding, data) added again returns the first one's id. Throws
  /// std::invalid_argument for an encoding the profile does not allow, std::logic_error after close().
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);

  /// Registers a channel on `topic` whose messages use schema `schema_id` (0: none) and writes its
  /// record to the data section; returns its id (1, 2, ...). An identical channel added again returns
  /// the first one's id. Throws std::invalid_argument for an unknown schema id or a message encoding
  /// the profile does not allow, std::logic_error after close().
  std::uint16_t add_channel(const std::string& topic, std::uint16_t schema_id, const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata = {});

  /// Appends one message to the open chunk: `data`/`size` are the serialized message (for ros2: CDR
  /// with its 4-byte encapsulation header, see ros2_cdr.hpp), `log_time_ns` when it was recorded,
  /// `publish_time_ns` when it was sent (use the log time if unknown) [ns, any one epoch for the whole
  /// file]. Writes the chunk when it is full. Throws std::invalid_argument for an unknown channel id,
  /// std::runtime_error naming the path on a write error, std::logic_error after close().
  void write(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns, std::uint64_t publish_time_ns,
             const std::uint8_t* data, std::size_t size);

  /// Writes the open chunk now (if it holds any message) and flushes to the OS: a recorder that calls
  /// this every few seconds bounds what a crash can lose by time as well as by chunk size.
  void flush();

  /// Writes the last chunk, Data End, the summary, Summary Offsets, Footer and magic, and closes the
  /// file. Throws std::runtime_error naming the path on a write error. A second call does nothing.
  void close();

  /// Messages written so far (including those in the open chunk).
  std::uint64_t messages() const { return message_count_; }
  /// Chunks written so far.
  std::uint64_t chunks() const { return chunk_count_; }
  /// Bytes of Chunk Index records moved to the spill file so far (0 until the memory bound is reached).
  std::uint64_t spilled_index_bytes() const { return spilled_bytes_; }

  /// Chunk Index records kept in memory before they go to the spill file [bytes] (reserved at once, so
  /// the writer's memory does not change as they come and go: about 400 chunks, 3-5 simulated minutes
  /// of a recorded run at 100 Hz).
  static constexpr std::size_t kChunkIndexMemoryBytes = 64 * 1024;

 private:
  struct Schema {
    std::uint16_t id;
    std::string name, encoding, data;
  };
  struct Channel {
    std::uint16_t id, schema_id;
    std::string topic, message_encoding;
    std::map<std::string, std::string> metadata;
  };

  void require_open(const char* what) const;
  /// Writes bytes to the file, keeping the offset and the running CRC.
  void emit(const void* bytes, std::size_t n);
  void emit_record(std::uint8_t opcode, const std::vector<std::uint8_t>& body);
  /// fflush; throws std::runtime_error naming the path when the OS refuses the bytes.
  void flush_file();
  void write_chunk();
  /// Moves the Chunk Index records held in memory to the spill file (opened on first use).
  void spill_chunk_indexes();
  void finish();

  std::string path_;
  McapOptions options_;
  std::FILE* file_ = nullptr;
  ZSTD_CCtx_s* zstd_ = nullptr;
  std::uint64_t offset_ = 0;  ///< bytes written to the file
  std::uint32_t crc_ = 0;     ///< running CRC32 state of the current section (data, then summary)

  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;                      ///< channels_[id - 1]
  std::vector<std::uint64_t> channel_message_counts_;  ///< by channel id - 1
  std::uint64_t chunk_count_ = 0;
  std::vector<std::uint8_t> chunk_indexes_;  ///< serialised Chunk Index records not spilled yet
  std::FILE* spill_ = nullptr;               ///< the spill file (unlinked), once opened
  std::uint64_t spilled_bytes_ = 0;

  // The open chunk: its uncompressed records, log time range and message index (channel -> log
  // time, offset in the records).
  std::vector<std::uint8_t> chunk_;
  std::uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::vector<std::uint8_t> compressed_;

  std::uint64_t message_count_ = 0;
  std::uint64_t start_time_ = 0, end_time_ = 0;
  bool closed_ = false;
};

}  // namespace quadcosim::io
