// Benchmark of `microcobot serve`: the command-to-target latency on loopback and
// what eight telemetry clients cost the real-time loop, in one run.
//
//   node --experimental-websocket bench/serve_bench.mjs [--phase-s 15] [--clients 8] [--json]
//   (MC_CLI defaults to build/release/apps/microcobot/microcobot)
//
// One controlling client sends the console's command (deadman held, a slow jog back and forth)
// at 50 Hz for the whole run. Phase A: nobody else is connected. Phase B: eight more clients
// subscribe to every channel (telemetry and feedback at 60 Hz, status, scene). The loop's tick
// times come from the recording (every 1 kHz telemetry sample's tick_us, read back with
// @mcap/core), split by phase, each phase's first second dropped; the latency (server receipt
// to the loop tick that applies the command) from the status the server publishes.
import { spawn } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import foxglove from "@foxglove/ws-protocol";
import { jogAsOperator, quantile, readTelemetry } from "./serve_common.mjs";
const { FoxgloveClient } = foxglove;

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? Number(process.argv[i + 1]) : fallback;
};
const phaseS = arg("--phase-s", 15);
const nClients = arg("--clients", 8);
const asJson = process.argv.includes("--json");
const cli = process.env.MC_CLI || "build/release/apps/microcobot/microcobot";
if (!existsSync(cli)) {
  console.error(`serve_bench: ${cli} not found (build first, or set MC_CLI)`);
  process.exit(2);
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const log = (msg) => asJson || console.error(msg);

const dir = mkdtempSync(join(tmpdir(), "mc-serve-bench-"));
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, "--record"],
                     { stdio: ["ignore", "pipe", "ignore"] });
const exited = new Promise((resolve) => server.on("exit", (code) => resolve(code)));
const url = await new Promise((resolve, reject) => {
  createInterface({ input: server.stdout }).once("line", resolve);
  server.once("exit", () => reject(new Error("serve exited before printing its URL")));
});
const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");

// A client: subscribes to `topics` (all when null), counts messages, keeps the latest status.
function connect(topics) {
  return new Promise((resolve) => {
    const c = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    const subs = new Map();
    const state = { client: c, received: 0, status: null };
    c.on("advertise", (list) => {
      for (const ch of list) if (!topics || topics.includes(ch.topic)) subs.set(c.subscribe(ch.id), ch.topic);
      resolve(state);
    });
    c.on("message", ({ subscriptionId, data }) => {
      state.received++;
      if (subs.get(subscriptionId) === "/platform/status") state.status = JSON.parse(new TextDecoder().decode(data));
    });
  });
}

const controller = await connect(["/platform/status"]);
const stopJog = jogAsOperator(controller.client);

const liveTime = async () => {
  const before = controller.status;
  while (controller.status === before) await sleep(20);
  return controller.status.t_s;
};
await sleep(1000);
const aStart = await liveTime();
log(`phase A: the controlling client only, ${phaseS} s`);
await sleep(phaseS * 1000);
const aEnd = await liveTime();
log(`phase B: ${nClients} more clients on every channel, ${phaseS} s`);
const observers = await Promise.all(Array.from({ length: nClients }, () => connect(null)));
const bStart = await liveTime();
const counted0 = observers.map((o) => o.received);
const wall0 = performance.now();
await sleep(phaseS * 1000);
const perClientHz = observers.map((o, i) => (o.received - counted0[i]) / ((performance.now() - wall0) / 1000));
const bEnd = await liveTime();
const latency = controller.status.command_latency_ms;
stopJog();
for (const o of observers) o.client.close();
controller.client.close();
server.kill("SIGTERM");
const code = await exited;
if (code !== 0) {
  console.error(`serve_bench: serve exited with ${code}`);
  process.exit(1);
}

// The loop's tick times of each phase, from the recording: on the wall clock (tick_us) and on
// the loop thread's CPU clock (tick_cpu_us: the tick and its wake-up, preemption excluded).
const name = readdirSync(dir).find((f) => f.endsWith(".mcap"));
const ticks = { A: { wall: [], cpu: [] }, B: { wall: [], cpu: [] } };
for (const s of await readTelemetry(join(dir, name))) {
  const phase = s.t_s >= aStart + 1 && s.t_s < aEnd ? ticks.A : s.t_s >= bStart + 1 && s.t_s < bEnd ? ticks.B : null;
  if (phase) phase.wall.push(s.tick_us), phase.cpu.push(s.tick_cpu_us);
}
rmSync(dir, { recursive: true, force: true });
const stats = (v) => ({ samples: v.length, p50: quantile(v, 0.5), p99: quantile(v, 0.99) });
const result = {
  phase_s: phaseS,
  clients: nClients,
  command_latency_ms: { p50: latency.p50, p99: latency.p99, max: latency.max, count: latency.count },
  telemetry_clients_msgs_per_s: { min: Math.min(...perClientHz), max: Math.max(...perClientHz) },
  tick_us: { without_clients: stats(ticks.A.wall), with_clients: stats(ticks.B.wall) },
  tick_cpu_us: { without_clients: stats(ticks.A.cpu), with_clients: stats(ticks.B.cpu) },
};
result.tick_p99_ratio_with_without = result.tick_us.with_clients.p99 / result.tick_us.without_clients.p99;
result.tick_cpu_p99_ratio_with_without = result.tick_cpu_us.with_clients.p99 / result.tick_cpu_us.without_clients.p99;
if (asJson) {
  console.log(JSON.stringify(result, null, 2));
} else {
  console.log(`command-to-target latency: p50 ${latency.p50.toFixed(3)} ms, p99 ${latency.p99.toFixed(3)} ms ` +
              `(max ${latency.max.toFixed(3)} ms, ${latency.count} commands)`);
  console.log(`${nClients} clients: ${result.telemetry_clients_msgs_per_s.min.toFixed(1)}-` +
              `${result.telemetry_clients_msgs_per_s.max.toFixed(1)} messages/s each`);
  for (const [label, t, ratio] of [["wall clock", result.tick_us, result.tick_p99_ratio_with_without],
                                    ["loop thread CPU", result.tick_cpu_us, result.tick_cpu_p99_ratio_with_without]]) {
    console.log(`loop tick (${label}) without clients: p50 ${t.without_clients.p50.toFixed(2)} us, ` +
                `p99 ${t.without_clients.p99.toFixed(2)} us (${t.without_clients.samples} samples)`);
    console.log(`loop tick (${label}) with ${nClients} clients: p50 ${t.with_clients.p50.toFixed(2)} us, ` +
                `p99 ${t.with_clients.p99.toFixed(2)} us (${t.with_clients.samples} samples); p99 ratio ${ratio.toFixed(3)}`);
  }
}
