// The recordings' H.264 over a long session (docs/benchmarks.md, "The camera recorded as H.264"):
// goal zero dropped frames over 10 minutes at 30 fps, and the loop's tick p99 while the camera is
// recorded as H.264 within 1.1x of the same run's without recording.
//
//   MC_CLI=build/release/apps/microcobot/microcobot node --experimental-websocket \
//     bench/recording_video_bench.mjs [--minutes 10] [--baseline-seconds 60]
//
// One `serve` (its defaults: the pick-and-place, 1280 x 1024 at 30 fps) with an operator jogging
// the stage the whole run (deadman held, the console's 50 Hz heartbeat) and a viewer subscribed
// to the telemetry and the camera's calibration: the camera forms every frame in every phase (as
// while anyone watches it), and the viewer's 60 Hz telemetry samples carry the loop's tick_us in
// every phase alike. Phases of one run, by the console's record requests:
//   A  --baseline-seconds without recording;
//   B  --minutes recording with `"video": "h264"` (the frames encoded by the recording's writer);
//   A' again without recording (a baseline on both sides of B: a drift of the machine shows);
//   C  --baseline-seconds recording with `"video": "jpeg"`: the JPEG frames' bytes, for the ratio.
// Ticks: the p99 of each phase's tick_us samples (its first 2 s left out). Frames: B's
// /camera/state (sequence gaps, the camera's own dropped count), the frames due at 30 fps over
// B's span that were not formed, and B's events (messages the writer dropped).
import { readdirSync, mkdtempSync, rmSync, statSync } from "node:fs";
import { spawn } from "node:child_process";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import zstd from "@foxglove/wasm-zstd";
import foxglove from "@foxglove/ws-protocol";
import { openMcap, quantile } from "./serve_common.mjs";
const { FoxgloveClient } = foxglove;

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? Number(process.argv[i + 1]) : fallback;
};
const minutes = arg("--minutes", 10), baselineS = arg("--baseline-seconds", 60);
if (!(minutes > 0 && minutes <= 120) || !(baselineS >= 10 && baselineS <= 600)) {
  console.error(`recording_video_bench: --minutes ${minutes} (0, 120], --baseline-seconds ${baselineS} [10, 600]`);
  process.exit(2);
}
const cli = process.env.MC_CLI || "build/release/apps/microcobot/microcobot";
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const dir = mkdtempSync(join(tmpdir(), "mc-video-bench-"));
await zstd.isLoaded;

