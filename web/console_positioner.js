// The parallel positioner in 3-D (`positioner: parallel`; docs/console.md, "In 3-D"): its base
// plate, its three carriages and legs and its moving platform, drawn from what Foxglove's 3D panel
// gets: the bodies of /robot/scene (foxglove.SceneUpdate: cubes, cylinders and spheres in their
// frames) placed by the frames of /tf (foxglove.FrameTransforms, one set per telemetry sample:
// world -> positioner, world -> positioner_base -> carriage_i and leg_i; live/robot_frames.h).
// The measured pose is shown in numbers beside it from the telemetry (x, y, z in µm, rx, ry, rz
// in degrees, R = Rz(rz) Ry(ry) Rx(rx) about the platform frame's origin in its home frame); the
// platform's plate at home is outlined dashed, so that a pose's few millimetres show (zoomed).
// Dragging turns the view and the wheel zooms it. Below it, the go-to pose: the goal typed in
// (µm, degrees), sent as the command's pose_goal (SI) with every command while it stands; the
// platform moves only while the deadman is held (the server plans, the loop starts: docs/console.md).
"use strict";

const pos3d = {
  frames: new Map(),    // child frame -> {parent, t: [x, y, z] m, q: [x, y, z, w]}
  entities: new Map(),  // entity id -> foxglove.SceneEntity (the positioner's only)
  yaw: -0.55, pitch: 0.45,  // the view: turned about z, then tilted down [rad]
  zoom: 1,              // the wheel's magnification (the moves are millimetres on a 110 mm base)
  span_m: 0,            // the bodies' extent, fixed once they arrive (the scale must not breathe)
  dirty: false,
  shown: false,
};
// For the browser tests: where the platform's origin was last drawn [canvas px] and the pose shown.
mc.positioner3d = {shown: false, platformPx: null, pose: null, draws: 0, zoom: 1, yaw: 0};

const isPositionerBody = (id) => id === "positioner" || id === "positioner_base" || /^(leg|carriage)_\d+$/.test(id);

listen("/tf", (m) => {
  for (const t of m.transforms || []) {
    const r = t.rotation, p = t.translation;
    pos3d.frames.set(t.child_frame_id, {parent: t.parent_frame_id, t: [p.x, p.y, p.z], q: [r.x, r.y, r.z, r.w]});
  }
  pos3d.dirty = true;
});

listen("/robot/scene", (u) => {
  for (const d of u.deletions || []) {
    if (d.type === 1) pos3d.entities.clear();  // all
    else pos3d.entities.delete(d.id);
  }
  for (const e of u.entities || []) if (isPositionerBody(e.id)) pos3d.entities.set(e.id, e);
  pos3d.span_m = 0;  // new bodies: fit them again
  pos3d.dirty = true;
});

// The panel appears with the positioner's pose in the telemetry; the numbers follow every sample.
listen("/platform/telemetry", (t) => {
  const has = isNum(t.positioner_x_m);
  if (has !== pos3d.shown) {
    pos3d.shown = has;
    mc.positioner3d.shown = has;
    $("positioner-group").hidden = !has;
  }
  if (!has) return;
  const deg = 180 / Math.PI;
  const pose = {x_um: t.positioner_x_m * um, y_um: t.positioner_y_m * um, z_um: t.positioner_z_m * um,
                rx_deg: t.positioner_rx_rad * deg, ry_deg: t.positioner_ry_rad * deg, rz_deg: t.positioner_rz_rad * deg};
  mc.positioner3d.pose = pose;
  for (const [k, v] of Object.entries(pose)) {
    const digits = k.endsWith("um") ? 1 : 3, shown = Number(v.toFixed(digits));
    $("pos3d-" + k).textContent = (shown === 0 ? 0 : shown).toFixed(digits);  // no "-0.0"
  }
  showPoseGoal(pose);
  $("pos3d-moving").textContent = t.positioner_moving ? "moving" : "at rest";
  $("pos3d-moving").className = t.positioner_moving ? "pill warn" : "pill";
});

