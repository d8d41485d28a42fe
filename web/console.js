// The Chronogrip console (issue #14): the microscope, the operator's inputs and the platform's
// feedback, over the Foxglove WebSocket protocol (docs/console.md). Everything the loop receives
// is checked and clamped again by the server; this page only presents and collects.
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
    const payload = JSON.parse(new TextDecoder().decode(new Uint8Array(data, 13)));
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
// State, shared with the browser test through window.mc.
const um = 1e6;
const mc = (window.mc = {
  connected: false,
  inControl: false,
  telemetry: null,  // the latest /platform/telemetry sample
  status: null,     // the latest /platform/status
  scene: null,      // /platform/scene: geometry and limits
  feedback: null,   // /console/feedback: forces and the vibrotactile channel
  messages: [],
  input: {deadman: false, joystick: [0, 0], zJog: 0, goal: null, gripper: 600e-6, gripperTouched: false},
});
const $ = (id) => document.getElementById(id);

function note(text) {
  mc.messages.push(text);
  const div = document.createElement("div");
  div.textContent = new Date().toLocaleTimeString() + "  " + text;
  $("messages").prepend(div);
}

// ---------------------------------------------------------------------------------------------
// Connection.
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
      if (m.message.startsWith("control: ")) {
        setControl(m.message === "control: granted");
      }
      note(m.message);
    },
    message(topic, payload) {
      if (topic === "/platform/telemetry") onTelemetry(payload);
      else if (topic === "/platform/status") onStatus(payload);
      else if (topic === "/platform/scene") onScene(payload);
      else if (topic === "/console/feedback") onFeedback(payload);
    },
  });
}

function action(name) {
  client && client.publish("/console/action", {action: name});
}

function setControl(on) {
  mc.inControl = on;
  $("control-state").textContent = on ? "in control" : "observing";
  $("control-state").className = on ? "pill ok" : "pill";
  $("take-control").textContent = on ? "Release control" : "Take control";
}

// ---------------------------------------------------------------------------------------------
// Operator inputs: the deadman (button, Space, gamepad shoulder), the joystick (touch pad,
// arrows/WASD, gamepad stick), Z (buttons, PageUp/PageDown, wheel, right stick), the gripper
// (slider, gamepad trigger), click-to-go on the microscope and side views.
const keys = new Set();
function holdDeadman(el) {
  const on = (e) => { e.preventDefault(); mc.input.deadmanButton = true; };
  const off = () => { mc.input.deadmanButton = false; };
  el.addEventListener("pointerdown", on);
  el.addEventListener("pointerup", off);
  el.addEventListener("pointerleave", off);
  el.addEventListener("pointercancel", off);
}
holdDeadman($("deadman"));

window.addEventListener("keydown", (e) => {
  if (e.key === "Escape") { action("estop"); e.preventDefault(); return; }
  if (e.target.tagName === "INPUT" && e.key !== " ") return;
  keys.add(e.key);
  if ([" ", "ArrowUp", "ArrowDown", "ArrowLeft", "ArrowRight", "PageUp", "PageDown"].includes(e.key)) e.preventDefault();
  if (e.key === "[") setGripper(mc.input.gripper - 20e-6);
  if (e.key === "]") setGripper(mc.input.gripper + 20e-6);
});
window.addEventListener("keyup", (e) => {
  keys.delete(e.key);
  if (e.key === " ") e.preventDefault();  // Space is the deadman, never a button's click
});
// Buttons give the focus back at once, so that the keyboard stays the operator's.
document.addEventListener("click", (e) => { if (e.target.tagName === "BUTTON") e.target.blur(); });
// So do the objective and the sliders once set (Space on a focused list would open it).
document.addEventListener("change", (e) => { if (e.target.tagName === "SELECT" || e.target.type === "range") e.target.blur(); });
window.addEventListener("blur", () => { keys.clear(); mc.input.deadmanButton = false; });

function holdButton(el, field, value) {
  el.addEventListener("pointerdown", () => { mc.input[field] = value; });
  for (const ev of ["pointerup", "pointerleave", "pointercancel"]) el.addEventListener(ev, () => { mc.input[field] = 0; });
}
holdButton($("z-up"), "zButton", 1);
holdButton($("z-down"), "zButton", -1);

