// Soak of `microcobot serve`: the live platform under a lab's long session, watched for leaks.
//
//   node --experimental-websocket bench/soak.mjs [--minutes 30] [--check] [--json]
//   (MC_CLI defaults to build/release/apps/microcobot/microcobot)
//
// One `serve` records with its camera on while: an operator jogs the stage (deadman held, the
// console's 50 Hz heartbeat), four Foxglove clients subscribe to every channel (the camera's
// images too), and a PI GCS 2.0 client on the vendor-protocol twin asks `POS?` at 100 Hz. Every
// minute it reports the server's resident memory and its peak, open file descriptors and threads
// (/proc), the loop's tick p99 and overruns and the camera's dropped frames (the status), the
// recording's bytes, and the GCS client's replies. With --check it exits 1 when, after the first
// minute, resident memory grows by more than 2 % (5 % for runs under 10 minutes: the allocator's
// arenas settle over minutes), descriptors or threads change, or GCS queries go unanswered. The
// timing figures are reported, not judged: `make test` runs the 3-minute version beside other tests.
import { spawn } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync, statSync } from "node:fs";
import { connect as tcpConnect } from "node:net";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import foxglove from "@foxglove/ws-protocol";
import { jogAsOperator } from "./serve_common.mjs";
const { FoxgloveClient } = foxglove;

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i > 0 ? Number(process.argv[i + 1]) : fallback;
};
const minutes = arg("--minutes", 30);
const check = process.argv.includes("--check");
const asJson = process.argv.includes("--json");
const cli = process.env.MC_CLI || "build/release/apps/microcobot/microcobot";
if (!existsSync(cli)) {
  console.error(`soak: ${cli} not found (build first, or set MC_CLI)`);
  process.exit(2);
}
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const log = (msg) => asJson || console.error(msg);

const dir = mkdtempSync(join(tmpdir(), "mc-soak-"));
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, "--record", "--emulate", "gcs2=127.0.0.1:0"],
                     { stdio: ["ignore", "pipe", "ignore"] });
const exited = new Promise((resolve) => server.on("exit", (code) => resolve(code)));
const lines = createInterface({ input: server.stdout });
const printed = [];
const ready = new Promise((resolve, reject) => {
  lines.on("line", (l) => {
    printed.push(l);
    if (printed.length === 2) resolve();
  });
  server.once("exit", () => reject(new Error("serve exited before printing its URL and twin")));
});
await ready;
const url = printed[0];
const [gcsHost, gcsPort] = printed[1].split(" ")[2].split(":");
const wsUrl = url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");

// A Foxglove client subscribed to every channel; keeps the latest status.
const clientOf = () => new Promise((resolve) => {
  const c = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const state = { client: c, received: 0, status: null, statusId: -1 };
  c.on("advertise", (list) => {
    for (const ch of list) {
      const id = c.subscribe(ch.id);
      if (ch.topic === "/platform/status") state.statusId = id;
    }
    resolve(state);
  });
  c.on("message", ({ subscriptionId, data }) => {
    state.received++;
    if (subscriptionId === state.statusId) state.status = JSON.parse(new TextDecoder().decode(data));
  });
  c.on("error", () => {});
});
const operator = await clientOf();
const stopJog = jogAsOperator(operator.client);
const watchers = [];
for (let i = 0; i < 4; ++i) watchers.push(await clientOf());

// The GCS 2.0 client: POS? at 100 Hz, each reply counted.
const gcs = { asked: 0, answered: 0 };
const socket = tcpConnect(Number(gcsPort), gcsHost);
await new Promise((resolve, reject) => { socket.once("connect", resolve); socket.once("error", reject); });
createInterface({ input: socket }).on("line", (l) => { if (!l.endsWith(" ")) gcs.answered++; });
const poll = setInterval(() => { socket.write("POS?\n"); gcs.asked++; }, 10);

const proc = () => {
  const status = readFileSync(`/proc/${server.pid}/status`, "utf8");
  const kb = (key) => Number(status.match(new RegExp(`^${key}:\\s+(\\d+)`, "m"))[1]);
  return { rss_MB: kb("VmRSS") / 1024, hwm_MB: kb("VmHWM") / 1024, threads: kb("Threads"),
           fds: readdirSync(`/proc/${server.pid}/fd`).length };
};
const recordingBytes = () => readdirSync(dir).reduce((n, f) => n + statSync(join(dir, f)).size, 0);

const rows = [];
const t0 = Date.now();
let lastDropped = 0, lastOverruns = 0, lastAnswered = 0, lastAsked = 0;
for (let m = 1; m <= minutes; ++m) {
  await sleep(t0 + m * 60000 - Date.now());
  const s = operator.status || {};
  const p = proc();
  const dropped = s.camera ? s.camera.dropped : 0;
  const row = { minute: m, ...p, tick_p99_us: s.tick_p99_us, overruns: (s.overruns ?? 0) - lastOverruns,
                dropped_frames: dropped - lastDropped, recording_MB: recordingBytes() / 1e6,
                gcs_replies: gcs.answered - lastAnswered, gcs_asked: gcs.asked - lastAsked };
  lastDropped = dropped;
  lastOverruns = s.overruns ?? 0;
  lastAnswered = gcs.answered;
  lastAsked = gcs.asked;
  rows.push(row);
  log(`[${m} min] rss ${row.rss_MB.toFixed(1)} MB (peak ${row.hwm_MB.toFixed(1)}), fds ${row.fds}, threads ${row.threads}, ` +
      `tick p99 ${row.tick_p99_us} us, overruns ${row.overruns}, dropped frames ${row.dropped_frames}, ` +
      `recording ${row.recording_MB.toFixed(0)} MB, GCS replies ${row.gcs_replies} of ${row.gcs_asked}`);
}
clearInterval(poll);
socket.destroy();
stopJog();
for (const w of [operator, ...watchers]) w.client.close();
server.kill("SIGTERM");
const code = await exited;
rmSync(dir, { recursive: true, force: true });

const problems = [];
if (code !== 0) problems.push(`serve exited ${code} on SIGTERM`);
if (rows.length >= 2) {
  const first = rows[0], last = rows[rows.length - 1];
  const allowed = minutes >= 10 ? 0.02 : 0.05;
  const growth = last.rss_MB / first.rss_MB - 1;
  if (growth > allowed) problems.push(`resident memory grew ${(100 * growth).toFixed(1)} % after the first minute (at most ${100 * allowed} %)`);
  if (rows.some((r) => r.fds !== first.fds)) problems.push(`file descriptors changed: ${rows.map((r) => r.fds).join(", ")}`);
  if (rows.some((r) => r.threads !== first.threads)) problems.push(`threads changed: ${rows.map((r) => r.threads).join(", ")}`);
  // Every query answered (a few in flight at the minute's edge).
  if (rows.some((r) => Math.abs(r.gcs_replies - r.gcs_asked) > 10 || r.gcs_asked < 1000))
    problems.push(`the GCS client went unanswered: ${rows.map((r) => `${r.gcs_replies}/${r.gcs_asked}`).join(", ")}`);
}
const result = { minutes, rows, problems };
if (asJson) console.log(JSON.stringify(result));
for (const p of problems) console.error("soak: " + p);
process.exit(check && problems.length ? 1 : 0);