// ---------------------------------------------------------------------------------------------
// The go-to pose: the fields in µm and degrees, the goal sent in metres and radians.
const poseKeys = ["x_um", "y_um", "z_um", "rx_deg", "ry_deg", "rz_deg"];
$("pose-go").addEventListener("click", () => {
  const values = poseKeys.map((k) => Number($("pose-goal-" + k).value || "0"));
  if (!values.every(Number.isFinite)) {
    $("pose-goal-state").textContent = "a field is not a number";
    return;
  }
  mc.input.poseGoal = values.map((v, i) => (i < 3 ? v / um : (v * Math.PI) / 180));
  mc.input.poseGoalShown = values;
});
$("pose-here").addEventListener("click", () => {
  const p = mc.positioner3d.pose;
  if (!p) return;
  for (const k of poseKeys) $("pose-goal-" + k).value = String(Number(p[k].toFixed(k.endsWith("um") ? 3 : 5)));
});
$("pose-cancel").addEventListener("click", () => { mc.input.poseGoal = null; });
// A step along or about one axis from the goal standing, or from the measured pose: the fields
// show the new goal, sent as Go would.
function poseJog(sign) {
  const p = mc.positioner3d.pose;
  if (!p) return;
  const base = mc.input.poseGoal ? mc.input.poseGoalShown.slice() : poseKeys.map((k) => p[k]);
  const axis = Number($("pose-jog-axis").value), size = Number($("pose-jog-size").value);
  base[axis] += sign * (axis < 3 ? size : size / 100);  // µm, or degrees (the sizes pair 1 µm with 0.01°)
  poseKeys.forEach((k, i) => { $("pose-goal-" + k).value = String(Number(base[i].toFixed(i < 3 ? 3 : 5))); });
  $("pose-go").click();
}
$("pose-jog-minus").addEventListener("click", () => poseJog(-1));
$("pose-jog-plus").addEventListener("click", () => poseJog(1));
// Hold to jog: the twist [vx, vy, vz, wx, wy, wz] (m/s, rad/s) sent while a button is pressed
// (the server clamps it to the positioner's move speeds); a goal standing is forgotten.
function holdJog(sign) {
  const axis = Number($("pose-jog-axis").value), speed = Number($("pose-hold-speed").value);
  const twist = [0, 0, 0, 0, 0, 0];
  twist[axis] = sign * (axis < 3 ? speed / um : ((speed / 100) * Math.PI) / 180);  // µm/s, or °/s (50 µm/s with 0.5°/s)
  mc.input.poseGoal = null;
  mc.input.poseJog = twist;
}
for (const [id, sign] of [["pose-hold-minus", -1], ["pose-hold-plus", 1]]) {
  const b = $(id);
  b.addEventListener("pointerdown", (e) => { b.setPointerCapture(e.pointerId); holdJog(sign); });
  for (const end of ["pointerup", "pointercancel", "lostpointercapture"]) {
    b.addEventListener(end, () => { mc.input.poseJog = null; });
  }
}
// Where the goal stands: reached (within 0.5 µm and 0.001°), or how to get there.
function showPoseGoal(pose) {
  const g = mc.input.poseGoal ? mc.input.poseGoalShown : null;
  let text = "";
  if (g) {
    const reached = poseKeys.every((k, i) => Math.abs(pose[k] - g[i]) <= (i < 3 ? 0.5 : 1e-3));
    text = reached ? "goal reached" : mc.input.deadman ? "going to the goal…" : "hold the deadman (Space) to go";
  }
  $("pose-goal-state").textContent = text;
}

// ---------------------------------------------------------------------------------------------
// Geometry: 3-vectors as arrays, rotations as row-major 3 x 3 arrays.
function quatMatrix([x, y, z, w]) {
  return [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
          2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
          2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)];
}
const mulMV = (R, v) => [R[0] * v[0] + R[1] * v[1] + R[2] * v[2], R[3] * v[0] + R[4] * v[1] + R[5] * v[2],
                         R[6] * v[0] + R[7] * v[1] + R[8] * v[2]];
function mulMM(A, B) {
  const C = new Array(9);
  for (let i = 0; i < 3; i++)
    for (let j = 0; j < 3; j++) C[3 * i + j] = A[3 * i] * B[j] + A[3 * i + 1] * B[3 + j] + A[3 * i + 2] * B[6 + j];
  return C;
}
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
// A pose {R, t}: a point p of the child at R p + t in the parent.
const compose = (a, b) => ({R: mulMM(a.R, b.R), t: add(mulMV(a.R, b.t), a.t)});
const apply = (T, p) => add(mulMV(T.R, p), T.t);

// The frame's pose in the world through the tree (null while a frame of its chain is unknown).
function worldPose(frame) {
  let T = {R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 0]};
  for (let f = frame, depth = 0; f !== "world"; depth++) {
    const tf = pos3d.frames.get(f);
    if (!tf || depth > 8) return null;
    T = compose({R: quatMatrix(tf.q), t: tf.t}, T);
    f = tf.parent;
  }
  return T;
}

