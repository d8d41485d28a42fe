// The platform in 3-D through the reference Foxglove client: `microcobot serve` advertises /tf
// (foxglove.FrameTransforms) and /robot/scene (foxglove.SceneUpdate); every message received
// satisfies Foxglove's own JSON schemas (npm @foxglove/schemas, validated by ajv), the frames form
// the documented tree (world -> tool -> gripper -> fingers, world -> part) with unit rotations,
// the fingers stand apart by the gripper's measured opening, the tool where the telemetry puts
// it, and the part's box has the scene's size. Then again with the parallel positioner
// (`positioner: parallel`): its base, carriages and legs join the tree, and each leg drawn (its
// frame and its cylinder's length from the scene) runs from its carriage's joint to a revolute
// joint of the platform drawn in the positioner's frame: the drawn legs hold the drawn platform.
// Run by CTest (`robot_frames_foxglove`); node --experimental-websocket.
import { spawn } from "node:child_process";
import { existsSync, mkdtempSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { connect } from "node:net";
import { createInterface } from "node:readline";
import foxglove from "@foxglove/ws-protocol";
import schemas from "@foxglove/schemas/jsonschema.js";
import AjvModule from "ajv";
const { FrameTransforms, SceneUpdate } = schemas;
const Ajv = AjvModule.default ?? AjvModule;
const { FoxgloveClient } = foxglove;

const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("robot_frames_foxglove: set MC_CLI to the microcobot binary");
  process.exit(2);
}
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(1)} s] ${msg}`);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Foxglove's schemas as published (the integers of its time type carry a "uint32" format ajv
// does not know: formats are not checked, types and required fields are).
const ajv = new Ajv({ strict: false, validateFormats: false, allErrors: true });
const validators = { "/tf": ajv.compile(FrameTransforms), "/robot/scene": ajv.compile(SceneUpdate) };

const dir = mkdtempSync(join(tmpdir(), "mc-frames-"));
async function check(label, extraArgs, parallel) {
  const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, ...extraArgs], { stdio: ["ignore", "pipe", "inherit"] });
  const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
  let urlTimer;
  const stdoutLines = [];
  const url = await new Promise((resolve, reject) => {
    const rl = createInterface({ input: server.stdout });
    rl.once("line", resolve);
    rl.on("line", (line) => stdoutLines.push(line));  // then "emulate NAME ADDR:PORT" per twin
    server.once("exit", () => reject(new Error("serve exited before printing its URL")));
    urlTimer = setTimeout(() => reject(new Error("no URL within 60 s")), 60000);
  });
  clearTimeout(urlTimer);
  const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");
  log("serve at " + url);

  const client = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const channels = new Map();
  const subs = new Map();
  const received = { "/tf": [], "/robot/scene": [], "/platform/telemetry": [], "/platform/scene": [] };
  client.on("advertise", (list) => {
    for (const c of list) {
      channels.set(c.topic, c);
      if (c.topic in received) subs.set(client.subscribe(c.id), c.topic);
    }
  });
  client.on("message", ({ subscriptionId, data }) => {
    const topic = subs.get(subscriptionId);
    const value = JSON.parse(new TextDecoder().decode(data));
    received[topic].push(value);
    const validate = validators[topic];
    if (validate && !validate(value) && received[topic].length <= 3)
      fail(`${topic}: ${ajv.errorsText(validate.errors)} in ${JSON.stringify(value).slice(0, 300)}`);
  });
  const deadline = Date.now() + 20000;
  while ((received["/tf"].length < 30 || received["/robot/scene"].length < 1 || received["/platform/scene"].length < 1) &&
         Date.now() < deadline)
    await sleep(100);

  if (parallel) {
    // A pose off home through the hexapod twin, then the frames it sends at rest there.
    const twin = stdoutLines.find((l) => l.startsWith("emulate gcs2-hexapod "));
    if (!twin) throw new Error("serve printed no gcs2-hexapod twin");
    await movePositioner(Number(twin.split(":").at(-1)), "MOV X 1 Y -0.5 Z -0.6 U 1.5 V -1 W 3");
    const n = received["/tf"].length;
    while (received["/tf"].length < n + 10) await sleep(50);
  }

  for (const [topic, schemaName] of [["/tf", "foxglove.FrameTransforms"], ["/robot/scene", "foxglove.SceneUpdate"]]) {
    const c = channels.get(topic);
    if (!c) { fail(`${topic} is not advertised`); continue; }
    if (c.schemaName !== schemaName || c.encoding !== "json") fail(`${topic} advertised as ${c.schemaName} (${c.encoding})`);
    if (received[topic].length === 0) fail(`no message on ${topic} within 20 s`);
  }

  // The frame tree.
  const lastTf = received["/tf"].at(-1);
  if (lastTf) {
    const parents = Object.fromEntries(lastTf.transforms.map((t) => [t.child_frame_id, t.parent_frame_id]));
    const expected = { tool: "world", gripper: "tool", finger_left: "gripper", finger_right: "gripper", part: "world" };
    for (const [child, parent] of Object.entries(expected))
      if (parents[child] !== parent) fail(`frame ${child}'s parent is ${parents[child]}, expected ${parent}`);
    for (const t of lastTf.transforms) {
      const q = t.rotation;
      const norm = Math.hypot(q.x, q.y, q.z, q.w);
      if (Math.abs(norm - 1) > 1e-9) fail(`${t.child_frame_id}: rotation of norm ${norm}`);
    }
  }

  // The fingers apart by the measured opening: the transforms and the telemetry are the same
  // samples, so the last of each within a few samples agree to the opening's change in that time.
  function fingerGap(tf) {
    const y = (id) => tf.transforms.find((t) => t.child_frame_id === id).translation.y;
    return y("finger_left") - y("finger_right");
  }
  const lastTel = received["/platform/telemetry"].at(-1);
  if (lastTf && lastTel) {
    const gap = fingerGap(lastTf);
    if (Math.abs(gap - lastTel.gripper_opening_m) > 2e-6)
      fail(`the fingers stand ${gap} m apart, the gripper measures ${lastTel.gripper_opening_m} m`);
    const tool = lastTf.transforms.find((t) => t.child_frame_id === "tool").translation;
    if (Math.abs(tool.x - lastTel.measured_x_m) > 5e-6 || Math.abs(tool.z - lastTel.measured_z_m) > 5e-6)
      fail(`the tool frame at ${JSON.stringify(tool)}, the telemetry measures ${lastTel.measured_x_m}, ${lastTel.measured_z_m}`);
    log(`fingers ${(gap * 1e6).toFixed(1)} um apart; tool at (${tool.x}, ${tool.y}, ${tool.z}) m`);
  }

  // The part's box has the scene's size.
  const scene = received["/platform/scene"].at(-1);
  const update = received["/robot/scene"].at(-1);
  if (scene && update) {
    const part = update.entities.find((e) => e.id === "part");
    if (!part) fail("the scene update draws no part");
    else {
      const s = part.cubes[0].size;
      if (Math.abs(s.x - scene.part_side_m) > 1e-12 || Math.abs(s.z - scene.part_height_m) > 1e-12)
        fail(`the part's box is ${JSON.stringify(s)}, the scene's part ${scene.part_side_m} x ${scene.part_height_m}`);
      if (part.frame_id !== "part") fail(`the part drawn in frame ${part.frame_id}`);
    }
    for (const id of ["finger_left", "finger_right"])
      if (!update.entities.some((e) => e.id === id && e.frame_id === id)) fail(`no ${id} drawn in its frame`);
  }
  if (parallel && lastTf && update) checkPositioner(lastTf, update, lastTel);
  log(`${label}: ${received["/tf"].length} transforms, ${received["/robot/scene"].length} scene updates`);

  client.close();
  server.kill("SIGINT");
  const { code } = await exited;
  if (code !== 0) fail(`serve exited with ${code}`);
}

