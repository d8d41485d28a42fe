// Browser test of the console's ergonomics: `microcobot serve` (pick-place) in
// Debian's headless Chromium at a tablet's 1024x768. The microscope and the main controls are on
// screen without scrolling; plots fill their panels (also after a resize to 1400x950) and their
// legends show the latest sample; a server warning shows as a dismissable banner; with the
// deadman held, the X/Y/Z readout follows the stage, the step jog, the go-to entry and a saved
// position each bring the stage where they say; an off-field target gets its arrow; the demo's
// result, the force limits and an unavailable demo show as the lead's status/scene fields say
// (injected into the page: the page must work with or without them). Run by CTest
// (`console_browser_ergonomics`); screenshots to MC_ARTIFACTS.
import { join } from "node:path";
import { startConsole, withoutCamera } from "./console_session.mjs";

const tablet = { width: 1024, height: 768 };
const s = await startConsole("console_ergonomics", (dir) => ["--out", join(dir, "rec"), ...withoutCamera(dir)], 200, { viewport: tablet });
const { page, t, until, shot, goWithDeadman, setSlider, selectObjective, fail, log } = s;
const um = (v) => (v * 1e6).toFixed(1);

// Everything named is inside the viewport, and the page does not scroll.
async function onScreen(what, selectors, viewport) {
  for (const sel of selectors) {
    const box = await page.locator(sel).first().boundingBox();
    if (!box) { fail(`${what}: ${sel} is not displayed`); continue; }
    if (box.x < 0 || box.y < 0 || box.x + box.width > viewport.width + 0.5 || box.y + box.height > viewport.height + 0.5)
      fail(`${what}: ${sel} at (${box.x.toFixed(0)}, ${box.y.toFixed(0)}) ${box.width.toFixed(0)}x${box.height.toFixed(0)} ` +
           `is not inside ${viewport.width}x${viewport.height}`);
  }
  const scroll = await page.evaluate(() => ({ x: window.scrollX, y: window.scrollY, w: document.documentElement.scrollWidth, vw: innerWidth }));
  if (scroll.x !== 0 || scroll.y !== 0) fail(`${what}: the page is scrolled (${scroll.x}, ${scroll.y})`);
  if (scroll.w > scroll.vw) fail(`${what}: the page is ${scroll.w} px wide in a ${scroll.vw} px window`);
}

