// Browser test of the supervised task (`serve --cell`): from the page's task
// panel the operator starts the automatic insertion, pauses it while it carries the pin (the
// commanded position stops at the first telemetry sample of the pause and stays; the stage
// settles there), takes over (no jump in the commanded position; the operator jogs with the
// deadman from where it is), hands back (the step again, from there) and sees the task go on to
// insert the pin. Every 60 Hz telemetry sample is kept by the page for the checks. Run by CTest
// (`console_browser_task`); screenshots to MC_ARTIFACTS.
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

const s = await startConsole("console_task", (dir) => ["--cell", "--out", join(dir, "rec"), ...withoutCamera(dir)], 240);
const { page, until, shot, fail, log, task, untilTask } = s;
const samples = () => page.evaluate(() => window.taskSamples);
const target = (x) => [x.target_x_m, x.target_y_m, x.target_z_m];
const dist = (a, b) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
// The largest change of the commanded position between two consecutive samples of [from, to).
const largestStep = (xs, from, to) => {
  let m = 0;
  for (let i = Math.max(1, from); i < Math.min(to, xs.length); i++) m = Math.max(m, dist(target(xs[i]), target(xs[i - 1])));
  return m;
};
const um = (v) => (v * 1e6).toFixed(2);

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry and the task in the status", () =>
    window.mc.connected && window.mc.telemetry && window.mc.status && window.mc.status.task, 20);
  // Keep every telemetry sample the page receives (the page's own channel listener).
  await page.evaluate(() => {
    window.taskSamples = [];
    listen("/platform/telemetry", (t) => window.taskSamples.push({ ...t, at: performance.now() }));
    // The page's timers' gaps (its 30 Hz command is the heartbeat the task's supervision needs).
    window.timerGaps = { last: performance.now(), max: 0, over200: 0 };
    setInterval(() => {
      const g = window.timerGaps, now = performance.now(), gap = now - g.last;
      g.max = Math.max(g.max, gap);
      if (gap > 200) g.over200++;
      g.last = now;
    }, 33);
  });
  if (!(await page.isVisible("#task-group"))) fail("the task panel is not shown");
  if ((await task()).status !== "idle") fail(`the task is ${(await task()).status} before Start`);
  await shot("task-01-idle");
  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);

  // Start: the robot approaches, grasps, lifts and carries the pin across.
  await until("Start enabled", () => !document.getElementById("task-start").disabled, 5);
  await page.click("#task-start");
  await until("the task running", () => window.mc.status.task.status === "running", 5);
  // No screenshot while the task runs: it stalls the page's heartbeat for seconds here.
  await untilTask("the pin carried to its bore (transport)", (t) => t.step === "transport" && t.status === "running", 120);
  await page.waitForTimeout(700);
  await untilTask("the task running", (t) => t.status === "running", 30);

  // Pause: the commanded position stops at the first sample of the pause (the loop's tick that
  // applies it) and stays; the stage settles onto it.
  const clickedAt = await page.evaluate(() => performance.now());
  await page.click("#task-pause");
  // (A pause the platform made for a heartbeat gap just before becomes the operator's.)
  await until("the task paused by the operator", () => {
    const t = window.mc.status.task;
    return t.status === "paused" && !t.heartbeat_gap && !t.supervisor_lost;
  }, 5);
  await page.waitForTimeout(1500);
  let xs = await samples();
  // The first sample of the pause: the one after the last the task drove.
  let first = xs.length - 1;
  while (first > 0 && xs[first - 1].engaged === 0) first--;
  if (first < 2 || xs[first - 1].engaged !== 1) throw new Error("no telemetry sample of the task driving before the pause");
  if (dist(target(xs[first - 1]), target(xs[first - 2])) < 1e-6) fail("the stage was not moving when paused");
  const held = target(xs[first]);
  log(`paused ${(xs[first].at - clickedAt).toFixed(0)} ms after the click; moving ${um(dist(target(xs[first - 1]), target(xs[first - 2])))} um a sample up to it`);
  for (let i = first; i < xs.length; i++)
    if (dist(target(xs[i]), held) > 0) { fail(`the commanded position moved ${um(dist(target(xs[i]), held))} um while paused`); break; }
  const last = xs[xs.length - 1];
  const settled = dist([last.measured_x_m, last.measured_y_m, last.measured_z_m], held);
  if (settled > 2e-6) fail(`the stage is ${um(settled)} um from its held target a second after the pause`);
  await shot("task-02-paused");

  // Take over: the commanded position does not jump; the operator jogs from there (deadman).
  const beforeTakeOver = xs.length;
  await page.click("#task-take-over");
  await until("the operator drives", () => window.mc.status.task.status === "operator", 3);
  await page.waitForTimeout(400);
  xs = await samples();
  const atTakeOver = largestStep(xs, beforeTakeOver, xs.length);
  if (atTakeOver > 0) fail(`the commanded position moved ${um(atTakeOver)} um at the take-over without the deadman`);
  await page.keyboard.down(" ");
  await page.keyboard.down("ArrowUp");
  await page.waitForTimeout(600);
  await page.keyboard.up("ArrowUp");
  await page.keyboard.up(" ");
  await page.waitForTimeout(300);
  xs = await samples();
  const jogged = target(xs[xs.length - 1]);
  const jogStep = largestStep(xs, beforeTakeOver, xs.length);
  log(`the operator jogged ${um(jogged[1] - held[1])} um along y; largest change a sample ${um(jogStep)} um`);
  if (jogged[1] - held[1] < 10e-6) fail("the operator's jog did not move the stage");
  // 100 um/s (the speed scale) over a 60 Hz sample is 1.7 um; a jump would be far more.
  if (jogStep > 2.5e-6) fail(`a step of ${um(jogStep)} um in the commanded position during the take-over`);
  await shot("task-03-operator");

  // Hand back: the transport again from where the operator left the stage, then the insertion.
  const beforeHandBack = xs.length;
  await page.click("#task-hand-back");
  await until("the task running again", () => window.mc.status.task.status === "running", 3);
  await untilTask("the task past the transport", (t) => t.step_index > 4, 60);
  await untilTask("the task ended", (t) => ["succeeded", "failed"].includes(t.status), 90);
  const end = await task();
  log(`the task ${end.status} in ${end.elapsed_s.toFixed(1)} s, ${end.search_tries} search tries, inserted ${end.inserted}`);
  if (end.status !== "succeeded") fail(`the task ${end.status} in ${end.step}: ${end.failure}`);
  if (end.inserted !== true) fail("the pin is not in its bore");
  await page.waitForTimeout(800);
  xs = await samples();
  let lastDriven = xs.length - 1;
  while (lastDriven > beforeHandBack && xs[lastDriven].engaged === 0) lastDriven--;
  const driveStep = largestStep(xs, beforeHandBack, lastDriven + 1);
  // The travel speed, 500 um/s, is 8.3 um a 60 Hz sample.
  if (driveStep > 9e-6) fail(`a step of ${um(driveStep)} um in the commanded position after the hand-back`);
  if (xs[xs.length - 1].engaged !== 0) fail("the stage is not holding after the task's end");
  await until("the panel says it succeeded", () => /Succeeded/.test(document.getElementById("task-hint").textContent), 3);
  // The console has the stage again: its gripper slider where the gripper holds (so that it moves nothing).
  await until("the gripper slider at the held opening", () =>
    Math.abs(window.mc.input.gripper - window.mc.telemetry.gripper_command_m) < 2e-6, 3);
  await shot("task-04-succeeded");
  const gaps = await page.evaluate(() => window.timerGaps);
  log(`the page's timers: largest gap ${gaps.max.toFixed(0)} ms, ${gaps.over200} over 200 ms; ${s.resumed} latched pauses resumed`);
}, "started, paused, taken over, handed back and inserted from the page");
