// Browser test of an assisted step (`serve --cell --task FILE` with
// `steps: {transport: assisted}`): the robot grasps and lifts the pin, then hands the transport to
// the operator under the platform's guidance. The panel says so; the operator clicks on the
// microscope 12 um off the bore (by eye) and holds the deadman; the guide puts the stage on the
// bore's axis, the task goes on by itself once it is there, and the robot turns and inserts the
// pin. Run by CTest (`console_browser_task_assisted`); screenshots to MC_ARTIFACTS.
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

const s = await startConsole("console_task_assisted", (dir) => {
  const file = join(dir, "assisted.yaml");
  writeFileSync(file, "steps: {transport: assisted}\n");
  return ["--cell", "--task", file, ...withoutCamera(dir)];
}, 240);
const { page, until, shot, clickTop, fail, log, task, untilTask } = s;
const um = (v) => (v * 1e6).toFixed(2);

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry, scene and the task", () =>
    window.mc.connected && window.mc.telemetry && window.mc.scene && window.mc.status && window.mc.status.task, 20);
  const scene = await page.evaluate(() => window.mc.scene);
  const levels = (await task()).steps.map((x) => `${x.name} ${x.autonomy}`);
  if (!levels.includes("transport assisted")) fail(`the panel's steps do not show the assisted transport: ${levels}`);
  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  await until("Start enabled", () => !document.getElementById("task-start").disabled, 5);
  await page.click("#task-start");
  await untilTask("the transport handed to the operator", (t) => t.step === "transport" && t.status === "assisted", 120);
  await until("the panel says the operator is guided", () =>
    document.getElementById("task-state").textContent === "assisted" &&
    /guided to its goal/.test(document.getElementById("task-hint").textContent) &&
    !document.getElementById("task-hand-back").disabled, 3);
  await until("the gripper slider at the held opening", () =>
    Math.abs(window.mc.input.gripper - window.mc.telemetry.gripper_command_m) < 2e-6, 3);
  await shot("assisted-01-handed");

  // The operator aims by eye, 12 um off the bore. The bore is out of the view (which follows the
  // tool): first clicks toward it as far as the view shows, each held to its end with the deadman.
  const [bx, by] = scene.target_m;
  const aim = [bx + 8e-6, by - 9e-6];
  for (let hop = 0; hop < 10; hop++) {
    const inView = await page.evaluate(([x, y]) => {
      const [px, py] = window.mc.worldToCanvas(x, y), c = document.getElementById("microscope");
      return px > 0.05 * c.width && px < 0.95 * c.width && py > 0.05 * c.height && py < 0.95 * c.height;
    }, aim);
    if (inView) break;
    const t = await page.evaluate(() => window.mc.telemetry);
    const far = await page.evaluate(([x0, y0, x1, y1]) => {  // 40 % of the view's smaller side toward the aim
      const c = document.getElementById("microscope"), [ax, ay] = window.mc.worldToCanvas(x0, y0),
            [bx, by] = window.mc.worldToCanvas(x1, y1), d = Math.hypot(bx - ax, by - ay),
            k = 0.4 * Math.min(c.width, c.height) / d;
      return [x0 + k * (x1 - x0), y0 + k * (y1 - y0)];
    }, [t.measured_x_m, t.measured_y_m, aim[0], aim[1]]);
    log(`toward the bore: a click at (${um(far[0])}, ${um(far[1])}) um`);
    await clickTop(far[0], far[1]);
    await page.keyboard.down(" ");
    try {
      // (Within 10 um: the guide along the way holds the stage on the path, a few um off a click.)
      await until("the stage at the click", ([x, y]) => {
        const t = window.mc.telemetry;
        return Math.hypot(t.measured_x_m - x, t.measured_y_m - y) < 10e-6;
      }, 30, far);
    } finally {
      await page.keyboard.up(" ");
    }
  }
  await clickTop(aim[0], aim[1]);
  await page.keyboard.down(" ");
  let atEnd;
  try {
    await untilTask("the transport done (the task in the rotation or beyond)", (t) => t.step_index > 5, 60);
    atEnd = await page.evaluate(() => window.mc.telemetry);
  } finally {
    await page.keyboard.up(" ");
  }
  const off = Math.hypot(atEnd.measured_x_m - bx, atEnd.measured_y_m - by);
  log(`the transport ended ${um(off)} um from the bore's axis (the click was 12.04 um off)`);
  if (off > 2e-6) fail(`the guide did not put the stage on the bore's axis: ${um(off)} um off`);
  await until("the page dropped the operator's click-to-go once the robot drives", () => window.mc.input.goal === null, 3);
  await shot("assisted-02-guided");

  const end = await untilTask("the task ended", (t) => ["succeeded", "failed"].includes(t.status), 120);
  log(`the task ${end.status} in ${end.elapsed_s.toFixed(1)} s, inserted ${end.inserted}`);
  if (end.status !== "succeeded") fail(`the task ${end.status} in ${end.step}: ${end.failure}`);
  if (end.inserted !== true) fail("the pin is not in its bore");
  await shot("assisted-03-succeeded");
}, "an assisted transport guided onto the bore from the page, then inserted by the robot");
