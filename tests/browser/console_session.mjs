// What the console's browser tests share: `microcobot serve` started on a free port (its first
// stdout line is the console's URL), Debian's headless Chromium through playwright-core on it,
// and the operator's gestures as the page's own controls take them (click-to-go through the
// page's world-to-canvas mapping, the Space deadman, sliders). Failures are counted, not thrown.
import { spawn } from "node:child_process";
import { mkdtempSync, mkdirSync, existsSync, writeFileSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { chromium } from "playwright-core";

// options.viewport: the page's size ({width, height}; 1280x1000 unless given).
// serve's options for a platform without a camera (`devices.camera.driver: none`): the tests
// that are not about the camera leave it out. A 1280x1024 stream at 30 fps costs the server
// a core and headless Chromium (software rendering) its main thread on a 2-core machine, enough
// to starve the page's command heartbeat; the camera's panel is console_browser_camera's.
export function withoutCamera(dir) {
  const file = join(dir, "no-camera.yaml");
  writeFileSync(file, "devices:\n  camera:\n    driver: none\n");
  return ["--config", file];
}

// serve's options for a configuration given as YAML text (written into the test's directory).
export function withConfig(yaml) {
  return (dir) => {
    const file = join(dir, "config.yaml");
    writeFileSync(file, yaml);
    return ["--config", file];
  };
}

export async function startConsole(name, serveArgs, timeoutS, options = {}) {
  const cli = process.env.MC_CLI;
  if (!cli || !existsSync(cli)) {
    console.error(`${name}: set MC_CLI to the microcobot binary`);
    process.exit(2);
  }
  const dir = mkdtempSync(join(tmpdir(), "mc-console-"));
  const artifacts = process.env.MC_ARTIFACTS || join(dir, "screenshots");
  mkdirSync(artifacts, { recursive: true });
  const s = { dir, artifacts, failures: 0, pageErrors: [], outside: [] };
  s.fail = (msg) => { console.error("FAIL: " + msg); s.failures++; };
  s.log = (msg) => console.log(`[${(performance.now() / 1000).toFixed(1)} s] ${msg}`);

  const args = typeof serveArgs === "function" ? serveArgs(dir) : serveArgs;  // (dir) => args: files in dir
  s.server = spawn(cli, ["serve", "--listen", "127.0.0.1:0", ...args], { stdio: ["ignore", "pipe", "inherit"] });
  s.exited = new Promise((resolve) => s.server.on("exit", (code, signal) => resolve({ code, signal })));
  let urlTimer;
  // serve's stdout after its URL: one line per vendor-protocol twin ("emulate NAME ADDR:PORT").
  s.stdoutLines = [];
  s.url = await new Promise((resolve, reject) => {
    const rl = createInterface({ input: s.server.stdout });
    rl.once("line", resolve);
    rl.on("line", (line) => s.stdoutLines.push(line));
    s.server.once("exit", () => reject(new Error("serve exited before printing its URL")));
    urlTimer = setTimeout(() => reject(new Error("serve printed no URL within 60 s")), 60000);
  });
  clearTimeout(urlTimer);  // a pending timer would keep node alive for its whole minute
  s.log("console at " + s.url);
  // Whatever happens, never outlive CTest's timeout with the server left running.
  s.guard = setTimeout(() => {
    console.error(`FAIL: ${name} took longer than ${timeoutS} s`);
    s.server.kill("SIGKILL");
    process.exit(1);
  }, timeoutS * 1000);

  s.browser = await chromium.launch({
    executablePath: process.env.MC_CHROMIUM || "/usr/bin/chromium",
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
  const page = await s.browser.newPage({ viewport: options.viewport || { width: 1280, height: 1000 } });
  s.page = page;
  page.on("pageerror", (e) => s.pageErrors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") s.pageErrors.push(m.text()); });
  page.on("request", (r) => { if (!r.url().startsWith(s.url.split("?")[0])) s.outside.push(r.url()); });

  s.t = () => page.evaluate(() => window.mc.telemetry);
  s.until = async (what, predicate, timeoutS, arg) => {
    const end = Date.now() + timeoutS * 1000;
    while (Date.now() < end) {
      if (await page.evaluate(predicate, arg)) return true;
      await page.waitForTimeout(50);
    }
    throw new Error(`timed out after ${timeoutS} s: ${what}`);
  };
  // The supervised task in the page's status (serve --cell).
  s.task = () => page.evaluate(() => window.mc.status && window.mc.status.task);
  // Waits for the task to satisfy `pred`. A pause the platform latched because the page's
  // heartbeat stopped for longer than its gap (headless Chromium on a loaded 2-core machine stalls
  // for seconds, screenshots most) is resumed, as the operator would, and counted in s.resumed.
  s.resumed = 0;
  s.untilTask = async (what, pred, timeoutS) => {
    const end = Date.now() + timeoutS * 1000;
    while (Date.now() < end) {
      const t = await s.task();
      if (pred(t)) return t;
      if (t.status === "paused" && t.supervisor_lost) {
        s.log("the platform paused the task (the page's heartbeat was away): resumed");
        s.resumed++;
        await page.evaluate(() => action("task_resume"));  // the Resume button's action
        await page.waitForTimeout(500);
      }
      await page.waitForTimeout(100);
    }
    throw new Error(`timed out after ${timeoutS} s: ${what}; the task: ${JSON.stringify(await s.task())}`);
  };
  s.shot = (file) => page.screenshot({ path: join(artifacts, file + ".png") });
  // Clicks the microscope (top view) at world (x, y) or the side view at (x, z), as an operator
  // clicks what they see: the page's own mapping from the world to its canvases.
  const clickCanvas = async (id, toCanvas, a, b) => {
    const [px, py] = await page.evaluate(([f, a, b]) => window.mc[f](a, b), [toCanvas, a, b]);
    const box = await page.locator(id).boundingBox();
    const c = await page.evaluate((id) => [document.querySelector(id).width, document.querySelector(id).height], id);
    await page.mouse.click(box.x + px * box.width / c[0], box.y + py * box.height / c[1]);
  };
  s.clickTop = (x, y) => clickCanvas("#microscope", "worldToCanvas", x, y);
  s.clickSide = (x, z) => clickCanvas("#side", "worldToSide", x, z);
  // Holds the deadman (Space) until the stage is within `tol` of the clicked goal (x, y; z
  // within 1.5 tol).
  s.goWithDeadman = async (what, timeoutS, tol = 2e-6) => {
    await page.keyboard.down(" ");
    try {
      await s.until(what, (tol) => {
        const g = window.mc.input.goal, t = window.mc.telemetry;
        if (!g || !t) return false;
        return Math.abs(t.measured_x_m - g[0]) < tol && Math.abs(t.measured_y_m - g[1]) < tol &&
               Math.abs(t.measured_z_m - g[2]) < 1.5 * tol;
      }, timeoutS, tol);
    } finally {
      await page.keyboard.up(" ");
    }
  };
  s.setSlider = (id, value) => page.locator(id).fill(String(value));
  // The gripper's slider as a drag leaves it (an input event with the new value, in um).
  s.setGripper = (um) => page.$eval("#gripper", (el, v) => {
    el.value = String(v);
    el.dispatchEvent(new Event("input"));
  }, um);
  // The page loaded with the camera's frames shown and force by vision tared (at the scene's
  // start), the gauge row `row` shown.
  s.openTared = async (row) => {
    await page.goto(s.url, { waitUntil: "domcontentloaded", timeout: 90000 });
    await s.until("connected, frames shown, the gauge tared at the start", () =>
      window.mc.connected && window.mc.camera.frames >= 3 && window.mc.status && window.mc.status.grip_vision &&
      window.mc.status.grip_vision.tared, 30);
    if (await page.isHidden(row)) s.fail(`the gauge ${row} is hidden`);
  };
  // Takes control as an operator would, clicking again when nothing happened: with the camera
  // streaming on a loaded machine a click can be lost (seen in CI: never granted in 30 s, no
  // command seen by the server); each retry is logged, and control must come within three clicks.
  s.takeControl = async () => {
    for (let attempt = 1; ; ++attempt) {
      await page.click("#take-control");
      try {
        await s.until("control granted", () => window.mc.inControl, 15);
        return;
      } catch (e) {
        const state = await page.evaluate(() => ({ connected: window.mc.connected, lastAction: window.mc.lastAction }));
        s.log(`take control: not granted after click ${attempt} (${JSON.stringify(state)})`);
        if (attempt === 3 || await page.evaluate(() => window.mc.inControl)) throw e;
      }
    }
  };
  // The objective turret by name ("20x"): the options are the camera's objectives, by index.
  s.selectObjective = async (name) => {
    await s.until(`the ${name} objective offered`, (n) =>
      [...document.getElementById("objective").options].some((o) => o.textContent.startsWith(n + " ")), 10, name);
    const value = await page.evaluate((n) =>
      [...document.getElementById("objective").options].find((o) => o.textContent.startsWith(n + " ")).value, name);
    await page.selectOption("#objective", value);
  };
  // The e-stop button: latched, every device in fault (its safe state), the drives at 0 V.
  // Returns the telemetry after it.
  s.estopAndCheck = async () => {
    await page.click("#estop");
    await s.until("e-stop latched", () => window.mc.status && window.mc.status.estopped, 5);
    const status = await page.evaluate(() => window.mc.status);
    for (const [device, state] of Object.entries(status.lifecycle)) if (state !== "fault") s.fail(`${device} is ${state} after the e-stop`);
    await page.waitForTimeout(300);
    const stopped = await s.t();
    if (stopped.u_x_V !== 0 || stopped.u_y_V !== 0 || stopped.u_z_V !== 0) s.fail("drive voltages not zero after the e-stop");
    return stopped;
  };
  // After a failure: what the page last saw, and a screenshot.
  s.diagnose = async () => {
    const diag = await page.evaluate(() => JSON.stringify({ messages: window.mc.messages.slice(-10), status: window.mc.status,
                                                           goal: window.mc.input.goal, t: window.mc.telemetry })).catch(() => "");
    console.error("page state: " + diag);
    await s.shot("failure").catch(() => {});
  };
  // Closes the browser and checks what the page did overall (no errors, nothing fetched elsewhere).
  s.closeBrowser = async () => {
    await s.browser.close();
    if (s.pageErrors.length) s.fail("the page reported errors: " + s.pageErrors.join(" | "));
    if (s.outside.length) s.fail("the console fetched from elsewhere (it must work offline): " + s.outside.join(", "));
  };
  // SIGTERM: the server must put every device in its safe state and exit 0.
  s.terminate = async () => {
    s.server.kill("SIGTERM");
    const { code, signal } = await s.exited;
    if (code !== 0) s.fail(`serve exited with ${code} (${signal}) on SIGTERM`);
    clearTimeout(s.guard);
  };
  // Runs the test's body, then closes the browser and the server and exits: 1 with the count of
  // failures (a throw counts, with the page's state and a screenshot), else 0 after `okMessage`.
  s.run = async (body, okMessage) => {
    try {
      await body();
    } catch (e) {
      s.fail(String(e.stack || e));
      await s.diagnose();
    }
    await s.closeBrowser();
    await s.terminate();
    if (s.failures) {
      console.error(`${name}: ${s.failures} failure(s)`);
      process.exit(1);
    }
    s.log(`${name}: ${okMessage}`);
  };
  return s;
}
