// Benchmark of the distributed platform: what the DDS link costs the real-time loop,
// and the link's round trip, in one run.
//
//   node --experimental-websocket bench/link_bench.mjs [--phase-s 15] [--json]
//   (MC_CLI defaults to build/release/apps/microcobot/microcobot)
//
// 1. `serve` (the whole platform in one process), alone and beside a second `serve` (two loops,
// no link), 2. `serve --role slave` + `serve --role master` on a free DDS domain: each for --phase-s seconds with one controlling client on the (master's)
// console, jogging the stage back and forth at 20 um/s (deadman held, 50 Hz). 3. The link's own
// cost at equal work: `serve` alone without a client, and slave + master without a client (the
// stage holding while the link carries its whole 1 kHz traffic both ways: targets, poses,
// forces, port energies). The loops' tick
// times come from each process's recording (every 1 kHz telemetry sample's tick_us, read back
// with @mcap/core), the first second dropped; and the link's own work on the slave's loop thread,
// timed there (the remote end's poll and publish in each 1 kHz tick, the console's
// `link_cost_us`), against the slave's tick p99 of the same run. 4. `link ping` through `link
// echo`: 5000 targets at 1 kHz, the round trip master -> slave -> master.
import { spawn, execFileSync } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import foxglove from "@foxglove/ws-protocol";
import { jogAsOperator, nextStatus, quantile, readTelemetry } from "./serve_common.mjs";
const { FoxgloveClient } = foxglove;

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? Number(process.argv[i + 1]) : fallback;
};
const phaseS = arg("--phase-s", 15);
const asJson = process.argv.includes("--json");
const cli = process.env.MC_CLI || "build/release/apps/microcobot/microcobot";
if (!existsSync(cli)) {
  console.error(`link_bench: ${cli} not found (build first, or set MC_CLI)`);
  process.exit(2);
}
const domain = String(100 + (process.pid % 100));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const log = (msg) => asJson || console.error(msg);
// A `serve` process recording into its own directory; resolves once it printed its URL.
async function serve(args) {
  const dir = mkdtempSync(join(tmpdir(), "mc-link-bench-"));
  const p = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, "--record", ...args],
                  { stdio: ["ignore", "pipe", "ignore"] });
  const exited = new Promise((resolve) => p.on("exit", (code) => resolve(code)));
  const url = await new Promise((resolve, reject) => {
    createInterface({ input: p.stdout }).once("line", resolve);
    p.once("exit", () => reject(new Error(`serve ${args.join(" ")} exited before printing its URL`)));
  });
  return { p, dir, exited, ws: url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1") };
}

// The controlling client: takes control and jogs until stopped.
async function operate(wsUrl) {
  const c = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  await new Promise((resolve) => c.on("advertise", resolve));
  const stopJog = jogAsOperator(c);
  return () => {
    stopJog();
    c.close();
  };
}

// Stops a server and reads its loop's tick times (after its first second) off its recording.
async function ticks(server) {
  server.p.kill("SIGTERM");
  const code = await server.exited;
  if (code !== 0) throw new Error(`serve exited with ${code}`);
  const name = readdirSync(server.dir).find((f) => f.endsWith(".mcap"));
  const samples = await readTelemetry(join(server.dir, name));
  const kept = samples.filter((s) => s.t_s >= samples[0].t_s + 1);
  rmSync(server.dir, { recursive: true, force: true });
  const stats = (t) => ({ samples: t.length, p50: quantile(t, 0.5), p99: quantile(t, 0.99), max: Math.max(...t) });
  // Wall clock (tick_us), and the loop thread's CPU clock (tick_cpu_us: preemption excluded).
  return { ...stats(kept.map((s) => s.tick_us)), cpu: stats(kept.map((s) => s.tick_cpu_us)) };
}

log(`single process: ${phaseS} s`);
const single = await serve([]);
let stop = await operate(single.ws);
await sleep(phaseS * 1000);
stop();
const singleTicks = await ticks(single);

// The same with a second whole platform running beside it (no link): two 10 kHz loops share the
// machine's cores, as master and slave do, so that the link's own cost is what differs.
log(`single process beside another one: ${phaseS} s`);
const peer = await serve([]);
const besidePeer = await serve([]);
stop = await operate(besidePeer.ws);
await sleep(phaseS * 1000);
stop();
const besidePeerTicks = await ticks(besidePeer);
await ticks(peer);

log(`slave + master over DDS domain ${domain}: ${phaseS} s`);
const slave = await serve(["--role", "slave", "--domain", domain]);
const master = await serve(["--role", "master", "--domain", domain]);
stop = await operate(master.ws);
await sleep(phaseS * 1000);
stop();
// The link's own work on the slave's loop thread, timed there (poll + publish per 1 kHz tick).
const slaveLinkCost = (await nextStatus(slave.ws)).link_cost_us;
const masterTicks = await ticks(master);
const slaveTicks = await ticks(slave);

