// The microscope. With a camera (scene.camera), the panel is the camera's image
// (console_camera.js) with the graticule (target, goal, scale bar, arrows toward what is off the
// field); the simulation's ground truth is only an overlay, labelled, off by default. Without a
// camera, a schematic: top view through an objective (field of view, numerical aperture), focused on
// the finger tips; what lies off the focal plane is blurred by defocus, detail finer than the
// optical resolution (0.61 lambda / NA) is not shown. Plus a side view (x, z), click-to-go on
// both, and arrows at the field's edge toward what lies outside it (part, target, goal): at
// 20x the field is 0.6 mm and the target is millimetres away.
"use strict";

const kFieldNumber = 12e-3;  // the schematic's field of view = field number / magnification
const view = {center: [0, 0], fov: 1.2e-3};
// The objective the selector names: the server's turret (scene.optics, by index), whose
// magnification, numerical aperture and wavelength set the schematic's field and resolution.
function optics() {
  const list = mc.scene && mc.scene.optics ? mc.scene.optics.objectives : [];
  const o = list[Number($("objective").value)];
  if (!o) return null;
  const na = o.numerical_aperture;
  return {mag: o.magnification, na, fov: kFieldNumber / o.magnification, resolution: (0.61 * o.wavelength_m) / na};
}
// Without a camera the selector offers the turret's objectives with the schematic's field, and
// starts at the one nearest 10x; with a camera, console_camera.js fills it from the camera's turret.
let schematicTurretFor = null;
listen("/platform/scene", (sc) => {
  if (sc.camera || !sc.optics || schematicTurretFor === JSON.stringify(sc.optics)) return;
  schematicTurretFor = JSON.stringify(sc.optics);
  const sel = $("objective"), list = sc.optics.objectives;
  sel.innerHTML = "";
  list.forEach((o, i) => {
    const opt = document.createElement("option"), field = kFieldNumber / o.magnification;
    opt.value = String(i);
    opt.textContent = `${o.name} (${field >= 1e-3 ? (field * 1e3).toFixed(1) + " mm" : Math.round(field * 1e6) + " µm"})`;
    sel.appendChild(opt);
  });
  const near10 = list.reduce((b, o, i) => (Math.abs(Math.log(o.magnification / 10)) <
                                          Math.abs(Math.log(list[b].magnification / 10)) ? i : b), 0);
  sel.value = String(near10);
});
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

// The camera's image, the graticule over it and, when asked for, the ground truth's outlines.
function drawCameraPanel(c, g, t, sc) {
  g.filter = "none";
  g.fillStyle = "#111";
  g.fillRect(0, 0, c.width, c.height);
  const cv = mc.cameraView();
  if (cv) {
    view.center = cv.center;
    view.fov = cv.fov;
  }
  const shown = mc.drawCameraImage(g, c);
  if (!t || !cv || !shown) return;
  const s = c.width / view.fov;
  if ($("overlay").checked) drawGroundTruth(g, c, t, sc, s);
  if (sc.kind !== "optical-trap") {
    const [tx, ty] = worldToCanvas(sc.target_m[0], sc.target_m[1]);
    g.strokeStyle = "#46c47e";
    g.lineWidth = 2;
    g.beginPath(); g.arc(tx, ty, Math.max(3, sc.tolerance_m * s), 0, 2 * Math.PI);
    g.moveTo(tx - 20, ty); g.lineTo(tx + 20, ty); g.moveTo(tx, ty - 20); g.lineTo(tx, ty + 20); g.stroke();
  }
  if (mc.input.goal) {
    const [gx, gy] = worldToCanvas(mc.input.goal[0], mc.input.goal[1]);
    g.strokeStyle = "#4fa3ff";
    g.lineWidth = 2;
    g.beginPath(); g.arc(gx, gy, 6, 0, 2 * Math.PI); g.stroke();
  }
  drawScaleBar(g, c, s);
  drawOffField(g, c);
}

// Runs `draw` with the canvas' origin at world point (x, y), turned by `yaw` (world,
// counter-clockwise; the canvas' y points down): a turned part, bore or pair of fingers.
function turned(g, x, y, yaw, draw) {
  const [px, py] = worldToCanvas(x, y);
  g.save();
  g.translate(px, py);
  g.rotate(-(isNum(yaw) ? yaw : 0));
  draw();
  g.restore();
}

