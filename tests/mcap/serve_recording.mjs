// A live `microcobot serve` recording read as Foxglove reads it: @mcap/core's McapIndexedReader
// with the zstd decompressor of npm @foxglove/wasm-zstd (both pinned in package-lock.json).
// A client takes control, drives, sends a refused command and a malformed message, presses the
// e-stop and resets; then SIGTERM closes the recording. Checks: every channel the server
// publishes (the 3-D frames and bodies among them) plus the clients' commands, actions and the events; the events of what happened
// (take_control, estop, refused with the client id, protocol); metadata (version, scene,
// configuration) and the configuration attachment; zstd chunks smaller than their records;
// log times on the wall clock (within a minute of Date.now()), t_s kept, monotonic per channel;
// the 1 kHz telemetry complete; no CSV without --record-csv, no temporary file left.
//
// Usage: MC_CLI=path/to/microcobot node --experimental-websocket serve_recording.mjs
// Run by CTest (`mcap_serve_recording`); exits 77 (skipped) when node_modules lacks the readers.
import { spawn } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, rmSync } from "node:fs";
import { open } from "node:fs/promises";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";

let McapIndexedReader, zstd;
try {
  ({ McapIndexedReader } = await import("@mcap/core"));
  zstd = (await import("@foxglove/wasm-zstd")).default;
  await zstd.isLoaded;
} catch {
  console.error("serve_recording: @mcap/core or @foxglove/wasm-zstd is not installed (scripts/install-deps.sh): skipped");
  process.exit(77);
}
const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("serve_recording: set MC_CLI to the microcobot binary");
  process.exit(2);
}

let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const dir = mkdtempSync(join(tmpdir(), "mc-rec-"));
const started = Date.now();

