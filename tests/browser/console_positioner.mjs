// Browser test of the parallel positioner's 3-D view: `serve --emulate gcs2-hexapod` (the PI C-887
// dialect over the platform's 6-DOF parallel positioner, `positioner: parallel`), the console
// shows the positioner's panel with its bodies drawn and the measured pose in numbers; a pose move
// commanded through the twin's GCS socket (FRF, MOV, polled with ONT?) moves the drawn platform by
// where the page's own projection puts the measured pose, and the numbers follow the telemetry
// throughout. Turning the view sends nothing. The panel's go-to pose moves the platform only
// while the deadman is held, to the goal typed in.
// Screenshots at 1400x950 and 1024x768 go to MC_ARTIFACTS.
import { connect } from "node:net";
import { createInterface } from "node:readline";
import { startConsole, withoutCamera } from "./console_session.mjs";

const s = await startConsole("console_positioner",
                             (dir) => [...withoutCamera(dir), "--emulate", "gcs2-hexapod=127.0.0.1:0"], 200,
                             { viewport: { width: 1400, height: 950 } });
const { page, until, shot, fail, log, url } = s;

// The twin's GCS socket, line by line (a query's reply has one line per axis asked).
async function gcs(port) {
  const socket = connect(port, "127.0.0.1");
  await new Promise((resolve, reject) => { socket.once("connect", resolve); socket.once("error", reject); });
  const lines = [], waiters = [];
  createInterface({ input: socket }).on("line", (l) => (waiters.length ? waiters.shift()(l) : lines.push(l)));
  const readLine = () => new Promise((resolve, reject) => {
    if (lines.length) return resolve(lines.shift());
    const timer = setTimeout(() => reject(new Error("the twin did not answer within 10 s")), 10000);
    waiters.push((l) => { clearTimeout(timer); resolve(l); });
  });
  return {
    write: (line) => socket.write(line + "\n"),
    ask: async (line, n = 1) => {
      socket.write(line + "\n");
      const out = [];
      for (let i = 0; i < n; i++) out.push((await readLine()).trim());
      return out;
    },
    close: () => socket.destroy(),
  };
}

// The numbers shown against the telemetry they came from (read together: the same sample).
const shown = () => page.evaluate(() => {
  const t = window.mc.telemetry, deg = 180 / Math.PI;
  const text = (k) => Number(document.getElementById("pos3d-" + k).textContent);
  return {
    shown: [text("x_um"), text("y_um"), text("z_um"), text("rx_deg"), text("ry_deg"), text("rz_deg")],
    telemetry: [t.positioner_x_m * 1e6, t.positioner_y_m * 1e6, t.positioner_z_m * 1e6,
                t.positioner_rx_rad * deg, t.positioner_ry_rad * deg, t.positioner_rz_rad * deg],
  };
});
const checkNumbers = (what, n) => {
  // Shown to 0.1 um and 0.001 deg.
  for (let i = 0; i < 6; i++) {
    const tol = i < 3 ? 0.051 : 0.00051;
    if (!(Math.abs(n.shown[i] - n.telemetry[i]) <= tol))
      fail(`${what}: ${"xyz"[i % 3]}${i < 3 ? "" : " rotation"} shown ${n.shown[i]}, the telemetry ${n.telemetry[i]}`);
  }
};

