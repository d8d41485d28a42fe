// Soak of `microcobot serve`: the live platform under a lab's long session, watched for leaks.
//
//   node --experimental-websocket bench/soak.mjs [--minutes 30] [--check] [--json] [--no-dds]
//                                                [--domain N]
//   (MC_CLI defaults to build/release/apps/microcobot/microcobot)
//
// The soaked `serve` is the slave of a distributed platform (`--role slave`, DDS domain N on
// loopback: 1 + pid % 200 unless given) and records with its camera on while: a second process,
// `serve --role master`, drives it over the DDS link, its operator jogging the stage (deadman
// held, the console's 50 Hz heartbeat); four Foxglove clients subscribe to every channel of the
// slave (the camera's images too); and a PI GCS 2.0 client on the slave's vendor-protocol twin
// asks `POS?` at 100 Hz. With --no-dds the soaked `serve` runs alone and the operator jogs its
// own console.
//
// Every minute it reports the slave's resident memory (the median of the minute's 2-s samples) and
// its peak, open file descriptors and threads (/proc), the loop's tick p99 and overruns, the
// camera's dropped frames (the status; and when, to the 2-s sample), the recording's bytes, the
// GCS client's replies, the master's memory, descriptors and threads, and the share of the slave's
// statuses that heard its master. With --check it exits 1 when, after the first minute, either process's median resident
// memory grows by more than 2 % (5 % for runs under 10 minutes: the allocator's arenas settle over
// minutes), descriptors or threads change, GCS queries go unanswered, or the slave heard its
// master in less than 90 % of a minute's statuses. The timing figures are reported, not judged:
// `make test` runs the 3-minute version beside other tests.
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
const dds = !process.argv.includes("--no-dds");
const domain = arg("--domain", 1 + (process.pid % 200));
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
const children = [];
// A `serve` process; resolves with it and the lines it printed first (its URL, then its twins).
const startServe = (args, linesWanted) => {
  const child = spawn(cli, ["serve", "--listen", "127.0.0.1:0", ...args], { stdio: ["ignore", "pipe", "ignore"] });
  children.push(child);
  const exited = new Promise((resolve) => child.on("exit", (code) => resolve(code)));
  const printed = [];
  return new Promise((resolve, reject) => {
    createInterface({ input: child.stdout }).on("line", (l) => {
      printed.push(l);
      if (printed.length === linesWanted) resolve({ child, exited, printed });
    });
    child.once("exit", () => reject(new Error(`serve ${args.join(" ")} exited before printing ${linesWanted} lines`)));
  });
};
const role = dds ? ["--role", "slave", "--domain", String(domain)] : [];
const slave = await startServe([...role, "--out", join(dir, "slave"), "--record", "--emulate", "gcs2=127.0.0.1:0"], 2);
const master = dds ? await startServe(["--role", "master", "--domain", String(domain), "--out", join(dir, "master")], 1)
                   : null;
const server = slave.child;
const url = slave.printed[0];
const [gcsHost, gcsPort] = slave.printed[1].split(" ")[2].split(":");
const wsOf = (u) => u.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1");
const wsUrl = wsOf(url);