$("speed").addEventListener("input", () => { $("speed-out").textContent = $("speed").value + " µm/s"; });
function speed() { return Number($("speed").value) * 1e-6; }

function setGripper(o) {
  const max = mc.scene ? mc.scene.max_opening_m : 600e-6;
  mc.input.gripper = Math.min(max, Math.max(0, o));
  mc.input.gripperTouched = true;
  $("gripper").value = Math.round(mc.input.gripper * um);
  $("gripper-out").textContent = Math.round(mc.input.gripper * um) + " µm";
}
$("gripper").addEventListener("input", () => setGripper(Number($("gripper").value) * 1e-6));

// The touch joystick: drag from the centre; released, it springs back.
(function joystick() {
  const c = $("joystick");
  let active = false;
  const move = (e) => {
    if (!active) return;
    const r = c.getBoundingClientRect();
    let x = (e.clientX - r.left) / r.width * 2 - 1, y = -((e.clientY - r.top) / r.height * 2 - 1);
    const n = Math.hypot(x, y);
    if (n > 1) { x /= n; y /= n; }
    mc.input.joystick = [x, y];
  };
  c.addEventListener("pointerdown", (e) => { active = true; c.setPointerCapture(e.pointerId); move(e); });
  c.addEventListener("pointermove", move);
  const up = () => { active = false; mc.input.joystick = [0, 0]; };
  c.addEventListener("pointerup", up);
  c.addEventListener("pointercancel", up);
})();

function drawJoystick(v) {
  const c = $("joystick"), g = c.getContext("2d"), r = c.width / 2;
  g.clearRect(0, 0, c.width, c.height);
  g.strokeStyle = "#3a4250";
  g.beginPath(); g.arc(r, r, r - 2, 0, 2 * Math.PI); g.moveTo(0, r); g.lineTo(2 * r, r); g.moveTo(r, 0); g.lineTo(r, 2 * r); g.stroke();
  g.fillStyle = mc.input.deadman ? "#46c47e" : "#4fa3ff";
  g.beginPath(); g.arc(r + v[0] * (r - 20), r - v[1] * (r - 20), 18, 0, 2 * Math.PI); g.fill();
}

let gamepad = {connected: false, lastRumble: 0};
function pollGamepad() {
  const pads = navigator.getGamepads ? navigator.getGamepads() : [];
  const p = Array.from(pads).find((x) => x && x.connected);
  gamepad.pad = p || null;
  $("gamepad-state").textContent = p ? "gamepad: " + p.id.slice(0, 24) : "no gamepad";
  if (!p) return {xy: [0, 0], z: 0, deadman: false, trigger: null};
  const dz = (v) => (Math.abs(v) < 0.12 ? 0 : v);
  const trig = p.buttons[7] ? p.buttons[7].value : 0;
  return {
    xy: [dz(p.axes[0] || 0), -dz(p.axes[1] || 0)],
    z: -dz(p.axes[3] || 0),
    deadman: !!((p.buttons[4] && p.buttons[4].pressed) || (p.buttons[5] && p.buttons[5].pressed)),
    trigger: trig > 0.05 ? trig : null,
  };
}

// The command the console sends at 30 Hz while it holds control (also its heartbeat: the
// platform's watchdog holds the stage when it stops).
function currentCommand() {
  const pad = pollGamepad();
  const k = (a, b) => (keys.has(a) || keys.has(b) ? 1 : 0);
  let jx = mc.input.joystick[0] + pad.xy[0] + k("ArrowRight", "d") - k("ArrowLeft", "a");
  let jy = mc.input.joystick[1] + pad.xy[1] + k("ArrowUp", "w") - k("ArrowDown", "s");
  const n = Math.hypot(jx, jy);
  if (n > 1) { jx /= n; jy /= n; }
  let jz = (mc.input.zButton || 0) + pad.z + k("PageUp", "e") - k("PageDown", "q") + mc.input.zJog;
  jz = Math.max(-1, Math.min(1, jz));
  mc.input.zJog *= 0.5;  // the wheel's impulse decays
  mc.input.deadman = !!(mc.input.deadmanButton || keys.has(" ") || pad.deadman);
  if (pad.trigger !== null) setGripper((1 - pad.trigger) * (mc.scene ? mc.scene.max_opening_m : 600e-6));
  drawJoystick([jx, jy]);
  $("deadman").classList.toggle("held", mc.input.deadman);
  const v = speed();
  const cmd = {deadman: mc.input.deadman, velocity_m_s: [jx * v, jy * v, jz * v]};
  if (jx !== 0 || jy !== 0 || jz !== 0) mc.input.goal = null;  // a jog cancels click-to-go
  if (mc.input.goal) {
    cmd.goal_m = mc.input.goal;
    cmd.goal_speed_m_s = v;
  }
  if (mc.input.gripperTouched) cmd.gripper_opening_m = mc.input.gripper;
  return cmd;
}
setInterval(() => {
  const cmd = currentCommand();
  if (mc.inControl) client.publish("/console/command", cmd);
}, 33);

