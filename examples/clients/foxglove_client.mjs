// Watch the live platform as Foxglove does: the Foxglove WebSocket client of npm
// (@foxglove/ws-protocol, what Foxglove Studio's own connection uses) on `microcobot serve`.
// Lists the channels the server advertises, then prints the stage's position from a few
// telemetry messages.
//
//   microcobot serve &                       # ws://127.0.0.1:8080/
//   node --experimental-websocket --no-warnings examples/clients/foxglove_client.mjs [ws://127.0.0.1:8080/]
//
// Tutorial: docs/tutorials/foxglove-ros2.md.
import foxglove from "@foxglove/ws-protocol";

const { FoxgloveClient } = foxglove;
const url = process.argv[2] || "ws://127.0.0.1:8080/";
const client = new FoxgloveClient({ ws: new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]) });
const channels = new Map();
let received = 0;

client.on("serverInfo", (info) => console.log(`server: ${info.name}`));
client.on("advertise", (list) => {
  for (const c of list) channels.set(c.id, c);
  const topics = list.map((c) => `${c.topic} (${c.schemaName}, ${c.encoding})`).sort();
  console.log(`${list.length} channels:\n  ${topics.join("\n  ")}`);
  const telemetry = list.find((c) => c.topic === "/platform/telemetry");
  if (telemetry) client.subscribe(telemetry.id);
});
client.on("message", ({ data }) => {
  const m = JSON.parse(new TextDecoder().decode(data));
  if (received++ % 20 === 0)
    console.log(`t ${m.t_s.toFixed(3)} s: stage x ${(m.measured_x_m * 1e6).toFixed(1)} um, ` +
                `y ${(m.measured_y_m * 1e6).toFixed(1)} um, z ${(m.measured_z_m * 1e6).toFixed(1)} um`);
  if (received >= 60) {
    client.close();
    process.exit(0);
  }
});
client.on("error", (e) => {
  console.error(`foxglove_client: ${e?.message || e}`);
  process.exit(1);
});
setTimeout(() => {
  console.error("foxglove_client: no telemetry within 20 s");
  process.exit(1);
}, 20000);
