// The robot in 3-D from a recording alone: a `microcobot serve --record` session with the thesis's
// assembly (`positioner: parallel`), an operator jogging the stage, read back as Foxglove reads
// it (@mcap/core with @foxglove/wasm-zstd's zstd). Checks: /tf (foxglove.FrameTransforms) and
// /robot/scene (foxglove.SceneUpdate) are JSON channels with the schemas the live server
// advertises; every message satisfies Foxglove's own JSON schemas (@foxglove/schemas, ajv); /tf
// comes at 100 Hz, each at the log time of a telemetry sample of the same file whose channels it
// carries (the tool at the measured position, the gripper turned by the measured angle, the
// fingers +-half the measured opening, the positioner at its measured pose as q = qz qy qx); the
// tool moves; one /robot/scene (the scene did not change: the fingers, the part, the positioner's
// base, carriages, legs and platform, each in a frame /tf gives), before the first /tf; `recording
// info` lists both channels; a copy cut mid-file and recovered (`recording recover`) keeps them.
//
// Usage: MC_CLI=path/to/microcobot node --experimental-websocket recording_frames.mjs
// Run by CTest (`mcap_recording_frames`); exits 77 (skipped) when node_modules lacks the readers.
import { execFileSync, spawn } from "node:child_process";
import { existsSync, mkdirSync, mkdtempSync, readdirSync, readFileSync, rmSync, statSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import schemas from "@foxglove/schemas/jsonschema.js";
import AjvModule from "ajv";
import { loadReaders, openIndexed } from "./indexed_reader.mjs";
const Ajv = AjvModule.default ?? AjvModule;

const readers = await loadReaders("recording_frames");
const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("recording_frames: set MC_CLI to the microcobot binary");
  process.exit(2);
}
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
// Foxglove's schemas as published (its time type's "uint32" format is not one ajv knows: types
// and required fields are checked, formats not).
const ajv = new Ajv({ strict: false, validateFormats: false, allErrors: true });
const validators = { "/tf": ajv.compile(schemas.FrameTransforms), "/robot/scene": ajv.compile(schemas.SceneUpdate) };