// A primitive's solid as faces (each a list of world points) and its colour.
function primitiveFaces(T, prim, kind) {
  const P = compose(T, {R: quatMatrix([prim.pose.orientation.x, prim.pose.orientation.y, prim.pose.orientation.z,
                                       prim.pose.orientation.w]),
                        t: [prim.pose.position.x, prim.pose.position.y, prim.pose.position.z]});
  const s = prim.size, hx = s.x / 2, hy = s.y / 2, hz = s.z / 2;
  const at = (x, y, z) => apply(P, [x, y, z]);
  if (kind === "cube") {
    const c = [[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1], [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]]
                  .map(([a, b, d]) => at(a * hx, b * hy, d * hz));
    return [[0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]].map((f) => f.map((i) => c[i]));
  }
  const n = 18, bottom = [], top = [];  // a cylinder: an 18-sided prism
  for (let i = 0; i < n; i++) {
    const a = (2 * Math.PI * i) / n, cx = Math.cos(a), sy = Math.sin(a);
    bottom.push(at(hx * cx * (prim.bottom_scale ?? 1), hy * sy * (prim.bottom_scale ?? 1), -hz));
    top.push(at(hx * cx * (prim.top_scale ?? 1), hy * sy * (prim.top_scale ?? 1), hz));
  }
  const faces = [bottom.slice().reverse(), top];
  for (let i = 0; i < n; i++) faces.push([bottom[i], bottom[(i + 1) % n], top[(i + 1) % n], top[i]]);
  return faces;
}

// The view: world [m] to canvas [px] and depth (larger: farther), orthographic.
function viewer(canvas) {
  const cy = Math.cos(pos3d.yaw), sy = Math.sin(pos3d.yaw), cp = Math.cos(pos3d.pitch), sp = Math.sin(pos3d.pitch);
  // The base's width across 75 % of the canvas (its height: a tilted base and the legs above it).
  const scale = (pos3d.zoom * 0.75 * Math.min(canvas.width, 1.3 * canvas.height)) / (pos3d.span_m || 0.12);
  const ox = canvas.width / 2, oy = canvas.height * 0.47;
  // Zoomed, the view closes in on the platform's home (the world's origin), where the motion is.
  const centre = (pos3d.centre || [0, 0, 0]).map((c) => c / pos3d.zoom);
  return (p) => {
    const x = p[0] - centre[0], y = p[1] - centre[1], z = p[2] - centre[2];
    const u = cy * x - sy * y, w = sy * x + cy * y;  // across the screen, into it (before the tilt)
    return [ox + scale * u, oy - scale * (z * cp + w * sp), w * cp - z * sp];
  };
}

const rgb = (c, k) => `rgba(${Math.round(255 * Math.min(1, c.r * k))},${Math.round(255 * Math.min(1, c.g * k))},` +
                      `${Math.round(255 * Math.min(1, c.b * k))},${c.a})`;

