// The camera of `microcobot serve` as Foxglove and a ROS 2 tool see it:
//  - the Foxglove WebSocket client of npm @foxglove/ws-protocol receives /camera/image/compressed
//    and /camera/camera_info (encoding cdr, ros2msg schemas) and decodes them with
//    @foxglove/rosmsg2-serialization from the schemas the server advertises (@foxglove/rosmsg
//    parses them): a CompressedImage of format "jpeg" whose JPEG an independent decoder (Pillow,
//    Debian's python3-pil) opens at the sensor's size; a CameraInfo whose K is the objective's
//    scale; frame rate and stamps;
//  - a recording taken meanwhile (its request asks for the JPEG frames), read by @mcap/core with
//    @foxglove/wasm-zstd's decompressor, holds the image channel, every frame of the recording in
//    sequence, decodable the same way.
// Run by CTest (`camera_foxglove`); node --experimental-websocket.
import { spawn, execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, writeFileSync } from "node:fs";
import { open } from "node:fs/promises";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";

let FoxgloveClient, MessageReader, parse, McapIndexedReader, zstd;
try {
  ({ FoxgloveClient } = (await import("@foxglove/ws-protocol")).default);
  ({ MessageReader } = await import("@foxglove/rosmsg2-serialization"));
  ({ parse } = await import("@foxglove/rosmsg"));
  ({ McapIndexedReader } = await import("@mcap/core"));
  zstd = (await import("@foxglove/wasm-zstd")).default;
  await zstd.isLoaded;
} catch (e) {
  console.error("camera_foxglove: npm packages missing (npm ci): skipped: " + e.message);
  process.exit(77);
}
const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("camera_foxglove: set MC_CLI to the microcobot binary");
  process.exit(2);
}
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(1)} s] ${msg}`);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const dir = mkdtempSync(join(tmpdir(), "mc-camera-"));
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir], { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
const url = await new Promise((resolve, reject) => {
  createInterface({ input: server.stdout }).once("line", resolve);
  server.once("exit", () => reject(new Error("serve exited before printing its URL")));
});
const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");
log("serve at " + url);

const client = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const channels = new Map(), readers = new Map(), subs = new Map();
const got = { "/camera/image/compressed": [], "/camera/camera_info": [], "/camera/state": [] };
client.on("advertise", (list) => {
  for (const c of list) {
    channels.set(c.topic, c);
    if (!(c.topic in got)) continue;
    if (c.encoding === "cdr") readers.set(c.topic, new MessageReader(parse(c.schema, { ros2: true })));
    subs.set(client.subscribe(c.id), c.topic);
  }
});
client.on("message", ({ subscriptionId, data }) => {
  const topic = subs.get(subscriptionId);
  const bytes = new Uint8Array(data.buffer, data.byteOffset, data.byteLength);
  try {
    const value = readers.has(topic) ? readers.get(topic).readMessage(bytes) : JSON.parse(new TextDecoder().decode(bytes));
    got[topic].push({ value, at: performance.now() });
  } catch (e) {
    fail(`${topic}: undecodable: ${e.message}`);
  }
});
await sleep(1500);  // connected, subscribed, the first frames in flight
for (const [topic, schema] of [["/camera/image/compressed", "sensor_msgs/msg/CompressedImage"],
                               ["/camera/camera_info", "sensor_msgs/msg/CameraInfo"]]) {
  const c = channels.get(topic);
  if (!c) { fail(`${topic} not advertised`); continue; }
  if (c.encoding !== "cdr" || c.schemaEncoding !== "ros2msg" || c.schemaName !== schema)
    fail(`${topic}: ${c.encoding}/${c.schemaEncoding}/${c.schemaName}`);
}

// Record while watching: the console's action channel.
const actionChannel = client.advertise({ topic: "/console/action", encoding: "json", schemaName: "microcobot.Action" });
const send = (name, options = {}) =>
  client.sendMessage(actionChannel, new TextEncoder().encode(JSON.stringify({ action: name, ...options })));
for (const k of Object.keys(got)) got[k].length = 0;
const t0 = performance.now();
send("record_start", { video: "jpeg" });  // the frames as the console's channel sends them
await sleep(5000);
send("record_stop");
const seconds = (performance.now() - t0) / 1000;
await sleep(500);

const images = got["/camera/image/compressed"], infos = got["/camera/camera_info"], states = got["/camera/state"];
const rate = images.length / seconds;
log(`received ${images.length} images in ${seconds.toFixed(2)} s: ${rate.toFixed(1)} fps`);
if (images.length < 10) fail(`only ${images.length} frames in ${seconds.toFixed(1)} s`);
if (images.length > 0) {
  const m = images[images.length - 1].value;
  if (m.format !== "jpeg") fail(`format ${m.format}`);
  if (m.header.frame_id !== "camera_optical_frame") fail(`frame_id ${m.header.frame_id}`);
  if (!(m.data instanceof Uint8Array) || m.data[0] !== 0xff || m.data[1] !== 0xd8) fail("data is not a JPEG");
  // An independent decoder: Pillow opens the JPEG at the sensor's size.
  const jpg = join(dir, "frame.jpg");
  writeFileSync(jpg, m.data);
  const size = execFileSync("/usr/bin/python3", ["-c",
    "import sys; from PIL import Image; im = Image.open(sys.argv[1]); im.load(); " +
    "import statistics; px = list(im.getdata()); print(im.size[0], im.size[1], im.mode, min(px), max(px))", jpg]).toString().trim();
  log(`Pillow decoded the last frame: ${size} (width height mode min max), ${m.data.length} bytes`);
  const [w, h, , lo, hi] = size.split(" ");
  if (w !== "1280" || h !== "1024") fail(`decoded ${w}x${h}, expected the 1280x1024 sensor`);
  if (!(Number(hi) - Number(lo) > 30)) fail(`a flat image (grey ${lo}..${hi}): nothing imaged`);
  // Stamps: the state of the same frame carries the same loop time.
  const st = states.find((s) => Math.abs(s.value.t_s - (m.header.stamp.sec + m.header.stamp.nanosec * 1e-9)) < 1e-6);
  if (!st) fail("no /camera/state with the image's stamp");
}
if (infos.length > 0 && states.length > 0) {
  const info = infos[infos.length - 1].value, st = states[states.length - 1].value;
  const objective = st.m_per_px;
  if (info.width !== 1280 || info.height !== 1024) fail(`camera_info ${info.width}x${info.height}`);
  if (info.k.length !== 9 || info.p.length !== 12 || info.distortion_model !== "plumb_bob") fail("camera_info layout");
  log(`camera_info: fx ${info.k[0].toFixed(1)} px, ${(objective * 1e6).toFixed(3)} um/px (${st.objective_name})`);
  if (!(info.k[0] > 1000 && Math.abs(info.k[2] - 639.5) < 1e-9 && Math.abs(info.k[5] - 511.5) < 1e-9)) fail(`K ${info.k}`);
  log(`camera thread: capture ${st.capture_ms.toFixed(1)} ms, JPEG ${st.encode_ms.toFixed(1)} ms, ` +
      `scene-to-JPEG ${st.latency_ms.toFixed(1)} ms, dropped ${st.dropped}`);
}

server.kill("SIGTERM");
const { code, signal } = await exited;
if (code !== 0) fail(`serve exited ${code} (${signal})`);

// The recording: the image channel, every frame in sequence.
const mcaps = readdirSync(dir).filter((f) => /^recording-[0-9-]+\.mcap$/.test(f));
if (mcaps.length !== 1) fail(`expected one recording, found ${mcaps.join(", ")}`);
else {
  const file = await open(join(dir, mcaps[0]), "r");
  const reader = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt((await file.stat()).size),
      read: async (offset, size) => {
        const buf = Buffer.alloc(Number(size));
        await file.read(buf, 0, buf.length, Number(offset));
        return new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
      },
    },
    decompressHandlers: { zstd: (data, size) => zstd.decompress(data, Number(size)) },
  });
  const byTopic = new Map([...reader.channelsById.values()].map((c) => [c.topic, c]));
  const ic = byTopic.get("/camera/image/compressed"), sc = byTopic.get("/camera/state");
  if (!ic || !sc) fail("the recording has no camera channels");
  else {
    const schema = reader.schemasById.get(ic.schemaId);
    if (ic.messageEncoding !== "cdr" || schema.encoding !== "ros2msg") fail(`recorded ${ic.messageEncoding}/${schema.encoding}`);
    const mr = new MessageReader(parse(new TextDecoder().decode(schema.data), { ros2: true }));
    let n = 0, jpegs = 0;
    const seq = [];
    for await (const m of reader.readMessages({ topics: ["/camera/image/compressed", "/camera/state"] })) {
      if (m.channelId === ic.id) {
        n++;
        const img = mr.readMessage(m.data);
        if (img.format === "jpeg" && img.data[0] === 0xff && img.data[1] === 0xd8) jpegs++;
      } else {
        seq.push(JSON.parse(new TextDecoder().decode(m.data)).sequence);
      }
    }
    const gaps = seq.filter((s, i) => i > 0 && s !== seq[i - 1] + 1).length;
    const chunks = reader.chunkIndexes.length;
    log(`recording: ${n} frames (${jpegs} JPEG), ${gaps} gaps in the sequence, ${chunks} chunks`);
    if (n < 10 || jpegs !== n) fail(`recorded ${n} frames, ${jpegs} JPEG`);
    if (gaps !== 0) fail(`${gaps} frames missing from the recording`);
    if (seq.length !== n) fail(`${seq.length} states for ${n} images`);
  }
  await file.close();
}

if (failures > 0) {
  console.error(`camera_foxglove: ${failures} failure(s)`);
  process.exit(1);
}
log("camera_foxglove: CDR images and camera info decoded by the Foxglove libraries, JPEG by Pillow, recording complete");
