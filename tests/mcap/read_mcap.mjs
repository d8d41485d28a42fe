// Reads the session's recording.mcap with the MCAP project's own TypeScript reader
// (@mcap/core's McapIndexedReader, pinned in package-lock.json), as Foxglove and Lichtblick do:
// through the footer, the summary and the chunk and message indexes. Checks the summary (one
// jsonschema schema, one json channel, statistics equal to the CSV's row count), reads every
// message and a time range (a seek through the indexes), and compares the JSON to the CSV.
//
// Usage: MC_CLI=path/to/microcobot node read_mcap.mjs      (runs a short session itself)
//        node read_mcap.mjs DIR                            (DIR holds recording.{csv,mcap})
// Run by CTest (`mcap_node`); exits 77 (skipped) when node_modules lacks @mcap/core.
import { spawnSync } from "node:child_process";
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from "node:fs";
import { open } from "node:fs/promises";
import { tmpdir } from "node:os";
import { join } from "node:path";

let McapIndexedReader;
try {
  ({ McapIndexedReader } = await import("@mcap/core"));
} catch {
  console.error("read_mcap: @mcap/core is not installed (run scripts/install-deps.sh): skipped");
  process.exit(77);
}

let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };

let dir = process.argv[2];
let scratch;
if (!dir) {
  const cli = process.env.MC_CLI;
  if (!cli || !existsSync(cli)) {
    console.error("read_mcap: set MC_CLI to the microcobot binary, or give a directory");
    process.exit(2);
  }
  scratch = mkdtempSync(join(tmpdir(), "mc-mcap-"));
  dir = join(scratch, "session");
  // A short transport (0.3 mm) so that the scenario succeeds in a few simulated seconds: a
  // failed run keeps no outputs. Several seconds at 1 kHz fill more than one 1 MiB chunk.
  const config = join(scratch, "platform.yaml");
  writeFileSync(config, "world:\n  target_x_m: 0.3e-3\n");
  const r = spawnSync(cli, ["run", "--config", config, "--out", dir], { encoding: "utf8" });
  if (r.status !== 0) {
    console.error(`read_mcap: microcobot run exited ${r.status}: ${r.stderr}`);
    process.exit(1);
  }
}

// A readable over node's fs, as McapIndexedReader asks for (size, and read at an offset).
const file = await open(join(dir, "recording.mcap"), "r");
const readable = {
  size: async () => BigInt((await file.stat()).size),
  read: async (offset, size) => {
    const buf = Buffer.alloc(Number(size));
    const { bytesRead } = await file.read(buf, 0, buf.length, Number(offset));
    if (bytesRead !== buf.length) throw new Error(`short read at ${offset}`);
    return new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
  },
};

// The CSV: comment lines start with '#', then a header and numeric rows.
const lines = readFileSync(join(dir, "recording.csv"), "utf8").split("\n").filter((l) => l && !l.startsWith("#"));
const names = lines[0].split(",");
const rows = lines.slice(1).map((l) => l.split(",").map(Number));

const close = (a, b) => a === b || Math.abs(a - b) <= 1e-9 * Math.max(Math.abs(a), Math.abs(b));
const checkMessage = (msg, row, what) => {
  const json = JSON.parse(new TextDecoder().decode(msg.data));
  const keys = Object.keys(json);
  if (keys.join(",") !== names.join(",")) return fail(`${what}: keys ${keys} differ from the CSV's ${names}`);
  names.forEach((n, c) => {
    if (typeof json[n] !== "number" || !close(json[n], row[c])) fail(`${what}: ${n} = ${json[n]}, CSV has ${row[c]}`);
  });
  if (Math.abs(Number(msg.logTime) - row[0] * 1e9) > 1) fail(`${what}: log time ${msg.logTime} ns is not t_s = ${row[0]}`);
};

try {
  const reader = await McapIndexedReader.Initialize({ readable });
  if (reader.header.library !== "microcobot") fail(`library '${reader.header.library}'`);

  // Summary: one schema, one channel, statistics.
  if (reader.schemasById.size !== 1) fail(`${reader.schemasById.size} schemas, expected 1`);
  const [schema] = reader.schemasById.values();
  if (schema.encoding !== "jsonschema") fail(`schema encoding '${schema.encoding}'`);
  if (schema.name !== "microcobot.Telemetry") fail(`schema name '${schema.name}'`);
  const props = Object.keys(JSON.parse(new TextDecoder().decode(schema.data)).properties);
  if (props.join(",") !== names.join(",")) fail(`schema properties ${props} differ from the CSV columns`);
  if (reader.channelsById.size !== 1) fail(`${reader.channelsById.size} channels, expected 1`);
  const [channel] = reader.channelsById.values();
  if (channel.messageEncoding !== "json") fail(`message encoding '${channel.messageEncoding}'`);
  if (channel.topic !== "/platform/telemetry") fail(`topic '${channel.topic}'`);
  if (channel.schemaId !== schema.id) fail(`channel's schema ${channel.schemaId} is not ${schema.id}`);
  const stats = reader.statistics;
  if (!stats) fail("no statistics");
  else if (stats.messageCount !== BigInt(rows.length)) fail(`statistics: ${stats.messageCount} messages, CSV has ${rows.length} rows`);
  else if (stats.chunkCount !== reader.chunkIndexes.length) fail(`statistics: ${stats.chunkCount} chunks, ${reader.chunkIndexes.length} indexed`);

  // Every message, through the indexes, in order.
  const all = [];
  for await (const msg of reader.readMessages()) all.push(msg);
  if (all.length !== rows.length) fail(`${all.length} messages read, CSV has ${rows.length} rows`);
  all.forEach((m, i) => { if (i < rows.length) checkMessage(m, rows[i], `message ${i}`); });

  // A seek: the messages of a time range in the middle (crossing a chunk boundary when there is one).
  const a = Math.floor(rows.length / 3), b = Math.floor((2 * rows.length) / 3);
  const range = [];
  for await (const msg of reader.readMessages({ startTime: all[a].logTime, endTime: all[b].logTime })) range.push(msg);
  if (range.length !== b - a + 1) fail(`time range: ${range.length} messages, expected ${b - a + 1}`);
  range.forEach((m, k) => checkMessage(m, rows[a + k], `range message ${k}`));
  // And the last message alone, read backwards from the end.
  const last = [];
  for await (const msg of reader.readMessages({ startTime: all.at(-1).logTime, reverse: true })) last.push(msg);
  if (last.length !== 1) fail(`last message: read ${last.length}`);
  else checkMessage(last[0], rows.at(-1), "last message");

  console.log(`read_mcap: ${all.length} messages in ${reader.chunkIndexes.length} chunk(s), ` +
              `range of ${range.length} read by seek: ${failures ? "FAILED" : "ok"}`);
} catch (e) {
  fail(String(e?.stack ?? e));
} finally {
  await file.close();
  if (scratch) rmSync(scratch, { recursive: true, force: true });
}
process.exit(failures ? 1 : 0);