$("take-control").addEventListener("click", () => action(mc.inControl ? "release_control" : "take_control"));
$("estop").addEventListener("click", () => action("estop"));
$("reset").addEventListener("click", () => action("reset"));
$("demo").addEventListener("click", () => action("demo"));
$("restart").addEventListener("click", () => action("restart"));
$("record").addEventListener("click", () => action(mc.status && mc.status.recording ? "record_stop" : "record_start"));

// ---------------------------------------------------------------------------------------------
// The microscope: top view through an objective (field of view, numerical aperture), focused on
// the finger tips; what lies off the focal plane is blurred by defocus, detail finer than the
// optical resolution (0.61 lambda / NA) is not shown. Plus a side view (x, z).
// magnification: NA (100x: the oil-immersion objective that focuses optical tweezers' trap;
// 200x: the same behind a 2x tube lens, which magnifies without resolving more)
const objectives = {2: 0.06, 5: 0.14, 10: 0.28, 20: 0.42, 50: 0.55, 100: 1.3, 200: 1.3};
const kFieldNumber = 12e-3;  // field of view = field number / magnification
const kLambda = 550e-9;
const view = {center: [0, 0], fov: 1.2e-3};
function optics() {
  const mag = Number($("objective").value);
  const na = objectives[mag];
  return {mag, na, fov: kFieldNumber / mag, resolution: (0.61 * kLambda) / na};
}
function worldToCanvas(x, y) {
  const c = $("microscope"), s = c.width / view.fov;
  return [c.width / 2 + (x - view.center[0]) * s, c.height / 2 - (y - view.center[1]) * s];
}
function canvasToWorld(px, py) {
  const c = $("microscope"), s = c.width / view.fov;
  return [view.center[0] + (px - c.width / 2) / s, view.center[1] - (py - c.height / 2) / s];
}
mc.worldToCanvas = worldToCanvas;

function blurPx(dz, o, scale) {
  // Geometric defocus: a point dz off the focal plane spreads over a disc of diameter
  // 2 dz tan(asin NA); never sharper than the optical resolution.
  const tan = Math.tan(Math.asin(o.na));
  return Math.max(o.resolution, Math.abs(dz) * tan) * scale;
}

// A rectangle blurred by `blur` pixels. A wide blur is rendered at a reduced scale and drawn
// enlarged: the result is the same to the eye, at a fraction of the cost (a blur filter over a
// large area would stall the page, and with it the commands' heartbeat).
const blurCanvas = document.createElement("canvas");
function drawBlurred(g, x, y, w, h, blur, color) {
  if (blur < 1) {
    g.fillStyle = color;
    g.fillRect(x, y, w, h);
    return;
  }
  const k = Math.max(1, blur / 2);  // downscale so that the blur is ~2 px there
  const margin = 2 * blur;
  const bw = Math.ceil((w + 2 * margin) / k), bh = Math.ceil((h + 2 * margin) / k);
  if (bw > 2048 || bh > 2048) return;
  blurCanvas.width = bw;
  blurCanvas.height = bh;
  const b = blurCanvas.getContext("2d");
  b.filter = `blur(${(blur / k).toFixed(2)}px)`;
  b.fillStyle = color;
  b.fillRect(margin / k, margin / k, w / k, h / k);
  g.imageSmoothingEnabled = true;
  g.drawImage(blurCanvas, x - margin, y - margin, bw * k, bh * k);
}

