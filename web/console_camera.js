// The microscope camera: the image of /camera/preview/compressed (a ROS 2
// sensor_msgs/msg/CompressedImage in CDR: the frame binned to the panel's 640 px by the server,
// live/camera_preview.h; its JPEG decoded by the browser), scaled into the
// microscope panel; the objective turret, the focus drive, exposure and gain, sent with the
// console's command while in control. The image is fixed to the microscope's optical axis: a
// pixel (u, v) of the W x H sensor (u right, v down) is the world point
//   x = cx + (u - W/2) s,   y = cy - (v - H/2) s
// with (cx, cy) the view centre and s = pixel pitch / magnification (/camera/state), which is
// how click-to-go turns a click into a goal.
"use strict";

mc.camera = {
  state: null,     // the latest /camera/state: objective, focus, exposure, gain, scale
  bitmap: null,    // the latest decoded frame
  frames: 0,       // decoded since the page opened
  decoding: false, // a decode in flight (newer frames wait: only the latest is decoded)
  pending: null,
  decodeMs: 0,
  receivedAt: 0,   // performance.now() when the last frame arrived
  // How old the scene of each decoded frame was when the page could show it [s]: from the
  // frame's stamp (mid-exposure, live time) to its bitmap, on the page's clock (the last 4000).
  shownAges: [],
};

// Live time on this page's clock: the smallest (arrival - t_s) of the telemetry of the last
// two seconds (60 Hz), the least delayed sample bounding the offset from above.
const liveClock = {offsets: [], offset: NaN};
listen("/platform/telemetry", (t) => {
  const o = performance.now() / 1e3 - t.t_s;
  liveClock.offsets.push(o);
  if (liveClock.offsets.length > 120) liveClock.offsets.shift();
  liveClock.offset = Math.min(...liveClock.offsets);
});

// CDR (little-endian, after the 4-byte encapsulation header): std_msgs/Header, string format,
// uint8[] data. Returns {stamp, format, data} or throws on a truncated message.
function readCompressedImage(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let at = 4;
  const align = (n) => { at += (n - ((at - 4) % n)) % n; };
  const u32 = () => { align(4); const v = view.getUint32(at, true); at += 4; return v; };
  const i32 = () => { align(4); const v = view.getInt32(at, true); at += 4; return v; };
  const str = () => {
    const n = u32();
    if (at + n > bytes.byteLength) throw new Error("truncated string");
    const s = new TextDecoder().decode(bytes.subarray(at, at + Math.max(0, n - 1)));
    at += n;
    return s;
  };
  const sec = i32(), nanosec = u32();
  const frameId = str(), format = str();
  const n = u32();
  if (at + n > bytes.byteLength) throw new Error("truncated data");
  return {stamp: sec + nanosec * 1e-9, frameId, format, data: bytes.subarray(at, at + n)};
}
mc.readCompressedImage = readCompressedImage;

function decodeFrame(bytes) {
  const cam = mc.camera;
  if (cam.decoding) { cam.pending = bytes; return; }
  let msg;
  try { msg = readCompressedImage(bytes); } catch (e) { note("camera: " + e.message); return; }
  cam.decoding = true;
  const t0 = performance.now();
  createImageBitmap(new Blob([msg.data], {type: "image/" + msg.format}))
    .then((bm) => {
      if (cam.bitmap) cam.bitmap.close();
      cam.bitmap = bm;
      cam.stamp = msg.stamp;
      cam.frames += 1;
      cam.decodeMs = performance.now() - t0;
      if (isNum(liveClock.offset)) {
        cam.shownAges.push(performance.now() / 1e3 - liveClock.offset - msg.stamp);
        if (cam.shownAges.length > 4000) cam.shownAges.shift();
      }
    })
    .catch((e) => note("camera: cannot decode a frame: " + e.message))
    .finally(() => {
      cam.decoding = false;
      if (cam.pending) { const next = cam.pending; cam.pending = null; decodeFrame(next); }
    });
}
listen("/camera/preview/compressed", (bytes) => { mc.camera.receivedAt = performance.now(); decodeFrame(bytes); });
listen("/camera/state", (s) => { mc.camera.state = s; showCameraState(); });

// The controls follow the scene's camera (its turret, travel and ranges) once it is known.
let cameraControlsFor = null;
listen("/platform/scene", (sc) => {
  const cam = sc.camera;
  $("camera-controls").hidden = !cam;
  $("snapshot").hidden = !cam;
  $("snapshot").href = "/camera/snapshot.tiff" + location.search;  // the token, when the server needs one
  $("follow-label").hidden = !!cam;
  $("overlay-label").hidden = !cam;
  $("record-video-label").hidden = !cam;
  // The server's default until the operator chooses (a later scene keeps the choice).
  if (cam && !mc.recordVideoChosen) $("record-video").value = cam.record_video;
  if (!cam || cameraControlsFor === JSON.stringify(cam)) return;
  cameraControlsFor = JSON.stringify(cam);
  const sel = $("objective");
  sel.innerHTML = "";
  cam.objectives.forEach((o, i) => {
    const opt = document.createElement("option");
    opt.value = String(i);
    const field = o.m_per_px * cam.width_px;
    opt.textContent = `${o.name} (${field >= 1e-3 ? (field * 1e3).toFixed(2) + " mm" : Math.round(field * um) + " µm"})`;
    sel.appendChild(opt);
  });
  const focus = $("focus");
  focus.min = String(Math.round(cam.focus_min_m * um));
  focus.max = String(Math.round(cam.focus_max_m * um));
  $("exposure").min = String(cam.exposure_range_s[0] * 1e3);
  $("exposure").max = String(cam.exposure_range_s[1] * 1e3);
  $("gain").min = String(cam.gain_range[0]);
  $("gain").max = String(cam.gain_range[1]);
  const c = $("microscope");
  c.height = Math.round((c.width * cam.height_px) / cam.width_px);  // the sensor's aspect
});

