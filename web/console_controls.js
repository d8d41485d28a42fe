// The operator's inputs: the deadman (button, Space, gamepad shoulder), the joystick (touch pad,
// arrows/WASD, gamepad stick), Z (buttons, PageUp/PageDown, wheel, right stick), the gripper
// (slider, gamepad trigger; its release burst: the Shake button or B), the rotary axis under it (buttons, ',' and '.', or a goal from the
// readout's θ row), and the command they make, sent at 30 Hz while in control. Goals
// (click-to-go, go-to, step jog, saved positions) ride on the same command: the server applies
// them, like every motion, only while the deadman is held.
"use strict";

const keys = new Set();
const kThetaRate = 0.05;  // rad/s (2.9 deg/s): the buttons' and keys' turn
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
holdButton($("theta-ccw"), "thetaButton", 1);
holdButton($("theta-cw"), "thetaButton", -1);
holdButton($("gripper-shake"), "shakeButton", 1);

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
  // The release burst (held button or B): a gripper command, so it carries the opening; one the
  // operator has not set yet is the measured one (the burst must not move the fingers).
  const shake = !!(mc.input.shakeButton || keys.has("b") || keys.has("B"));
  if (shake && !mc.input.gripperTouched && mc.telemetry) setGripper(mc.telemetry.gripper_opening_m);
  $("gripper-shake").classList.toggle("held", shake);
  if (mc.input.gripperTouched) cmd.gripper_opening_m = mc.input.gripper;
  if (shake) cmd.gripper_shake = true;
  // The rotary axis (when the scene has one): a turn at the dial's rate, or a goal from the readout.
  if (mc.scene && mc.scene.theta_max_rad > mc.scene.theta_min_rad) {
    const turn = (mc.input.thetaButton || 0) + k(",", "<") - k(".", ">");
    if (turn !== 0) {
      mc.input.thetaGoal = null;
      cmd.theta_rate_rad_s = Math.max(-1, Math.min(1, turn)) * kThetaRate;
    } else if (mc.input.thetaGoal !== null && mc.input.thetaGoal !== undefined) {
      cmd.theta_goal_rad = mc.input.thetaGoal;
    }
  }
  if (mc.input.poseJog) {
    cmd.pose_jog = mc.input.poseJog;  // the parallel positioner's jog, while a hold button is pressed
  } else if (mc.input.poseGoal) {
    cmd.pose_goal = mc.input.poseGoal;  // its go-to pose
  }
  Object.assign(cmd, mc.microscopeCommand ? mc.microscopeCommand() : {});  // focus, objective, exposure, gain
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
$("vision-tare").addEventListener("click", () => action("vision_tare"));
$("level-tips").addEventListener("click", () => action("level_tips"));
$("record").addEventListener("click", () => {
  if (mc.status && mc.status.recording) action("record_stop");
  else action("record_start", $("record-video-label").hidden ? {} : {video: $("record-video").value});
});
$("record-video").addEventListener("change", () => { mc.recordVideoChosen = true; });

