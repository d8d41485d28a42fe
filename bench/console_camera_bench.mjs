// The camera's goal "scene change to image in the browser p95 <= 3 frame periods": how old the
// scene of each frame is when the console page has decoded it and can show it, in Chromium
// (Debian's, via playwright-core), against `microcobot serve` at its defaults (1280 x 1024 at
// 30 fps, 2x). The page (web/console_camera.js) stamps each decoded frame with its age: its
// mid-exposure stamp (live time) against the page's clock, mapped through the telemetry's least
// delayed sample of the last two seconds (so the age is low by that delay, a few ms at most).
// Also the frame rate the page decoded and the server's own snapshot-to-JPEG latency.
//
//   MC_CLI=build/release/apps/microcobot/microcobot node bench/console_camera_bench.mjs [--seconds 30]
//     [--config FILE.yaml] [--distributed]
import { startConsole } from "../tests/browser/console_session.mjs";
import { join } from "node:path";
import { mkdtempSync } from "node:fs";
import { tmpdir } from "node:os";
import { spawn } from "node:child_process";

const i = process.argv.indexOf("--seconds");
const seconds = i > 0 ? Number(process.argv[i + 1]) : 30;
if (!(seconds >= 5 && seconds <= 600)) {
  console.error(`console_camera_bench: --seconds ${process.argv[i + 1]}: must be within [5, 600]`);
  process.exit(2);
}
process.env.MC_CLI ||= "build/release/apps/microcobot/microcobot";
const c = process.argv.indexOf("--config");  // e.g. another frame rate or sensor size
const config = c > 0 ? ["--config", process.argv[c + 1]] : [];
// --distributed: the console is a master's (`serve --role master`) whose camera is the slave's,
// received over DDS (net/remote_camera.h), with the slave a second process on this machine.
let slave = null, role = [];
if (process.argv.includes("--distributed")) {
  const domain = String(100 + (process.pid % 100));
  const dir = mkdtempSync(join(tmpdir(), "mc-bench-slave-"));
  slave = spawn(process.env.MC_CLI, ["serve", "--role", "slave", "--domain", domain, "--listen", "127.0.0.1:0",
                                     "--out", join(dir, "rec"), "--duration", String(seconds + 200), ...config],
                { stdio: "ignore" });
  role = ["--role", "master", "--domain", domain];
  process.on("exit", () => slave.kill("SIGTERM"));  // also when the run fails
}
const s = await startConsole("console_camera_bench", (dir) => ["--out", join(dir, "rec"), ...role, ...config],
                             seconds + 120);
const { page, until, log } = s;
const quantile = (v, q) => {
  const a = [...v].sort((x, y) => x - y);
  return a.length ? a[Math.min(a.length - 1, Math.floor(q * a.length))] : NaN;
};

await s.run(async () => {
  await page.goto(s.url, { waitUntil: "domcontentloaded", timeout: 90000 });
  await until("frames", () => window.mc && window.mc.camera && window.mc.camera.frames >= 30, 60);
  await page.waitForTimeout(2000);  // the clock mapping settles over its two-second window
  const f0 = await page.evaluate(() => { window.mc.camera.shownAges = []; return window.mc.camera.frames; });
  const latencies = [], decodes = [];
  const t0 = performance.now();
  while (performance.now() - t0 < seconds * 1e3) {
    await page.waitForTimeout(1000);
    const st = await page.evaluate(() => window.mc.camera.state);
    if (st) latencies.push(st.latency_ms);
    decodes.push(await page.evaluate(() => window.mc.camera.decodeMs));
  }
  const { ages, frames, rate } = await page.evaluate(() => ({
    ages: window.mc.camera.shownAges.slice(),
    frames: window.mc.camera.frames,
    rate: window.mc.camera.state.frame_rate_Hz,
  }));
  const elapsed = (performance.now() - t0) / 1e3;
  const period_ms = 1e3 / rate;
  const ms = ages.map((a) => 1e3 * a);
  const out = {
    seconds: elapsed,
    frames_decoded_per_s: (frames - f0) / elapsed,
    frame_period_ms: period_ms,
    shown_age_ms_p50: quantile(ms, 0.5),
    shown_age_ms_p95: quantile(ms, 0.95),
    shown_age_ms_max: quantile(ms, 1),
    shown_age_p95_frame_periods: quantile(ms, 0.95) / period_ms,
    samples: ms.length,
    server_latency_ms_p50_of_1s_samples: quantile(latencies, 0.5),
    page_decode_ms_p50_of_1s_samples: quantile(decodes, 0.5),
  };
  log(JSON.stringify(out));
}, "measured");
