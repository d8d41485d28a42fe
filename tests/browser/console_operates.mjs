// Browser test of the live console (issue #14): starts `microcobot serve` on a free port, opens
// the console in Debian's headless Chromium through playwright-core, takes control and does a
// pick-and-place through the page's own controls (objective, click-to-go on the microscope and
// side views, the Space deadman, the gripper slider), then checks from the streamed telemetry
// that the part ends within 10 um of its target, presses the e-stop and checks the safe state,
// and stops the server with SIGTERM (exit 0, a closed MCAP recording). Screenshots go to
// MC_ARTIFACTS (default: a temporary directory). Run by CTest (`console_browser`).
import { spawn } from "node:child_process";
import { mkdtempSync, mkdirSync, readdirSync, readFileSync, existsSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { chromium } from "playwright-core";

const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("console_operates: set MC_CLI to the microcobot binary");
  process.exit(2);
}
const chromiumPath = process.env.MC_CHROMIUM || "/usr/bin/chromium";
const dir = mkdtempSync(join(tmpdir(), "mc-console-"));
const artifacts = process.env.MC_ARTIFACTS || join(dir, "screenshots");
mkdirSync(artifacts, { recursive: true });
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };
const log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(1)} s] ${msg}`);

// The server: its first stdout line is the console's URL.
const server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", "--out", join(dir, "rec"), "--record"],
                     { stdio: ["ignore", "pipe", "inherit"] });
const exited = new Promise((resolve) => server.on("exit", (code, signal) => resolve({ code, signal })));
const url = await new Promise((resolve, reject) => {
  const rl = createInterface({ input: server.stdout });
  rl.once("line", resolve);
  server.once("exit", () => reject(new Error("serve exited before printing its URL")));
  setTimeout(() => reject(new Error("serve printed no URL within 60 s")), 60000);
});
log("console at " + url);
// Whatever happens, never outlive CTest's timeout with the server left running.
const guard = setTimeout(() => {
  console.error("FAIL: console_operates took longer than 240 s");
  server.kill("SIGKILL");
  process.exit(1);
}, 240000);

const browser = await chromium.launch({
  executablePath: chromiumPath,
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
const page = await browser.newPage({ viewport: { width: 1280, height: 1000 } });
const pageErrors = [];
page.on("pageerror", (e) => pageErrors.push(String(e)));
page.on("console", (m) => { if (m.type() === "error") pageErrors.push(m.text()); });
const outside = [];
page.on("request", (r) => { if (!r.url().startsWith(url.split("?")[0])) outside.push(r.url()); });

const t = () => page.evaluate(() => window.mc.telemetry);
async function until(what, predicate, timeoutS) {
  const end = Date.now() + timeoutS * 1000;
  while (Date.now() < end) {
    if (await page.evaluate(predicate)) return true;
    await page.waitForTimeout(50);
  }
  throw new Error(`timed out after ${timeoutS} s: ${what}`);
}
const shot = (name) => page.screenshot({ path: join(artifacts, name + ".png") });

// Clicks the microscope (top view) at world (x, y) or the side view at (x, z), as an operator
// clicks what they see: the page's own mapping from the world to its canvases.
async function clickTop(x, y) {
  const [px, py] = await page.evaluate(([x, y]) => window.mc.worldToCanvas(x, y), [x, y]);
  const box = await page.locator("#microscope").boundingBox();
  const c = await page.evaluate(() => [document.getElementById("microscope").width, document.getElementById("microscope").height]);
  await page.mouse.click(box.x + px * box.width / c[0], box.y + py * box.height / c[1]);
}
async function clickSide(x, z) {
  const [px, py] = await page.evaluate(([x, z]) => window.mc.worldToSide(x, z), [x, z]);
  const box = await page.locator("#side").boundingBox();
  const c = await page.evaluate(() => [document.getElementById("side").width, document.getElementById("side").height]);
  await page.mouse.click(box.x + px * box.width / c[0], box.y + py * box.height / c[1]);
}
// Holds the deadman (Space) until the stage has reached the clicked goal (all three axes).
async function goWithDeadman(what, timeoutS) {
  await page.keyboard.down(" ");
  try {
    await until(what, () => {
      const g = window.mc.input.goal, t = window.mc.telemetry;
      if (!g || !t) return false;
      return Math.abs(t.measured_x_m - g[0]) < 2e-6 && Math.abs(t.measured_y_m - g[1]) < 2e-6 &&
             Math.abs(t.measured_z_m - g[2]) < 3e-6;
    }, timeoutS);
  } finally {
    await page.keyboard.up(" ");
  }
}
async function setSlider(id, value) {
  await page.locator(id).fill(String(value));
}

try {
  await page.goto(url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry and scene", () => window.mc.connected && window.mc.telemetry && window.mc.scene, 20);
  const scene = await page.evaluate(() => window.mc.scene);
  await shot("01-connected");

  // Nothing moves without control and the deadman.
  const before = await t();
  await page.keyboard.down("ArrowRight");
  await page.waitForTimeout(500);
  await page.keyboard.up("ArrowRight");
  if (Math.abs((await t()).target_x_m - before.target_x_m) > 1e-12) fail("an observer moved the stage");

  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  await page.keyboard.down("ArrowRight");  // control but no deadman
  await page.waitForTimeout(500);
  await page.keyboard.up("ArrowRight");
  if (Math.abs((await t()).target_x_m - before.target_x_m) > 1e-12) fail("the stage moved without the deadman");

  await setSlider("#speed", 200);
  await setSlider("#gripper", Math.round(scene.max_opening_m * 1e6));
  const part = await t();
  log(`part at (${(part.part_x_m * 1e6).toFixed(1)}, ${(part.part_y_m * 1e6).toFixed(1)}) um, gripper at ` +
      `(${(part.measured_x_m * 1e6).toFixed(1)}, ${(part.measured_y_m * 1e6).toFixed(1)}, ${(part.measured_z_m * 1e6).toFixed(1)}) um`);

  // Approach: over the part at 20x (the fingers straddle it along x), then down to the grasp height.
  await page.selectOption("#objective", "20");
  await clickTop(part.part_x_m, part.part_y_m);
  await goWithDeadman("over the part", 20);
  await clickSide(part.part_x_m, 100e-6);
  await goWithDeadman("down to the grasp height", 20);
  await shot("02-grasp-height");

  // Grasp: close the gripper until the grip force is felt.
  await setSlider("#gripper", 0);
  await page.keyboard.down(" ");
  await until("grip force", () => window.mc.telemetry.grip_force_N > 10e-6, 10);
  await page.waitForTimeout(300);
  await page.keyboard.up(" ");
  log("gripped: " + ((await t()).grip_force_N * 1e6).toFixed(1) + " uN");

  // Lift, transport at 2x (the target is out of the 20x field), refine at 20x.
  const held = await t();
  await clickSide(held.measured_x_m, 400e-6);
  await goWithDeadman("lift", 20);
  log("lifted");
  if ((await t()).part_z_m < 100e-6) fail("the part did not come up with the gripper");
  await page.selectOption("#objective", "2");
  await setSlider("#speed", 500);  // the long move at the console's full speed scale
  await clickTop(scene.target_m[0], scene.target_m[1]);
  await goWithDeadman("transport", 60);
  await setSlider("#speed", 200);
  await page.selectOption("#objective", "20");
  const near = await t();
  await clickTop(near.measured_x_m + (scene.target_m[0] - near.part_x_m),
                 near.measured_y_m + (scene.target_m[1] - near.part_y_m));
  await goWithDeadman("refine over the target", 20);
  log("over the target");
  await shot("03-over-target");

  // Place: set down, release, retract.
  const over = await t();
  await clickSide(over.measured_x_m, 95e-6);
  await goWithDeadman("set down", 20).catch(() => {});  // the substrate may stop the fingers first
  await setSlider("#gripper", Math.round(scene.max_opening_m * 1e6));
  await page.keyboard.down(" ");
  await until("released", () => window.mc.telemetry.grip_force_N < 1e-7, 10);
  await page.keyboard.up(" ");
  const placed = await t();
  const error = Math.hypot(placed.part_x_m - scene.target_m[0], placed.part_y_m - scene.target_m[1]);
  log(`placement error ${(error * 1e6).toFixed(2)} um (part z ${(placed.part_z_m * 1e6).toFixed(1)} um)`);
  if (!(error <= 10e-6)) fail(`the part ended ${(error * 1e6).toFixed(1)} um from its target (10 um allowed)`);
  // Retract: the part stays where it was set down.
  await clickSide(placed.measured_x_m, 300e-6);
  await goWithDeadman("retract", 30);
  const end = await t();
  const moved = Math.hypot(end.part_x_m - placed.part_x_m, end.part_y_m - placed.part_y_m);
  if (!(moved <= 2e-6)) fail(`the part moved ${(moved * 1e6).toFixed(1)} um when the gripper retracted`);
  await shot("04-placed");

  // E-stop: every device in its safe state, latched.
  await page.click("#estop");
  await until("e-stop latched", () => window.mc.status && window.mc.status.estopped, 5);
  const status = await page.evaluate(() => window.mc.status);
  for (const [device, state] of Object.entries(status.lifecycle)) if (state !== "fault") fail(`${device} is ${state} after the e-stop`);
  await page.waitForTimeout(300);
  const stopped = await t();
  if (stopped.u_x_V !== 0 || stopped.u_y_V !== 0 || stopped.u_z_V !== 0) fail("drive voltages not zero after the e-stop");
  await shot("05-estop");

  // Stop the recording: it is listed with its download and report links; the report is made on
  // demand and draws the session's figures. Then record again (SIGTERM must close that one).
  await page.click("#record");
  await until("the recording listed as finished", () => !!document.querySelector("#recordings a[download]"), 10);
  const download = await page.$eval("#recordings a[download]", (a) => a.href);
  const reportLink = await page.$("#recordings a[target=_blank]");
  const [reportPage] = await Promise.all([page.context().waitForEvent("page"), reportLink.click()]);
  reportPage.on("pageerror", (e) => pageErrors.push("report: " + String(e)));
  const reportDeadline = Date.now() + 60000;
  let figures = 0;
  while (Date.now() < reportDeadline) {
    await reportPage.waitForLoadState("load").catch(() => {});
    figures = await reportPage.evaluate(() => document.querySelectorAll(".uplot canvas").length).catch(() => 0);
    if (figures > 0) break;
    await reportPage.waitForTimeout(200);
  }
  const title = await reportPage.title().catch(() => "");
  log(`report on demand: "${title}", ${figures} plots; download ${download}`);
  if (!title.startsWith("microcobot recording: ") || figures < 8) fail(`the report did not render ("${title}", ${figures} plots)`);
  await reportPage.screenshot({ path: join(artifacts, "06-report.png") });
  await reportPage.close();
  const res = await page.evaluate(async (u) => { const r = await fetch(u); return { status: r.status, bytes: (await r.arrayBuffer()).byteLength }; }, download);
  if (res.status !== 200 || res.bytes < 1000) fail(`download: HTTP ${res.status}, ${res.bytes} bytes`);
  await page.click("#record");
  await until("recording again", () => window.mc.status && !!window.mc.status.recording, 5);
} catch (e) {
  fail(String(e.stack || e));
  const diag = await page.evaluate(() => JSON.stringify({ messages: window.mc.messages.slice(-10), status: window.mc.status,
                                                         goal: window.mc.input.goal, t: window.mc.telemetry })).catch(() => "");
  console.error("page state: " + diag);
  await shot("failure").catch(() => {});
} finally {
  await browser.close();
}

if (pageErrors.length) fail("the page reported errors: " + pageErrors.join(" | "));
if (outside.length) fail("the console fetched from elsewhere (it must work offline): " + outside.join(", "));

// SIGTERM: devices safe, the recording closed as a valid MCAP file (both magics), exit 0.
server.kill("SIGTERM");
const { code, signal } = await exited;
if (code !== 0) fail(`serve exited with ${code} (${signal}) on SIGTERM`);
const recordings = readdirSync(join(dir, "rec")).filter((f) => f.endsWith(".mcap")).sort();
if (recordings.length !== 2) fail("expected two recordings, found: " + readdirSync(join(dir, "rec")).join(", "));
else {
  const bytes = readFileSync(join(dir, "rec", recordings[1]));  // the one SIGTERM closed
  const magic = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);
  if (!bytes.subarray(0, 8).equals(magic) || !bytes.subarray(bytes.length - 8).equals(magic))
    fail("the recording is not a closed MCAP file");
  log(`recording ${recordings[1]}: ${bytes.length} bytes`);
}
log(`screenshots in ${artifacts}`);
clearTimeout(guard);
if (failures) {
  console.error(`console_operates: ${failures} failure(s)`);
  process.exit(1);
}
log("console_operates: pick-and-place through the console, e-stop and SIGTERM all held");
