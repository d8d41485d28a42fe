// Browser test of the live console: starts `microcobot serve` on a free port, opens
// the console in Debian's headless Chromium through playwright-core, takes control and does a
// pick-and-place through the page's own controls (objective, click-to-go on the microscope and
// side views, the Space deadman, the gripper slider), then checks from the streamed telemetry
// that the part ends within 10 um of its target, presses the e-stop and checks the safe state,
// and stops the server with SIGTERM (exit 0, a closed MCAP recording). Screenshots go to
// MC_ARTIFACTS (default: a temporary directory). Run by CTest (`console_browser`).
import { existsSync, readdirSync, readFileSync } from "node:fs";
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

// --record-csv: the CSV beside each recording is opt-in; this test downloads it from the console.
// Without a camera (`devices.camera.driver: none`): the operation through the schematic view,
// whose field follows the gripper; the camera's own panel is console_browser_camera's (the
// simulated camera looks at a fixed field, where the 20x approach over the part is off-field).
const s = await startConsole("console_operates",
  (dir) => ["--out", join(dir, "rec"), "--record", "--record-csv", ...withoutCamera(dir)], 240);
const { page, t, until, shot, clickTop, clickSide, goWithDeadman, setSlider, selectObjective, fail, log, url, dir } = s;
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
  await selectObjective("20x");
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
  await selectObjective("2x");
  await setSlider("#speed", 500);  // the long move at the console's full speed scale
  await clickTop(scene.target_m[0], scene.target_m[1]);
  await goWithDeadman("transport", 60);
  await setSlider("#speed", 200);
  await selectObjective("20x");
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
  await s.estopAndCheck();
  await shot("05-estop");

  // Stop the recording: it is listed with its download and report links; the report is made on
  // demand and draws the session's figures. Then record again (SIGTERM must close that one).
  await page.click("#record");
  await until("the recording listed as finished", () => !!document.querySelector("#recordings a[download]"), 10);
  const download = await page.$eval("#recordings a[download]", (a) => a.href);
  const reportLink = await page.$("#recordings a[target=_blank]");
  const [reportPage] = await Promise.all([page.context().waitForEvent("page"), reportLink.click()]);
  reportPage.on("pageerror", (e) => s.pageErrors.push("report: " + String(e)));
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
  await reportPage.screenshot({ path: join(s.artifacts, "06-report.png") });
  // The data behind each figure: its link (relative to the report) answers with the CSV.
  const figCsv = await reportPage.$eval("a.csv", (a) => a.href).catch(() => "");
  const fig = figCsv ? await reportPage.evaluate(async (u) => { const r = await fetch(u); return { status: r.status, text: await r.text() }; }, figCsv) : { status: 0, text: "" };
  if (fig.status !== 200 || !fig.text.startsWith("#")) fail(`the report's figure data ${figCsv}: HTTP ${fig.status}`);
  await reportPage.close();
  const res = await page.evaluate(async (u) => { const r = await fetch(u); return { status: r.status, bytes: (await r.arrayBuffer()).byteLength }; }, download);
  if (res.status !== 200 || res.bytes < 1000) fail(`download: HTTP ${res.status}, ${res.bytes} bytes`);
  // The same samples as a CSV table, linked beside it.
  const csvLink = await page.$eval("#recordings a[download$='.csv']", (a) => a.href).catch(() => "");
  const csv = csvLink ? await page.evaluate(async (u) => { const r = await fetch(u); return { status: r.status, text: await r.text() }; }, csvLink) : { status: 0, text: "" };
  const csvRows = csv.text.split("\n").filter((l) => l.length).length - 1;
  log(`CSV download ${csvLink}: HTTP ${csv.status}, ${csvRows} rows`);
  if (csv.status !== 200 || !csv.text.startsWith("t_s,") || csvRows < 100) fail(`CSV download: HTTP ${csv.status}, ${csvRows} rows`);
  await page.click("#record");
  await until("recording again", () => window.mc.status && !!window.mc.status.recording, 5);
} catch (e) {
  fail(String(e.stack || e));
  await s.diagnose();
}
await s.closeBrowser();

// SIGTERM: devices safe, the recording closed as a valid MCAP file (both magics) with its CSV
// beside it, exit 0.
await s.terminate();
const recordings = readdirSync(join(dir, "rec")).filter((f) => f.endsWith(".mcap")).sort();
if (recordings.length !== 2) fail("expected two recordings, found: " + readdirSync(join(dir, "rec")).join(", "));
else {
  const bytes = readFileSync(join(dir, "rec", recordings[1]));  // the one SIGTERM closed
  const magic = Buffer.from([0x89, 0x4d, 0x43, 0x41, 0x50, 0x30, 0x0d, 0x0a]);
  if (!bytes.subarray(0, 8).equals(magic) || !bytes.subarray(bytes.length - 8).equals(magic))
    fail("the recording is not a closed MCAP file");
  const csvName = recordings[1].replace(/\.mcap$/, ".csv");
  const text = existsSync(join(dir, "rec", csvName)) ? readFileSync(join(dir, "rec", csvName), "utf8") : "";
  if (!text.startsWith("t_s,") || !text.endsWith("\n")) fail(`no complete ${csvName} beside it`);
  log(`recording ${recordings[1]}: ${bytes.length} bytes; ${csvName}: ${text.split("\n").length - 2} rows`);
}
log(`screenshots in ${s.artifacts}`);
if (s.failures) {
  console.error(`console_operates: ${s.failures} failure(s)`);
  process.exit(1);
}
log("console_operates: pick-and-place through the console, e-stop and SIGTERM all held");
