// Browser test of the optical-tweezers scene (thesis §3.5.2, Fig. 3.16): `microcobot
// serve --scene optical-trap` in Debian's headless Chromium. The page switches to the 100x oil
// objective (behind a 2x tube lens) and piconewtons; the operator takes control and clicks the trap 1 um past where
// the probe bead touches the stuck bead, holding the deadman: the streamed telemetry must show
// the probe stopped against the stuck bead and the trap's force opposing the push (the linear
// spring of Fig. 3.3), the page must show it in pN. The scripted demo is refused with the
// server's message in a banner; the e-stop latches every device in its safe state; SIGTERM exits 0. Run by CTest
// (`console_browser_optical_trap`); screenshots to MC_ARTIFACTS.
import { join } from "node:path";
import { startConsole } from "./console_session.mjs";

const s = await startConsole("console_optical_trap", (dir) => ["--scene", "optical-trap", "--out", join(dir, "rec")], 150);
const { page, t, until, shot, clickTop, goWithDeadman, fail, log } = s;
await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry and scene", () => window.mc.connected && window.mc.telemetry && window.mc.scene, 20);
  const scene = await page.evaluate(() => window.mc.scene);
  if (scene.kind !== "optical-trap") fail(`scene kind ${scene.kind}`);
  await until("the camera on the beads at 50x", () => {
    const sel = document.getElementById("objective");
    return sel.selectedIndex >= 0 && sel.options[sel.selectedIndex].textContent.startsWith("50x ");
  }, 10);
  await shot("trap-01-connected");
  const start = await t();
  log(`probe bead at (${(start.part_x_m * 1e6).toFixed(3)}, ${(start.part_y_m * 1e6).toFixed(3)}) um, trap at ` +
      `${(start.measured_x_m * 1e6).toFixed(3)} um, stuck bead at ${(scene.obstacle_m[0] * 1e6).toFixed(3)} um`);

  await page.click("#take-control");
  // Generous: a loaded 2-core machine decodes the 50x stream slowly and the page answers late.
  await until("control granted", () => window.mc.inControl, 30);
  // The demo is the pick-and-place: refused here, with the server's message in a banner. A
  // server that says so in the scene (demo_available false) has the button disabled with the
  // reason: the action is then sent as a client would, and still refused.
  if (await page.locator("#demo").isDisabled()) {
    const title = await page.getAttribute("#demo", "title");
    log(`Demo disabled: "${title}"`);
    if (!/unavailable: ./.test(title)) fail(`the disabled Demo button's title: "${title}"`);
    await page.evaluate(() => action("demo"));
  } else {
    await page.click("#demo");
  }
  await until("the demo refused", () => window.mc.status && /optical-trap/.test(window.mc.status.last_error), 5);
  await until("the refusal's banner", () => window.mc.banners().some((b) => b === window.mc.status.last_error), 3);
  const banner = await page.locator("#banners .banner").first().boundingBox();
  if (!banner || banner.y + banner.height > 1000 || banner.y < 0) fail("the refusal's banner is not on screen");
  log("banner: " + (await page.textContent("#banners .banner .text")));
  await shot("trap-01b-demo-refused");
  await page.click("#banners .banner button");
  await until("the banner dismissed", () => window.mc.banners().length === 0, 2);
  // Click-to-go (the trap's focus) to 1 um past the contact, along the line of centres (x).
  const touch = scene.obstacle_m[0] - (scene.bead_radius_m + scene.obstacle_radius_m);
  await clickTop(touch + 1e-6, scene.obstacle_m[1]);
  const goal = await page.evaluate(() => window.mc.input.goal);
  log(`goal ${(goal[0] * 1e6).toFixed(3)} um (contact at ${(touch * 1e6).toFixed(3)} um)`);
  await goWithDeadman("the trap pushed past the contact", 20, 0.1e-6);
  await page.waitForTimeout(300);  // the probe settles against the stuck bead (2.4 ms time constant)
  const pushed = await t();
  const k = scene.force_full_scale_N / scene.bead_radius_m;  // the trap's stiffness
  log(`trap ${(pushed.measured_x_m * 1e6).toFixed(3)} um, probe ${(pushed.part_x_m * 1e6).toFixed(3)} um, ` +
      `force ${(pushed.contact_x_N * 1e12).toFixed(2)} pN`);
  if (!(Math.abs(pushed.part_x_m - touch) < 0.3e-6)) fail(`the probe is ${((pushed.part_x_m - touch) * 1e6).toFixed(2)} um from the contact`);
  if (!(pushed.contact_x_N < -0.5 * k * 1e-6)) fail(`the probe's force ${pushed.contact_x_N} N does not oppose the push`);
  const shown = await page.textContent("#contact-out");
  if (!/pN$/.test(shown) || !(parseFloat(shown) > 3)) fail(`the contact gauge shows "${shown}"`);
  await shot("trap-02-contact");

  const stopped = await s.estopAndCheck();
  // The laser stays on: the probe is still held near its trap.
  if (!(Math.abs(stopped.part_x_m - stopped.measured_x_m) < 3e-6)) fail("the probe left its trap at the e-stop");
  await shot("trap-03-estop");
}, "the probe pushed against the stuck bead through the console, felt in pN; e-stop and SIGTERM held");