function drawMicroscope() {
  const c = $("microscope"), g = c.getContext("2d"), t = mc.telemetry, sc = mc.scene;
  const o = optics();
  view.fov = o.fov;
  if (t && $("follow").checked) view.center = [t.measured_x_m, t.measured_y_m];
  const s = c.width / view.fov;
  g.filter = "none";
  g.fillStyle = "#2a2722";
  g.fillRect(0, 0, c.width, c.height);
  if (!t || !sc) return;
  if (sc.kind === "optical-trap") {
    drawTrapScene(g, o, s);
    drawScaleBar(g, c, s);
    $("scope-info").textContent = `NA ${o.na}, resolution ${(o.resolution * um).toFixed(2)} µm, ` +
                                  `focus on the trap's plane`;
    return;
  }
  const focus = t.measured_z_m;  // autofocus on the finger tips
  // The substrate's texture (a 50 um polishing grid) at z = 0: out of focus by more than a
  // few pixels it washes out entirely, as a fine pattern does under a microscope.
  if (blurPx(focus, o, s) < 2) {
    g.strokeStyle = "#3b372f";
    g.lineWidth = 1;
    const step = 50e-6, [x0, y1] = canvasToWorld(0, 0), [x1, y0] = canvasToWorld(c.width, c.height);
    g.beginPath();
    for (let x = Math.floor(x0 / step) * step; x <= x1; x += step) { const [px] = worldToCanvas(x, 0); g.moveTo(px, 0); g.lineTo(px, c.height); }
    for (let y = Math.floor(y0 / step) * step; y <= y1; y += step) { const [, py] = worldToCanvas(0, y); g.moveTo(0, py); g.lineTo(c.width, py); }
    g.stroke();
  }
  // The hole at the target (pin-in-hole): its rim at z = 0.
  if (sc.hole_side_m > 0) {
    const hs = sc.hole_side_m, [hx, hy] = worldToCanvas(sc.target_m[0] - hs / 2, sc.target_m[1] + hs / 2);
    drawBlurred(g, hx, hy, hs * s, hs * s, blurPx(focus, o, s), "#0c0b09");
  }
  // The part: a brass cube or pin, its top face at part_z + height / 2, blurred by its defocus.
  // (A master of a distributed platform has no part in its telemetry: the microworld is the
  // slave's.)
  const side = sc.part_side_m, height = sc.part_height_m || side;
  if (t.part_x_m !== undefined) {
    const [px, py] = worldToCanvas(t.part_x_m - side / 2, t.part_y_m + side / 2);
    drawBlurred(g, px, py, side * s, side * s, blurPx(focus - (t.part_z_m + height / 2), o, s), "#c9a04a");
  }
  // The target: a reticle overlaid on the view (a graticule, always sharp), with the tolerance.
  const [tx, ty] = worldToCanvas(sc.target_m[0], sc.target_m[1]);
  g.strokeStyle = "#46c47e";
  g.lineWidth = 2;
  g.beginPath(); g.arc(tx, ty, Math.max(3, sc.tolerance_m * s), 0, 2 * Math.PI);
  g.moveTo(tx - 20, ty); g.lineTo(tx + 20, ty); g.moveTo(tx, ty - 20); g.lineTo(tx, ty + 20); g.stroke();
  // The gripper's two fingers (in focus: the microscope follows their tips), along x.
  const w = sc.finger_width_m, half = t.gripper_opening_m / 2;
  g.fillStyle = "#b8c4d6";
  for (const sign of [-1, 1]) {
    const cx = t.measured_x_m + sign * (half + w / 2);
    const [fx, fy] = worldToCanvas(cx - w / 2, t.measured_y_m + w);
    g.fillRect(fx, fy, w * s, 2 * w * s);
  }
  if (mc.input.goal) {
    const [gx, gy] = worldToCanvas(mc.input.goal[0], mc.input.goal[1]);
    g.strokeStyle = "#4fa3ff";
    g.beginPath(); g.arc(gx, gy, 6, 0, 2 * Math.PI); g.stroke();
  }
  drawScaleBar(g, c, s);
  $("scope-info").textContent = `NA ${o.na}, resolution ${(o.resolution * um).toFixed(1)} µm, ` +
                                `focus z ${(focus * um).toFixed(0)} µm`;
}