// What the operator asks of the microscope; sent with every command once touched.
mc.input.microscope = {};
function setFocus(z) {
  const sc = mc.scene && mc.scene.camera;
  if (!sc) return;
  z = clamp(z, sc.focus_min_m, sc.focus_max_m);
  mc.input.microscope.focus_z_m = z;
  $("focus").value = String(Math.round(z * um));
  $("focus-out").textContent = Math.round(z * um) + " µm";
}
mc.setFocus = setFocus;
$("focus").addEventListener("input", () => setFocus(Number($("focus").value) * 1e-6));
$("focus-up").addEventListener("click", () => setFocus(focusNow() + 10e-6));
$("focus-down").addEventListener("click", () => setFocus(focusNow() - 10e-6));
function focusNow() {
  if (isNum(mc.input.microscope.focus_z_m)) return mc.input.microscope.focus_z_m;
  return mc.camera.state ? mc.camera.state.focus_z_m : 0;
}
$("objective").addEventListener("change", () => {
  if (mc.scene && mc.scene.camera) mc.input.microscope.objective = Number($("objective").value);
});
$("exposure").addEventListener("input", () => {
  mc.input.microscope.exposure_s = Number($("exposure").value) * 1e-3;
  $("exposure-out").textContent = Number($("exposure").value).toFixed(1) + " ms";
});
$("gain").addEventListener("input", () => {
  mc.input.microscope.gain = Number($("gain").value);
  $("gain-out").textContent = Number($("gain").value).toFixed(1) + "×";
});
mc.microscopeCommand = () => mc.input.microscope;

function showCameraState() {
  const s = mc.camera.state;
  if (!s) return;
  // The controls show the camera's state unless the operator is moving them.
  if (!isNum(mc.input.microscope.focus_z_m)) {
    $("focus").value = String(Math.round(s.focus_z_m * um));
    $("focus-out").textContent = Math.round(s.focus_z_m * um) + " µm";
  }
  if (document.activeElement !== $("objective") && mc.input.microscope.objective === undefined)
    $("objective").value = String(s.objective);
  if (mc.input.microscope.exposure_s === undefined) {
    $("exposure").value = String(s.exposure_s * 1e3);
    $("exposure-out").textContent = (s.exposure_s * 1e3).toFixed(1) + " ms";
  }
  if (mc.input.microscope.gain === undefined) {
    $("gain").value = String(s.gain);
    $("gain-out").textContent = s.gain.toFixed(1) + "×";
  }
}

// The camera's view for the microscope panel: centre and field width (world), from the frame's
// state; null until a frame came.
mc.cameraView = () => {
  const s = mc.camera.state;
  if (!s || !mc.scene || !mc.scene.camera) return null;
  return {center: s.view_center_m, fov: s.width * s.m_per_px};
};

// Draws the latest frame over the whole canvas (the canvas has the sensor's aspect).
mc.drawCameraImage = (g, c) => {
  const cam = mc.camera;
  if (!cam.bitmap) {
    g.fillStyle = "#8a93a3";
    g.font = "14px system-ui";
    g.fillText("waiting for the camera…", 12, 22);
    return false;
  }
  g.imageSmoothingEnabled = true;
  g.drawImage(cam.bitmap, 0, 0, c.width, c.height);
  const s = cam.state;
  if (s)
    $("scope-info").textContent = `${s.objective_name}, ${(s.m_per_px * um).toFixed(2)} µm/px, ` +
      `focus ${(s.focus_z_m * um).toFixed(0)} µm, ${(s.exposure_s * 1e3).toFixed(1)} ms × ${s.gain.toFixed(1)}, ` +
      `frame ${s.sequence}`;
  const vi = visionInfo();
  $("vision-info").hidden = !vi;
  $("vision-info").textContent = vi;
  drawVision(g, c);
  return true;
};

// The stage positioned by vision (stage.xy_sensor: vision, /console/status "vision"): where the
// camera thread's tracker sees the tool point (a cross) and where the servo sends it (a ring),
// in the full frame's pixels scaled to the canvas; its state in the panel's caption.
function visionInfo() {
  const v = mc.status && mc.status.vision;
  if (!v) return "";
  if (v.error) return `vision: ${v.error}`;
  const left = v.has_goal ? `, ${(v.error_m * um).toFixed(2)} µm to go` : "";
  return `vision: ${v.state}${left}${v.calibrated ? "" : " (nominal scale)"}`;
}
function drawVision(g, c) {
  const v = mc.status && mc.status.vision, s = mc.camera.state;
  if (!v || !v.taught || !s) return;
  const kx = c.width / s.width, ky = c.height / s.height;
  g.lineWidth = 1.5;
  g.strokeStyle = v.found ? "#ffd23f" : "#ff6b6b";
  const [tx, ty] = [v.tool_px[0] * kx, v.tool_px[1] * ky];
  g.beginPath();
  g.moveTo(tx - 8, ty); g.lineTo(tx + 8, ty); g.moveTo(tx, ty - 8); g.lineTo(tx, ty + 8);
  g.stroke();
  if (v.goal_px) {
    g.strokeStyle = "#4fa3ff";
    g.beginPath();
    g.arc(v.goal_px[0] * kx, v.goal_px[1] * ky, 6, 0, 2 * Math.PI);
    g.stroke();
  }
}