// Rigid motions as {R (row-major 3 x 3), t}: a frame's transform, and its pose in the world.
function rigid(tf) {
  const { x, y, z, w } = tf.rotation, p = tf.translation;
  return { R: [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
               2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
               2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], t: [p.x, p.y, p.z] };
}
const apply = (T, v) => [0, 1, 2].map((i) => T.R[3 * i] * v[0] + T.R[3 * i + 1] * v[1] + T.R[3 * i + 2] * v[2] + T.t[i]);
function inWorld(transforms, frame, v) {
  for (let f = frame; f !== "world";) {
    const tf = transforms.find((t) => t.child_frame_id === f);
    if (!tf) throw new Error(`no frame ${f} in /tf`);
    v = apply(rigid(tf), v);
    f = tf.parent_frame_id;
  }
  return v;
}
const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
const position = (prim) => [prim.pose.position.x, prim.pose.position.y, prim.pose.position.z];

// The parallel positioner: the platform where the telemetry measures it; each leg's cylinder
// from its frame's origin, the carriage's joint (the carriage frame's origin, its sphere), along
// its z for its length, ends on one of the platform's revolute joints (the positioner entity's
// joint cylinders, in the platform's frame), each joint held by one leg.
function checkPositioner(tf, update, tel) {
  const platform = tf.transforms.find((t) => t.child_frame_id === "positioner");
  const away = Math.hypot(platform.translation.x, platform.translation.y, platform.translation.z);
  if (!(away > 1e-3)) fail(`the platform's frame is ${away} m from home: the pose move did not happen`);
  if (tel && Math.abs(platform.translation.x - tel.positioner_x_m) > 5e-6)
    fail(`the platform's frame at x ${platform.translation.x}, the telemetry measures ${tel.positioner_x_m}`);
  const entity = (id) => update.entities.find((e) => e.id === id && e.frame_id === id);
  const top = entity("positioner"), base = entity("positioner_base");
  if (!top || !base) return fail("the positioner's platform or base is not drawn in its frame");
  const joints = top.cylinders.slice(1).map((c) => inWorld(tf.transforms, "positioner", position(c)));
  if (joints.length !== 3) return fail(`the platform has ${joints.length} revolute joints drawn`);
  const held = new Set();
  for (let i = 0; i < 3; i++) {
    const leg = entity("leg_" + i), carriage = entity("carriage_" + i);
    if (!leg || !carriage) { fail(`leg ${i} or its carriage is not drawn in its frame`); continue; }
    const L = leg.cylinders[0].size.z;
    if (Math.abs(leg.cylinders[0].pose.position.z - L / 2) > 1e-12) fail(`leg ${i}'s cylinder does not start at its origin`);
    const start = inWorld(tf.transforms, "leg_" + i, [0, 0, 0]);
    const joint = inWorld(tf.transforms, "carriage_" + i, position(carriage.spheres[0]));
    if (dist(start, joint) > 1e-12) fail(`leg ${i} starts ${dist(start, joint)} m from its carriage's joint`);
    const end = inWorld(tf.transforms, "leg_" + i, [0, 0, L]);
    const gaps = joints.map((j) => dist(end, j));
    const k = gaps.indexOf(Math.min(...gaps));
    held.add(k);
    // The frames travel as JSON doubles: the tree composes them to rounding.
    if (gaps[k] > 1e-9) fail(`leg ${i} ends ${gaps[k]} m from the platform's nearest joint`);
    log(`leg ${i}: ${(L * 1e3).toFixed(3)} mm, ends ${(gaps[k] * 1e12).toFixed(1)} pm from joint ${k}`);
  }
  if (held.size !== 3) fail(`the legs hold ${held.size} distinct joints of the platform`);
}

