// Browser test of the contact force seen by the camera (live): `serve` with the
// pin-in-hole's 200 um pin down in its bore (10 um of play each side) between the open fingers,
// the tips 200 um above the substrate under the 10x objective. The operator takes control, holds
// the deadman (Space), closes the gripper on the pin with its slider and sends the stage 4 um past
// the bore's right wall with the go-to entry: the fingers bend, the gripper's sensor feels
// 2 k x 4 um = 400 uN, and "contact, seen" shows the force the camera measures (the tips' common
// bend against where the stage's sensors put the fingers) within 5 % of it. Run by CTest
// (`console_browser_contact_vision`); screenshots to MC_ARTIFACTS.
import { startConsole, withConfig } from "./console_session.mjs";

// The pin-in-hole scene (microworld/pick_place_world.h) with the pin starting in its bore at the
// target and the stage's home over it.
const config = `stage:
  home_x_m: 2.0e-3
  home_y_m: 0.0
  home_z_m: 0.2e-3
world:
  part_side_m: 200e-6
  part_height_m: 600e-6
  hole_side_m: 220e-6
  hole_depth_m: 300e-6
  part_start_x_m: 2.0e-3
  part_start_y_m: 0.0
  gripper:
    max_opening_m: 300e-6
camera:
  objective: 2
  view_center_x_m: 2.0e-3
  view_center_y_m: 0.0
  focus_start_m: 0.2e-3
  sensor:
    width_px: 800
    height_px: 600
`;
const s = await startConsole("console_contact_vision", withConfig(config), 200);
const { page, until, shot, fail, log, setGripper } = s;

await s.run(async () => {
  await s.openTared("#contact-vision-row");
  await s.takeControl();
  await page.keyboard.down(" ");
  try {
    // 1 mN on the pin (free opening 160 um): the grip holds 0.6 mN against a wall.
    await setGripper(160);
    await until("the pin gripped at 1 mN", () => window.mc.feedback && Math.abs(window.mc.feedback.grip_N - 1e-3) < 0.03e-3, 15);
    await until("no contact seen while centred", () => {
      const g = window.mc.status.grip_vision;
      return g.state === "measuring" && typeof g.contact_force_N === "number" && Math.abs(g.contact_force_N) < 10e-6;
    }, 10);
    // 14 um right of the bore's centre: 4 um past its wall.
    await page.fill("#goto-x", "2014");
    await page.click("#goto-go");
    await until("the sensor's contact at -400 uN", () =>
      window.mc.feedback && Math.abs(window.mc.feedback.contact_N[0] + 400e-6) < 20e-6, 20);
    await until("the contact seen within 5 % of the sensor's", () => {
      const g = window.mc.status.grip_vision, f = window.mc.feedback.contact_N[0];
      return g.state === "measuring" && typeof g.contact_force_N === "number" &&
        Math.abs(g.contact_force_N - f) < 0.05 * Math.abs(f);
    }, 10);
    await page.waitForTimeout(300);  // the gauges redrawn
    await shot("contact-vision-01-pushed");
    const seen = await page.textContent("#contact-vision-out"), sensed = await page.textContent("#contact-out");
    log(`pushed 4 um into the wall: sensor ${sensed}, seen ${seen}`);
    // The page writes the signed value with a true minus sign.
    const value = parseFloat(seen.replace("−", "-"));
    if (!(Math.abs(value + 400) < 20)) fail(`the gauge shows ${seen}, not about −400 µN`);
  } finally {
    await page.keyboard.up(" ");
  }
}, "force by vision in the console: the contact seen beside the sensor's");
