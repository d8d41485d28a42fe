// The Chronogrip console: the microscope, the operator's inputs and the
// platform's feedback, over the Foxglove WebSocket protocol (docs/console.md). Everything the
// loop receives is checked and clamped again by the server; this page only presents and collects.
//
// The page's scripts, inlined in this order (web/console.html): console_link.js (the protocol,
// the shared state, the connection), console_plots.js, console_microscope.js,
// console_controls.js (the operator's inputs and the command), console_positions.js (readout,
// go-to, step jog, saved positions), console_positioner.js (the parallel positioner in 3-D),
// console_task.js, console_status.js (banners, status, scene, forces,
// recordings; it connects last). They share the page's global scope as classic scripts do.
"use strict";

// ---------------------------------------------------------------------------------------------
// Foxglove WebSocket protocol v1, the subset the console needs (the npm client is an ES module
// with dependencies: this page is embedded without a bundler, so the 60 lines are written here).
class FoxgloveClient {
  constructor(url, handlers) {
    this.channels = new Map();  // topic -> advertised channel
    this.subscriptions = new Map();  // subscription id -> topic
    this.clientChannels = new Map();  // topic -> client channel id
    this.nextSub = 1;
    this.h = handlers;
    this.ws = new WebSocket(url, ["foxglove.websocket.v1"]);
    this.ws.binaryType = "arraybuffer";
    this.ws.onopen = () => this.h.open && this.h.open();
    this.ws.onclose = (e) => this.h.close && this.h.close(e);
    this.ws.onmessage = (e) => this.receive(e.data);
  }
  receive(data) {
    if (typeof data === "string") {
      const m = JSON.parse(data);
      if (m.op === "advertise") {
        for (const c of m.channels) {
          this.channels.set(c.topic, c);
          this.subscribe(c.topic);
        }
      } else if (m.op === "unadvertise") {
        for (const [t, c] of this.channels) if (m.channelIds.includes(c.id)) this.channels.delete(t);
      } else if (m.op === "status") {
        this.h.status && this.h.status(m);
      } else if (m.op === "serverInfo") {
        this.h.serverInfo && this.h.serverInfo(m);
      }
      return;
    }
    const view = new DataView(data);
    if (view.byteLength < 13 || view.getUint8(0) !== 1) return;  // messageData only
    const topic = this.subscriptions.get(view.getUint32(1, true));
    if (topic === undefined) return;
    // CDR channels (the camera's ROS 2 messages) are handed over as bytes, JSON ones parsed.
    const channel = this.channels.get(topic), bytes = new Uint8Array(data, 13);
    const payload = channel && channel.encoding === "cdr" ? bytes : JSON.parse(new TextDecoder().decode(bytes));
    this.h.message && this.h.message(topic, payload);
  }
  subscribe(topic) {
    const c = this.channels.get(topic);
    const id = this.nextSub++;
    this.subscriptions.set(id, topic);
    this.send({op: "subscribe", subscriptions: [{id, channelId: c.id}]});
  }
  advertise(topic, schemaName) {
    const id = this.clientChannels.size + 1;
    this.clientChannels.set(topic, id);
    this.send({op: "advertise", channels: [{id, topic, encoding: "json", schemaName}]});
  }
  publish(topic, object) {
    const id = this.clientChannels.get(topic);
    if (id === undefined || this.ws.readyState !== WebSocket.OPEN) return;
    const body = new TextEncoder().encode(JSON.stringify(object));
    const frame = new Uint8Array(5 + body.length);
    frame[0] = 1;
    new DataView(frame.buffer).setUint32(1, id, true);
    frame.set(body, 5);
    this.ws.send(frame);
  }
  send(object) {
    if (this.ws.readyState === WebSocket.OPEN) this.ws.send(JSON.stringify(object));
  }
}

// ---------------------------------------------------------------------------------------------
// State, shared with the browser tests through window.mc.
const um = 1e6;
const mc = (window.mc = {
  connected: false,
  inControl: false,
  telemetry: null,  // the latest /platform/telemetry sample
  status: null,     // the latest /platform/status
  scene: null,      // /platform/scene: geometry and limits
  feedback: null,   // /console/feedback: forces and the vibrotactile channel
  messages: [],     // every status message the server sent, as text
  input: {deadman: false, joystick: [0, 0], zJog: 0, goal: null, gripper: 600e-6, gripperTouched: false,
          thetaGoal: null, thetaButton: 0},
});
const $ = (id) => document.getElementById(id);
const clamp = (v, lo, hi) => Math.max(lo, Math.min(hi, v));
const isNum = (v) => typeof v === "number" && Number.isFinite(v);

// Each script registers what it does with a channel's messages; the link only routes them.
const listeners = new Map();  // topic -> [fn(payload)]
function listen(topic, fn) {
  if (!listeners.has(topic)) listeners.set(topic, []);
  listeners.get(topic).push(fn);
}
listen("/platform/telemetry", (t) => { mc.telemetry = t; });  // first: the others read it

// The message log under the status table (every server status, whatever its level).
function note(text) {
  mc.messages.push(text);
  const div = document.createElement("div");
  div.textContent = new Date().toLocaleTimeString() + "  " + text;
  $("messages").prepend(div);
  while ($("messages").childElementCount > 200) $("messages").lastChild.remove();
}

// ---------------------------------------------------------------------------------------------
// Connection: reconnects every second while the server is away.
const params = new URLSearchParams(location.search);
const wsUrl = (location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws" +
              (params.get("token") ? "?token=" + encodeURIComponent(params.get("token")) : "");
let client = null;
function connect() {
  client = new FoxgloveClient(wsUrl, {
    open() {
      mc.connected = true;
      $("link").textContent = "connected";
      $("link").className = "pill ok";
      client.advertise("/console/command", "microcobot.ConsoleCommand");
      client.advertise("/console/action", "microcobot.ConsoleAction");
    },
    close() {
      mc.connected = false;
      setControl(false);
      $("link").textContent = "disconnected — retrying";
      $("link").className = "pill bad";
      setTimeout(connect, 1000);
    },
    status(m) {
      if (m.id === "report") listRecordings();
      if (typeof m.message === "string" && m.message.startsWith("control: ")) setControl(m.message === "control: granted");
      note(m.message);
      onServerStatus(m);
    },
    message(topic, payload) {
      for (const fn of listeners.get(topic) || []) fn(payload);
    },
  });
}

// An action on /console/action; the ones the control thread may refuse (demo, restart, reset)
// are answered through the status's last_error, which the status script watches after them.
// `extra`: the action's other keys (record_start's "video").
function action(name, extra = {}) {
  if (!client) return;
  client.publish("/console/action", {action: name, ...extra});
  mc.lastAction = {name, at: performance.now()};
}

function setControl(on) {
  mc.inControl = on;
  $("control-state").textContent = on ? "in control" : "observing";
  $("control-state").className = on ? "pill ok" : "pill";
  $("take-control").textContent = on ? "Release control" : "Take control";
}
