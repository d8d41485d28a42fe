// The camera in a `microcobot serve` recording as H.264 (serve's default, `--record-video h264`),
// through decoders that share none of our code: @mcap/core's indexed reader with
// @foxglove/wasm-zstd (as Foxglove reads), then Debian's `ffmpeg` on the CompressedVideo messages'
// Annex B data. An operator jogs the stage for a few seconds while the test takes lossless
// snapshots of the frames (GET /camera/snapshot.tiff: the sensor's samples and the frame's state);
// then the same session recorded with `--record-video jpeg`. Checks:
//   - foxglove.CompressedVideo (JSON) on /camera/video, format h264, one message a frame (as many
//     as /camera/state), every message decoded by ffmpeg to one picture, keyframes (IDR with SPS)
//     at least every 2 s, no B slice (the slice headers read here);
//   - PSNR of the decoded pictures against the lossless snapshots of the same frames >= 38 dB
//     (8-bit: the sensor's top 8 bits, as the JPEG frames);
//   - H.264 bytes per minute <= 1/10 of the JPEG frames' in the other recording.
// Prints the figures (docs/benchmarks.md).
//
// Usage: MC_CLI=path/to/microcobot node --experimental-websocket recorded_video.mjs
// Run by CTest (`mcap_recorded_video`); exits 77 (skipped) without the readers or ffmpeg.
import { spawn, spawnSync } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync, statSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { loadReaders, openIndexed } from "./indexed_reader.mjs";

const readers = await loadReaders("recorded_video");
if (spawnSync("ffmpeg", ["-version"]).status !== 0) {
  console.error("recorded_video: no ffmpeg (scripts/install-deps.sh): skipped");
  process.exit(77);
}
const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("recorded_video: set MC_CLI to the microcobot binary");
  process.exit(2);
}
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const root = mkdtempSync(join(tmpdir(), "mc-video-"));