// Scale bar: a round length near a fifth of the field.
function drawScaleBar(g, c, s) {
  const nice = [1e-6, 2e-6, 5e-6, 10e-6, 20e-6, 50e-6, 100e-6, 200e-6, 500e-6, 1e-3, 2e-3];
  const bar = nice.find((v) => v * s > c.width / 6) || 1e-3;
  g.fillStyle = "#fff";
  g.fillRect(c.width - 20 - bar * s, c.height - 24, bar * s, 5);
  g.font = "13px system-ui";
  g.fillText(bar >= 1e-3 ? bar * 1e3 + " mm" : Math.round(bar * um) + " µm", c.width - 20 - bar * s, c.height - 30);
}

// The optical-tweezers scene (thesis §3.5.2, Fig. 3.16) in bright field: the stuck bead and the
// probe bead as dark-rimmed discs (a bead smaller than the resolution would be a blur), the
// trap's focus as a green mark at the stage's measured position, and the force the trap
// measures as an arrow from the probe's centre (Fig. 3.14b's black arrow).
function drawTrapScene(g, o, s) {
  const t = mc.telemetry, sc = mc.scene;
  const bead = (x, y, r, fill) => {
    const [px, py] = worldToCanvas(x, y), pr = Math.max(r * s, (o.resolution * s) / 2);
    g.filter = o.resolution * s > 2 ? `blur(${((o.resolution * s) / 4).toFixed(1)}px)` : "none";
    g.fillStyle = fill;
    g.beginPath(); g.arc(px, py, pr, 0, 2 * Math.PI); g.fill();
    g.strokeStyle = "#0c0b09";
    g.lineWidth = Math.max(1, 0.15 * pr);
    g.stroke();
    g.filter = "none";
  };
  bead(sc.obstacle_m[0], sc.obstacle_m[1], sc.obstacle_radius_m, "#8d8778");
  if (t.part_x_m !== undefined) bead(t.part_x_m, t.part_y_m, sc.bead_radius_m, "#b9b3a2");
  const [tx, ty] = worldToCanvas(t.measured_x_m, t.measured_y_m);
  g.strokeStyle = "#46c47e";
  g.lineWidth = 2;
  g.beginPath(); g.moveTo(tx - 8, ty); g.lineTo(tx + 8, ty); g.moveTo(tx, ty - 8); g.lineTo(tx, ty + 8); g.stroke();
  if (t.part_x_m !== undefined) {
    const [bx, by] = worldToCanvas(t.part_x_m, t.part_y_m), k = (sc.bead_radius_m * s * 3) / sc.force_full_scale_N;
    g.strokeStyle = "#ff9f43";
    g.beginPath(); g.moveTo(bx, by); g.lineTo(bx + t.contact_x_N * k, by - t.contact_y_N * k); g.stroke();
  }
  if (mc.input.goal) {
    const [gx, gy] = worldToCanvas(mc.input.goal[0], mc.input.goal[1]);
    g.strokeStyle = "#4fa3ff";
    g.beginPath(); g.arc(gx, gy, 6, 0, 2 * Math.PI); g.stroke();
  }
  g.lineWidth = 1;
}

