// A Foxglove WebSocket client for quadcosim's tests: Foxglove's own protocol client
// (@foxglove/ws-protocol, over the `ws` package) and ROS 2 decoders (@foxglove/rosmsg parses the
// advertised ros2msg schema, @foxglove/rosmsg2-serialization reads the CDR), so what quadcosim's server
// sends is checked by an implementation that is not quadcosim's. Prints one JSON object on stdout.
//
//   node client.mjs watch URL TOPIC...   subscribe to TOPICs, decode every message until the server
//                                        closes the connection (or --seconds S); messages per topic,
//                                        and the schema text of each subscribed channel
//   node client.mjs stall URL TOPIC...   subscribe, take the first message, then stop reading (the
//                                        socket paused) until killed or --seconds S
//   node client.mjs abuse URL TOPIC      a handshake without the subprotocol, malformed JSON, an unknown
//                                        op, an unknown channel id, an unknown subscription id, a binary
//                                        frame, a valid subscription to TOPIC (messages must still
//                                        come), then a frame longer than the server takes; the answer to
//                                        each
//   node client.mjs origin URL ORIGIN... one handshake per ORIGIN sent as its Origin header ("-": none);
//                                        whether each opened or the HTTP status that refused it
//   node client.mjs burst URL N          N connections started at once; how many opened and the status
//                                        of each refusal (all held open until every one has settled)
//   node client.mjs flood URL N          one subscribe frame (under the 64 KiB frame limit) with N
//                                        empty subscriptions, each an error; the statuses and the close
// Progress goes to stderr ("subscribed", "paused") for the test driving it.
import FoxgloveClientModule from "@foxglove/ws-protocol";
import { parse } from "@foxglove/rosmsg";
import { MessageReader } from "@foxglove/rosmsg2-serialization";
import WebSocket from "ws";

const FoxgloveClient = FoxgloveClientModule.FoxgloveClient ?? FoxgloveClientModule.default ?? FoxgloveClientModule;
const SUBPROTOCOL = "foxglove.websocket.v1";

const args = process.argv.slice(2);
let seconds = 60;
const si = args.indexOf("--seconds");
if (si >= 0) {
  seconds = Number(args[si + 1]);
  args.splice(si, 2);
}
const [mode, url, ...topics] = args;
if (!mode || !url) {
  console.error("usage: client.mjs watch|stall|abuse|origin|burst|flood URL ARG... [--seconds S]");
  process.exit(2);
}

const plain = (v) =>
  JSON.parse(JSON.stringify(v, (_k, x) => (typeof x === "bigint" ? Number(x) : ArrayBuffer.isView(x) ? Array.from(x) : x)));

function done(result, code = 0) {
  process.stdout.write(JSON.stringify(result) + "\n", () => process.exit(code));
}

// watch and stall: Foxglove's client.
function subscribeClient(stall) {
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL ?? SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const result = { subprotocol: null, serverInfo: null, channels: [], messages: {}, timeFrames: 0, lastTime: null,
                   status: [], close: null, outOfOrderTime: 0, messageAfterTime: 0 };
  const readers = new Map();  // subscription id -> {topic, reader}
  let paused = false;
  client.on("open", () => { result.subprotocol = ws.protocol; });
  client.on("serverInfo", (info) => { result.serverInfo = plain(info); });
  client.on("status", (s) => { result.status.push(plain(s)); });
  client.on("time", (t) => {
    const ns = Number(t.timestamp);
    if (result.lastTime !== null && ns < result.lastTime) result.outOfOrderTime++;
    result.lastTime = ns;
    result.timeFrames++;
  });
  client.on("advertise", (channels) => {
    for (const c of channels) {
      const channel = { id: c.id, topic: c.topic, encoding: c.encoding, schemaName: c.schemaName,
                        schemaEncoding: c.schemaEncoding, schemaLines: c.schema.split("\n").length };
      result.channels.push(channel);
      if (!topics.includes(c.topic)) continue;
      channel.schema = c.schema;  // the subscribed ones' whole text, to compare with a recording's
      const reader = new MessageReader(parse(c.schema, { ros2: true }));
      const id = client.subscribe(c.id);
      readers.set(id, { topic: c.topic, reader });
      result.messages[c.topic] = [];
    }
    if (readers.size === topics.length) console.error("subscribed");
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const r = readers.get(subscriptionId);
    if (!r) return;
    const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
    const msg = plain(r.reader.readMessage(bytes));
    const t = Number(timestamp);
    if (result.lastTime !== null && t > result.lastTime) result.messageAfterTime++;  // newer than the server time
    result.messages[r.topic].push({ t, msg });
    if (stall && !paused) {
      paused = true;
      ws._socket.pause();  // stop reading: the server's queue for us fills up
      console.error("paused");
    }
  });
  client.on("close", (ev) => {
    result.close = { code: ev.code, reason: String(ev.reason ?? "") };
    done(result);
  });
  client.on("error", (e) => { result.error = String(e?.message ?? e); });
  setTimeout(() => { result.timedOut = true; done(result); }, seconds * 1000);
  process.on("SIGTERM", () => done(result));
}