const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir], { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code) => resolve(code)));
const url = await new Promise((resolve) => createInterface({ input: server.stdout }).once("line", resolve));
const client = new FoxgloveClient({
  ws: new WebSocket(url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1"), [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
let phaseTicks = null;  // the running phase's tick_us samples
const subscriptions = new Map();
client.on("advertise", (list) => {
  for (const c of list)
    if (["/platform/telemetry", "/platform/status", "/camera/camera_info"].includes(c.topic))
      subscriptions.set(client.subscribe(c.id), c.topic);
});
let camera = { frames: 0, dropped: 0 };  // the latest status's
client.on("message", ({ subscriptionId, data }) => {
  const topic = subscriptions.get(subscriptionId);
  if (topic === "/platform/status") camera = JSON.parse(new TextDecoder().decode(data)).camera ?? camera;
  if (topic !== "/platform/telemetry" || !phaseTicks) return;
  phaseTicks.push(JSON.parse(new TextDecoder().decode(data)).tick_us);
});
await new Promise((resolve) => client.on("open", resolve));
const command = client.advertise({ topic: "/console/command", encoding: "json", schemaName: "microcobot.Command" });
const action = client.advertise({ topic: "/console/action", encoding: "json", schemaName: "microcobot.Action" });
const send = (ch, obj) => client.sendMessage(ch, new TextEncoder().encode(JSON.stringify(obj)));
send(action, { action: "take_control" });
let sent = 0;
const jog = setInterval(() => {  // 20 um/s, 2 s each way, as bench/serve_common.mjs's operator
  send(command, { deadman: true, velocity_m_s: [Math.floor(sent / 100) % 2 ? -20e-6 : 20e-6, 0, 0] });
  sent++;
}, 20);

const ticks = {}, recordings = [], rates = {};
async function phase(label, video, seconds) {
  const before = new Set(readdirSync(dir));
  if (video) send(action, { action: "record_start", video });
  await sleep(2000);
  phaseTicks = ticks[label] = [];
  const c0 = camera, w0 = performance.now();
  await sleep((seconds - 2) * 1000);
  phaseTicks = null;
  const s = (performance.now() - w0) / 1000;
  rates[label] = { frames_per_s: +((camera.frames - c0.frames) / s).toFixed(2), camera_dropped: camera.dropped - c0.dropped };
  if (video) {
    send(action, { action: "record_stop" });
    await sleep(1500);  // closed and renamed
    const name = readdirSync(dir).find((f) => !before.has(f) && /^recording-[0-9-]+\.mcap$/.test(f));
    if (!name) throw new Error(`phase ${label}: no recording`);
    recordings.push({ label, video, path: join(dir, name) });
  }
  console.error(`recording_video_bench: phase ${label} (${video || "no recording"}, ${seconds} s): ` +
                `${ticks[label].length} tick samples, p99 ${quantile(ticks[label], 0.99)} us`);
}
await sleep(3000);  // the platform built, the operator in control, the camera forming frames
await phase("A", null, baselineS);
await phase("B", "h264", minutes * 60);
await phase("A'", null, baselineS);
await phase("C", "jpeg", baselineS);
clearInterval(jog);
client.close();
server.kill("SIGTERM");
const code = await exited;

// Each recording: its ticks, its camera frames, its bytes.
async function read(r) {
  const { reader, file } = await openMcap(r.path, { zstd: (data, size) => zstd.decompress(data, Number(size)) });
  const topics = new Map([...reader.channelsById.values()].map((c) => [c.id, c.topic]));
  const ticks = [], out = { ticks, frames: 0, gaps: 0, missing: 0, cameraDropped: 0, writerDropped: 0, videoBytes: 0 };
  let prev = null, firstDropped = null, lastDropped = null, t0 = null, t1 = null, v0 = null, v1 = null, s0 = null, s1 = null;
  for await (const m of reader.readMessages({ logTimeOrder: false })) {
    const topic = topics.get(m.channelId);
    const text = () => new TextDecoder().decode(m.data);
    if (topic === "/platform/telemetry") {
      const s = JSON.parse(text());
      ticks.push(s.tick_us);
      t0 ??= s.t_s;
      t1 = s.t_s;
    } else if (topic === "/camera/state") {
      const s = JSON.parse(text());
      if (prev !== null && s.sequence !== prev + 1) { out.gaps++; out.missing += s.sequence - prev - 1; }
      prev = s.sequence;
      firstDropped ??= s.dropped;
      lastDropped = s.dropped;
      s0 ??= s.t_s;
      s1 = s.t_s;
      out.frames++;
    } else if (topic === "/camera/video" || topic === "/camera/image/compressed") {
      out.videoBytes += topic === "/camera/video" ? Buffer.from(JSON.parse(text()).data, "base64").length : m.data.length;
      v0 ??= m.logTime;
      v1 = m.logTime;
    } else if (topic === "/events") {
      const e = JSON.parse(text());
      if (e.kind === "dropped" || e.kind === "video") out.writerDropped++;
    }
  }
  await file.close();
  out.cameraDropped = lastDropped === null ? 0 : lastDropped - firstDropped;
  out.seconds = t1 - t0;
  out.stateSpan = s1 === null ? 0 : s1 - s0;
  out.videoBytesPerMinute = v1 > v0 ? out.videoBytes / (Number(v1 - v0) / 1e9) * 60 : 0;
  out.fileBytesPerMinute = statSync(r.path).size / out.seconds * 60;
  return out;
}
const got = {};
for (const r of recordings) got[r.label] = await read(r);
rmSync(dir, { recursive: true, force: true });

const baseline = [...ticks.A, ...ticks["A'"]];
const p99 = (v) => quantile(v, 0.99);
const B = got.B, C = got.C;
const expected = Math.floor(B.stateSpan * 30) + 1;
const result = {
  minutes_recorded_h264: +(B.seconds / 60).toFixed(2),
  frames: B.frames, frames_due_at_30fps: expected, frames_not_formed: Math.max(0, expected - B.frames - B.missing),
  recording_gaps: B.gaps, recording_missing: B.missing, camera_dropped: B.cameraDropped,
  writer_dropped_events: B.writerDropped,
  tick_us_p99: { without_A: p99(ticks.A), h264_B: p99(ticks.B), without_A2: p99(ticks["A'"]), jpeg_C: p99(ticks.C),
                 h264_B_every_1kHz_sample: p99(B.ticks) },
  camera_per_phase: rates,
  tick_samples: { A: ticks.A.length, B: ticks.B.length, "A'": ticks["A'"].length },
  tick_p99_ratio_h264_over_without: p99(ticks.B) / p99(baseline),
  h264_MB_per_min: B.videoBytesPerMinute / 1e6, jpeg_MB_per_min: C.videoBytesPerMinute / 1e6,
  video_ratio: B.videoBytesPerMinute / C.videoBytesPerMinute,
  file_MB_per_min: { h264: B.fileBytesPerMinute / 1e6, jpeg: C.fileBytesPerMinute / 1e6 },
  file_ratio_h264_over_jpeg: B.fileBytesPerMinute / C.fileBytesPerMinute,
  serve_exit: code,
};
console.log(JSON.stringify(result, null, 1));
const dropped = B.missing + B.cameraDropped + B.writerDropped + result.frames_not_formed;
const ok = dropped === 0 && result.tick_p99_ratio_h264_over_without <= 1.1 && code === 0;
console.log(`recording_video_bench: ${dropped} dropped frames over ${result.minutes_recorded_h264} min, tick p99 ratio ` +
            `${result.tick_p99_ratio_h264_over_without.toFixed(3)}, H.264/JPEG ${result.video_ratio.toFixed(4)}: ` +
            (ok ? "goals met" : "goals NOT met"));
process.exit(ok ? 0 : 1);