// The hexapod twin's GCS socket: referenced, then `move` (mm, deg), waited for on target.
async function movePositioner(port, move) {
  const socket = connect(port, "127.0.0.1");
  await new Promise((resolve, reject) => { socket.once("connect", resolve); socket.once("error", reject); });
  const lines = [];
  createInterface({ input: socket }).on("line", (l) => lines.push(l.trim()));
  const ask = async (line, n = 1) => {
    socket.write(line + "\n");
    const end = Date.now() + 10000;
    while (lines.length < n && Date.now() < end) await sleep(5);
    if (lines.length < n) throw new Error(`no reply to ${line}`);
    return lines.splice(0, n);
  };
  const onTarget = async () => {
    const end = Date.now() + 60000;
    while (Date.now() < end) {
      if ((await ask("ONT? X Y Z U V W", 6)).every((l) => l.endsWith("=1"))) return;
      await sleep(100);
    }
    throw new Error("the positioner not on target within 60 s");
  };
  try {
    for (const line of ["FRF", "VLS 0.5", move]) {
      socket.write(line + "\n");
      const [err] = await ask("ERR?");
      if (err !== "0") throw new Error(`${line}: error ${err}`);
      if (line !== "VLS 0.5") await onTarget();
    }
    log(`positioner at ${(await ask("POS?", 6)).join(" ")}`);
  } finally {
    socket.destroy();
  }
}

await check("default platform", [], false);
const parallelConfig = join(dir, "parallel.yaml");
writeFileSync(parallelConfig, "devices:\n  camera:\n    driver: none\n");
// The hexapod twin puts the part on the parallel positioner (positioner: parallel) and moves it.
await check("parallel positioner", ["--config", parallelConfig, "--emulate", "gcs2-hexapod=127.0.0.1:0"], true);

if (failures) process.exit(1);
log("robot_frames_foxglove: the 3-D frames and bodies hold Foxglove's schemas and the platform's state");