// The gripper's two fingers about the tool point, in the canvas frame `turned` sets up.
function fingerRects(sc, t, s, rect) {
  const w = sc.finger_width_m, half = t.gripper_opening_m / 2;
  for (const sign of [-1, 1]) rect((sign * (half + w / 2) - w / 2) * s, -w * s, w * s, 2 * w * s);
}

// The simulation's ground truth as outlines (part or beads, fingers), labelled as such.
function drawGroundTruth(g, c, t, sc, s) {
  g.save();
  g.strokeStyle = "#ff5bd1";
  g.fillStyle = "#ff5bd1";
  g.lineWidth = 1.5;
  g.setLineDash([5, 4]);
  if (sc.kind === "optical-trap") {
    const ring = (x, y, r) => { const [px, py] = worldToCanvas(x, y); g.beginPath(); g.arc(px, py, r * s, 0, 2 * Math.PI); g.stroke(); };
    ring(sc.obstacle_m[0], sc.obstacle_m[1], sc.obstacle_radius_m);
    if (isNum(t.part_x_m)) ring(t.part_x_m, t.part_y_m, sc.bead_radius_m);
  } else {
    const side = sc.part_side_m;
    if (isNum(t.part_x_m))
      turned(g, t.part_x_m, t.part_y_m, t.part_yaw_rad, () => g.strokeRect(-side * s / 2, -side * s / 2, side * s, side * s));
    turned(g, t.slave_x_m ?? t.measured_x_m, t.slave_y_m ?? t.measured_y_m, t.slave_theta_rad,
           () => fingerRects(sc, t, s, (x, y, w, h) => g.strokeRect(x, y, w, h)));
  }
  g.setLineDash([]);
  g.font = "bold 12px system-ui";
  g.fillText("GROUND-TRUTH OVERLAY (simulation)", 10, 18);
  g.restore();
}

