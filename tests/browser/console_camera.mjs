// Browser test of the camera in the console: the microscope panel is the camera's
// image (CDR CompressedImage decoded by the page); the part's centre found in the displayed
// pixels lies within 2 px of where the calibration (view centre, objective scale) puts the
// part's true position; focusing on the part's top sharpens it; the 5x objective shows it 2.5
// times larger; the ground-truth overlay is off by default and labelled when on; a click on the
// image sends the stage there (with the deadman); a recording made with the video chosen under
// Recordings keeps the camera that way. Run by CTest (`console_browser_camera`);
// screenshots to MC_ARTIFACTS.
import { readdirSync, writeFileSync } from "node:fs";
import { join } from "node:path";
import { loadReaders, openIndexed } from "../mcap/indexed_reader.mjs";
import { startConsole } from "./console_session.mjs";

// The microscope looks at the part's start (x = 0), the whole part in the 5x field too.
const s = await startConsole("console_camera", (dir) => {
  writeFileSync(join(dir, "camera.yaml"), "camera:\n  view_center_x_m: 0.0\n");
  return ["--config", join(dir, "camera.yaml"), "--out", join(dir, "rec")];
}, 240);
const { page, t, until, shot, fail, log } = s;

// In the displayed canvas, around the expected place of the part (canvas px, its expected side
// `side` px): pixels brighter than halfway between the window's border (substrate) and its
// middle (part); the part's extent from the columns and rows that are mostly bright (a finger
// crossing the part does not move it), its centre and width; and the steepness of its left
// edge (the largest step of the column profile over the part's lower half, relative to the
// contrast): 1 for a sharp edge, small for a blurred one.
const measure = ([ex, ey], side) => page.evaluate(([ex, ey, side]) => {
  const c = document.getElementById("microscope"), g = c.getContext("2d");
  const half = Math.round(0.8 * side), x0 = Math.max(0, Math.round(ex - half)), y0 = Math.max(0, Math.round(ey - half));
  const w = Math.min(c.width - x0, 2 * half), h = Math.min(c.height - y0, 2 * half);
  const d = g.getImageData(x0, y0, w, h).data;
  const grey = (x, y) => { const i = 4 * (y * w + x); return (d[i] + d[i + 1] + d[i + 2]) / 3; };
  const median = (v) => v.sort((a, b) => a - b)[Math.floor(v.length / 2)];
  const border = [], middle = [];
  for (let y = 0; y < h; y++)
    for (let x = 0; x < w; x++) {
      if (x < 4 || y < 4 || x >= w - 4 || y >= h - 4) border.push(grey(x, y));
      if (Math.abs(x - w / 2) < side / 6 && Math.abs(y - h / 2) < side / 6) middle.push(grey(x, y));
    }
  const bg = median(border), fg = median(middle), thr = (bg + fg) / 2;
  const extent = (n, m, at) => {
    let first = -1, last = -1;
    for (let i = 0; i < n; i++) {
      let bright = 0;
      for (let j = 0; j < m; j++) if (at(i, j) > thr) bright++;
      if (bright > 0.3 * m) { if (first < 0) first = i; last = i; }
    }
    return [first, last];
  };
  const [cx0, cx1] = extent(w, h, (x, y) => grey(x, y)), [cy0, cy1] = extent(h, w, (y, x) => grey(x, y));
  const profile = [];
  for (let x = 0; x < w; x++) {
    let sum = 0, n = 0;
    for (let y = Math.round((cy0 + cy1) / 2); y <= cy1 - 2; y++) { sum += grey(x, y); n++; }
    profile.push(sum / n);
  }
  let step = 0;
  for (let x = Math.max(0, cx0 - 10); x < Math.min(w - 1, cx0 + 10); x++) step = Math.max(step, profile[x + 1] - profile[x]);
  return { cx: x0 + (cx0 + cx1 + 1) / 2, cy: y0 + (cy0 + cy1 + 1) / 2, width: cx1 - cx0 + 1,
           steepness: step / Math.max(1, fg - bg), contrast: fg - bg };
}, [ex, ey, side]);
// The part's side in canvas px through the present objective.
const partSide = () => page.evaluate(() => window.mc.scene.part_side_m * document.getElementById("microscope").width /
                                            (window.mc.camera.state.width * window.mc.camera.state.m_per_px));
