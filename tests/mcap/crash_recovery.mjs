// A `microcobot serve` recording cut by kill -9 at a seeded random moment, recovered and read as Foxglove reads it
// (@mcap/core's McapIndexedReader, @foxglove/wasm-zstd): the recording's temporary file is left
// by the crash; `microcobot recording recover` turns a copy of it into an indexed file by hand;
// a second `serve` on the same --out recovers it at start, says so, lists it as recovered at
// /recordings, and removes the temporary. Judged: under a second before the kill is
// lost (the telemetry's last log time, on the wall clock, against the kill's; and every sample
// a subscribed client received up to a second before its last is in the file), the recovered
// files are read whole by the independent reader, and `recording info` names the recovery.
//
// Usage: MC_CLI=path/to/microcobot [MC_SEED=n] node --experimental-websocket crash_recovery.mjs
// Run by CTest (`mcap_crash_recovery`); exits 77 (skipped) when node_modules lacks the readers.
import { execFileSync, spawn } from "node:child_process";
import { copyFileSync, existsSync, mkdtempSync, readdirSync, rmSync, statSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { loadReaders, openIndexed } from "./indexed_reader.mjs";

const readers = await loadReaders("crash_recovery");
const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("crash_recovery: set MC_CLI to the microcobot binary");
  process.exit(2);
}

let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const dir = mkdtempSync(join(tmpdir(), "mc-crash-"));
const guard = setTimeout(() => { console.error("FAIL: took longer than 150 s"); process.exit(1); }, 150000);

// Starts serve; resolves with the process, its URL and its stderr lines so far.
const serve = async (extra) => {
  const p = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, ...extra],
                  { stdio: ["ignore", "pipe", "pipe"] });
  const lines = [];
  createInterface({ input: p.stderr }).on("line", (l) => { lines.push(l); process.stderr.write(l + "\n"); });
  const exited = new Promise((resolve) => p.on("exit", (code, signal) => resolve({ code, signal })));
  const url = await new Promise((resolve, reject) => {
    createInterface({ input: p.stdout }).once("line", resolve);
    p.once("exit", () => reject(new Error("serve exited before printing its URL")));
  });
  return { p, url, lines, exited };
};
const temporaries = () => readdirSync(dir).filter((f) => /^\.recording-[0-9-]+\.mcap\.[A-Za-z0-9]{6}$/.test(f));

const readMcap = async (path) => {
  const { reader, close } = await openIndexed(readers, path);
  const topics = new Map([...reader.channelsById.values()].map((c) => [c.id, c.topic]));
  let telemetry = 0, messages = 0, lastTelemetryNs = 0n;
  const times = new Set();  // the telemetry's t_s, in microseconds
  for await (const m of reader.readMessages({ logTimeOrder: false })) {
    ++messages;
    if (topics.get(m.channelId) === "/platform/telemetry") {
      ++telemetry;
      times.add(Math.round(JSON.parse(new TextDecoder().decode(m.data)).t_s * 1e6));
      if (m.logTime > lastTelemetryNs) lastTelemetryNs = m.logTime;
    }
  }
  const meta = [];
  for await (const m of reader.readMetadata({ name: "recovery" })) meta.push(m);
  await close();
  return { reader, messages, telemetry, lastTelemetryNs, times, recovery: meta[0] };
};

// The moment of the kill: seeded (MC_SEED, default 1), uniform within [2, 7] s of recording.
const seed = Number(process.env.MC_SEED ?? 1);
const rand = (() => { let a = seed >>> 0; return () => { a = (a + 0x6D2B79F5) >>> 0; let t = a;
  t = Math.imul(t ^ (t >>> 15), t | 1); t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
  return ((t ^ (t >>> 14)) >>> 0) / 4294967296; }; })();  // mulberry32
const killAfterMs = 2000 + 5000 * rand();

// A client subscribed to the telemetry (60 Hz): the loop times it received.
const watch = (url) => {
  const seen = [];
  const ws = new WebSocket(url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1"), ["foxglove.websocket.v1"]);
  ws.binaryType = "arraybuffer";
  ws.onmessage = (ev) => {
    if (typeof ev.data === "string") {
      const m = JSON.parse(ev.data);
      const c = m.op === "advertise" && m.channels.find((c) => c.topic === "/platform/telemetry");
      if (c) ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: c.id }] }));
      return;
    }
    const b = new Uint8Array(ev.data);
    if (b[0] === 0x01) seen.push(JSON.parse(new TextDecoder().decode(b.subarray(13))).t_s);
  };
  ws.onerror = () => {};
  return seen;
};

