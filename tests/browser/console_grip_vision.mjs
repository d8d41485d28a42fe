// Browser test of the grip force seen by the camera (live): `serve` with the
// part between the open fingers and the tips at its mid-height under the 5x objective; the
// operator takes control, holds the deadman (Space) and closes the gripper with its slider onto
// the part; the "grip, seen" gauge shows the force the camera measures (the tips' distance
// against the drive's free opening, times the fingers' stiffness) beside the sensor's "grip".
// Then the gripper opens, the operator tares, and the force seen is back at zero. Run by CTest
// (`console_browser_grip_vision`); screenshots to MC_ARTIFACTS.
import { startConsole, withConfig } from "./console_session.mjs";

// The stage's home at (-0.2 mm, 0), the tips 150 um above the substrate: the 300 um part's
// mid-height, with the part centred between them.
const config = `stage:
  home_z_m: 0.15e-3
world:
  part_start_x_m: -0.2e-3
  part_start_y_m: 0.0
camera:
  objective: 1
  view_center_x_m: -0.2e-3
  view_center_y_m: 0.0
  focus_start_m: 0.15e-3
  sensor:
    width_px: 800
    height_px: 600
`;
const s = await startConsole("console_grip_vision", withConfig(config), 200);
const { page, until, shot, fail, log, setGripper } = s;

await s.run(async () => {
  await s.openTared("#grip-vision-row");
  await s.takeControl();
  // 0.8 mN, under the default 1 mN limit: the free opening 300 - 2 * 0.8 mN / (50 N/m) = 268 um.
  await page.keyboard.down(" ");
  try {
    await setGripper(268);
    await until("the sensor's grip at 0.8 mN", () => window.mc.feedback && Math.abs(window.mc.feedback.grip_N - 0.8e-3) < 0.02e-3, 15);
    await until("the force seen within 5 % of the sensor's", () => {
      const g = window.mc.status.grip_vision;
      return g.state === "measuring" && typeof g.grip_force_N === "number" &&
        Math.abs(g.grip_force_N - window.mc.feedback.grip_N) < 0.05 * window.mc.feedback.grip_N;
    }, 10);
    await page.waitForTimeout(300);  // the gauges redrawn
    await shot("grip-vision-01-squeezed");
    const seen = await page.textContent("#grip-vision-out"), sensed = await page.textContent("#grip-out");
    log(`squeezed: sensor ${sensed}, seen ${seen}`);
    const value = parseFloat(seen);
    if (!(Math.abs(value - 800) < 40)) fail(`the gauge shows ${seen}, not about 800 µN`);
    await setGripper(600);
    await until("let go", () => window.mc.feedback.grip_N === 0, 10);
  } finally {
    await page.keyboard.up(" ");
  }
  const tares = await page.evaluate(() => window.mc.status.grip_vision.tares);
  await page.click("#vision-tare");
  await until("tared on request", (n) => window.mc.status.grip_vision.tares > n, 10, tares);
  await until("no force seen once open", () => {
    const g = window.mc.status.grip_vision;
    return typeof g.grip_force_N === "number" && Math.abs(g.grip_force_N) < 20e-6;
  }, 10);
  await shot("grip-vision-02-open");
}, "force by vision in the console: the grip seen beside the sensor's, tared on request");