function drawSide() {
  const c = $("side"), g = c.getContext("2d"), t = mc.telemetry, sc = mc.scene;
  g.fillStyle = "#111";
  g.fillRect(0, 0, c.width, c.height);
  if (!t || !sc) return;
  if (sc.kind === "optical-trap") {  // the trap's model is planar: nothing to show in z
    g.fillStyle = "#8a93a3";
    g.fillText("optical trap: a planar scene (the probe stays in the trap's focal plane)", 8, 14);
    return;
  }
  const s = c.width / view.fov, zmax = 1.0e-3, zs = sideScale();
  const X = (x) => c.width / 2 + (x - view.center[0]) * s, Z = (z) => mc.worldToSide(0, z)[1];
  g.fillStyle = "#3b372f";
  g.fillRect(0, Z(0), c.width, c.height - Z(0));
  if (sc.hole_side_m > 0) {  // the hole, in section
    g.fillStyle = "#111";
    g.fillRect(X(sc.target_m[0] - sc.hole_side_m / 2), Z(0), sc.hole_side_m * s, sc.hole_depth_m * zs);
  }
  const side = sc.part_side_m, height = sc.part_height_m || side;
  g.fillStyle = "#c9a04a";
  if (t.part_x_m !== undefined) g.fillRect(X(t.part_x_m - side / 2), Z(t.part_z_m + height / 2), side * s, height * zs);
  g.fillStyle = "#b8c4d6";
  const w = sc.finger_width_m, half = t.gripper_opening_m / 2;
  for (const sign of [-1, 1]) {
    const cx = t.measured_x_m + sign * (half + w / 2);
    g.fillRect(X(cx - w / 2), Z(zmax), w * s, Z(t.measured_z_m) - Z(zmax));
  }
  g.strokeStyle = "#46c47e";
  g.beginPath(); g.moveTo(X(sc.target_m[0]), Z(0)); g.lineTo(X(sc.target_m[0]), Z(0) - 12); g.stroke();
  g.fillStyle = "#8a93a3";
  g.fillText(`z ${(t.measured_z_m * um).toFixed(1)} µm`, 8, 14);
}
// The side view spans z from the bottom of the hole (or the substrate) to 1 mm above it.
const sideZmin = () => (mc.scene && mc.scene.hole_side_m > 0 ? -mc.scene.hole_depth_m : 0);
const sideScale = () => ($("side").height - 20) / (1.0e-3 - sideZmin());
mc.sideToWorld = (px, py) => {
  const c = $("side"), s = c.width / view.fov;
  return [view.center[0] + (px - c.width / 2) / s, sideZmin() + (c.height - 10 - py) / sideScale()];
};
mc.worldToSide = (x, z) => {
  const c = $("side"), s = c.width / view.fov;
  return [c.width / 2 + (x - view.center[0]) * s, c.height - 10 - (z - sideZmin()) * sideScale()];
};

// Click-to-go: the stage moves straight to the clicked point while the deadman is held (the
// closed-loop positioning). Top view: x, y at the present height; side view: x, z.
function canvasPoint(c, e) {
  const r = c.getBoundingClientRect();
  return [(e.clientX - r.left) * (c.width / r.width), (e.clientY - r.top) * (c.height / r.height)];
}
$("microscope").addEventListener("click", (e) => {
  const t = mc.telemetry;
  if (!t) return;
  const [x, y] = canvasToWorld(...canvasPoint($("microscope"), e));
  mc.input.goal = [x, y, t.target_z_m];
});
$("side").addEventListener("click", (e) => {
  const t = mc.telemetry;
  if (!t) return;
  const [x, z] = mc.sideToWorld(...canvasPoint($("side"), e));
  mc.input.goal = [x, t.target_y_m, z];
});
$("microscope").addEventListener("wheel", (e) => {
  e.preventDefault();
  mc.input.zJog = Math.max(-1, Math.min(1, mc.input.zJog - Math.sign(e.deltaY)));
}, {passive: false});
$("objective").addEventListener("change", () => draw());

// ---------------------------------------------------------------------------------------------
// Feedback: force vector and gauges; the gamepad's rumble follows the high band of the contact
// force (the crossover's HF channel, computed by the server).
function drawForce(f) {
  const c = $("force-vector"), g = c.getContext("2d"), r = c.width / 2;
  g.clearRect(0, 0, c.width, c.height);
  g.strokeStyle = "#3a4250";
  g.beginPath(); g.arc(r, r, r - 2, 0, 2 * Math.PI); g.stroke();
  const full = mc.scene ? mc.scene.force_full_scale_N : 50e-6, k = (r - 6) / full;
  const fx = Math.max(-full, Math.min(full, f[0])), fy = Math.max(-full, Math.min(full, f[1]));
  g.strokeStyle = "#ff9f43";
  g.lineWidth = 3;
  g.beginPath(); g.moveTo(r, r); g.lineTo(r + fx * k, r - fy * k); g.stroke();
  g.lineWidth = 1;
}
function onFeedback(p) {
  mc.feedback = p;
  const [fx, fy, fz] = p.contact_N;
  const n = Math.hypot(fx, fy, fz), f = forceUnit();
  $("contact-gauge").max = mc.scene ? mc.scene.force_full_scale_N * f.scale : 50;
  $("contact-gauge").value = n * f.scale;
  $("contact-out").textContent = (n * f.scale).toFixed(1) + " " + f.label;
  $("grip-gauge").value = p.grip_N * um;
  $("grip-out").textContent = (p.grip_N * um).toFixed(1) + " µN";
  $("rumble-gauge").value = p.rumble;
  drawForce(p.contact_N);
  const pad = gamepad.pad;
  const now = performance.now();
  if (pad && pad.vibrationActuator && p.rumble > 0.02 && now - gamepad.lastRumble > 90) {
    gamepad.lastRumble = now;
    pad.vibrationActuator.playEffect("dual-rumble", {duration: 100, strongMagnitude: 0, weakMagnitude: Math.min(1, p.rumble)});
  }
}

