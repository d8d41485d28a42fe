// Counts the camera frames of a `serve` recording (the 10-minute benchmark,
// docs/benchmarks.md): frames, gaps in their sequence, the camera's own dropped count (frames
// due the loop could not hand over), the span and rate, and the file's size per minute.
//   node bench/camera_recording_count.mjs out/live/recording-*.mcap
import { stat } from "node:fs/promises";
import zstd from "@foxglove/wasm-zstd";
import { openMcap } from "./serve_common.mjs";

await zstd.isLoaded;
const path = process.argv[2];
const { reader, file } = await openMcap(path, { zstd: (data, size) => zstd.decompress(data, Number(size)) });
const topic = new Map([...reader.channelsById.values()].map((c) => [c.topic, c.id]));
const counts = reader.statistics.channelMessageCounts;
// The frames as JPEG (`--record-video jpeg`) or H.264 (`h264`, the default).
const images = Number(counts.get(topic.get("/camera/image/compressed")) || 0n) +
               Number(counts.get(topic.get("/camera/video")) || 0n);
let first = null, last = null, gaps = 0, missing = 0, prev = null, t0 = null, t1 = null, dropped = 0, lat = [];
for await (const m of reader.readMessages({ topics: ["/camera/state"] })) {
  const s = JSON.parse(new TextDecoder().decode(m.data));
  if (prev !== null && s.sequence !== prev + 1) { gaps++; missing += s.sequence - prev - 1; }
  prev = s.sequence;
  if (first === null) { first = s.sequence; t0 = s.t_s; dropped = s.dropped; }
  last = s.sequence; t1 = s.t_s;
  lat.push(s.latency_ms);
  var droppedEnd = s.dropped;
}
lat.sort((a, b) => a - b);
const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))];
const bytes = (await stat(path)).size, minutes = (t1 - t0) / 60;
console.log(JSON.stringify({
  file: path, images, states: lat.length, span_s: +(t1 - t0).toFixed(3), fps: +(images / (t1 - t0)).toFixed(2),
  expected_at_30fps: Math.round((t1 - t0) * 30) + 1, recording_gaps: gaps, recording_missing: missing,
  camera_dropped_during: droppedEnd - dropped, size_MB: +(bytes / 1e6).toFixed(1),
  MB_per_minute: +(bytes / 1e6 / minutes).toFixed(1), scene_to_jpeg_ms: { p50: q(0.5), p95: q(0.95), p99: q(0.99) },
}));
await file.close();
