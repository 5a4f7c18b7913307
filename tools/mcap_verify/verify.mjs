#!/usr/bin/env node
// Reads an MCAP file with the MCAP reference implementation (@mcap/core) and decodes every message
// with Foxglove's ROS 2 decoders (@foxglove/rosmsg parses the ros2msg schema text,
// @foxglove/rosmsg2-serialization decodes the CDR), then prints a JSON summary on stdout. It shares
// no code with quadcosim's writer: it is the independent reader of quadcosim's MCAP interop test.
//
//   node verify.mjs FILE            indexed read: footer, summary (summary CRC checked by the
//                                   reader), chunk indexes, message indexes, chunk CRCs; plus the
//                                   data section CRC
//   node verify.mjs --stream FILE   streaming read from the start, as a recovery tool reads a file
//                                   whose summary and footer are missing (McapStreamReader)
//
// Output: {mode, profile, library, messageCount, trailingByteMessages, channels: {topic: {id,
// messageEncoding, metadata, schemaName, schemaEncoding, count, first, last}}, ...} where first/last
// are {sequence, logTime, publishTime, message} with the decoded ROS fields (bigints as strings,
// typed arrays as arrays). Indexed mode adds statistics, chunks (from the chunk indexes, with the
// message count of each from its message index records) and dataSectionCrc; stream mode adds
// chunks (message count of each), complete (a valid footer was reached) and bytesRemaining.
// Exits non-zero with the error on stderr when the file cannot be read or a message not decoded.
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { decompress } from "fzstd";
import { open, readFile } from "node:fs/promises";
import { crc32 } from "node:zlib";

const decompressHandlers = {
  zstd: (buffer, size) => decompress(buffer, new Uint8Array(Number(size))),
};

/** JSON-friendly copy: bigint -> string, typed arrays -> arrays, Maps -> objects. */
function plain(v) {
  if (typeof v === "bigint") return v.toString();
  if (ArrayBuffer.isView(v)) return Array.from(v, plain);
  if (Array.isArray(v)) return v.map(plain);
  if (v instanceof Map) return Object.fromEntries([...v].map(([k, x]) => [String(k), plain(x)]));
  if (v && typeof v === "object") return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, plain(x)]));
  return v;
}

/** Collects schemas, channels and decoded messages, in whatever order the reader yields them. */
class Collector {
  schemas = new Map();
  channels = new Map();
  decoders = new Map();
  perChannel = new Map();
  messageCount = 0;
  trailingByteMessages = 0;

  schema(s) {
    this.schemas.set(s.id, s);
  }
  channel(c) {
    this.channels.set(c.id, c);
  }
  decoder(channel) {
    let d = this.decoders.get(channel.id);
    if (!d) {
      const schema = this.schemas.get(channel.schemaId);
      if (!schema) throw new Error(`channel ${channel.id} (${channel.topic}): unknown schema ${channel.schemaId}`);
      if (channel.messageEncoding !== "cdr" || schema.encoding !== "ros2msg") {
        throw new Error(`channel ${channel.topic}: cannot decode ${channel.messageEncoding} / ${schema.encoding}`);
      }
      const text = new TextDecoder().decode(schema.data);
      d = new MessageReader(parse(text, { ros2: true }));
      this.decoders.set(channel.id, d);
    }
    return d;
  }
  message(m) {
    const channel = this.channels.get(m.channelId);
    if (!channel) throw new Error(`message on unknown channel ${m.channelId}`);
    const reader = this.decoder(channel);
    let decoded;
    try {
      decoded = reader.readMessage(m.data);
    } catch (e) {
      throw new Error(`${channel.topic} sequence ${m.sequence}: ${e.message}`);
    }
    if (reader.lastReadHadTrailingBytes()) this.trailingByteMessages++;
    const entry = { sequence: m.sequence, logTime: m.logTime, publishTime: m.publishTime, message: decoded };
    const c = this.perChannel.get(m.channelId);
    if (c) {
      c.count++;
      c.last = entry;
    } else {
      this.perChannel.set(m.channelId, { count: 1, first: entry, last: entry });
    }
    this.messageCount++;
  }
  summary() {
    const channels = {};
    for (const [id, c] of [...this.channels].sort(([a], [b]) => a - b)) {
      const s = this.schemas.get(c.schemaId);
      const got = this.perChannel.get(id) ?? { count: 0 };
      channels[c.topic] = {
        id,
        messageEncoding: c.messageEncoding,
        metadata: c.metadata,
        schemaName: s?.name,
        schemaEncoding: s?.encoding,
        count: got.count,
        first: got.first,
        last: got.last,
      };
    }
    return { messageCount: this.messageCount, trailingByteMessages: this.trailingByteMessages, channels };
  }
}