const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, "--record"],
                     { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
const guard = setTimeout(() => { fail("took longer than 150 s"); server.kill("SIGKILL"); }, 150000);
const url = await new Promise((resolve, reject) => {
  createInterface({ input: server.stdout }).once("line", resolve);
  server.once("exit", () => reject(new Error("serve exited before printing its URL")));
});
const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");

// A raw Foxglove WebSocket client that publishes on the console's channels.
const connect = () => new Promise((resolve, reject) => {
  const ws = new WebSocket(wsUrl, ["foxglove.websocket.v1"]);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => {
    ws.send(JSON.stringify({ op: "advertise", channels: [
      { id: 1, topic: "/console/command", encoding: "json", schemaName: "c" },
      { id: 2, topic: "/console/action", encoding: "json", schemaName: "a" }] }));
    resolve(ws);
  };
  ws.onerror = () => reject(new Error("cannot connect to " + wsUrl));
});
const send = (ws, channel, text) => {
  const body = new TextEncoder().encode(text);
  const frame = new Uint8Array(5 + body.length);
  frame[0] = 0x01;
  new DataView(frame.buffer).setUint32(1, channel, true);
  frame.set(body, 5);
  ws.send(frame);
};
const action = (ws, a) => send(ws, 2, JSON.stringify({ action: a }));
const command = (ws, c) => send(ws, 1, JSON.stringify(c));

const operator = await connect(), other = await connect();
await sleep(300);
action(operator, "take_control");
await sleep(200);
for (let i = 0; i < 30; ++i) {  // a second of driving, the deadman held
  command(operator, { deadman: true, velocity_m_s: [50e-6, 0, 0] });
  await sleep(33);
}
command(operator, { deadman: true, velocity_m_s: ["fast", 0, 0] });  // refused: not a number
command(other, { deadman: true, velocity_m_s: [1e-5, 0, 0] });        // refused: not in control
other.send("{");                                                       // refused by the protocol
await sleep(200);
action(other, "estop");
await sleep(500);
action(operator, "reset");
await sleep(1500);  // a few statuses after the reset
operator.close();
other.close();
await sleep(200);
server.kill("SIGTERM");
const { code } = await exited;
clearTimeout(guard);
if (code !== 0) fail(`serve exited ${code} on SIGTERM`);

const files = readdirSync(dir);
const mcaps = files.filter((f) => /^recording-[0-9-]+\.mcap$/.test(f));
if (mcaps.length !== 1 || files.length !== 1) fail(`expected one recording and nothing else, found: ${files.join(", ")}`);

try {
  const file = await open(join(dir, mcaps[0]), "r");
  const readable = {
    size: async () => BigInt((await file.stat()).size),
    read: async (offset, size) => {
      const buf = Buffer.alloc(Number(size));
      const { bytesRead } = await file.read(buf, 0, buf.length, Number(offset));
      if (bytesRead !== buf.length) throw new Error(`short read at ${offset}`);
      return new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
    },
  };
  const reader = await McapIndexedReader.Initialize({
    readable, decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) } });
  const decode = (m) => JSON.parse(new TextDecoder().decode(m.data));

  const topics = new Map([...reader.channelsById.values()].map((c) => [c.id, c.topic]));
  const expected = ["/platform/telemetry", "/platform/status", "/platform/scene", "/console/feedback",
                    "/console/command", "/console/action", "/events", "/tf", "/robot/scene",
                    "/camera/video", "/camera/camera_info", "/camera/state"];
  for (const t of expected) if (![...topics.values()].includes(t)) fail(`no channel ${t}`);
  // The camera's calibration is a ROS 2 message in CDR (tests/live/camera_foxglove.mjs decodes
  // it), its frames H.264 in Foxglove's CompressedVideo (serve's default; tests/mcap/recorded_video.mjs
  // decodes them); every channel but the calibration is JSON with its JSON Schema.
  const cdr = new Map([["/camera/camera_info", "sensor_msgs/msg/CameraInfo"]]);
  for (const c of reader.channelsById.values()) {
    const s = reader.schemasById.get(c.schemaId);
    const ok = cdr.has(c.topic)
      ? c.messageEncoding === "cdr" && s?.encoding === "ros2msg" && s?.name === cdr.get(c.topic)
      : c.messageEncoding === "json" && s?.encoding === "jsonschema" &&
        (c.topic !== "/camera/video" || s?.name === "foxglove.CompressedVideo");
    if (!ok) fail(`${c.topic}: ${c.messageEncoding}/${s?.encoding} (${s?.name})`);
  }

  // Chunks: zstd, each smaller than its records.
  if (reader.chunkIndexes.length === 0) fail("no chunk");
  for (const ci of reader.chunkIndexes) {
    if (ci.compression !== "zstd") fail(`chunk at ${ci.chunkStartOffset}: compression '${ci.compression}'`);
    if (!(ci.compressedSize < ci.uncompressedSize)) fail(`chunk at ${ci.chunkStartOffset}: ${ci.compressedSize} >= ${ci.uncompressedSize} bytes`);
  }

  // Metadata and the configuration attachment.
  const metadata = new Map();
  for await (const m of reader.readMetadata()) metadata.set(m.name, m.metadata);
  const version = metadata.get("microcobot")?.get("version") ?? "";
  if (!/^microcobot \d+\.\d+\.\d+/.test(version)) fail(`metadata version '${version}'`);
  if (metadata.get("scene")?.get("kind") !== "pick-place") fail("metadata scene kind is not pick-place");
  const yaml = metadata.get("configuration")?.get("yaml") ?? "";
  if (!/^loop:/m.test(yaml) || !/^teleop:/m.test(yaml)) fail("metadata configuration is not the platform configuration");
  const attachments = [];
  for await (const a of reader.readAttachments()) attachments.push(a);
  if (attachments.length !== 1 || attachments[0].name !== "configuration.yaml" ||
      new TextDecoder().decode(attachments[0].data) !== yaml) fail("no configuration.yaml attachment equal to the metadata's");

  // Every message: log times on the wall clock, monotonic per channel, t_s kept.
  const now = Date.now();
  const last = new Map(), counts = new Map(), events = [], actions = [], commands = [];
  const offset = BigInt(metadata.get("microcobot")?.get("time_offset_ns") ?? "0");
  let badTime = 0, backwards = 0, badTs = 0;
  for await (const m of reader.readMessages({ logTimeOrder: false })) {
    const topic = topics.get(m.channelId);
    counts.set(topic, (counts.get(topic) ?? 0) + 1);
    const ms = Number(m.logTime / 1000000n);
    if (ms < started - 60000 || ms > now + 60000) badTime++;
    if (last.has(topic) && m.logTime < last.get(topic)) backwards++;
    last.set(topic, m.logTime);
    if (cdr.has(topic)) continue;
    const j = decode(m);
    if (topic === "/camera/video") {  // stamped as Foxglove's schemas are, no t_s
      if (j.format !== "h264" || typeof j.timestamp?.sec !== "number" || typeof j.data !== "string") badTs++;
      continue;
    }
    if (topic === "/tf" || topic === "/robot/scene") {  // Foxglove's too (tests/mcap/recording_frames.mjs)
      const stamps = topic === "/tf" ? j.transforms : j.entities;
      if (!stamps?.length || stamps.some((e) => typeof e.timestamp?.sec !== "number")) badTs++;
      continue;
    }
    if (topic !== "/platform/scene" && typeof j.t_s !== "number") badTs++;  // the scene is geometry
    else if (topic === "/platform/telemetry" && Math.abs(Number(m.logTime - offset) - j.t_s * 1e9) > 1000) badTs++;
    if (topic === "/events") events.push(j);
    if (topic === "/console/action") actions.push(j);
    if (topic === "/console/command") commands.push(j);
  }
  if (badTime) fail(`${badTime} messages with log times more than a minute from the wall clock`);
  if (backwards) fail(`${backwards} messages whose log time goes back on their channel`);
  if (badTs) fail(`${badTs} messages without t_s or whose log time is not t_s on the time base`);
  console.log("serve_recording: messages per channel " + JSON.stringify(Object.fromEntries(counts)));

  // The telemetry at 1 kHz, the other channels at their rates.
  const tel = counts.get("/platform/telemetry") ?? 0;
  const span = Number(reader.statistics.messageEndTime - reader.statistics.messageStartTime) / 1e9;
  if (!(tel > 900 * span)) fail(`${tel} telemetry messages over ${span.toFixed(2)} s: not the full 1 kHz`);
  if (!((counts.get("/platform/status") ?? 0) >= 3 * span)) fail("too few status messages");
  if (!(counts.get("/platform/scene") >= 1 && counts.get("/console/feedback") >= 30 * span)) fail("scene or feedback missing");

  // What the clients sent, with their ids; the events of what happened.
  const opId = actions.find((a) => a.message?.action === "take_control")?.client;
  if (!(opId > 0)) fail("the take_control action is not recorded with its client id");
  if (!actions.some((a) => a.message?.action === "estop" && a.client !== opId)) fail("the other client's estop is not recorded");
  if (commands.length < 25 || !commands.some((c) => c.message?.velocity_m_s?.[0] === "fast")) fail(`commands recorded: ${commands.length}, the refused one among them?`);
  const has = (kind, pred = () => true) => events.some((e) => e.kind === kind && pred(e));
  for (const e of events) {
    if (typeof e.level !== "number" || typeof e.message !== "string" || !("client" in e)) { fail("event off its schema: " + JSON.stringify(e)); break; }
  }
  if (!has("record_start")) fail("no record_start event");
  if (!has("take_control", (e) => e.client === opId)) fail("no take_control event of the operator");
  if (!has("estop", (e) => e.level === 1)) fail("no estop event");
  if (!has("estopped")) fail("no event of the latched e-stop (status)");
  if (!has("reset")) fail("no reset event");
  if (!has("refused", (e) => e.client === opId && /velocity_m_s/.test(e.message) && e.level === 2)) fail("the malformed command's refusal is not an event");
  if (!has("refused", (e) => e.client !== opId && /take control first/.test(e.message))) fail("the refusal of the client not in control is not an event");
  if (!has("protocol", (e) => /malformed-json/.test(e.message))) fail("the protocol's refusal is not an event");
  console.log("serve_recording: events " + events.map((e) => e.kind).join(", "));
  await file.close();
} catch (e) {
  fail(String(e?.stack ?? e));
}
rmSync(dir, { recursive: true, force: true });
console.log(`serve_recording: ${failures ? "FAILED" : "ok"}`);
process.exit(failures ? 1 : 0);