// Each plot as wide as its panel (less its padding), and a legend with numbers in it.
async function plotsFill(what) {
  await page.waitForTimeout(400);  // the ResizeObserver's callback and a redraw
  const plots = await page.evaluate(() => Array.from(document.querySelectorAll(".plot"), (d) => ({
    panel: d.clientWidth, plot: d.querySelector(".uplot").getBoundingClientRect().width,
    legend: Array.from(d.querySelectorAll(".u-legend .u-series:not(:first-child) .u-value"), (v) => v.textContent),
  })));
  if (plots.length !== 4) fail(`${what}: ${plots.length} plots`);
  for (const p of plots) {
    if (Math.abs(p.plot - (p.panel - 16)) > 2) fail(`${what}: a ${p.plot.toFixed(0)} px plot in a ${p.panel} px panel`);
    if (!p.legend.length || p.legend.some((v) => !/^-?\d/.test(v))) fail(`${what}: legend values ${JSON.stringify(p.legend)}`);
  }
  return plots.map((p) => p.plot);
}

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded" });
  await until("connected, telemetry and scene", () => window.mc.connected && window.mc.telemetry && window.mc.scene, 20);
  await page.waitForTimeout(1000);  // a second of plotted samples

  // The tablet: the microscope and the operator's controls, no scrolling.
  await onScreen("1024x768", ["#microscope", "#estop", "#take-control", "#demo", "#deadman", "#joystick", "#speed",
                              "#z-up", "#z-down", "#gripper", "#readout", "#readout button[data-step='100']", "#goto-go"], tablet);
  const narrow = await plotsFill("1024x768");
  await shot("ergo-01-tablet-1024x768");

  // A wider window: the plots widen with their panels.
  const desk = { width: 1400, height: 950 };
  await page.setViewportSize(desk);
  const wide = await plotsFill("1400x950");
  if (!(Math.abs(wide[0] - narrow[0]) > 50)) fail(`the plots kept their size (${narrow[0]} -> ${wide[0]} px)`);
  await onScreen("1400x950", ["#microscope", "#deadman", "#joystick", "#gripper", "#readout"], desk);
  await page.screenshot({ path: join(s.artifacts, "ergo-02-desktop-1400x950.png"), fullPage: true });
  await page.setViewportSize(tablet);

  // A server warning (an action without control) as a banner with the server's words; dismissed.
  await page.click("#demo");
  await until("the warning's banner", () => window.mc.banners().some((b) => /take control first/.test(b)), 5);
  await shot("ergo-03-banner");
  await page.click("#banners .banner button");
  await until("the banner dismissed", () => window.mc.banners().length === 0, 2);

  await page.click("#take-control");
  await until("control granted", () => window.mc.inControl, 5);
  await setSlider("#speed", 200);
  const start = await t();
  const shown = await page.evaluate(() => ["x", "y", "z"].map((a) => document.getElementById("pos-" + a).textContent));
  log(`readout ${shown.join(", ")} um; measured ${um(start.measured_x_m)}, ${um(start.measured_y_m)}, ${um(start.measured_z_m)} um`);
  ["x", "y", "z"].forEach((a, i) => {
    if (Math.abs(parseFloat(shown[i]) - start["measured_" + a + "_m"] * 1e6) > 1) fail(`readout ${a} shows ${shown[i]}`);
  });

  // Step jog: +100 um in x, then +10 um in y. Until the deadman is held, the hint says so.
  await page.click("#readout button[data-axis='x'][data-step='100']");
  await until("the hint: hold the deadman", () => /hold the deadman/.test(document.getElementById("goal-hint").textContent), 2);
  await goWithDeadman("step jog x +100 um", 20);
  await page.click("#readout button[data-axis='y'][data-step='10']");
  await goWithDeadman("step jog y +10 um", 20);
  const jogged = await t();
  log(`after the step jog: ${um(jogged.measured_x_m - start.measured_x_m)}, ${um(jogged.measured_y_m - start.measured_y_m)} um`);
  if (Math.abs(jogged.measured_x_m - start.measured_x_m - 100e-6) > 2e-6) fail("the x step did not move 100 um");
  if (Math.abs(jogged.measured_y_m - start.measured_y_m - 10e-6) > 2e-6) fail("the y step did not move 10 um");
  await until("the hint: reached", () => /reached/.test(document.getElementById("goal-hint").textContent), 2);

  // Save this position, go elsewhere through the go-to entry, come back through the saved one.
  await page.click("#save-position");
  await until("a saved position", () => document.querySelectorAll("#saved button").length === 2, 2);
  const go = [jogged.measured_x_m - 150e-6, jogged.measured_y_m + 80e-6, jogged.measured_z_m + 50e-6];
  for (const [i, a] of ["x", "y", "z"].entries()) await page.fill("#goto-" + a, (go[i] * 1e6).toFixed(1));
  await page.click("#goto-go");
  const goal = await page.evaluate(() => window.mc.input.goal);
  if (goal.some((v, i) => Math.abs(v - go[i]) > 0.1e-6)) fail(`go-to set the goal ${goal} for ${go}`);
  await goWithDeadman("go to", 20);
  await selectObjective("50x");  // a 136 um field: the target lies outside it
  await until("an arrow toward the target", () => window.mc.offField().includes("target"), 3);
  await shot("ergo-04-goto-arrow");
  await page.click("#saved button:has-text('Go')");
  await goWithDeadman("back to the saved position", 20);
  const back = await t();
  const err = Math.hypot(back.measured_x_m - jogged.measured_x_m, back.measured_y_m - jogged.measured_y_m, back.measured_z_m - jogged.measured_z_m);
  log(`back at the saved position within ${um(err)} um`);
  if (!(err < 3e-6)) fail(`the saved position was missed by ${um(err)} um`);
  await page.click("#saved button:has-text('✕')");
  await until("the saved position deleted", () => document.querySelectorAll("#saved button").length === 0, 2);

  // The lead's status/scene fields, injected: the demo's result, the force limits, the demo
  // unavailable. The page shows them; the server's own messages at 1-5 Hz come after.
  // (One evaluation: a real status arriving in between would replace the injected one.)
  const injected = await page.evaluate(() => {
    const status = (extra) => { for (const fn of listeners.get("/platform/status")) fn({ ...window.mc.status, ...extra }); };
    status({ demo_result: { outcome: "running", phase: "approach", placement_error_m: null, reason: "", duration_s: 3 }, ticks: 2000000, overruns: 6000 });
    status({ demo_result: { outcome: "placed", phase: "done", placement_error_m: 1.23e-6, reason: "", duration_s: 41 }, ticks: 2010000, overruns: 6000 });
    for (const fn of listeners.get("/platform/scene"))
      fn({ ...window.mc.scene, grip_force_limit_N: 150e-6, contact_force_limit_N: 40e-6, demo_available: false, demo_unavailable_reason: "no demo here" });
    const el = (id) => document.getElementById(id);
    return {
      banners: window.mc.banners(), grip: el("grip-gauge").max, gripLimit: el("grip-limit").textContent,
      contact: el("contact-gauge").max, demo: el("demo").disabled, title: el("demo").title,
      overruns: Array.from(document.querySelectorAll("#status tr"), (r) => r.textContent).find((r) => r.startsWith("loop overruns")),
    };
  });
  log("injected fields shown: " + JSON.stringify(injected));
  if (!injected.banners.includes("Demo: placed, error 1.2 µm, 41 s")) fail("no banner of the demo's result");
  if (injected.grip !== 150 || !/150 µN limit/.test(injected.gripLimit) || injected.contact !== 40) fail("the gauges do not span the force limits");
  if (!injected.demo || !/no demo here/.test(injected.title)) fail("the Demo button is not disabled with its reason");
  if (!/0\.3 % of 2010000 ticks/.test(injected.overruns || "")) fail(`overruns shown as "${injected.overruns}"`);
  await shot("ergo-05-injected-fields");
}, "tablet layout, plots, banners, readout, step jog, go-to, saved positions and the lead's fields held");