// A raw Foxglove WebSocket client on the console's channels.
function connect(wsUrl) {
  return new Promise((resolve, reject) => {
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
}
function send(ws, channel, object) {
  const body = new TextEncoder().encode(JSON.stringify(object));
  const frame = new Uint8Array(5 + body.length);
  frame[0] = 0x01;
  new DataView(frame.buffer).setUint32(1, channel, true);
  frame.set(body, 5);
  ws.send(frame);
}

// A baseline TIFF of one grey channel (what imaging/tiff_file writes): samples, bit depth (from
// MaxSampleValue), the ImageDescription (the frame's /camera/state).
function readTiff(buf) {
  const dv = new DataView(buf.buffer, buf.byteOffset, buf.byteLength);
  if (buf[0] !== 0x49 || buf[1] !== 0x49 || dv.getUint16(2, true) !== 42) throw new Error("not a little-endian TIFF");
  const ifd = dv.getUint32(4, true), n = dv.getUint16(ifd, true), tags = new Map();
  for (let i = 0; i < n; ++i) {
    const e = ifd + 2 + 12 * i, type = dv.getUint16(e + 2, true), count = dv.getUint32(e + 4, true);
    const value = type === 3 ? dv.getUint16(e + 8, true) : dv.getUint32(e + 8, true);
    tags.set(dv.getUint16(e, true), { type, count, value });
  }
  const width = tags.get(256).value, height = tags.get(257).value, bits = tags.get(258).value;
  const max = tags.get(281)?.value ?? (2 ** bits - 1), at = tags.get(273).value, d = tags.get(270);
  const description = new TextDecoder().decode(buf.subarray(d.value, d.value + d.count - 1));
  const samples = bits === 16 ? new Uint16Array(buf.buffer.slice(buf.byteOffset + at, buf.byteOffset + at + 2 * width * height))
                              : buf.subarray(at, at + width * height);
  return { width, height, depth: Math.round(Math.log2(max + 1)), samples, state: JSON.parse(description.trim()) };
}

// One `serve` session: the operator jogs back and forth for `seconds` while the test takes
// `snapshots` lossless snapshots; then SIGTERM. Returns the recording's path and the snapshots.
async function session(video, seconds, snapshots) {
  const dir = join(root, video);
  const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, "--record", "--record-video", video],
                       { stdio: ["ignore", "pipe", "inherit"] });
  const exited = new Promise((resolve) => server.on("exit", (code) => resolve(code)));
  const url = await new Promise((resolve, reject) => {
    createInterface({ input: server.stdout }).once("line", resolve);
    server.once("exit", () => reject(new Error("serve exited before printing its URL")));
  });
  const ws = await connect(url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1"));
  await sleep(300);
  send(ws, 2, { action: "take_control" });
  const shots = [];
  const t0 = Date.now();
  let next = 1000;
  while (Date.now() - t0 < seconds * 1000) {
    const t = (Date.now() - t0) / 1000;
    const v = 80e-6 * Math.sign(Math.sin(2 * Math.PI * t / 2.4) || 1);  // back and forth, 1.2 s each way
    send(ws, 1, { deadman: true, velocity_m_s: [v, 0.5 * v, 0] });
    if (shots.length < snapshots && Date.now() - t0 >= next) {
      next += (seconds * 1000 - 1500) / snapshots;
      const r = await fetch(url.replace(/\/(\?.*)?$/, "/camera/snapshot.tiff$1"));
      if (r.ok) shots.push(readTiff(new Uint8Array(await r.arrayBuffer())));
    }
    await sleep(33);
  }
  ws.close();
  server.kill("SIGTERM");
  const code = await exited;
  if (code !== 0) fail(`${video}: serve exited ${code} on SIGTERM`);
  const files = readdirSync(dir).filter((f) => /^recording-[0-9-]+\.mcap$/.test(f));
  if (files.length !== 1) throw new Error(`${video}: expected one recording, found ${files.join(", ")}`);
  return { path: join(dir, files[0]), shots };
}

// The messages of `topics` in a recording, by topic, in log-time order.
async function messages(path, topics) {
  const { reader, close } = await openIndexed(readers, path);
  const byId = new Map([...reader.channelsById.values()].map((c) => [c.id, c]));
  const out = Object.fromEntries(topics.map((t) => [t, []]));
  const channels = Object.fromEntries([...byId.values()].map((c) => [c.topic, { ...c, schema: reader.schemasById.get(c.schemaId) }]));
  const metadata = new Map();
  for await (const m of reader.readMetadata()) metadata.set(m.name, m.metadata);
  for await (const m of reader.readMessages({ topics })) out[byId.get(m.channelId).topic].push(m);
  await close();
  return { out, channels, metadata };
}

// The NAL unit types of an Annex B access unit, and its slices' slice_type (ITU-T H.264 7.3.3:
// first_mb_in_slice then slice_type, both ue(v); emulation prevention bytes skipped).
function nalUnits(au) {
  const units = [];
  let start = -1;
  for (let i = 0; i + 2 < au.length; ++i) {
    if (au[i] === 0 && au[i + 1] === 0 && au[i + 2] === 1) {
      if (start >= 0) units.push(au.subarray(start, i));
      start = i + 3;
    }
  }
  if (start >= 0) units.push(au.subarray(start));
  return units.map((u) => {
    const type = u[0] & 0x1f;
    let sliceType = null;
    if (type === 1 || type === 5) {
      const bytes = [];
      for (let i = 1, zeros = 0; i < Math.min(u.length, 16); ++i) {
        if (zeros >= 2 && u[i] === 3) { zeros = 0; continue; }
        zeros = u[i] === 0 ? zeros + 1 : 0;
        bytes.push(u[i]);
      }
      let bit = 0;
      const next = () => (bytes[bit >> 3] >> (7 - (bit++ & 7))) & 1;
      const ue = () => { let z = 0; while (next() === 0 && z < 31) z++; let v = 0; for (let k = 0; k < z; ++k) v = v * 2 + next(); return 2 ** z - 1 + v; };
      ue();  // first_mb_in_slice
      sliceType = ue() % 5;
    }
    return { type, sliceType };
  });
}

try {
  const h264 = await session("h264", 5, 5);
  const jpeg = await session("jpeg", 5, 0);

  // The H.264 recording.
  const { out, channels, metadata } = await messages(h264.path, ["/camera/video", "/camera/state"]);
  const vc = channels["/camera/video"];
  if (!vc) throw new Error("no /camera/video channel");
  if (vc.messageEncoding !== "json" || vc.schema?.encoding !== "jsonschema" || vc.schema?.name !== "foxglove.CompressedVideo")
    fail(`/camera/video: ${vc.messageEncoding}/${vc.schema?.encoding} (${vc.schema?.name})`);
  if (channels["/camera/image/compressed"]) fail("a JPEG channel beside the video");
  if (metadata.get("video")?.get("format") !== "h264") fail("metadata video.format is not h264");
  const video = out["/camera/video"], states = out["/camera/state"];
  if (video.length !== states.length) fail(`${video.length} video messages, ${states.length} states`);
  // Every frame the camera formed is recorded (their sequence without a gap); how many it forms
  // in 5 s is the machine's (the renderer's speed: docs/benchmarks.md), not the recording's.
  const sequence = states.map((m) => JSON.parse(new TextDecoder().decode(m.data)).sequence);
  const gaps = sequence.filter((q, i) => i > 0 && q !== sequence[i - 1] + 1).length;
  if (gaps) fail(`${gaps} gaps in the recorded frames' sequence`);
  if (video.length < 30) fail(`only ${video.length} frames in 5 s`);
  const units = [], stamps = [];
  let bytes = 0, bFrames = 0, keyframes = [], keyWithoutSps = 0;
  for (const m of video) {
    const j = JSON.parse(new TextDecoder().decode(m.data));
    if (j.format !== "h264" || j.frame_id !== "camera_optical_frame") fail("message off the schema: " + j.format);
    const au = Buffer.from(j.data, "base64");
    units.push(au);
    bytes += au.length;
    const t = j.timestamp.sec + 1e-9 * j.timestamp.nsec;
    stamps.push(t);
    const nal = nalUnits(au);
    if (nal.some((u) => u.sliceType === 1)) bFrames++;
    if (nal.some((u) => u.type === 5)) {
      keyframes.push(t);
      if (!nal.some((u) => u.type === 7)) keyWithoutSps++;
    }
  }
  if (bFrames) fail(`${bFrames} access units with B slices`);
  if (keyWithoutSps) fail(`${keyWithoutSps} keyframes without their SPS`);
  if (keyframes[0] !== stamps[0]) fail("the first message is not a keyframe");
  let longestKeyGap = 0;
  for (let i = 1; i < keyframes.length; ++i) longestKeyGap = Math.max(longestKeyGap, keyframes[i] - keyframes[i - 1]);
  longestKeyGap = Math.max(longestKeyGap, stamps.at(-1) - keyframes.at(-1));
  if (!(longestKeyGap <= 2.0 + 1e-6)) fail(`keyframes ${longestKeyGap.toFixed(3)} s apart`);

  // ffmpeg: one picture a message (framecrc lists each), then the snapshots' pictures as grey.
  const stream = join(root, "video.h264");
  writeFileSync(stream, Buffer.concat(units));
  const crc = spawnSync("ffmpeg", ["-v", "error", "-nostdin", "-f", "h264", "-i", stream, "-fps_mode", "passthrough",
                                   "-f", "framecrc", "-"], { encoding: "utf8" });
  const pictures = crc.stdout.split("\n").filter((l) => /^\d/.test(l)).length;
  if (crc.status !== 0 || crc.stderr.trim()) fail(`ffmpeg: ${crc.stderr.trim().split("\n")[0]}`);
  if (pictures !== video.length) fail(`ffmpeg decoded ${pictures} pictures of ${video.length} messages`);

  const matched = [];
  for (const s of h264.shots) {
    const k = stamps.findIndex((t) => Math.abs(t - s.state.t_s) < 1e-6);
    if (k >= 0) matched.push({ k, s });
  }
  if (matched.length < 3) fail(`only ${matched.length} of ${h264.shots.length} snapshots found among the recorded frames`);
  const psnrs = [];
  for (const { k, s } of matched) {
    // The k-th picture's luma plane exactly (extractplanes: no range or colour conversion).
    const r = spawnSync("ffmpeg", ["-v", "error", "-nostdin", "-f", "h264", "-i", stream, "-fps_mode", "passthrough",
                                   "-vf", `select=eq(n\\,${k}),extractplanes=y`, "-f", "rawvideo", "-pix_fmt", "gray", "-"],
                        { maxBuffer: 1 << 26 });
    const y = r.stdout;
    if (r.status !== 0 || y.length !== s.width * s.height) { fail(`picture ${k}: ${y.length} bytes (${r.stderr})`); continue; }
    const shift = Math.max(0, s.depth - 8);
    let sq = 0;
    for (let i = 0; i < y.length; ++i) {
      const d = y[i] - Math.min(255, s.samples[i] >> shift);
      sq += d * d;
    }
    psnrs.push(10 * Math.log10(255 * 255 * y.length / Math.max(sq, 1e-9)));
  }
  const worst = Math.min(...psnrs);
  if (!(worst >= 38)) fail(`PSNR ${psnrs.map((p) => p.toFixed(2)).join(", ")} dB: below 38`);

  // The JPEG recording of the same session: its frames' bytes a minute against the video's.
  const j = await messages(jpeg.path, ["/camera/image/compressed"]);
  const images = j.out["/camera/image/compressed"];
  const jpegBytes = images.reduce((a, m) => a + m.data.length, 0);
  const perMinute = (b, ms) => b / (Number(ms.at(-1).logTime - ms[0].logTime) / 1e9) * 60;
  const h264PerMin = perMinute(bytes, video), jpegPerMin = perMinute(jpegBytes, images);
  const fileRatio = statSync(h264.path).size / statSync(jpeg.path).size;
  const ratio = h264PerMin / jpegPerMin;
  if (!(ratio <= 0.1)) fail(`H.264 ${(h264PerMin / 1e6).toFixed(2)} MB/min against JPEG ${(jpegPerMin / 1e6).toFixed(2)} MB/min: ratio ${ratio.toFixed(3)} > 1/10`);
  console.log("recorded_video: " + JSON.stringify({
    frames: video.length, span_s: +(stamps.at(-1) - stamps[0]).toFixed(3), keyframes: keyframes.length, longest_keyframe_gap_s: +longestKeyGap.toFixed(3),
    psnr_dB: psnrs.map((p) => +p.toFixed(2)), h264_MB_per_min: +(h264PerMin / 1e6).toFixed(3),
    jpeg_MB_per_min: +(jpegPerMin / 1e6).toFixed(3), video_ratio: +ratio.toFixed(4),
    file_bytes: { h264: statSync(h264.path).size, jpeg: statSync(jpeg.path).size }, file_ratio: +fileRatio.toFixed(4) }));
} catch (e) {
  fail(e.stack || String(e));
} finally {
  rmSync(root, { recursive: true, force: true });
}
if (failures) process.exit(1);
console.log("recorded_video: OK");
