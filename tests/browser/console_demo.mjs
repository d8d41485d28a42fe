// Browser test of the demo's end: in a pin-in-hole scene (the repository's scene
// file with a 300 um transport, to keep the test short), Demo from the page runs the scripted
// operator live; when it is done the page shows how it ended ("inserted", a banner with the
// server's result) and the platform has handed control back with every axis holding: the stage
// does not move for three seconds (a stage left drifting would show z rising after "demo: done"). Run by
// CTest (`console_browser_demo`); screenshots to MC_ARTIFACTS.
import { writeFileSync } from "node:fs";
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

const s = await startConsole("console_demo", (dir) => {
  writeFileSync(join(dir, "scene.yaml"),
                "part_side_m: 200.0e-6\npart_height_m: 600.0e-6\nhole_side_m: 220.0e-6\nhole_depth_m: 300.0e-6\n" +
                "target_x_m: 0.3e-3\ntarget_y_m: 0.0\n");
  return ["--out", join(dir, "rec"), "--scene", join(dir, "scene.yaml"), ...withoutCamera(dir)];
}, 240);
const { page, t, until, shot, fail, log } = s;

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry and scene", () => window.mc.connected && window.mc.telemetry && window.mc.scene, 20);
  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  await page.click("#demo");
  await until("the demo running", () => window.mc.status && window.mc.status.demo, 30);
  await shot("demo-01-running");
  await until("the demo ended", () => {
    const r = window.mc.status && window.mc.status.demo_result;
    return r && r.outcome !== "running";
  }, 150);
  const result = await page.evaluate(() => window.mc.status.demo_result);
  log(`demo: ${result.outcome} (${result.phase}): ${result.reason}; error ${(result.placement_error_m * 1e6).toFixed(2)} um, ${result.duration_s.toFixed(1)} s`);
  if (result.outcome !== "inserted") fail(`the pin-in-hole demo ended "${result.outcome}" in ${result.phase}: ${result.reason}`);
  await until("the result's banner", () => window.mc.banners().some((b) => /Demo/.test(b) && /inserted/.test(b)), 5);
  await shot("demo-02-inserted");
  // Handed back: the motion settles, then nothing moves for three seconds.
  await page.waitForTimeout(500);
  const a = await t();
  await page.waitForTimeout(3000);
  const b = await t();
  for (const k of ["slave_x_m", "slave_y_m", "slave_z_m", "target_x_m", "target_y_m", "target_z_m"]) {
    // 50 nm in 3 s: a held stick-slip axis; an axis left drifting moves um/s.
    if (Math.abs(b[k] - a[k]) > 50e-9) fail(`after the demo ${k} moved ${((b[k] - a[k]) * 1e9).toFixed(0)} nm in 3 s`);
  }
  if (b.engaged !== 0) fail("after the demo the coupling is still engaged");
  const status = await page.evaluate(() => window.mc.status);
  if (status.demo) fail("the status still says the demo drives");
  log(`held: z ${(a.slave_z_m * 1e6).toFixed(3)} -> ${(b.slave_z_m * 1e6).toFixed(3)} um over 3 s`);
}, "the pin inserted, the result shown, every axis holding afterwards");