// abuse: a raw WebSocket, one request at a time, waiting for the server's answer.
async function abuse() {
  const result = {};
  // 1. No foxglove.websocket.v1 offered: the handshake is refused.
  result.noSubprotocol = await new Promise((resolve) => {
    const w = new WebSocket(url, ["something.else"]);
    w.on("unexpected-response", (_req, res) => resolve({ refused: true, status: res.statusCode }));
    w.on("open", () => { w.close(); resolve({ refused: false }); });
    w.on("error", (e) => resolve({ refused: true, error: String(e.message) }));
  });

  const ws = new WebSocket(url, [SUBPROTOCOL]);
  const inbox = [];  // JSON messages not taken yet
  let waiter = null;
  let binary = 0, subscribedBinary = 0;
  let closed = null;
  ws.on("message", (data, isBinary) => {
    if (isBinary) {
      binary++;
      const b = Buffer.from(data);
      if (b[0] === 0x01 && b.readUInt32LE(1) === 7) subscribedBinary++;
      return;
    }
    inbox.push(JSON.parse(data.toString()));
    if (waiter) { const w = waiter; waiter = null; w(); }
  });
  ws.on("close", (code, reason) => {
    closed = { code, reason: reason.toString() };
    if (waiter) { const w = waiter; waiter = null; w(); }
  });
  await new Promise((resolve, reject) => { ws.on("open", resolve); ws.on("error", reject); });
  result.subprotocol = ws.protocol;
  const next = async (op, ms = 3000) => {
    const deadline = Date.now() + ms;
    for (;;) {
      const i = inbox.findIndex((m) => m.op === op);
      if (i >= 0) return inbox.splice(i, 1)[0];
      if (closed || Date.now() > deadline) return null;
      await new Promise((resolve) => { waiter = resolve; setTimeout(resolve, 100); });
    }
  };
  result.serverInfo = await next("serverInfo");
  const advertise = await next("advertise");
  const channels = advertise ? advertise.channels : [];
  const request = async (name, payload, isBinary = false) => {
    ws.send(payload, { binary: isBinary });
    const s = await next("status");
    result[name] = s ? { level: s.level, message: s.message } : { closed };
  };
  await request("malformedJson", "{\"op\": \"subscribe\", ");
  await request("unknownOp", JSON.stringify({ op: "frobnicate" }));
  await request("unknownChannel", JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 9999 }] }));
  await request("unknownSubscription", JSON.stringify({ op: "unsubscribe", subscriptionIds: [12345] }));
  await request("binaryFrame", Buffer.from([0x01, 0, 0, 0, 0, 1, 2, 3]), true);
  const good = channels.find((c) => c.topic === topics[0]);
  if (good) {
    ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 7, channelId: good.id }] }));
    const deadline = Date.now() + 5000;
    while (subscribedBinary < 5 && !closed && Date.now() < deadline) await new Promise((r) => setTimeout(r, 20));
  }
  result.afterErrors = { subscribedMessages: subscribedBinary, binaryFrames: binary };
  ws.send("x".repeat(1 << 20));  // 1 MiB: longer than the server takes
  const deadline = Date.now() + 8000;
  while (!closed && Date.now() < deadline) await new Promise((r) => setTimeout(r, 20));
  result.oversized = closed;
  done(result);
}

// One handshake; resolves to {opened, status, ws}.
function handshake(options = {}) {
  return new Promise((resolve) => {
    const w = new WebSocket(url, [SUBPROTOCOL], options);
    w.on("unexpected-response", (_req, res) => { resolve({ opened: false, status: res.statusCode }); res.resume(); });
    w.on("open", () => resolve({ opened: true, ws: w }));
    w.on("error", (e) => resolve({ opened: false, error: String(e.message) }));
  });
}

async function origins() {
  const result = {};
  for (const origin of topics) {
    const r = await handshake(origin === "-" ? {} : { origin });
    if (r.ws) r.ws.close();
    result[origin] = { opened: r.opened, status: r.status ?? null, error: r.error ?? null };
  }
  done(result);
}

async function burst() {
  const n = Number(topics[0]);
  const all = await Promise.all(Array.from({ length: n }, () => handshake()));
  const result = { started: n, opened: 0, refused: {} };
  for (const r of all) {
    if (r.opened) result.opened++;
    else { const k = String(r.status ?? r.error); result.refused[k] = (result.refused[k] ?? 0) + 1; }
  }
  for (const r of all) if (r.ws) r.ws.close();
  done(result);
}

async function flood() {
  const n = Number(topics[0]);
  const ws = new WebSocket(url, [SUBPROTOCOL]);
  const result = { sent: n, statuses: 0, close: null };
  ws.on("message", (data, isBinary) => {
    if (!isBinary && JSON.parse(data.toString()).op === "status") result.statuses++;
  });
  const closed = new Promise((resolve) => ws.on("close", (code) => { result.close = code; resolve(); }));
  await new Promise((resolve, reject) => { ws.on("open", resolve); ws.on("error", reject); });
  const subscriptions = Array.from({ length: n }, () => ({}));
  const frame = JSON.stringify({ op: "subscribe", subscriptions });
  result.frameBytes = frame.length;
  ws.send(frame);
  await Promise.race([closed, new Promise((r) => setTimeout(r, seconds * 1000))]);
  done(result);
}

if (mode === "watch") subscribeClient(false);
else if (mode === "origin") origins().catch((e) => done({ error: String(e?.stack ?? e) }, 1));
else if (mode === "burst") burst().catch((e) => done({ error: String(e?.stack ?? e) }, 1));
else if (mode === "flood") flood().catch((e) => done({ error: String(e?.stack ?? e) }, 1));
else if (mode === "stall") subscribeClient(true);
else if (mode === "abuse") abuse().catch((e) => done({ error: String(e?.stack ?? e) }, 1));
else {
  console.error(`unknown mode ${mode}`);
  process.exit(2);
}
