// A `microcobot serve` recording onto a disk that fills: a 3 MiB tmpfs as --out, the camera on
// (about 3 MB/s of JPEG frames). The write that fails (ENOSPC) ends the recording cleanly: the
// clients get an error status saying the disk is full and what was kept, the file is cut back to
// its last half-second chunk and closed there (read whole by @mcap/core's indexed reader), no
// temporary is left, and the loop and the session go on (the status keeps coming, the recording
// is listed, SIGTERM stops serve with 0).
//
// Usage: MC_CLI=path/to/microcobot node --experimental-websocket full_disk.mjs
// Run by CTest (`mcap_full_disk`); exits 77 (skipped) without the readers or without the right
// to mount a tmpfs (root).
import { execFileSync, spawn } from "node:child_process";
import { existsSync, mkdtempSync, readdirSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { loadReaders, openIndexed } from "./indexed_reader.mjs";

const readers = await loadReaders("full_disk");
const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("full_disk: set MC_CLI to the microcobot binary");
  process.exit(2);
}
const dir = mkdtempSync(join(tmpdir(), "mc-full-"));
try {
  execFileSync("mount", ["-t", "tmpfs", "-o", "size=3m", "tmpfs", dir], { stdio: "ignore" });
} catch {
  rmSync(dir, { recursive: true, force: true });
  console.error("full_disk: cannot mount a tmpfs (needs root): skipped");
  process.exit(77);
}

let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
let server;
try {
  // The pick-and-place scene with its microscope camera (the default scene has one).
  // JPEG frames: the disk fills within seconds (H.264 would take a minute).
  server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", dir, "--record", "--record-video", "jpeg"],
                 { stdio: ["ignore", "pipe", "inherit"] });
  const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
  const url = await new Promise((resolve, reject) => {
    createInterface({ input: server.stdout }).once("line", resolve);
    server.once("exit", () => reject(new Error("serve exited before printing its URL")));
  });
  const statuses = [];
  let lastStatusT = 0, statusesAfter = 0, stoppedAt = 0;
  const ws = new WebSocket(url.replace(/^http/, "ws").replace(/\/(\?.*)?$/, "/ws$1"), ["foxglove.websocket.v1"]);
  ws.binaryType = "arraybuffer";
  const channels = new Map();
  ws.onmessage = (ev) => {
    if (typeof ev.data === "string") {
      const m = JSON.parse(ev.data);
      if (m.op === "status") {
        statuses.push(m);
        if (/recording stopped/.test(m.message) && !stoppedAt) stoppedAt = Date.now();
      }
      if (m.op === "advertise") {
        for (const c of m.channels) channels.set(c.topic, c.id);
        const id = channels.get("/platform/status");
        if (id) ws.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: id }] }));
      }
      return;
    }
    const b = new Uint8Array(ev.data);
    if (b[0] === 0x01) {  // a message on our subscription: /platform/status
      const j = JSON.parse(new TextDecoder().decode(b.subarray(13)));
      lastStatusT = j.t_s;
      if (stoppedAt) ++statusesAfter;
    }
  };
  const t0 = Date.now();
  while (!stoppedAt && Date.now() - t0 < 60000) await sleep(100);
  const stopped = statuses.find((s) => /recording stopped/.test(s.message));
  if (!stopped) throw new Error(`no "recording stopped" status within 60 s (statuses: ${JSON.stringify(statuses)})`);
  console.error(`full_disk: after ${((stoppedAt - t0) / 1000).toFixed(1)} s: [level ${stopped.level}] ${stopped.message}`);
  if (stopped.level !== 2) fail("the status is not an error");
  if (!/disk full/.test(stopped.message)) fail("the status does not say the disk is full");
  if (!/kept up to its last half second/.test(stopped.message)) fail("the status does not say what was kept");
  const tBefore = lastStatusT;
  await sleep(1500);
  if (!(statusesAfter >= 3 && lastStatusT > tBefore + 0.5)) fail(`the session stopped with the recording (status t_s ${tBefore} -> ${lastStatusT})`);
  const list = await (await fetch(url.replace(/\/(\?.*)?$/, "/recordings$1"))).json();
  const files = readdirSync(dir);
  if (files.some((f) => f.startsWith("."))) fail(`a temporary was left: ${files.join(", ")}`);
  const mcaps = files.filter((f) => /^recording-[0-9-]+\.mcap$/.test(f));
  if (mcaps.length !== 1) fail(`expected one recording, found: ${files.join(", ")}`);
  if (!list.recordings.some((r) => r.name === mcaps[0] && !r.recording)) fail(`/recordings: ${JSON.stringify(list)}`);
  // Read whole by the indexed reader.
  const { reader, close } = await openIndexed(readers, join(dir, mcaps[0]));
  const topics = new Map([...reader.channelsById.values()].map((c) => [c.id, c.topic]));
  let n = 0, images = 0;
  for await (const m of reader.readMessages()) {
    ++n;
    if (topics.get(m.channelId) === "/camera/image/compressed") ++images;
  }
  await close();
  console.error(`full_disk: ${mcaps[0]}: ${n} messages, ${images} camera images, ${reader.chunkIndexes.length} chunks`);
  if (!(n > 0 && images > 0)) fail("the recording kept nothing");
  ws.close();
  server.kill("SIGTERM");
  const { code } = await exited;
  if (code !== 0) fail(`serve exited ${code} on SIGTERM`);
} catch (e) {
  fail(String(e && e.stack || e));
  if (server) server.kill("SIGKILL");
} finally {
  try { execFileSync("umount", [dir], { stdio: "ignore" }); } catch { /* busy: the next boot */ }
  rmSync(dir, { recursive: true, force: true });
}
console.error(failures ? `full_disk: ${failures} failure(s)` : "full_disk: passed");
process.exit(failures ? 1 : 0);