/** Random access to a file for McapIndexedReader. */
class FileReadable {
  constructor(handle, size) {
    this.handle = handle;
    this.fileSize = BigInt(size);
  }
  async size() {
    return this.fileSize;
  }
  async read(offset, length) {
    const buf = new Uint8Array(Number(length));
    const { bytesRead } = await this.handle.read(buf, 0, buf.length, Number(offset));
    if (bytesRead !== buf.length) throw new Error(`short read at ${offset}`);
    return buf;
  }
}

/** Message Index records in [offset, offset + length): total message count. */
function countIndexed(bytes) {
  const reader = new McapStreamReader({ noMagicPrefix: true });
  reader.append(bytes);
  let n = 0;
  for (let r; (r = reader.nextRecord()); ) {
    if (r.type !== "MessageIndex") throw new Error(`expected MessageIndex after chunk, found ${r.type}`);
    n += r.records.length;
  }
  return n;
}

async function indexed(path) {
  const handle = await open(path, "r");
  try {
    const { size } = await handle.stat();
    const readable = new FileReadable(handle, size);
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    const c = new Collector();
    for (const s of reader.schemasById.values()) c.schema(s);
    for (const ch of reader.channelsById.values()) c.channel(ch);
    for await (const m of reader.readMessages({ validateCrcs: true })) c.message(m);

    const chunks = [];
    for (const ci of reader.chunkIndexes) {
      const indexBytes = await readable.read(ci.chunkStartOffset + ci.chunkLength, ci.messageIndexLength);
      chunks.push({
        offset: ci.chunkStartOffset,
        length: ci.chunkLength,
        compression: ci.compression,
        compressedSize: ci.compressedSize,
        uncompressedSize: ci.uncompressedSize,
        messageStartTime: ci.messageStartTime,
        messageEndTime: ci.messageEndTime,
        messageIndexChannels: [...ci.messageIndexOffsets.keys()],
        messages: countIndexed(indexBytes),
      });
    }
    const dataSection = await readable.read(0n, reader.dataEndOffset);
    const computed = crc32(dataSection) >>> 0;
    const st = reader.statistics;
    const topicOf = (id) => reader.channelsById.get(id)?.topic ?? `#${id}`;
    return {
      mode: "indexed",
      profile: reader.header.profile,
      library: reader.header.library,
      ...c.summary(),
      statistics: st && {
        messageCount: st.messageCount,
        schemaCount: st.schemaCount,
        channelCount: st.channelCount,
        chunkCount: st.chunkCount,
        messageStartTime: st.messageStartTime,
        messageEndTime: st.messageEndTime,
        channelMessageCounts: Object.fromEntries([...st.channelMessageCounts].map(([id, n]) => [topicOf(id), n])),
      },
      summaryOffsetOpcodes: [...reader.summaryOffsetsByOpcode.keys()].sort((a, b) => a - b),
      summaryCrcChecked: reader.footer.summaryCrc !== 0,
      chunks,
      dataSectionCrc: { stored: reader.dataSectionCrc ?? 0, computed, ok: reader.dataSectionCrc === computed },
    };
  } finally {
    await handle.close();
  }
}

async function stream(path) {
  const reader = new McapStreamReader({ includeChunks: true, decompressHandlers, validateCrcs: true });
  reader.append(await readFile(path));
  const c = new Collector();
  let header;
  const chunks = [];
  let inDataSection = true;
  for (let r; (r = reader.nextRecord()); ) {
    switch (r.type) {
      case "Header":
        header = r;
        break;
      case "Schema":
        if (inDataSection) c.schema(r);
        break;
      case "Channel":
        if (inDataSection) c.channel(r);
        break;
      case "Chunk":
        chunks.push({ compression: r.compression, messages: 0 });
        break;
      case "Message":
        c.message(r);
        if (chunks.length > 0) chunks[chunks.length - 1].messages++;
        break;
      case "DataEnd":
        inDataSection = false;
        break;
      default:
        break;
    }
  }
  return {
    mode: "stream",
    profile: header?.profile,
    library: header?.library,
    ...c.summary(),
    chunks,
    complete: reader.done(),
    bytesRemaining: reader.bytesRemaining(),
  };
}

const args = process.argv.slice(2);
const streaming = args[0] === "--stream";
const file = streaming ? args[1] : args[0];
if (!file || args.length !== (streaming ? 2 : 1)) {
  console.error("usage: node verify.mjs [--stream] FILE.mcap");
  process.exit(2);
}
try {
  const result = streaming ? await stream(file) : await indexed(file);
  process.stdout.write(JSON.stringify(plain(result), null, 1) + "\n");
} catch (e) {
  console.error(`verify.mjs: ${file}: ${e?.message ?? e}`);
  process.exit(1);
}
