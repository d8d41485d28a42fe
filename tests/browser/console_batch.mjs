// Browser test of a batch in the console (`serve --cell` with a grid load): the task
// panel says which part of the batch the scene holds; the scene carries the load's other parts
// (drawn in the microscope, rendered in the camera's image); Next part rebuilds the scene on the
// batch's next part (its target and neighbours), its task waiting for Start; Next part is offered
// only while no task runs. Run by CTest (`console_browser_batch`); screenshots to MC_ARTIFACTS.
import { join } from "node:path";
import { writeFileSync } from "node:fs";
import { startConsole } from "./console_session.mjs";

const s = await startConsole("console_batch", (dir) => {
  const scene = join(dir, "grid.yaml");
  writeFileSync(scene, "parts: 3\nlayout: grid\n");
  return ["--cell", "--scene", scene, "--seed", "43", "--out", join(dir, "rec")];
}, 200);
const { page, until, shot, fail, log, task, untilTask } = s;

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, the scene and the task in the status", () =>
    window.mc.connected && window.mc.telemetry && window.mc.scene && window.mc.status && window.mc.status.task, 20);
  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  const first = await page.evaluate(() => window.mc.scene);
  let t = await task();
  if (t.part !== 0 || t.parts !== 3) fail(`the task is on part ${t.part} of ${t.parts}, not 0 of 3`);
  if (!Array.isArray(first.neighbours) || first.neighbours.length !== 2) fail(`the scene holds ${first.neighbours && first.neighbours.length} other parts, not 2`);
  await until("the panel naming the part", () => document.getElementById("task-info").textContent.includes("part 1 of 3"), 5);
  await until("Next part offered before the start", () => !document.getElementById("task-next-part").disabled, 5);
  await page.waitForTimeout(1500);  // a few camera frames
  await shot("batch-01-part-1-of-3");

  await page.click("#task-next-part");
  await untilTask("the task on the batch's second part, not started", (x) => x.part === 1 && x.status === "idle", 20);
  await until("the scene of the second part", (was) => {
    const sc = window.mc.scene;
    return sc.target_m[0] !== was[0] || sc.target_m[1] !== was[1];
  }, 10, first.target_m);
  const second = await page.evaluate(() => window.mc.scene);
  if (second.neighbours.length !== 2) fail(`the second part's scene holds ${second.neighbours.length} other parts, not 2`);
  // The first part, placed: it stands at its bore (the first scene's target), its top lower than standing.
  const placed = second.neighbours.find((n) => Math.hypot(n.xy_m[0] - first.target_m[0], n.xy_m[1] - first.target_m[1]) < 1e-9);
  if (!placed) fail("the first part is not among the second part's neighbours at its bore");
  else if (!(placed.top_z_m < first.part_height_m)) fail(`the placed first part's top is at ${placed.top_z_m} m, not below its height`);
  await until("the panel naming the second part", () => document.getElementById("task-info").textContent.includes("part 2 of 3"), 5);
  await page.waitForTimeout(1500);
  await shot("batch-02-part-2-of-3");

  await page.click("#task-start");
  await untilTask("the task started", (x) => x.started, 10);
  await until("Next part not offered while the task runs", () => document.getElementById("task-next-part").disabled, 5);
  t = await task();
  log(`part ${t.part + 1} of ${t.parts}: ${t.status} in ${t.step}; neighbours ${second.neighbours.length}`);
}, "the console went through the batch");
