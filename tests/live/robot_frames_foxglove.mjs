// The platform in 3-D through the reference Foxglove client: `microcobot serve` advertises /tf
// (foxglove.FrameTransforms) and /robot/scene (foxglove.SceneUpdate); every message received
// satisfies Foxglove's own JSON schemas (npm @foxglove/schemas, validated by ajv), the frames form
// the documented tree (world -> tool -> gripper -> fingers, world -> part) with unit rotations,
// the fingers stand apart by the gripper's measured opening, the tool where the telemetry puts
// it, and the part's box has the scene's size. Run by CTest (`robot_frames_foxglove`); node --experimental-websocket.
import { spawn } from "node:child_process";
import { existsSync, mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
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
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir], { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
let urlTimer;
const url = await new Promise((resolve, reject) => {
  createInterface({ input: server.stdout }).once("line", resolve);
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
log(`${received["/tf"].length} transforms, ${received["/robot/scene"].length} scene updates`);

client.close();
server.kill("SIGINT");
const { code } = await exited;
if (code !== 0) fail(`serve exited with ${code}`);
if (failures) process.exit(1);
log("robot_frames_foxglove: the 3-D frames and bodies hold Foxglove's schemas and the platform's state");