// The same work with and without the link: nobody operates, every stage holds its place.
log(`single process, holding, no client: ${phaseS} s`);
const idle = await serve([]);
await sleep(phaseS * 1000);
const idleTicks = await ticks(idle);
log(`slave + master, holding, no client: ${phaseS} s`);
const idleSlave = await serve(["--role", "slave", "--domain", domain]);
const idleMaster = await serve(["--role", "master", "--domain", domain]);
await sleep(phaseS * 1000);
const idleSlaveLinkCost = (await nextStatus(idleSlave.ws)).link_cost_us;
await ticks(idleMaster);
const idleSlaveTicks = await ticks(idleSlave);

log("link ping through link echo: 5000 targets at 1 kHz");
const echo = spawn(cli, ["link", "echo", "--domain", domain, "--duration", "120"], { stdio: "ignore" });
const ping = JSON.parse(execFileSync(cli, ["link", "ping", "--domain", domain, "--count", "5000", "--json"]).toString());
echo.kill("SIGTERM");

const result = {
  phase_s: phaseS,
  tick_us: { single: singleTicks, single_beside_another: besidePeerTicks, slave: slaveTicks, master: masterTicks },
  tick_p99_ratio_slave_single: slaveTicks.p99 / singleTicks.p99,
  tick_p99_ratio_slave_single_beside_another: slaveTicks.p99 / besidePeerTicks.p99,
  tick_p99_ratio_master_single: masterTicks.p99 / singleTicks.p99,
  holding_tick_us: { single: idleTicks, slave: idleSlaveTicks },
  holding_tick_p99_ratio_slave_single: idleSlaveTicks.p99 / idleTicks.p99,
  tick_cpu_p99_ratio_slave_single: slaveTicks.cpu.p99 / singleTicks.cpu.p99,
  tick_cpu_p99_ratio_slave_single_beside_another: slaveTicks.cpu.p99 / besidePeerTicks.cpu.p99,
  holding_tick_cpu_p99_ratio_slave_single: idleSlaveTicks.cpu.p99 / idleTicks.cpu.p99,
  // The link's code on the slave's loop thread against the loop's tick p99 in the same run.
  link_cost_us: { jogging: slaveLinkCost, holding: idleSlaveLinkCost },
  link_cost_p99_to_slave_tick_p99: slaveLinkCost.p99 / slaveTicks.p99,
  holding_link_cost_p99_to_slave_tick_p99: idleSlaveLinkCost.p99 / idleSlaveTicks.p99,
  round_trip_ms: { p50: 1e3 * ping.rtt_p50_s, p99: 1e3 * ping.rtt_p99_s, max: 1e3 * ping.rtt_max_s, loss: ping.loss },
};
if (asJson) {
  console.log(JSON.stringify(result, null, 2));
} else {
  const f = (t) => `p50 ${t.p50.toFixed(2)} us, p99 ${t.p99.toFixed(2)} us, max ${t.max.toFixed(1)} us (${t.samples} samples)`;
  console.log(`loop tick, single process: ${f(singleTicks)}`);
  console.log(`loop tick, single beside another: ${f(besidePeerTicks)}`);
  console.log(`loop tick, slave:          ${f(slaveTicks)}; p99 ratio to single ${result.tick_p99_ratio_slave_single.toFixed(3)}, ` +
              `to single beside another ${result.tick_p99_ratio_slave_single_beside_another.toFixed(3)}`);
  console.log(`loop tick, master:         ${f(masterTicks)}; p99 ratio to single ${result.tick_p99_ratio_master_single.toFixed(3)}`);
  console.log(`holding, single:          ${f(idleTicks)}`);
  console.log(`holding, slave (link on): ${f(idleSlaveTicks)}; p99 ratio ${result.holding_tick_p99_ratio_slave_single.toFixed(3)}`);
  const c = (t) => `CPU p50 ${t.cpu.p50.toFixed(2)} us, p99 ${t.cpu.p99.toFixed(2)} us`;
  console.log(`loop thread CPU per tick: single ${c(singleTicks)}; beside another ${c(besidePeerTicks)}; ` +
              `slave ${c(slaveTicks)} (p99 ratio to single ${result.tick_cpu_p99_ratio_slave_single.toFixed(3)}, ` +
              `to beside another ${result.tick_cpu_p99_ratio_slave_single_beside_another.toFixed(3)})`);
  console.log(`loop thread CPU per tick, holding: single ${c(idleTicks)}; slave ${c(idleSlaveTicks)} ` +
              `(p99 ratio ${result.holding_tick_cpu_p99_ratio_slave_single.toFixed(3)})`);
  const l = (x) => `p50 ${x.p50.toFixed(2)} us, p99 ${x.p99.toFixed(2)} us, max ${x.max.toFixed(1)} us (${x.count} ticks)`;
  console.log(`the link's code on the slave's loop, jogging: ${l(slaveLinkCost)}; p99 / slave tick p99 ` +
              `${result.link_cost_p99_to_slave_tick_p99.toFixed(3)}`);
  console.log(`the link's code on the slave's loop, holding: ${l(idleSlaveLinkCost)}; p99 / slave tick p99 ` +
              `${result.holding_link_cost_p99_to_slave_tick_p99.toFixed(3)}`);
  const r = result.round_trip_ms;
  console.log(`round trip at 1 kHz: p50 ${r.p50.toFixed(3)} ms, p99 ${r.p99.toFixed(3)} ms, max ${r.max.toFixed(3)} ms, ` +
              `loss ${(100 * r.loss).toFixed(1)} %`);
}