const dir = mkdtempSync(join(tmpdir(), "mc-recframes-"));
const out = join(dir, "out");
const config = join(dir, "parallel.yaml");
writeFileSync(config, "positioner: parallel\n");
mkdirSync(out);
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", out, "--record", "--record-video", "off",
                           "--config", config], { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
const guard = setTimeout(() => { fail("took longer than 150 s"); server.kill("SIGKILL"); }, 150000);
const url = await new Promise((resolve, reject) => {
  createInterface({ input: server.stdout }).once("line", resolve);
  server.once("exit", () => reject(new Error("serve exited before printing its URL")));
});
const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");

// A raw Foxglove WebSocket client: the channels as advertised, and an operator's commands.
const advertised = new Map();
const ws = await new Promise((resolve, reject) => {
  const w = new WebSocket(wsUrl, ["foxglove.websocket.v1"]);
  w.binaryType = "arraybuffer";
  w.onmessage = (e) => {
    if (typeof e.data !== "string") return;
    const m = JSON.parse(e.data);
    if (m.op === "advertise") for (const c of m.channels) advertised.set(c.topic, c);
  };
  w.onopen = () => {
    w.send(JSON.stringify({ op: "advertise", channels: [
      { id: 1, topic: "/console/command", encoding: "json", schemaName: "c" },
      { id: 2, topic: "/console/action", encoding: "json", schemaName: "a" }] }));
    resolve(w);
  };
  w.onerror = () => reject(new Error("cannot connect to " + wsUrl));
});
const send = (channel, value) => {
  const body = new TextEncoder().encode(JSON.stringify(value));
  const frame = new Uint8Array(5 + body.length);
  frame[0] = 0x01;
  new DataView(frame.buffer).setUint32(1, channel, true);
  frame.set(body, 5);
  ws.send(frame);
};
await sleep(300);
send(2, { action: "take_control" });
await sleep(200);
for (let i = 0; i < 45; ++i) {  // a second and a half of jogging along x then y, the deadman held
  send(1, { deadman: true, velocity_m_s: i < 25 ? [60e-6, 0, 0] : [0, -40e-6, 0] });
  await sleep(33);
}
send(1, { deadman: false, velocity_m_s: [0, 0, 0] });
await sleep(500);
ws.close();
server.kill("SIGTERM");
const { code } = await exited;
if (code !== 0) fail(`serve exited ${code} on SIGTERM`);

const near = (a, b, tol) => Math.abs(a - b) <= tol;
// The telemetry's JSON keeps 10 significant digits, the frames every one.
const same = (frame, channel) => Math.abs(frame - channel) <= 1e-9 * Math.abs(channel);
// q = qz(rz) qy(ry) qx(rx), as Hamilton products of the three elementary turns.
const mul = (a, b) => ({
  w: a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
  x: a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
  y: a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
  z: a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w });
const turn = (axis, a) => ({ w: Math.cos(a / 2), x: 0, y: 0, z: 0, [axis]: Math.sin(a / 2) });
const zyx = (rx, ry, rz) => mul(mul(turn("z", rz), turn("y", ry)), turn("x", rx));

// Reads `path`; checks the frames against the telemetry of the same file. Returns what it found.
const check = async (path, label) => {
  const { reader, close } = await openIndexed(readers, path);
  const byTopic = new Map([...reader.channelsById.values()].map((c) => [c.topic, c]));
  for (const topic of ["/tf", "/robot/scene"]) {
    const c = byTopic.get(topic);
    if (!c) { fail(`${label}: no channel ${topic}`); continue; }
    const s = reader.schemasById.get(c.schemaId);
    const live = advertised.get(topic);
    if (c.messageEncoding !== "json" || s?.encoding !== "jsonschema") fail(`${label}: ${topic} is ${c.messageEncoding}/${s?.encoding}`);
    if (!live) fail(`${topic} was not advertised live`);
    else if (s?.name !== live.schemaName || new TextDecoder().decode(s.data) !== live.schema)
      fail(`${label}: ${topic}'s schema ${s?.name} is not the one the live channel advertises (${live.schemaName})`);
  }
  const topics = new Map([...reader.channelsById.values()].map((c) => [c.id, c.topic]));
  const telemetry = new Map(), tf = [], scenes = [];
  for await (const m of reader.readMessages({ logTimeOrder: true })) {
    const topic = topics.get(m.channelId);
    if (topic !== "/platform/telemetry" && topic !== "/tf" && topic !== "/robot/scene") continue;
    const j = JSON.parse(new TextDecoder().decode(m.data));
    if (topic === "/platform/telemetry") { telemetry.set(m.logTime, j); continue; }
    const validate = validators[topic];
    if (!validate(j)) fail(`${label}: ${topic}: ${ajv.errorsText(validate.errors)} in ${JSON.stringify(j).slice(0, 300)}`);
    (topic === "/tf" ? tf : scenes).push({ logTime: m.logTime, j });
  }
  await close();

  let unmatched = 0, off = 0, positioners = 0;
  const xs = new Set();
  for (const { logTime, j } of tf) {
    const s = telemetry.get(logTime);
    if (!s) { ++unmatched; continue; }
    const frames = new Map(j.transforms.map((t) => [t.child_frame_id, t]));
    const tool = frames.get("tool"), gripper = frames.get("gripper");
    const left = frames.get("finger_left"), right = frames.get("finger_right"), pos = frames.get("positioner");
    const stamp = tool.timestamp.sec + tool.timestamp.nsec * 1e-9;
    const ok =
      tool.parent_frame_id === "world" && near(stamp, s.t_s, 1e-9) &&
      same(tool.translation.x, s.measured_x_m) && same(tool.translation.y, s.measured_y_m) &&
      same(tool.translation.z, s.measured_z_m) &&
      gripper.parent_frame_id === "tool" && near(gripper.rotation.z, Math.sin(s.measured_theta_rad / 2), 1e-9) &&
      near(gripper.rotation.w, Math.cos(s.measured_theta_rad / 2), 1e-9) &&
      same(left.translation.y, s.gripper_opening_m / 2) && same(right.translation.y, -s.gripper_opening_m / 2);
    if (!ok) { if (++off <= 3) fail(`${label}: /tf at t_s ${s.t_s} is not its sample's: ${JSON.stringify(j).slice(0, 400)}`); continue; }
    xs.add(tool.translation.x);
    if (pos) {
      ++positioners;
      const q = zyx(s.positioner_rx_rad, s.positioner_ry_rad, s.positioner_rz_rad);
      const agrees = pos.parent_frame_id === "world" && same(pos.translation.x, s.positioner_x_m) &&
        same(pos.translation.y, s.positioner_y_m) && same(pos.translation.z, s.positioner_z_m) &&
        ["x", "y", "z", "w"].every((k) => near(pos.rotation[k], q[k], 1e-9));
      if (!agrees && ++off <= 3) fail(`${label}: the positioner's frame at t_s ${s.t_s} is not its measured pose: ${JSON.stringify(pos)}`);
    }
  }
  if (unmatched) fail(`${label}: ${unmatched} of ${tf.length} /tf messages have no telemetry sample at their log time`);
  if (off) fail(`${label}: ${off} /tf messages disagree with their samples`);
  if (positioners !== tf.length) fail(`${label}: ${positioners} of ${tf.length} /tf messages have the positioner's frame`);
  const times = [...telemetry.values()].map((s) => s.t_s);
  const span = times.length ? times[times.length - 1] - times[0] : 0;
  return { tf, scenes, telemetry: telemetry.size, span, xs };
};

try {
  const mcaps = readdirSync(out).filter((f) => /^recording-[0-9-]+\.mcap$/.test(f));
  if (mcaps.length !== 1) throw new Error(`expected one recording, found: ${readdirSync(out).join(", ")}`);
  const file = join(out, mcaps[0]);
  const whole = await check(file, "recording");
  const rate = whole.tf.length / whole.span;
  console.log(`recording_frames: ${whole.telemetry} telemetry samples over ${whole.span.toFixed(2)} s, ` +
              `${whole.tf.length} /tf (${rate.toFixed(1)} Hz), ${whole.scenes.length} /robot/scene, ` +
              `${whole.xs.size} distinct tool x`);
  if (!(rate > 95 && rate < 101.5)) fail(`/tf at ${rate.toFixed(1)} Hz, not 100 Hz`);
  if (whole.xs.size < 50) fail(`the tool hardly moved in the recorded frames (${whole.xs.size} positions)`);
  if (whole.scenes.length !== 1) fail(`${whole.scenes.length} /robot/scene messages for one scene`);
  else {
    if (whole.tf.length && whole.scenes[0].logTime > whole.tf[0].logTime + 300000000n)
      fail("the scene came more than 0.3 s after the first frames");
    const ids = whole.scenes[0].j.entities.map((e) => e.id).sort().join(",");
    // The fingers and the part, and the parallel positioner's base, carriages, legs and platform.
    const expected = "carriage_0,carriage_1,carriage_2,finger_left,finger_right,leg_0,leg_1,leg_2,part,positioner,positioner_base";
    if (ids !== expected) fail(`the scene draws ${ids}, not ${expected}`);
    // Every body's frame is one the recorded /tf places (a replay draws each where it is).
    const placed = new Set(["world", ...whole.tf.flatMap((m) => m.j.transforms.map((t) => t.child_frame_id))]);
    const unplaced = whole.scenes[0].j.entities.filter((e) => !placed.has(e.frame_id)).map((e) => `${e.id} in ${e.frame_id}`);
    if (unplaced.length) fail(`bodies in frames the recorded /tf never gives: ${unplaced.join(", ")}`);
  }

  // `recording info` lists both channels with their counts.
  const info = JSON.parse(execFileSync(cli, ["recording", "info", file, "--json"], { encoding: "utf8" }));
  const listed = new Map(info.channels.map((c) => [c.topic, c]));
  if (listed.get("/tf")?.messages !== whole.tf.length || listed.get("/robot/scene")?.messages !== 1)
    fail(`recording info: ${JSON.stringify(info.channels)}`);

  // A copy cut at two thirds of its bytes and recovered by hand keeps both channels, in agreement.
  const bytes = readFileSync(file);
  const part = join(dir, "copy.part");
  writeFileSync(part, bytes.subarray(0, Math.floor(bytes.length * 2 / 3)));
  const recovered = join(dir, "recovered.mcap");
  execFileSync(cli, ["recording", "recover", part, "--to", recovered, "--json"], { encoding: "utf8" });
  const cut = await check(recovered, "recovered");
  console.log(`recording_frames: recovered ${cut.telemetry} telemetry samples, ${cut.tf.length} /tf, ` +
              `${cut.scenes.length} /robot/scene (file ${statSync(recovered).size} bytes)`);
  if (!(cut.tf.length > 0 && cut.tf.length < whole.tf.length && cut.scenes.length === 1))
    fail(`the recovered copy holds ${cut.tf.length} /tf and ${cut.scenes.length} /robot/scene`);
} catch (e) {
  fail(String(e?.stack ?? e));
}
clearTimeout(guard);
rmSync(dir, { recursive: true, force: true });
console.log(`recording_frames: ${failures ? "FAILED" : "ok"}`);
process.exit(failures ? 1 : 0);
