// What the serve benchmarks share (serve_bench.mjs, link_bench.mjs): the controlling operator's
// jog, the telemetry read back from a recording, quantiles.
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import zstd from "@foxglove/wasm-zstd";
import foxglove from "@foxglove/ws-protocol";
const { FoxgloveClient } = foxglove;

// Takes control on a connected FoxgloveClient and jogs the stage back and forth at 20 um/s
// (deadman held) at 50 Hz, the console's heartbeat. Returns the function that stops it.
export function jogAsOperator(client) {
  const command = client.advertise({ topic: "/console/command", encoding: "json", schemaName: "microcobot.Command" });
  const action = client.advertise({ topic: "/console/action", encoding: "json", schemaName: "microcobot.Action" });
  const send = (ch, obj) => client.sendMessage(ch, new TextEncoder().encode(JSON.stringify(obj)));
  send(action, { action: "take_control" });
  let sent = 0;
  const timer = setInterval(() => {
    const vx = Math.floor(sent / 100) % 2 ? -20e-6 : 20e-6;  // 2 s each way
    send(command, { deadman: true, velocity_m_s: [vx, 0, 0] });
    sent++;
  }, 20);
  return () => clearInterval(timer);
}

// The next /platform/status of the console at `wsUrl` (a client that connects, reads one, leaves).
export function nextStatus(wsUrl) {
  return new Promise((resolve, reject) => {
    const c = new FoxgloveClient({ ws: new WebSocket(wsUrl, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
    let status = -1;
    c.on("advertise", (list) => {
      const ch = list.find((x) => x.topic === "/platform/status");
      if (ch) status = c.subscribe(ch.id);
    });
    c.on("message", ({ subscriptionId, data }) => {
      if (subscriptionId !== status) return;
      c.close();
      resolve(JSON.parse(new TextDecoder().decode(data)));
    });
    c.on("error", reject);
  });
}

// An MCAP file opened with @mcap/core's indexed reader; `decompressHandlers` for compressed
// chunks (e.g. zstd). Returns { reader, file }: close the file when done.
export async function openMcap(path, decompressHandlers = {}) {
  const file = await open(path, "r");
  const reader = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt((await file.stat()).size),
      read: async (offset, size) => {
        const buf = Buffer.alloc(Number(size));
        await file.read(buf, 0, buf.length, Number(offset));
        return new Uint8Array(buf.buffer, buf.byteOffset, buf.byteLength);
      },
    },
    decompressHandlers,
  });
  return { reader, file };
}

// Every telemetry sample of an MCAP recording, parsed, in order (@mcap/core's indexed reader;
// the live recordings' chunks are zstd-compressed, read with @foxglove/wasm-zstd).
export async function readTelemetry(path) {
  await zstd.isLoaded;
  const { reader, file } = await openMcap(path, { zstd: (data, size) => zstd.decompress(data, Number(size)) });
  const samples = [];
  for await (const msg of reader.readMessages({ topics: ["/platform/telemetry"] }))
    samples.push(JSON.parse(new TextDecoder().decode(msg.data)));
  await file.close();
  return samples;
}

export const quantile = (v, q) => {
  const s = [...v].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.ceil(q * s.length) - 1)];
};