// Where the calibration puts the part's true centre (its top face), in canvas px.
const expected = () => page.evaluate(() => window.mc.worldToCanvas(window.mc.telemetry.part_x_m, window.mc.telemetry.part_y_m));
const cameraState = () => page.evaluate(() => window.mc.camera.state);

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded", timeout: 90000 });
  await until("connected, scene with a camera, frames shown", () =>
    window.mc.connected && window.mc.scene && window.mc.scene.camera && window.mc.camera.frames >= 3, 30);
  if (await page.isChecked("#overlay")) fail("the ground-truth overlay is on by default");
  if (await page.isHidden("#camera-controls")) fail("no camera controls");
  await shot("camera-01-substrate-in-focus");
  const blurred = await measure(await expected(), await partSide());
  log(`focus on the substrate: part edge steepness ${blurred.steepness.toFixed(2)}`);

  await s.takeControl();
  // Focus on the part's top: the focus slider (as a hand sets it).
  const top = await page.evaluate(() => window.mc.scene.part_height_m);
  await page.evaluate((z) => window.mc.setFocus(z), top);
  await until("focused on the part's top", (z) => window.mc.camera.state && Math.abs(window.mc.camera.state.focus_z_m - z) < 1e-6, 10, top);
  const framesNow = await page.evaluate(() => window.mc.camera.frames);
  await until("a frame at that focus", (n) => window.mc.camera.frames >= n + 3, 10, framesNow);
  await shot("camera-02-part-in-focus");
  const exp2 = await expected();
  const sharp = await measure(exp2, await partSide());
  log(`focus on the part: edge steepness ${sharp.steepness.toFixed(2)}; centre found (${sharp.cx.toFixed(2)}, ${sharp.cy.toFixed(2)}) ` +
      `against the calibration's (${exp2[0].toFixed(2)}, ${exp2[1].toFixed(2)}), width ${sharp.width} px`);
  if (!(sharp.steepness > 1.5 * blurred.steepness)) fail(`focus did not sharpen the part's edge: ${blurred.steepness} -> ${sharp.steepness}`);
  const err = Math.hypot(sharp.cx - exp2[0], sharp.cy - exp2[1]);
  if (!(err <= 2)) fail(`the part's centre in the image is ${err.toFixed(2)} px from the calibration's`);

  // The 5x objective: the same part 2.5 times larger on the screen.
  await page.selectOption("#objective", "1");
  await until("the 5x objective turned in", () => window.mc.camera.state && window.mc.camera.state.objective_name === "5x", 10);
  const f5 = await page.evaluate(() => window.mc.camera.frames);
  await until("a 5x frame", (n) => window.mc.camera.frames >= n + 3, 10, f5);
  await shot("camera-03-5x");
  const exp5 = await expected();
  const at5 = await measure(exp5, await partSide());
  const ratio = at5.width / sharp.width;
  // The part's width on the screen against its calibrated size (2 px: the edges' pixels).
  const side5 = await partSide();
  if (!(Math.abs(at5.width - side5) <= 3)) fail(`5x: the part is ${at5.width} px wide, the calibration says ${side5.toFixed(1)}`);
  log(`5x: width ${at5.width} px against ${sharp.width} px at 2x (ratio ${ratio.toFixed(2)}, expected 2.5); ` +
      `centre off by ${Math.hypot(at5.cx - exp5[0], at5.cy - exp5[1]).toFixed(2)} px`);
  if (!(Math.abs(ratio - 2.5) < 0.2)) fail(`the 5x image scales the part by ${ratio.toFixed(2)}`);
  if (!(Math.hypot(at5.cx - exp5[0], at5.cy - exp5[1]) <= 2)) fail("5x: the part's centre is off the calibration");

  // The snapshot link: the latest full frame, lossless, the sensor's size (TIFF tags 256, 257).
  if (!(await page.isVisible("#snapshot"))) fail("no snapshot link beside the camera");
  const snap = await page.evaluate(async () => {
    const r = await fetch(document.getElementById("snapshot").href);
    const b = new DataView(await r.arrayBuffer());
    const ifd = b.getUint32(4, true), tags = {};
    for (let i = 0; i < b.getUint16(ifd, true); ++i) {
      const e = ifd + 2 + 12 * i;
      tags[b.getUint16(e, true)] = b.getUint16(e + 2, true) === 3 ? b.getUint16(e + 8, true) : b.getUint32(e + 8, true);
    }
    return {status: r.status, type: r.headers.get("content-type"), width: tags[256], height: tags[257], bits: tags[258]};
  });
  const cam5 = await cameraState();
  log(`snapshot: ${snap.status} ${snap.type}, ${snap.width} x ${snap.height}, ${snap.bits} bits`);
  if (snap.status !== 200 || snap.type !== "image/tiff") fail(`the snapshot answered ${snap.status} ${snap.type}`);
  if (snap.width !== cam5.width || snap.height !== cam5.height)
    fail(`the snapshot is ${snap.width} x ${snap.height}, the sensor ${cam5.width} x ${cam5.height}`);

  // The overlay, labelled.
  await page.check("#overlay");
  await page.waitForTimeout(300);
  await shot("camera-04-ground-truth-overlay");
  await page.uncheck("#overlay");

  // Click-to-go on the image: 100 um beside the tool, the deadman held.
  const now = await t();
  await s.clickTop(now.measured_x_m + 100e-6, now.measured_y_m - 50e-6);
  await s.goWithDeadman("the stage at the clicked point", 20, 3e-6);
  await shot("camera-05-after-click-to-go");
  // How old each frame's scene was when the page had it decoded (web/console_camera.js): never
  // before the scene (5 ms: the clock mapping's own error); the figures are the benchmark's
  // (bench/console_camera_bench.mjs), printed here.
  const ages = await page.evaluate(() => window.mc.camera.shownAges.slice().sort((a, b) => a - b));
  if (ages.length < 10) fail(`only ${ages.length} frames stamped with their age`);
  const q = (p) => 1e3 * ages[Math.min(ages.length - 1, Math.floor(p * ages.length))];
  log(`scene to decoded image in the page: p50 ${q(0.5).toFixed(1)} ms, p95 ${q(0.95).toFixed(1)} ms over ${ages.length} frames`);
  if (!(q(0) > -5)) fail(`a frame was shown ${(-q(0)).toFixed(1)} ms before its scene: the page's clock mapping is wrong`);
  const st = await cameraState();
  log(`camera: ${st.objective_name}, ${(st.m_per_px * 1e6).toFixed(3)} um/px, capture ${st.capture_ms.toFixed(1)} ms, ` +
      `JPEG ${st.encode_ms.toFixed(1)} ms, scene-to-JPEG ${st.latency_ms.toFixed(1)} ms, page decode ` +
      `${(await page.evaluate(() => window.mc.camera.decodeMs)).toFixed(1)} ms`);

  // How the next recording keeps the camera, chosen under Recordings: the server's default shown,
  // JPEG chosen, locked while recording; the file then holds the JPEG frames and no H.264
  // (read back by @mcap/core through its index).
  const video = page.locator("#record-video");
  if (!(await video.isVisible())) fail("no video choice under Recordings with a camera");
  const shown = await video.inputValue();
  if (shown !== "h264") fail(`the video choice shows ${shown}, the server's default is h264`);
  await video.selectOption("jpeg");
  await page.click("#record");
  await until("recording", () => window.mc.status && !!window.mc.status.recording, 10);
  if (!(await video.isDisabled())) fail("the video choice can change while recording");
  await page.waitForTimeout(1500);
  await video.scrollIntoViewIfNeeded();
  await shot("camera-06-recording-with-jpeg-video");
  await page.click("#record");
  await until("the recording listed as finished", () => !!document.querySelector("#recordings a[download]"), 15);
  const files = readdirSync(join(s.dir, "rec")).filter((f) => f.endsWith(".mcap"));
  if (files.length !== 1) fail(`expected one recording, found ${files.join(", ")}`);
  else {
    const { reader, close } = await openIndexed(await loadReaders("console_camera"), join(s.dir, "rec", files[0]));
    const counts = {};
    for (const [id, n] of reader.statistics.channelMessageCounts) counts[reader.channelsById.get(id).topic] = Number(n);
    await close();
    log(`recording ${files[0]}: ${counts["/camera/image/compressed"] || 0} JPEG frames, ${counts["/camera/video"] || 0} H.264 frames`);
    if (!(counts["/camera/image/compressed"] >= 10)) fail("the recording holds fewer than 10 JPEG frames");
    if (counts["/camera/video"]) fail("the recording holds H.264 frames though JPEG was chosen");
  }
}, "the console shows the camera, focus and objective change it, click-to-go through its scale");
