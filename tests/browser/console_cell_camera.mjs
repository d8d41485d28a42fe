// Browser test of the cell's camera in the supervised task (`serve --cell --cell-camera`;
// docs/cell.md, "The cell's camera"): started from the task panel, the task holds while the
// camera looks (the panel says so), takes its looks (the pin in its slot, its bore, the pin against its bore until
// the visual servo converges, placed: four when the first align look converges) and inserts the pin; the panel
// counts the looks. Screenshots to MC_ARTIFACTS.
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

const s = await startConsole("console_cell_camera",
  (dir) => ["--cell", "--cell-camera", "--out", join(dir, "rec"), ...withoutCamera(dir)], 240);
const { page, until, shot, fail, log } = s;
const task = () => page.evaluate(() => window.mc.status && window.mc.status.task);

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected and the task in the status", () => window.mc.connected && window.mc.status && window.mc.status.task, 20);
  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  await until("Start enabled", () => !document.getElementById("task-start").disabled, 5);
  await page.click("#task-start");
  // The first look, before the approach moves: the panel says the camera looks, the stage holds.
  await until("the camera's first look shown", () =>
    window.mc.status.task.status === "awaiting look" && document.getElementById("task-hint").textContent.includes("camera"), 20);
  await shot("cell-camera-01-started");
  // To its end; a pause the platform latched for a starved page's heartbeat is resumed, as the operator would.
  const end = Date.now() + 150e3;
  let t = await task();
  let alignShown = false;
  while (!["succeeded", "failed"].includes(t.status) && Date.now() < end) {
    if (!alignShown && t.look === "align") {  // the servo's look, if the poll meets it (it lasts ~0.5 s)
      alignShown = true;
      await shot("cell-camera-02-align");
    }
    if (t.status === "paused" && t.supervisor_lost) {
      log("the platform paused the task (the page's heartbeat was away): resumed");
      await page.evaluate(() => action("task_resume"));
    }
    await page.waitForTimeout(200);
    t = await task();
  }
  log(`the task ${t.status} in ${t.elapsed_s.toFixed(1)} s: camera ${t.looks_found}/${t.looks}, ${t.search_tries} search tries, inserted ${t.inserted}`);
  if (t.status !== "succeeded") fail(`the task ${t.status} in ${t.step}: ${t.failure}`);
  if (t.inserted !== true) fail("the pin is not in its bore");
  if (t.looks < 4 || t.looks_found !== t.looks) fail(`the camera's looks: ${t.looks_found} found of ${t.looks}`);
  const counted = `camera ${t.looks}/${t.looks}`;
  await until("the panel counts the looks", (c) => document.getElementById("task-info").textContent.includes(c), 5, counted);
  await shot("cell-camera-03-done");
}, "the task holds for the cell camera's looks, takes them and inserts the pin");