await s.run(async () => {
  const emulate = s.stdoutLines.find((l) => l.startsWith("emulate gcs2-hexapod "));
  if (!emulate) throw new Error("serve printed no gcs2-hexapod twin: " + s.stdoutLines.join(" | "));
  const port = Number(emulate.split(":").at(-1));
  // Every message the page sends to the server: the panel must add none.
  const sent = [];
  page.on("websocket", (ws) => ws.on("framesent", (f) => sent.push(f.payload)));
  await page.goto(url, { waitUntil: "domcontentloaded" });
  await until("connected, the positioner's pose in the telemetry",
              () => window.mc.connected && window.mc.telemetry && typeof window.mc.telemetry.positioner_x_m === "number", 20);
  await until("the positioner's panel shown", () => !document.getElementById("positioner-group").hidden, 5);
  await until("its bodies drawn", () => window.mc.positioner3d.draws > 0 && window.mc.positioner3d.platformPx !== null, 15);
  const home = await page.evaluate(() => ({ px: window.mc.positioner3d.platformPx, pose: window.mc.positioner3d.pose }));
  log(`at home: the platform's origin drawn at (${home.px.map((v) => v.toFixed(1)).join(", ")}) px`);
  checkNumbers("at home", await shown());
  // The panel lies inside the window and its canvas is not squeezed.
  await page.locator("#positioner-group").scrollIntoViewIfNeeded();
  const box = await page.locator("#positioner-view").boundingBox();
  if (!(box.width >= 300 && box.x + box.width <= 1400 && box.y >= 0 && box.y + box.height <= 950))
    fail(`the 3-D view is ${JSON.stringify(box)}`);
  await shot("positioner-1400x950-home");

  // Dragging turns the view (the drawing changes) and sends nothing: no protocol operation, no
  // action, no command with the deadman (the command's heartbeat goes on as before).
  const sentBefore = sent.length;
  const yaw0 = await page.evaluate(() => window.mc.positioner3d.yaw);
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 40, box.y + box.height / 2 + 10, { steps: 4 });
  await page.mouse.up();
  // 0.01 rad a pixel: 40 px across turn the view 0.4 rad about z.
  await until("the view turned by the drag", (y) => Math.abs(window.mc.positioner3d.yaw - y - 0.4) < 1e-9, 5, yaw0);
  const selectedAfterDrag = await page.evaluate(() => String(window.getSelection()));
  await page.dblclick("#positioner-view");  // back to the default view
  await until("the view back to its default", (y) => window.mc.positioner3d.yaw === y, 5, yaw0);
  // The gestures select no text of the page.
  const selected = await page.evaluate(() => String(window.getSelection()));
  if (selectedAfterDrag || selected) fail(`the view's gestures selected "${selectedAfterDrag}", then "${selected}"`);
  const commandChannel = 1;  // the console advertises /console/command first, /console/action second
  for (const p of sent.slice(sentBefore)) {
    if (typeof p === "string") { fail("the page sent a protocol operation while the view turned: " + p); continue; }
    const bytes = Buffer.from(p);
    const body = bytes.subarray(5).toString();
    if (bytes[0] !== 1 || bytes.readUInt32LE(1) !== commandChannel || body.includes('"deadman":true'))
      fail("the page sent while the view turned: " + body);
  }

  // A pose move through the twin: referenced, then a pose a few millimetres and degrees away.
  const c = await gcs(port);
  try {
    c.write("FRF");
    const err = await c.ask("ERR?");
    if (err[0] !== "0") throw new Error("FRF: error " + err[0]);
    const onTarget = async (what) => {
      const end = Date.now() + 60000;
      while (Date.now() < end) {
        if ((await c.ask("ONT? X Y Z U V W", 6)).every((l) => l.endsWith("=1"))) return;
        await new Promise((r) => setTimeout(r, 100));
      }
      throw new Error("not on target: " + what);
    };
    await onTarget("referenced");
    c.write("VLS 0.5");
    const err1 = await c.ask("ERR?");
    if (err1[0] !== "0") throw new Error("VLS: error " + err1[0]);
    const goal = [1.5, -1.0, -0.8, 2.0, -1.5, 3.0];  // X, Y, Z [mm], U, V, W [deg]: down, clear of the tips
    const move = async () => {
      c.write("MOV " + goal.map((v, i) => "XYZUVW"[i] + " " + v).join(" "));
      const err2 = await c.ask("ERR?");
      if (err2[0] !== "0") throw new Error("MOV: error " + err2[0]);
    };
    await move();
    // While it moves: the numbers follow the telemetry sample by sample.
    await until("the positioner moving", () => window.mc.telemetry.positioner_moving === 1, 10);
    await shot("positioner-1400x950-moving");
    for (let i = 0; i < 5; i++) {
      checkNumbers(`moving, read ${i}`, await shown());
      await page.waitForTimeout(150);
    }
    // The platform holds a move whose client falls silent for longer than the protocol's heartbeat
    // timeout (0.2 s), as a starved test client on a loaded machine can: the controller then reports
    // error 10 (stopped) and stands on target where it holds. A client finishes its move by sending
    // it again, as this one does (at most three times).
    for (let attempt = 1; ; attempt++) {
      await onTarget("the pose");
      const err3 = await c.ask("ERR?");
      if (err3[0] === "0") break;
      if (err3[0] !== "10" || attempt === 3) throw new Error("the pose move: error " + err3[0]);
      log(`the move was stopped (error 10: the client fell silent): sent again`);
      await move();
    }
    const pos = (await c.ask("POS?", 6)).map((l) => Number(l.split("=")[1]));
    log(`POS? ${pos.join(" ")}`);
  } finally {
    c.close();
  }
  await until("at rest in the page", () => window.mc.telemetry.positioner_moving === 0, 10);
  await page.waitForTimeout(300);
  const n = await shown();
  checkNumbers("on target", n);
  log(`shown: ${n.shown.join(", ")}`);
  // The platform's measured pose is where it was asked, so the numbers too (the twin's U, V, W are
  // about moving axes and the panel's rx, ry, rz fixed ones: the translations are compared, and the
  // rotations' size).
  if (Math.abs(n.shown[0] - 1500) > 2 || Math.abs(n.shown[1] + 1000) > 2 || Math.abs(n.shown[2] + 800) > 2)
    fail(`the translation shown ${n.shown.slice(0, 3)} um, asked (1500, -1000, -800)`);
  if (Math.abs(n.shown[5] - 3) > 0.5) fail(`rz shown ${n.shown[5]} deg, asked W 3 deg`);

  // The drawn platform moved to where this drawing's projection puts the measured translation.
  const moved = await page.evaluate(() => {
    const p = window.mc.positioner3d, t = window.mc.telemetry;
    return { px: p.platformPx, expected: p.project([t.positioner_x_m, t.positioner_y_m, t.positioner_z_m]),
             home: p.project([0, 0, 0]) };
  });
  const d = Math.hypot(moved.px[0] - moved.home[0], moved.px[1] - moved.home[1]);
  log(`the platform's origin drawn at (${moved.px.map((v) => v.toFixed(1)).join(", ")}) px, ${d.toFixed(1)} px from home`);
  if (Math.hypot(moved.px[0] - moved.expected[0], moved.px[1] - moved.expected[1]) > 0.5)
    fail(`the platform drawn at ${moved.px}, its measured pose projects to ${moved.expected}`);
  // A millimetre is a pixel or two on the whole 110 mm positioner: the zoom below shows it.
  if (!(d > 0.5)) fail(`the drawn platform moved ${d} px`);
  await shot("positioner-1400x950-moved");
  await page.locator("#positioner-group").screenshot({ path: `${s.artifacts}/positioner-panel-moved.png` });

  // Zoomed in (the wheel), the motion shows: the platform drawn further from home.
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  for (let i = 0; i < 3; i++) await page.mouse.wheel(0, -200);
  await until("zoomed", () => window.mc.positioner3d.zoom > 3, 5);
  await page.waitForTimeout(300);
  const zoomed = await page.evaluate(() => {
    const p = window.mc.positioner3d;
    const h = p.project([0, 0, 0]);
    return Math.hypot(p.platformPx[0] - h[0], p.platformPx[1] - h[1]);
  });
  log(`zoomed ${await page.evaluate(() => window.mc.positioner3d.zoom.toFixed(1))}x: ${zoomed.toFixed(1)} px from home`);
  if (!(zoomed > 2.5 * d && zoomed > 4)) fail(`zoomed, the platform is ${zoomed} px from home (${d} px unzoomed)`);
  await shot("positioner-1400x950-zoomed");
  await page.locator("#positioner-group").screenshot({ path: `${s.artifacts}/positioner-panel-zoomed.png` });
  await page.dblclick("#positioner-view");  // the whole positioner again

  // A tablet's 1024x768: the panel still fits beside the microscope.
  await page.setViewportSize({ width: 1024, height: 768 });
  await page.waitForTimeout(500);
  await page.locator("#positioner-group").scrollIntoViewIfNeeded();
  const small = await page.locator("#positioner-view").boundingBox();
  if (!(small.width >= 250 && small.x + small.width <= 1024)) fail(`at 1024x768 the 3-D view is ${JSON.stringify(small)}`);
  await shot("positioner-1024x768");

  // The go-to pose from the panel, as an operator uses it: control taken, a goal typed in
  // (µm, degrees) and Go pressed; nothing moves until the deadman is held; held, the platform goes
  // there (the numbers shown within 0.5 µm and 0.001°) and the panel says so.
  await page.setViewportSize({ width: 1400, height: 950 });
  await page.click("#take-control");
  await until("in control", () => window.mc.inControl, 10);
  const start = (await shown()).telemetry;
  const goal = [start[0] + 150, start[1] - 80, start[2] + 40, start[3] + 0.2, start[4] - 0.1, start[5] + 0.5];
  const keys = ["x_um", "y_um", "z_um", "rx_deg", "ry_deg", "rz_deg"];
  for (let i = 0; i < 6; i++) await page.fill("#pose-goal-" + keys[i], goal[i].toFixed(i < 3 ? 1 : 3));
  await page.click("#pose-go");
  await page.locator("#pose-go").scrollIntoViewIfNeeded();
  await until("the panel asks for the deadman", () => /deadman/.test(document.getElementById("pose-goal-state").textContent), 5);
  await page.waitForTimeout(600);
  const still = (await shown()).telemetry;
  if (Math.hypot(still[0] - start[0], still[1] - start[1], still[2] - start[2]) > 0.2)
    fail(`the platform moved without the deadman: ${start.slice(0, 3)} -> ${still.slice(0, 3)} µm`);
  await page.keyboard.down(" ");
  try {
    await until("the goal reached", () => document.getElementById("pose-goal-state").textContent === "goal reached", 60);
  } finally {
    await page.keyboard.up(" ");
  }
  const reached = await shown();
  checkNumbers("at the goal", reached);
  for (let i = 0; i < 6; i++)
    if (!(Math.abs(reached.telemetry[i] - Number(goal[i].toFixed(i < 3 ? 1 : 3))) <= (i < 3 ? 0.5 : 1e-3)))
      fail(`${keys[i]}: ${reached.telemetry[i]} at the goal ${goal[i]}`);
  log(`go-to pose: at (${reached.telemetry.map((v, i) => v.toFixed(i < 3 ? 2 : 4)).join(", ")}) µm, °`);
  // The step jog: 1° about z from that goal, with the deadman.
  await page.selectOption("#pose-jog-axis", "5");
  await page.selectOption("#pose-jog-size", "100");
  await page.click("#pose-jog-plus");
  await page.keyboard.down(" ");
  try {
    await until("the step reached", () => document.getElementById("pose-goal-state").textContent === "goal reached" &&
                Math.abs(window.mc.positioner3d.pose.rz_deg - Number(document.getElementById("pose-goal-rz_deg").value)) < 1e-3, 60);
  } finally {
    await page.keyboard.up(" ");
  }
  const stepped = (await shown()).telemetry;
  log(`step jog rz: ${reached.telemetry[5].toFixed(4)} -> ${stepped[5].toFixed(4)}°`);
  if (!(Math.abs(stepped[5] - reached.telemetry[5] - 1) <= 2e-3)) fail(`the 1° step about z turned ${stepped[5] - reached.telemetry[5]}°`);
  for (let i = 0; i < 5; i++)
    if (!(Math.abs(stepped[i] - reached.telemetry[i]) <= (i < 3 ? 0.5 : 1e-3))) fail(`the rz step moved ${keys[i]}`);
  await shot("positioner-1400x950-goto-reached");
  await page.locator("#positioner-group").screenshot({ path: `${s.artifacts}/positioner-panel-goto.png` });
  // Hold to jog: y at 50 µm/s while the button is pressed with the deadman; released, it holds.
  await page.selectOption("#pose-jog-axis", "1");
  await page.selectOption("#pose-hold-speed", "50");
  await page.locator("#pose-hold-plus").scrollIntoViewIfNeeded();
  await page.locator("#pose-hold-plus").hover();
  const before = (await shown()).telemetry;
  await page.keyboard.down(" ");
  const t0 = Date.now();
  await page.mouse.down();
  try {
    await page.waitForTimeout(1500);
  } finally {
    await page.mouse.up();
    await page.keyboard.up(" ");
  }
  const held_s = (Date.now() - t0) / 1000;
  await page.waitForTimeout(500);
  const jogged = (await shown()).telemetry;
  await page.waitForTimeout(500);
  const after = (await shown()).telemetry;
  const dy = jogged[1] - before[1];
  log(`hold jog y: ${dy.toFixed(1)} µm in ${held_s.toFixed(2)} s held`);
  if (!(dy > 40 && dy <= 50 * held_s + 1)) fail(`the 50 µm/s jog held ${held_s} s moved y by ${dy} µm`);
  if (!(Math.abs(after[1] - jogged[1]) <= 0.5)) fail(`released, the platform went on: ${jogged[1]} -> ${after[1]} µm`);
  for (const i of [0, 2, 3, 4, 5])
    if (!(Math.abs(jogged[i] - before[i]) <= (i < 3 ? 0.5 : 1e-3))) fail(`the y jog moved ${keys[i]}: ${before[i]} -> ${jogged[i]}`);
  await shot("positioner-1400x950-jogged");
}, "the positioner's 3-D panel draws the measured pose, its numbers follow the telemetry, and its go-to pose moves it with the deadman");