// ---------------------------------------------------------------------------------------------
// Status.
function onStatus(s) {
  mc.status = s;
  const rows = [
    ["time", s.t_s.toFixed(1) + " s"],
    ["e-stop", s.estopped ? "LATCHED" : "clear", !s.estopped],
    ["control", s.controlled ? "a client" : "nobody", true],
    ["watchdog", s.console_fresh ? "fresh" : "holding", s.console_fresh],
    ["mode", s.demo ? "demo: " + s.demo_phase : "console", true],
  ];
  for (const [name, state] of Object.entries(s.lifecycle)) rows.push([name, state, state === "active"]);
  rows.push(["loop overruns", String(s.overruns), s.overruns === 0]);
  rows.push(["tick p99", s.tick_p99_us.toFixed(1) + " µs (CPU " + s.tick_cpu_p99_us.toFixed(1) + " µs)", true]);
  rows.push(["clients", String(s.clients), true]);
  rows.push(["recording", s.recording || "off", true]);
  const lat = s.command_latency_ms;
  if (lat && lat.count > 0) rows.push(["command latency", "p50 " + lat.p50.toFixed(2) + " ms, p99 " + lat.p99.toFixed(2) + " ms", lat.p99 < 5]);
  $("status").innerHTML = "";
  for (const [name, value, ok] of rows) {
    const tr = document.createElement("tr");
    const a = document.createElement("td"), b = document.createElement("td");
    a.textContent = name;
    b.textContent = value;
    if (ok !== undefined) b.className = ok ? "ok" : "bad";
    tr.append(a, b);
    $("status").append(tr);
  }
  $("estop").classList.toggle("latched", s.estopped);
  $("record").textContent = s.recording ? "Stop recording" : "Record";
  $("record").classList.toggle("on", !!s.recording);
  if ((s.recording || "") !== mc.lastRecording) {  // a recording started or ended: list again
    mc.lastRecording = s.recording || "";
    listRecordings();
  }
}

// The recordings in --out with their downloads and session reports (made on the first click).
function listRecordings() {
  fetch("/recordings" + location.search, {cache: "no-store"})
    .then((r) => (r.ok ? r.json() : {recordings: []}))
    .then((j) => {
      const table = $("recordings");
      table.innerHTML = "";
      if (!j.recordings.length) {
        table.innerHTML = "<tr><td>none yet: press Record</td></tr>";
        return;
      }
      for (const rec of j.recordings) {
        const tr = document.createElement("tr");
        const name = document.createElement("td"), size = document.createElement("td"), links = document.createElement("td");
        name.textContent = rec.name;
        size.textContent = rec.recording ? "" : (rec.bytes / 1e6).toFixed(1) + " MB";
        if (rec.recording) {
          links.textContent = "recording…";
        } else {
          const dl = document.createElement("a");
          dl.href = rec.url + location.search;  // the token, when the server needs one
          dl.textContent = "MCAP";
          dl.setAttribute("download", rec.name);
          const rep = document.createElement("a");
          rep.href = rec.report_url + location.search;
          rep.target = "_blank";
          rep.textContent = rec.report_ready ? "report" : "make report";
          links.append(dl);
          if (rec.csv_url) {  // the same samples as a CSV table
            const csv = document.createElement("a");
            csv.href = rec.csv_url + location.search;
            csv.textContent = "CSV";
            csv.setAttribute("download", rec.csv_url.split("/").pop());
            links.append(" · ", csv);
          }
          links.append(" · ", rep);
        }
        tr.append(name, size, links);
        table.append(tr);
      }
    })
    .catch(() => {});
}