try {
  // 1. Recording, then killed at the seeded moment.
  const first = await serve(["--record"]);
  const received = watch(first.url);
  const t0 = Date.now();
  while (!(temporaries().length === 1 && Date.now() - t0 > killAfterMs)) await sleep(20);
  const killedNs = BigInt(Date.now()) * 1000000n;
  first.p.kill("SIGKILL");
  await first.exited;
  console.error(`crash_recovery: seed ${seed}: killed ${(killAfterMs / 1000).toFixed(2)} s after serve printed its URL; ` +
                `the client received ${received.length} telemetry samples`);
  const left = temporaries();
  if (left.length !== 1) throw new Error(`expected the recording's temporary after the crash, found: ${readdirSync(dir).join(", ")}`);
  console.error(`crash_recovery: killed after ${((Date.now() - t0) / 1000).toFixed(1)} s; left ${left[0]} ` +
                `(${(statSync(join(dir, left[0])).size / 1e6).toFixed(2)} MB)`);

  // 2. Recovered by hand from a copy (the original stays for serve).
  const copy = join(dir, "copy.part");
  copyFileSync(join(dir, left[0]), copy);
  const byHand = JSON.parse(execFileSync(cli, ["recording", "recover", copy, "--to", join(dir, "byhand.mcap"), "--json"],
                                         { encoding: "utf8" }));
  if (!(byHand.messages > 0) || byHand.complete) fail(`recording recover: ${JSON.stringify(byHand)}`);
  const hand = await readMcap(join(dir, "byhand.mcap"));
  // Every sample the client received up to a second before its last one is in the file.
  const last = received.length ? received[received.length - 1] : 0;
  const due = received.filter((t) => t <= last - 1.0);
  const missing = due.filter((t) => !hand.times.has(Math.round(t * 1e6)));
  console.error(`crash_recovery: of the client's ${due.length} samples logged over a second before its last ` +
                `(t_s ${last.toFixed(3)}), ${missing.length} missing from the recovered file`);
  if (!(due.length > 30)) fail(`too few samples received to judge (${due.length})`);
  if (missing.length) fail(`missing from the recovered file: t_s ${missing.slice(0, 5).join(", ")}...`);
  if (hand.messages !== byHand.messages) fail(`by hand: the reader read ${hand.messages} messages, recover said ${byHand.messages}`);
  const lostS = Number(killedNs - hand.lastTelemetryNs) / 1e9;
  console.error(`crash_recovery: by hand ${hand.messages} messages (${hand.telemetry} telemetry); ` +
                `the last telemetry ${lostS.toFixed(3)} s before the kill`);
  if (!(lostS >= 0 && lostS <= 1.0)) fail(`${lostS.toFixed(3)} s lost before the kill (the open half-second chunk and the writer's queue: under a second)`);
  if (!(hand.telemetry >= 1000)) fail(`only ${hand.telemetry} telemetry messages kept of 2-7 s at 1 kHz`);
  if (!hand.recovery || hand.recovery.metadata.get("from") !== "copy.part") fail("no recovery metadata naming the input");
  rmSync(copy);

  // 3. A second serve recovers the original at start, says so and lists it.
  const second = await serve([]);
  if (!second.lines.some((l) => l.includes("recovered") && l.includes(left[0]))) fail("serve did not say it recovered the recording");
  const list = await (await fetch(second.url.replace(/\/(\?.*)?$/, "/recordings$1"))).json();
  const listed = list.recordings.filter((r) => r.recovered);
  if (listed.length !== 1) fail(`/recordings lists ${listed.length} recovered recordings: ${JSON.stringify(list)}`);
  second.p.kill("SIGTERM");
  const { code } = await second.exited;
  if (code !== 0) fail(`serve exited ${code} on SIGTERM`);
  if (temporaries().length !== 0) fail("the temporary is still there after serve recovered it");
  const auto = await readMcap(join(dir, listed[0].name));
  if (auto.messages !== hand.messages) fail(`serve recovered ${auto.messages} messages, by hand ${hand.messages}`);

  // 4. `recording info` reads it and names the recovery.
  const info = JSON.parse(execFileSync(cli, ["recording", "info", join(dir, listed[0].name), "--json"], { encoding: "utf8" }));
  if (info.messages !== auto.messages || !info.recovery) fail(`recording info: ${JSON.stringify(info).slice(0, 300)}`);
  if (!info.channels.some((c) => c.topic === "/platform/telemetry" && c.rate_Hz > 900)) fail("recording info: no 1 kHz telemetry");
} catch (e) {
  fail(String(e && e.stack || e));
} finally {
  clearTimeout(guard);
  rmSync(dir, { recursive: true, force: true });
}
console.error(failures ? `crash_recovery: ${failures} failure(s)` : "crash_recovery: passed");
process.exit(failures ? 1 : 0);
