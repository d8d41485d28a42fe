// Browser test of click-to-go with the encoders off: `serve` with
// `stage.xy_sensor: vision`; the operator takes control, clicks on the camera's image 60 um
// beside the gripper's tips and holds the deadman (Space); the visual servo on the server's
// camera thread brings the tool point there. Judged on the simulation's ground truth (the
// telemetry's slave_x_m, slave_y_m: where the tips really are, which the servo never reads),
// and the page shows the tracker's cross and the goal's ring. Run by CTest
// (`console_browser_vision`); screenshots to MC_ARTIFACTS.
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { startConsole } from "./console_session.mjs";

// The 5x objective looking at the stage's home (-0.2 mm, 0), focused on the tips (0.45 mm); the
// part 0.6 mm aside, out of the field (under a tip its glow biases the tip's tracking:
// docs/benchmarks.md).
const config = `stage:
  xy_sensor: vision
world:
  part_start_x_m: 0.4e-3
camera:
  objective: 1
  view_center_x_m: -0.2e-3
  view_center_y_m: 0.0
  focus_start_m: 0.45e-3
  sensor:
    width_px: 640
    height_px: 512
`;
const s = await startConsole("console_vision", (dir) => {
  writeFileSync(join(dir, "vision.yaml"), config);
  return ["--config", join(dir, "vision.yaml")];
}, 240);
const { page, until, shot, fail, log } = s;

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded", timeout: 90000 });
  await until("connected, frames shown, the tips' templates taught", () =>
    window.mc.connected && window.mc.camera.frames >= 3 && window.mc.status && window.mc.status.vision &&
    window.mc.status.vision.taught, 30);
  await s.takeControl();
  await shot("vision-01-taught");
  const start = await page.evaluate(() => [window.mc.telemetry.slave_x_m, window.mc.telemetry.slave_y_m]);
  const goal = [start[0] + 60e-6, start[1] - 30e-6];
  await s.clickTop(goal[0], goal[1]);
  // What the click asked for (the clicked canvas pixel's world point).
  const asked = await page.evaluate(() => window.mc.input.goal.slice(0, 2));
  // Without the deadman nothing moves.
  await until("the servo waits for the deadman", () => window.mc.status.vision.state === "no-deadman", 5);
  await page.waitForTimeout(500);
  const still = await page.evaluate(() => [window.mc.telemetry.slave_x_m, window.mc.telemetry.slave_y_m]);
  if (Math.hypot(still[0] - start[0], still[1] - start[1]) > 0.05e-6) fail("the stage moved without the deadman");
  await page.keyboard.down(" ");
  try {
    await until("the servo converged on the clicked point", () => window.mc.status.vision.state === "converged", 30);
    // The caption is redrawn with the next frames; it shows the servo's state as the server
    // reports it (a loaded machine may already report the next one).
    await until("the caption shows the servo's state", () =>
      document.querySelector("#vision-info").textContent.includes(`vision: ${window.mc.status.vision.state}`), 5);
    await shot("vision-02-converged");
  } finally {
    await page.keyboard.up(" ");
  }
  await page.waitForTimeout(400);  // at rest, a few frames later
  const end = await page.evaluate(() => [window.mc.telemetry.slave_x_m, window.mc.telemetry.slave_y_m]);
  const err = Math.hypot(end[0] - asked[0], end[1] - asked[1]);
  const v = await page.evaluate(() => window.mc.status.vision);
  log(`clicked ${(1e6 * Math.hypot(goal[0] - start[0], goal[1] - start[1])).toFixed(1)} um away; true error ` +
      `${(1e6 * err).toFixed(3)} um after ${v.commands} commands over ${v.frames} frames; caption: ` +
      await page.textContent("#vision-info"));
  if (!(err < 0.3e-6)) fail(`the tool point ended ${(1e6 * err).toFixed(2)} um from the clicked point`);
}, "click-to-go with the encoders off: the servo on the camera brings the tips to the click");
