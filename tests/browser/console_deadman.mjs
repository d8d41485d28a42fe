// Browser test of the deadman rule through the console (docs/architecture.md: no slave
// actuator moves without the controlling operator's deadman): in control but without the
// deadman, the gripper slider, the arrow-key jog, the step jog and the go-to entry leave the
// stage's target and position and the gripper's opening unchanged in the telemetry; holding the
// deadman, the same gripper command then moves the fingers (the check is not vacuous). The
// gripper's release burst (the Shake button, B) does not shake it without the deadman, and does
// with it (the telemetry's simulation channel gripper_shaking). The
// platform enforces it, not the page: the page sends these commands all the same. Run by CTest
// (`console_browser_deadman`); screenshots to MC_ARTIFACTS.
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

const s = await startConsole("console_deadman", (dir) => ["--out", join(dir, "rec"), ...withoutCamera(dir)], 120);
const { page, t, until, shot, setSlider, fail, log } = s;
const still = (a, b, what) => {
  for (const k of ["target_x_m", "target_y_m", "target_z_m", "measured_x_m", "measured_y_m", "measured_z_m", "gripper_opening_m"]) {
    // 0.5 um: the stage's position noise at rest is far below it; any command would exceed it.
    if (Math.abs(b[k] - a[k]) > 0.5e-6) fail(`${what}: ${k} went from ${(a[k] * 1e6).toFixed(2)} to ${(b[k] * 1e6).toFixed(2)} um without the deadman`);
  }
};

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry and scene", () => window.mc.connected && window.mc.telemetry && window.mc.scene, 20);
  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  await page.waitForTimeout(500);
  const before = await t();
  log(`gripper opening ${(before.gripper_opening_m * 1e6).toFixed(1)} um`);
  // Each gesture against the telemetry just before it (one failure is reported once).
  const gesture = async (what, act) => {
    const from = await t();
    await act();
    await page.waitForTimeout(800);
    still(from, await t(), what);
  };
  await gesture("gripper slider", () => setSlider("#gripper", 0));  // the command carries gripper_opening_m 0
  await gesture("arrow-key jog", async () => {
    await page.keyboard.down("ArrowRight");
    await page.waitForTimeout(500);
    await page.keyboard.up("ArrowRight");
  });
  await gesture("step jog", () => page.click("#readout button[data-axis='x'][data-step='100']"));
  await gesture("go-to", async () => {
    await page.fill("#goto-y", ((before.measured_y_m + 200e-6) * 1e6).toFixed(1));
    await page.click("#goto-go");
  });
  // The gripper's release burst (Shake held, or B): never without the deadman.
  const shakingMax = () => page.evaluate(async () => {
    let m = 0;
    for (let i = 0; i < 25; ++i) {
      m = Math.max(m, window.mc.telemetry.gripper_shaking || 0);
      await new Promise((r) => setTimeout(r, 30));
    }
    return m;
  });
  await page.hover("#gripper-shake");
  await page.mouse.down();
  const shookAlone = await shakingMax();
  await page.mouse.up();
  if (shookAlone !== 0) fail("the Shake button shook the gripper without the deadman");
  await shot("deadman-01-commands-without-deadman");

  // The same commands with the deadman held: now the fingers close (and the stage goes).
  await page.keyboard.down(" ");
  try {
    await until("the gripper closing and the stage going with the deadman", (b) => {
      const now = window.mc.telemetry;
      return now.gripper_opening_m < b.gripper_opening_m - 20e-6 && Math.abs(now.measured_y_m - b.measured_y_m) > 5e-6;
    }, 10, before);
  } finally {
    await page.keyboard.up(" ");
  }
  log(`with the deadman: opening ${((await t()).gripper_opening_m * 1e6).toFixed(1)} um`);
  // ... and the burst with it (B and Space held together), stopping with the deadman.
  await page.keyboard.down(" ");
  await page.keyboard.down("b");
  try {
    await until("the gripper shaking with the deadman and B held", () => window.mc.telemetry.gripper_shaking === 1, 10);
    await shot("deadman-02-shake-with-deadman");
  } finally {
    await page.keyboard.up(" ");
  }
  await until("the burst stopping when the deadman is let go", () => window.mc.telemetry.gripper_shaking === 0, 5);
  await page.keyboard.up("b");
  log("the release burst: only with the deadman");
}, "nothing moved without the deadman");