// Forces are micronewtons on a watch part, piconewtons on a trapped bead.
function forceUnit() {
  return mc.scene && mc.scene.kind === "optical-trap" ? {scale: 1e12, label: "pN"} : {scale: um, label: "µN"};
}

function onScene(s) {
  const first = !mc.scene || mc.scene.kind !== s.kind;
  mc.scene = s;
  // The speed scale spans what the server accepts (20 um/s for a bead, 1 mm/s for a part).
  const maxSpeed = Math.max(1, Math.round(s.max_speed_m_s * um));
  if (Number($("speed").max) !== maxSpeed) {
    $("speed").max = maxSpeed;
    if (Number($("speed").value) > maxSpeed) $("speed").value = maxSpeed;
    $("speed-out").textContent = $("speed").value + " µm/s";
  }
  if (first) {
    // A bead a hundred times smaller than a watch part: the tweezers' objective.
    if (s.kind === "optical-trap") $("objective").value = "200";
    forcePlot.title.textContent = s.kind === "optical-trap" ? "Force on the probe bead [pN]" : "Forces on the gripper [µN]";
    forcePlot.scale = forceUnit().scale;
    for (const a of forcePlot.data) a.length = 0;
  }
  $("gripper").max = Math.round(s.max_opening_m * um);
  if (!mc.input.gripperTouched) {
    mc.input.gripper = s.max_opening_m;
    $("gripper").value = Math.round(s.max_opening_m * um);
    $("gripper-out").textContent = Math.round(s.max_opening_m * um) + " µm";
  }
}

// ---------------------------------------------------------------------------------------------
// Live plots (uPlot): the last 10 s.
const kWindow = 600;  // samples at 60 Hz
const plots = [];
function makePlot(title, unit, scale, series) {  // returns the plot (its title, scale and data)
  const div = document.createElement("div");
  div.className = "plot";
  const h = document.createElement("h3");
  h.textContent = title;
  div.append(h);
  $("plots").append(div);
  const colors = ["#4fa3ff", "#ff9f43", "#46c47e", "#c56cf0", "#ff5a5a", "#feca57"];
  const opts = {
    width: 520, height: 200,
    scales: {x: {time: false}},
    axes: [{stroke: "#8a93a3", label: "t [s]"}, {stroke: "#8a93a3", label: unit}],
    series: [{label: "t"}].concat(series.map((s, i) => ({label: s[1], stroke: colors[i % colors.length], width: 1.5, dash: s[2] ? [4, 4] : undefined}))),
  };
  const data = [[]].concat(series.map(() => []));
  const u = new uPlot(opts, data, div);
  const plot = {u, data, series, scale, title: h};
  plots.push(plot);
  return plot;
}
makePlot("Positions against targets", "µm", um, [
  ["measured_x_m", "x"], ["target_x_m", "x target", true], ["measured_y_m", "y"], ["target_y_m", "y target", true],
  ["measured_z_m", "z"], ["target_z_m", "z target", true]]);
const forcePlot = makePlot("Forces on the gripper [µN]", "", um, [
  ["contact_x_N", "contact x"], ["contact_y_N", "contact y"], ["contact_z_N", "contact z"], ["grip_force_N", "grip"]]);
makePlot("Drive amplitude", "V", 1, [["u_x_V", "u x"], ["u_y_V", "u y"], ["u_z_V", "u z"]]);
makePlot("Loop tick", "µs", 1, [["tick_us", "tick (wall clock)"], ["tick_cpu_us", "tick (loop thread CPU)"]]);

function onTelemetry(t) {
  mc.telemetry = t;
  for (const p of plots) {
    p.data[0].push(t.t_s);
    p.series.forEach((s, i) => p.data[i + 1].push(t[s[0]] * p.scale));
    if (p.data[0].length > kWindow) for (const a of p.data) a.shift();
  }
}
setInterval(() => { for (const p of plots) p.u.setData(p.data); }, 100);

// 30 frames per second: the blurred optics cost CPU on a tablet, and the commands' timer (the
// watchdog's heartbeat) must never wait behind the drawing.
let lastDraw = 0;
function draw(now) {
  if (!(now - lastDraw < 33)) {
    lastDraw = now;
    drawMicroscope();
    drawSide();
  }
  requestAnimationFrame(draw);
}
requestAnimationFrame(draw);
connect();