function drawPositioner() {
  const canvas = $("positioner-view"), g = canvas.getContext("2d");
  g.fillStyle = "#10141a";
  g.fillRect(0, 0, canvas.width, canvas.height);
  // Every face and sphere of the bodies whose frames are known, in the world.
  const items = [];
  for (const e of pos3d.entities.values()) {
    const T = worldPose(e.frame_id);
    if (!T) continue;
    for (const c of e.cubes || []) for (const f of primitiveFaces(T, c, "cube")) items.push({face: f, color: c.color});
    for (const c of e.cylinders || []) for (const f of primitiveFaces(T, c, "cylinder")) items.push({face: f, color: c.color});
    for (const s of e.spheres || [])
      items.push({centre: apply(T, [s.pose.position.x, s.pose.position.y, s.pose.position.z]), r: s.size.x / 2, color: s.color});
  }
  if (items.length === 0) {
    g.fillStyle = "#8a96a8";
    g.font = "13px sans-serif";
    g.fillText("waiting for the positioner's bodies…", 12, 22);
    return;
  }
  if (!pos3d.span_m) {  // fit: the bodies' bounding box, once
    const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
    for (const it of items)
      for (const p of it.face || [it.centre])
        for (let k = 0; k < 3; k++) { lo[k] = Math.min(lo[k], p[k]); hi[k] = Math.max(hi[k], p[k]); }
    pos3d.span_m = Math.max(hi[0] - lo[0], hi[1] - lo[1]);  // the base's width sets the scale
    pos3d.centre = lo.map((v, k) => (v + hi[k]) / 2);
  }
  const view = viewer(canvas), light = [0.35, -0.45, 0.82];
  for (const it of items) {
    if (it.face) {
      it.px = it.face.map(view);
      it.depth = it.px.reduce((s, p) => s + p[2], 0) / it.px.length;
      // Lambert shading on the face's normal (either side: the faces are not oriented).
      const [a, b, c] = it.face;
      const u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]], v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
      const n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
      const len = Math.hypot(...n) || 1;
      it.shade = 0.45 + 0.6 * Math.abs((n[0] * light[0] + n[1] * light[1] + n[2] * light[2]) / len);
    } else {
      it.px = view(it.centre);
      it.depth = it.px[2];
    }
  }
  items.sort((a, b) => b.depth - a.depth);  // the painter's order: the farthest first
  const scale = Math.hypot(view([1e-3, 0, 0])[0] - view([0, 0, 0])[0], view([1e-3, 0, 0])[1] - view([0, 0, 0])[1]) * 1e3;
  for (const it of items) {
    g.beginPath();
    if (it.face) {
      it.px.forEach((p, i) => (i ? g.lineTo(p[0], p[1]) : g.moveTo(p[0], p[1])));
      g.closePath();
      g.fillStyle = rgb(it.color, it.shade);
      g.fill();
      g.strokeStyle = rgb(it.color, it.shade * 0.8);
      g.lineWidth = 0.5;
      g.stroke();
    } else {
      g.arc(it.px[0], it.px[1], Math.max(2, it.r * scale), 0, 2 * Math.PI);
      g.fillStyle = rgb(it.color, 1);
      g.fill();
    }
  }
  // The platform's plate where it stands at home ({P} = {H}), dashed: how far the pose took it.
  const plate = pos3d.entities.get("positioner");
  if (plate && plate.cylinders && plate.cylinders.length) {
    const outline = primitiveFaces({R: [1, 0, 0, 0, 1, 0, 0, 0, 1], t: [0, 0, 0]}, plate.cylinders[0], "cylinder")[1].map(view);
    g.setLineDash([4, 3]);
    g.strokeStyle = "rgba(220, 230, 245, 0.8)";
    g.lineWidth = 1;
    g.beginPath();
    outline.forEach((p, i) => (i ? g.lineTo(p[0], p[1]) : g.moveTo(p[0], p[1])));
    g.closePath();
    g.stroke();
    g.setLineDash([]);
  }
  // The home frame {H} (the world's origin): its axes, 10 mm, over the bodies.
  const o = view([0, 0, 0]);
  for (const [axis, colour, name] of [[[0.01, 0, 0], "#ff5a4a", "x"], [[0, 0.01, 0], "#4ad06a", "y"], [[0, 0, 0.01], "#5a9cff", "z"]]) {
    const p = view(axis);
    g.strokeStyle = colour;
    g.lineWidth = 1.5;
    g.beginPath();
    g.moveTo(o[0], o[1]);
    g.lineTo(p[0], p[1]);
    g.stroke();
    g.fillStyle = colour;
    g.font = "11px sans-serif";
    g.fillText(name, p[0] + 3, p[1] - 3);
  }
  // Where the platform's origin (the default pivot) is drawn, for the tests.
  const P = worldPose("positioner");
  if (P) mc.positioner3d.platformPx = view(P.t).slice(0, 2);
  mc.positioner3d.project = (p) => view(p).slice(0, 2);  // this drawing's mapping, world [m] to px
  mc.positioner3d.draws++;
  mc.positioner3d.zoom = pos3d.zoom;
  mc.positioner3d.yaw = pos3d.yaw;
  g.fillStyle = "rgba(16, 20, 26, 0.75)";  // the hint over whatever is drawn there
  g.fillRect(0, canvas.height - 22, canvas.width, 22);
  g.fillStyle = "#8a96a8";
  g.font = "11px sans-serif";
  g.fillText(`drag: turn · wheel: zoom (${pos3d.zoom.toFixed(1)}×) · double-click: reset`, 8, canvas.height - 8);
}

(function setupPositionerView() {
  const canvas = $("positioner-view");
  let drag = null;
  canvas.addEventListener("pointerdown", (e) => {
    drag = {x: e.clientX, y: e.clientY, yaw: pos3d.yaw, pitch: pos3d.pitch};
    canvas.setPointerCapture(e.pointerId);
  });
  canvas.addEventListener("pointermove", (e) => {
    if (!drag) return;
    pos3d.yaw = drag.yaw + 0.01 * (e.clientX - drag.x);
    pos3d.pitch = clamp(drag.pitch + 0.01 * (e.clientY - drag.y), -0.2, 1.5);
    pos3d.dirty = true;
  });
  const end = () => { drag = null; };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
  canvas.addEventListener("mousedown", (e) => e.preventDefault());  // no text selected by a double-click
  canvas.addEventListener("wheel", (e) => {
    e.preventDefault();
    pos3d.zoom = clamp(pos3d.zoom * Math.exp(-0.002 * e.deltaY), 1, 8);
    pos3d.dirty = true;
  }, {passive: false});
  canvas.addEventListener("dblclick", () => {
    pos3d.yaw = -0.55;
    pos3d.pitch = 0.45;
    pos3d.zoom = 1;
    pos3d.dirty = true;
  });
  const frame = () => {
    if (pos3d.dirty && pos3d.shown) {
      pos3d.dirty = false;
      drawPositioner();
    }
    requestAnimationFrame(frame);
  };
  requestAnimationFrame(frame);
})();