function drawMicroscope() {
  const c = $("microscope"), g = c.getContext("2d"), t = mc.telemetry, sc = mc.scene;
  if (sc && sc.camera && mc.cameraView) {
    drawCameraPanel(c, g, t, sc);
    return;
  }
  const o = optics();
  if (o) view.fov = o.fov;
  if (t && $("follow").checked) view.center = [t.measured_x_m, t.measured_y_m];
  const s = c.width / view.fov;
  g.filter = "none";
  g.fillStyle = "#2a2722";
  g.fillRect(0, 0, c.width, c.height);
  if (!t || !sc || !o) return;
  if (sc.kind === "optical-trap") {
    drawTrapScene(g, o, s);
    drawScaleBar(g, c, s);
    drawOffField(g, c);
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
    const hs = sc.hole_side_m * s;
    turned(g, sc.target_m[0], sc.target_m[1], sc.hole_yaw_rad,
           () => drawBlurred(g, -hs / 2, -hs / 2, hs, hs, blurPx(focus, o, s), "#0c0b09"));
  }
  // The scene's other parts (a grid load's, `serve --cell`): standing in their slots or placed,
  // their tops at top_z_m, in a darker brass.
  for (const n of sc.neighbours || []) {
    const ns = n.side_m * s;
    turned(g, n.xy_m[0], n.xy_m[1], n.yaw_rad,
           () => drawBlurred(g, -ns / 2, -ns / 2, ns, ns, blurPx(focus - n.top_z_m, o, s), "#9c7d3c"));
  }
  // The part: a brass cube or pin, its top face at part_z + height / 2, blurred by its defocus.
  // (A master of a distributed platform has no part in its telemetry: the microworld is the
  // slave's.)
  const side = sc.part_side_m, height = sc.part_height_m || side;
  if (t.part_x_m !== undefined) {
    turned(g, t.part_x_m, t.part_y_m, t.part_yaw_rad, () =>
      drawBlurred(g, -side * s / 2, -side * s / 2, side * s, side * s, blurPx(focus - (t.part_z_m + height / 2), o, s), "#c9a04a"));
  }
  // The target: a reticle overlaid on the view (a graticule, always sharp), with the tolerance.
  const [tx, ty] = worldToCanvas(sc.target_m[0], sc.target_m[1]);
  g.strokeStyle = "#46c47e";
  g.lineWidth = 2;
  g.beginPath(); g.arc(tx, ty, Math.max(3, sc.tolerance_m * s), 0, 2 * Math.PI);
  g.moveTo(tx - 20, ty); g.lineTo(tx + 20, ty); g.moveTo(tx, ty - 20); g.lineTo(tx, ty + 20); g.stroke();
  // The gripper's two fingers (in focus: the microscope follows their tips), closing along their
  // x, turned with the rotary axis (its sensor) about the tool point.
  g.fillStyle = "#b8c4d6";
  turned(g, t.measured_x_m, t.measured_y_m, t.measured_theta_rad,
         () => fingerRects(sc, t, s, (x, y, w, h) => g.fillRect(x, y, w, h)));
  if (mc.input.goal) {
    const [gx, gy] = worldToCanvas(mc.input.goal[0], mc.input.goal[1]);
    g.strokeStyle = "#4fa3ff";
    g.beginPath(); g.arc(gx, gy, 6, 0, 2 * Math.PI); g.stroke();
  }
  drawScaleBar(g, c, s);
  drawOffField(g, c);
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
  g.fillStyle = "#9c7d3c";  // the other parts, in section along x (all of them: a side view)
  for (const n of sc.neighbours || []) g.fillRect(X(n.xy_m[0] - n.side_m / 2), Z(n.top_z_m), n.side_m * s, Z(0) - Z(n.top_z_m));
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
$("objective").addEventListener("change", () => { drawMicroscope(); drawSide(); });
$("overlay").addEventListener("change", () => drawMicroscope());

// What lies outside the field among the part, the target (or the stuck bead) and the pending
// goal: [{name, x, y, px, py, color}] (world and canvas coordinates).
function offField() {
  const t = mc.telemetry, sc = mc.scene, c = $("microscope"), marks = [];
  if (!t || !sc) return [];
  if (sc.kind === "optical-trap") {
    if (Array.isArray(sc.obstacle_m)) marks.push(["stuck bead", sc.obstacle_m[0], sc.obstacle_m[1], "#d8d2c2"]);
  } else {
    // With a camera the part is what the image shows; its ground truth only with the overlay.
    if (isNum(t.part_x_m) && (!sc.camera || $("overlay").checked)) marks.push(["part", t.part_x_m, t.part_y_m, "#c9a04a"]);
    marks.push(["target", sc.target_m[0], sc.target_m[1], "#46c47e"]);
  }
  if (mc.input.goal) marks.push(["goal", mc.input.goal[0], mc.input.goal[1], "#4fa3ff"]);
  return marks.map(([name, x, y, color]) => {
    const [px, py] = worldToCanvas(x, y);
    return {name, x, y, px, py, color};
  }).filter((m) => m.px < 0 || m.px > c.width || m.py < 0 || m.py > c.height);
}
mc.offField = () => offField().map((m) => m.name);

// An arrow at the edge of the field toward each of them, with its distance from the centre.
function drawOffField(g, c) {
  const inset = 22, cx = c.width / 2, cy = c.height / 2;
  g.font = "12px system-ui";
  for (const {name, x, y, px, py, color} of offField()) {
    // Where the line from the centre to the point crosses the inset border.
    const dx = px - cx, dy = py - cy;
    const k = Math.min((cx - inset) / Math.abs(dx || 1e-9), (cy - inset) / Math.abs(dy || 1e-9));
    const ax = cx + dx * k, ay = cy + dy * k, a = Math.atan2(dy, dx);
    g.fillStyle = color;
    g.beginPath();
    g.moveTo(ax + 14 * Math.cos(a), ay + 14 * Math.sin(a));
    g.lineTo(ax + 8 * Math.cos(a + 2.5), ay + 8 * Math.sin(a + 2.5));
    g.lineTo(ax + 8 * Math.cos(a - 2.5), ay + 8 * Math.sin(a - 2.5));
    g.fill();
    const d = Math.hypot(x - view.center[0], y - view.center[1]);
    const label = `${name} ${d >= 1e-3 ? (d * 1e3).toFixed(2) + " mm" : (d * um).toFixed(0) + " µm"}`;
    const w = g.measureText(label).width;
    // The label inward of the arrow, clear of it.
    g.fillText(label, clamp(ax - w / 2 - (w / 2 + 16) * Math.cos(a), 4, c.width - w - 4),
               clamp(ay + 4 - 18 * Math.sin(a), 14, c.height - 6));
  }
}

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
