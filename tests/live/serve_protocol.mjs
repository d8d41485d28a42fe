// Protocol test of `microcobot serve` with the Foxglove WebSocket client of npm
// @foxglove/ws-protocol (pinned): every advertised channel carries a JSON schema its messages
// satisfy and arrives at its rate. Then hostile clients (malformed JSON, wrong types, 1e308,
// binary garbage, a 1 MB frame, a burst of 10 000 messages, 200 connections) while the
// observer keeps watching: the server keeps serving, the loop keeps its rate and nothing moves
// without the deadman. Run by CTest (`serve_protocol`); node --experimental-websocket.
import { spawn } from "node:child_process";
import { existsSync, mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import foxglove from "@foxglove/ws-protocol";
const { FoxgloveClient } = foxglove;

const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("serve_protocol: set MC_CLI to the microcobot binary");
  process.exit(2);
}
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(1)} s] ${msg}`);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const dir = mkdtempSync(join(tmpdir(), "mc-serve-"));
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir], { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
let urlTimer;
const url = await new Promise((resolve, reject) => {
  createInterface({ input: server.stdout }).once("line", resolve);
  server.once("exit", () => reject(new Error("serve exited before printing its URL")));
  urlTimer = setTimeout(() => reject(new Error("no URL within 60 s")), 60000);
});
clearTimeout(urlTimer);  // pending, it would keep node alive for its whole minute
const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");
log("serve at " + url);

// The observer: subscribes to every channel, validates every message against its schema.
const channels = new Map();
const counts = new Map();
const latest = new Map();
const schemaErrors = [];
const observer = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const subs = new Map();
observer.on("advertise", (list) => {
  for (const c of list) {
    channels.set(c.topic, c);
    if (c.encoding !== "json") continue;  // the camera's CDR channels: tests/live/camera_foxglove.mjs
    counts.set(c.topic, 0);
    subs.set(observer.subscribe(c.id), c);
  }
});
function check(schema, value, path) {
  if (schema.type === "object") {
    if (typeof value !== "object" || value === null || Array.isArray(value)) return `${path}: not an object`;
    // JSON Schema: the properties listed as required must be there (all of them when the schema
    // lists none: our channels' schemas say when some are optional).
    const required = schema.required || Object.keys(schema.properties || {});
    for (const k of required) if (!(k in value)) return `${path}.${k}: missing`;
    for (const [k, s] of Object.entries(schema.properties || {})) {
      if (!(k in value)) continue;
      const e = check(s, value[k], `${path}.${k}`);
      if (e) return e;
    }
    return null;
  }
  const types = Array.isArray(schema.type) ? schema.type : [schema.type];
  const ok = types.some((t) => (t === "number" && typeof value === "number" && Number.isFinite(value)) ||
                               (t === "boolean" && typeof value === "boolean") ||
                               (t === "string" && typeof value === "string") ||
                               (t === "null" && value === null) ||
                               (t === "array" && Array.isArray(value)) ||
                               (t === "object" && typeof value === "object" && value !== null && !Array.isArray(value)) ||
                               t === undefined);
  return ok ? null : `${path}: ${JSON.stringify(value)} is not ${types.join("|")}`;
}
observer.on("message", ({ subscriptionId, data }) => {
  const c = subs.get(subscriptionId);
  let value;
  try {
    value = JSON.parse(new TextDecoder().decode(data));
  } catch (e) {
    if (schemaErrors.length < 5) schemaErrors.push(`${c.topic}: not JSON: ${e.message}`);
    return;
  }
  counts.set(c.topic, counts.get(c.topic) + 1);
  latest.set(c.topic, value);
  const e = check(JSON.parse(c.schema), value, c.topic);
  if (e && schemaErrors.length < 5) schemaErrors.push(e);
});
observer.on("error", (e) => fail("observer error: " + e));

await sleep(1500);
for (const topic of ["/platform/telemetry", "/platform/status", "/platform/scene", "/console/feedback"]) {
  const c = channels.get(topic);
  if (!c) { fail(`${topic} not advertised`); continue; }
  if (c.encoding !== "json" || c.schemaEncoding !== "jsonschema") fail(`${topic}: ${c.encoding}/${c.schemaEncoding}`);
}
// Rates over 3 s.
for (const k of counts.keys()) counts.set(k, 0);
await sleep(3000);
const rates = Object.fromEntries([...counts].map(([k, n]) => [k, n / 3]));
log("rates [Hz]: " + JSON.stringify(rates));
const expect = { "/platform/telemetry": [50, 70], "/console/feedback": [50, 70], "/platform/status": [4, 6], "/platform/scene": [0.6, 1.5],
                 "/tf": [50, 70], "/robot/scene": [0.6, 1.5] };
for (const [topic, [lo, hi]] of Object.entries(expect))
  if (!(rates[topic] >= lo && rates[topic] <= hi)) fail(`${topic} at ${rates[topic]} Hz, expected ${lo}-${hi}`);
if (schemaErrors.length) fail("messages off their schema: " + schemaErrors.join("; "));

// Hostile clients.
const target0 = latest.get("/platform/telemetry");
const t0 = target0.t_s, wall0 = performance.now();
const raw = (proto = ["foxglove.websocket.v1"]) => new Promise((resolve) => {
  const ws = new WebSocket(wsUrl, proto);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => resolve(ws);
  ws.onerror = () => resolve(null);
});
const evil = await raw();
if (!evil) fail("a second client could not connect");
else {
  evil.send(JSON.stringify({ op: "advertise", channels: [
    { id: 1, topic: "/console/command", encoding: "json", schemaName: "x" },
    { id: 2, topic: "/console/action", encoding: "json", schemaName: "x" }] }));
  const publish = (id, text) => {
    const body = new TextEncoder().encode(text);
    const f = new Uint8Array(5 + body.length);
    f[0] = 1;
    new DataView(f.buffer).setUint32(1, id, true);
    f.set(body, 5);
    evil.send(f);
  };
  await sleep(100);
  const granted = new Promise((resolve) => {
    evil.onmessage = (e) => { if (typeof e.data === "string" && e.data.includes("control: granted")) resolve(true); };
    setTimeout(() => resolve(false), 3000);
  });
  publish(2, JSON.stringify({ action: "take_control" }));  // control, but never the deadman
  if (!(await granted)) fail("the hostile client was not granted control: the test would prove nothing");
  for (const text of ["{not json", "[]", '{"deadman": "yes"}', '{"velocity_m_s": [NaN, 0, 0]}',
                      '{"velocity_m_s": [1e308, -1e308, 1e308]}', '{"goal_m": [1e308, 0, 0]}',
                      '{"velocity_m_s": [1, 2]}', '{"deadman": false, "velocity_m_s": [1e308, 0, 0], "goal_m": [-1, -1, -1]}'])
    publish(1, text);
  publish(2, '{"action": "self_destruct"}');
  evil.send("{garbage");
  evil.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: "a", channelId: -1 }] }));
  evil.send(new Uint8Array([7, 1, 2, 3]));
  evil.send(new Uint8Array(1 << 20));  // 1 MB
  for (let i = 0; i < 10000; ++i) publish(1, '{"deadman": false, "velocity_m_s": [0.001, 0, 0]}');
}
const crowd = await Promise.all(Array.from({ length: 200 }, () => raw()));
log(`200 connections: ${crowd.filter(Boolean).length} accepted`);
await sleep(2000);
for (const ws of crowd) ws && ws.close();
evil && evil.close();

const after = latest.get("/platform/telemetry");
const loopRate = (after.t_s - t0) / ((performance.now() - wall0) / 1000);
log(`loop time ran at ${loopRate.toFixed(3)}x the wall clock during the attack`);
if (!(loopRate > 0.9 && loopRate < 1.1)) fail(`the loop's time ran at ${loopRate}x the wall clock`);
for (const axis of ["x", "y", "z"])
  if (after[`target_${axis}_m`] !== target0[`target_${axis}_m`]) fail(`target ${axis} moved without the deadman`);
for (const k of counts.keys()) counts.set(k, 0);
await sleep(1000);
if (!(counts.get("/platform/telemetry") >= 45)) fail("the observer stopped receiving telemetry after the attack");
const late = await raw();
if (!late) fail("no new client accepted after the attack");
else late.close();
observer.close();

server.kill("SIGTERM");
const { code } = await exited;
if (code !== 0) fail(`serve exited ${code} on SIGTERM`);
if (failures) {
  console.error(`serve_protocol: ${failures} failure(s)`);
  process.exit(1);
}
log("serve_protocol: channels, schemas and rates held, and the server outlived its hostile clients");