// A Foxglove client subscribed to every channel; keeps the latest status.
const clientOf = (to = wsUrl) => new Promise((resolve) => {
  const c = new FoxgloveClient({ ws: new WebSocket(to, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
  const state = { client: c, received: 0, status: null, statusId: -1, statuses: 0, fresh: 0 };
  c.on("advertise", (list) => {
    for (const ch of list) {
      const id = c.subscribe(ch.id);
      if (ch.topic === "/platform/status") state.statusId = id;
    }
    resolve(state);
  });
  c.on("message", ({ subscriptionId, data }) => {
    state.received++;
    if (subscriptionId !== state.statusId) return;
    state.status = JSON.parse(new TextDecoder().decode(data));
    state.statuses++;
    if (state.status.console_fresh === true) state.fresh++;
  });
  c.on("error", () => {});
});
// The operator at the master's console (over the link), or at the slave's own without it.
const operator = await clientOf(master ? wsOf(master.printed[0]) : wsUrl);
const stopJog = jogAsOperator(operator.client);
const watchers = [];
for (let i = 0; i < 4; ++i) watchers.push(await clientOf());
const slaveStatus = () => watchers[0].status || {};

// The GCS 2.0 client: POS? at 100 Hz, each reply counted.
const gcs = { asked: 0, answered: 0 };
const socket = tcpConnect(Number(gcsPort), gcsHost);
await new Promise((resolve, reject) => { socket.once("connect", resolve); socket.once("error", reject); });
createInterface({ input: socket }).on("line", (l) => { if (!l.endsWith(" ")) gcs.answered++; });
const poll = setInterval(() => { socket.write("POS?\n"); gcs.asked++; }, 10);

const proc = (pid) => {
  const status = readFileSync(`/proc/${pid}/status`, "utf8");
  const kb = (key) => Number(status.match(new RegExp(`^${key}:\\s+(\\d+)`, "m"))[1]);
  return { rss_MB: kb("VmRSS") / 1024, hwm_MB: kb("VmHWM") / 1024, threads: kb("Threads"),
           fds: readdirSync(`/proc/${pid}/fd`).length };
};
const slaveDir = join(dir, "slave");
const recordingBytes = () => readdirSync(slaveDir).reduce((n, f) => n + statSync(join(slaveDir, f)).size, 0);

// Resident memory is sampled every 2 s and judged by each minute's median (the first minute's from
// its 30th second, after start-up): a leak moves the median minute after minute, while a burst (the
// recorder's bounded queue or a client's send buffer filling for a few seconds on a loaded machine)
// moves a few samples.
const kSampleMs = 2000;
const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length ? (s[(s.length - 1) >> 1] + s[s.length >> 1]) / 2 : NaN;
};
const rows = [];
const t0 = Date.now();
let lastDropped = 0, lastOverruns = 0, lastAnswered = 0, lastAsked = 0, lastStatuses = 0, lastFresh = 0;
let seenDropped = 0;
for (let m = 1; m <= minutes; ++m) {
  const rss = [], masterRss = [], dropsAt = [];
  for (let t = t0 + (m - 1) * 60000; t < t0 + m * 60000; t += kSampleMs) {
    await sleep(t - Date.now());
    // When the camera dropped frames: the seconds since the start of each 2-s sample that saw some.
    const d = slaveStatus().camera?.dropped ?? 0;
    if (d > seenDropped) dropsAt.push([Math.round((t - t0) / 1000), d - seenDropped]);
    seenDropped = Math.max(seenDropped, d);
    if (m === 1 && t < t0 + 30000) continue;
    rss.push(proc(server.pid).rss_MB);
    if (master) masterRss.push(proc(master.child.pid).rss_MB);
  }
  await sleep(t0 + m * 60000 - Date.now());
  const s = slaveStatus();
  const p = { ...proc(server.pid), rss_median_MB: median(rss) };
  const mp = master ? { ...proc(master.child.pid), rss_median_MB: median(masterRss) } : null;
  const dropped = s.camera ? s.camera.dropped : 0;
  const row = { minute: m, ...p, tick_p99_us: s.tick_p99_us, overruns: (s.overruns ?? 0) - lastOverruns,
                dropped_frames: dropped - lastDropped, dropped_at_s: dropsAt, recording_MB: recordingBytes() / 1e6,
                gcs_replies: gcs.answered - lastAnswered, gcs_asked: gcs.asked - lastAsked,
                ...(mp && { master_rss_MB: mp.rss_MB, master_rss_median_MB: mp.rss_median_MB, master_fds: mp.fds, master_threads: mp.threads,
                            // the share of the slave's 5 Hz statuses that heard the master
                            master_heard_pct: 100 * (watchers[0].fresh - lastFresh) /
                                              Math.max(1, watchers[0].statuses - lastStatuses) }) };
  lastStatuses = watchers[0].statuses;
  lastFresh = watchers[0].fresh;
  lastDropped = dropped;
  lastOverruns = s.overruns ?? 0;
  lastAnswered = gcs.answered;
  lastAsked = gcs.asked;
  rows.push(row);
  log(`[${m} min] rss median ${row.rss_median_MB.toFixed(1)} MB (now ${row.rss_MB.toFixed(1)}, peak ${row.hwm_MB.toFixed(1)}), fds ${row.fds}, threads ${row.threads}, ` +
      `tick p99 ${row.tick_p99_us} us, overruns ${row.overruns}, dropped frames ${row.dropped_frames}` +
      (dropsAt.length ? ` (at ${dropsAt.map(([t, n]) => `${n} by ${t} s`).join(", ")})` : "") + ", " +
      `recording ${row.recording_MB.toFixed(0)} MB, GCS replies ${row.gcs_replies} of ${row.gcs_asked}` +
      (mp ? `; master rss median ${mp.rss_median_MB.toFixed(1)} MB, fds ${mp.fds}, threads ${mp.threads}, heard ${row.master_heard_pct.toFixed(1)} %` : ""));
}
clearInterval(poll);
socket.destroy();
stopJog();
for (const w of [operator, ...watchers]) w.client.close();
for (const c of children) c.kill("SIGTERM");
const codes = await Promise.all([slave.exited, master ? master.exited : 0]);
rmSync(dir, { recursive: true, force: true });

const problems = [];
if (codes.some((c) => c !== 0)) problems.push(`serve exited ${codes.join(", ")} on SIGTERM`);
if (rows.length >= 2) {
  const first = rows[0], last = rows[rows.length - 1];
  const allowed = minutes >= 10 ? 0.02 : 0.05;
  for (const who of master ? ["", "master_"] : [""]) {
    const name = who ? "the master's" : "the slave's";
    const growth = last[`${who}rss_median_MB`] / first[`${who}rss_median_MB`] - 1;
    if (growth > allowed)
      problems.push(`${name} resident memory (a minute's median) grew ${(100 * growth).toFixed(1)} % after the first minute ` +
                    `(at most ${100 * allowed} %): ${rows.map((r) => r[`${who}rss_median_MB`].toFixed(1)).join(", ")} MB`);
    for (const key of ["fds", "threads"])
      if (rows.some((r) => r[who + key] !== first[who + key]))
        problems.push(`${name} ${key} changed: ${rows.map((r) => r[who + key]).join(", ")}`);
  }
  // After the first minute (the link comes up during it), the master's commands fresh at the
  // slave most of every minute: a loaded machine may starve the link for a moment; a lost link
  // stays lost.
  if (master && rows.slice(1).some((r) => r.master_heard_pct < 90))
    problems.push(`the slave lost its master (% of statuses that heard it, per minute): ${rows.map((r) => r.master_heard_pct.toFixed(0)).join(", ")}`);
  // Every query answered (a few in flight at the minute's edge).
  if (rows.some((r) => Math.abs(r.gcs_replies - r.gcs_asked) > 10 || r.gcs_asked < 1000))
    problems.push(`the GCS client went unanswered: ${rows.map((r) => `${r.gcs_replies}/${r.gcs_asked}`).join(", ")}`);
}
const result = { minutes, rows, problems };
if (asJson) console.log(JSON.stringify(result));
for (const p of problems) console.error("soak: " + p);
process.exit(check && problems.length ? 1 : 0);
