// Browser test of the HTML reports: builds the full report and a session report with the CLI, opens them offline
// in Debian's headless Chromium through playwright-core, and checks that every figure drew
// its data (uPlot's draw hook fired, the canvas has ink) and that the console stayed clean.
// Run by CTest (`report_browser`); needs MC_CLI (the microcobot binary).
import { execFileSync } from "node:child_process";
import { mkdtempSync, rmSync, existsSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { chromium } from "playwright-core";

const cli = process.env.MC_CLI;
if (!cli || !existsSync(cli)) {
  console.error("report_renders: set MC_CLI to the microcobot binary");
  process.exit(2);
}
const chromiumPath = process.env.MC_CHROMIUM || "/usr/bin/chromium";
const dir = mkdtempSync(join(tmpdir(), "mc-report-"));
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };

// The two reports a user opens: every module's figures, and the main job's session report.
const reports = [
  { name: "report", args: ["report", "--out", join(dir, "report")], index: join(dir, "report", "index.html") },
  { name: "session", args: ["run", "--out", join(dir, "session")], index: join(dir, "session", "index.html") },
];

try {
  const browser = await chromium.launch({
    executablePath: chromiumPath,
    args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
           "--disable-background-networking", "--disable-component-update", "--disable-sync"],
  });
  for (const rep of reports) {
    execFileSync(cli, rep.args, { stdio: ["ignore", "ignore", "inherit"] });
    const page = await browser.newPage({ viewport: { width: 1200, height: 900 } });
    const consoleErrors = [];
    page.on("console", (m) => { if (m.type() === "error") consoleErrors.push(m.text()); });
    page.on("pageerror", (e) => consoleErrors.push(String(e)));
    const requests = [];
    page.on("request", (r) => { if (!r.url().startsWith("file://") && !r.url().startsWith("data:")) requests.push(r.url()); });
    const t0 = Date.now();
    await page.goto("file://" + rep.index);
    await page.waitForLoadState("load");
    const loadMs = Date.now() - t0;

    const figures = await page.$$eval(".figure", (boxes) => boxes.map((box) => {
      const chart = box.querySelector(".chart");
      const canvas = box.querySelector("canvas");
      let ink = 0;
      if (canvas) {
        const ctx = canvas.getContext("2d");
        const { data } = ctx.getImageData(0, 0, canvas.width, canvas.height);
        for (let i = 3; i < data.length; i += 4) if (data[i] > 0) ink++;
      }
      return { id: box.id, title: box.querySelector(".u-title")?.textContent || box.id,
               drawn: chart.getAttribute("data-drawn"), points: Number(chart.getAttribute("data-points")), ink };
    }));
    if (figures.length === 0) fail(`${rep.name}: the report has no figures`);
    for (const f of figures) {
      if (f.drawn !== "1") fail(`${rep.name}: ${f.id} (${f.title}) was not drawn`);
      if (!(f.points > 0)) fail(`${rep.name}: ${f.id} (${f.title}) has no data points`);
      if (f.ink < 50) fail(`${rep.name}: ${f.id} (${f.title}) canvas is blank (${f.ink} painted pixels)`);
    }
    for (const e of consoleErrors) fail(`${rep.name}: console: ` + e);
    for (const r of requests) fail(`${rep.name}: network request from an offline report: ` + r);
    if (process.env.MC_SCREENSHOT) {
      await page.screenshot({ path: process.env.MC_SCREENSHOT.replace(/(\.png)?$/, `-${rep.name}.png`), fullPage: false });
    }
    await page.close();
    console.log(`report_renders: ${rep.name}: ${figures.length} figures checked, loaded in ${loadMs} ms`);
  }
  await browser.close();
} finally {
  rmSync(dir, { recursive: true, force: true });
}
process.exit(failures === 0 ? 0 : 1);
