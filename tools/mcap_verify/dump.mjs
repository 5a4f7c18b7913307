#!/usr/bin/env node
// Prints every message of the named topics of an MCAP file as JSON, decoded like verify.mjs does
// (@mcap/core reads the file, @foxglove/rosmsg parses the ros2msg schema text stored in it,
// @foxglove/rosmsg2-serialization decodes the CDR): the independent reader for tests that compare a
// whole topic, message by message, with what else a run wrote.
//
//   node dump.mjs FILE TOPIC...
//
// Output: {TOPIC: {schemaName, schemaText, metadata, messages: [{logTime, publishTime, sequence,
// message}]}} with bigints as strings and typed arrays as arrays; a topic not in the file maps to
// null. Doubles are printed by JSON.stringify, which round-trips them exactly.
import { McapIndexedReader } from "@mcap/core";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import { decompress } from "fzstd";
import { open } from "node:fs/promises";

function plain(v) {
  if (typeof v === "bigint") return v.toString();
  if (ArrayBuffer.isView(v)) return Array.from(v, plain);
  if (Array.isArray(v)) return v.map(plain);
  if (v && typeof v === "object") return Object.fromEntries(Object.entries(v).map(([k, x]) => [k, plain(x)]));
  return v;
}

const [file, ...topics] = process.argv.slice(2);
if (!file || topics.length === 0) {
  console.error("usage: node dump.mjs FILE.mcap TOPIC...");
  process.exit(2);
}
try {
  const handle = await open(file, "r");
  const { size } = await handle.stat();
  const readable = {
    size: async () => BigInt(size),
    read: async (offset, length) => {
      const buf = new Uint8Array(Number(length));
      const { bytesRead } = await handle.read(buf, 0, buf.length, Number(offset));
      if (bytesRead !== buf.length) throw new Error(`short read at ${offset}`);
      return buf;
    },
  };
  const reader = await McapIndexedReader.Initialize({
    readable,
    decompressHandlers: { zstd: (b, n) => decompress(b, new Uint8Array(Number(n))) },
  });
  const out = Object.fromEntries(topics.map((t) => [t, null]));
  const decoders = new Map();
  for (const c of reader.channelsById.values()) {
    if (!topics.includes(c.topic)) continue;
    const s = reader.schemasById.get(c.schemaId);
    if (c.messageEncoding !== "cdr" || s.encoding !== "ros2msg") throw new Error(`${c.topic}: not cdr/ros2msg`);
    const text = new TextDecoder().decode(s.data);
    decoders.set(c.id, new MessageReader(parse(text, { ros2: true })));
    out[c.topic] = { schemaName: s.name, schemaText: text, metadata: Object.fromEntries(c.metadata), messages: [] };
  }
  for await (const m of reader.readMessages({ topics, validateCrcs: true })) {
    const c = reader.channelsById.get(m.channelId);
    const d = decoders.get(m.channelId);
    const message = d.readMessage(m.data);
    if (d.lastReadHadTrailingBytes()) throw new Error(`${c.topic} sequence ${m.sequence}: trailing bytes`);
    out[c.topic].messages.push({ logTime: m.logTime, publishTime: m.publishTime, sequence: m.sequence, message });
  }
  await handle.close();
  process.stdout.write(JSON.stringify(plain(out)) + "\n");
} catch (e) {
  console.error(`dump.mjs: ${file}: ${e?.message ?? e}`);
  process.exit(1);
}
