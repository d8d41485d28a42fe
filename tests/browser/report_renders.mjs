// Browser test of the HTML reports: builds the full report, a session report and the assembly cell's
// comparison with the CLI, opens them offline in Debian's headless Chromium through playwright-core,
// and checks that every figure drew its data (uPlot's draw hook fired, the canvas has ink), that
// the cell's box plots drew one box per mode, and that the console stayed clean.
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

// The reports a user opens: every module's figures, the main job's session report, and the cell's
// modes side by side (box plots of cycle time, placement error, peak forces).
const cellModes = ["auto", "manual"];
const reports = [
  // Scatter figures (points in two coordinates of their own, uPlot's mode 2): the points of the
  // first two series painted, in the palette's first two colours.
  { name: "report", args: ["report", "--out", join(dir, "report")], index: join(dir, "report", "index.html"),
    scatters: ["Reach over x and y at the home height", "Reach over rx and ry at the home position"] },
  { name: "session", args: ["run", "--out", join(dir, "session")], index: join(dir, "session", "index.html") },
  { name: "cell", args: ["cell", "compare", "--batch", "2", "--seed", "61", "--modes", cellModes.join(","),
                         "--out", join(dir, "cell")],
    index: join(dir, "cell", "index.html"), boxes: ["Cycle time by mode", "Placement error by mode",
                                                    "Peak grip force by mode", "Peak contact force by mode"] },
  // Log axes over values far below 1 (dips of 1e-7 m against edges of 1e-5 s).
  { name: "edge-dip", args: ["stickslip", "edge-dip", "--out", join(dir, "edge-dip")],
    index: join(dir, "edge-dip", "index.html") },
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
      // A box plot's boxes are painted in the report's first palette colours, one per group: the
      // pixels of each, so that a box missing from the canvas fails even if the axes drew.
      const boxColours = [[0x1f, 0x77, 0xb4], [0xd6, 0x27, 0x28], [0x2c, 0xa0, 0x2c], [0xff, 0x7f, 0x0e]];
      const colourInk = boxColours.map(() => 0);
      if (canvas) {
        const ctx = canvas.getContext("2d");
        const { data } = ctx.getImageData(0, 0, canvas.width, canvas.height);
        for (let i = 3; i < data.length; i += 4) {
          if (data[i] > 0) ink++;
          if (data[i] < 200) continue;
          boxColours.forEach((c, k) => {
            if (Math.abs(data[i - 3] - c[0]) + Math.abs(data[i - 2] - c[1]) + Math.abs(data[i - 1] - c[2]) < 40) colourInk[k]++;
          });
        }
      }
      return { id: box.id, title: box.querySelector(".u-title")?.textContent || box.id,
               drawn: chart.getAttribute("data-drawn"), points: Number(chart.getAttribute("data-points")), ink,
               boxes: JSON.parse(chart.getAttribute("data-boxes") || "null"), colourInk,
               ticks: ["data-x-ticks", "data-y-ticks"].map((k) => chart.getAttribute(k)) };
    }));
    if (figures.length === 0) fail(`${rep.name}: the report has no figures`);
    for (const f of figures) {
      if (f.drawn !== "1") fail(`${rep.name}: ${f.id} (${f.title}) was not drawn`);
      if (!(f.points > 0)) fail(`${rep.name}: ${f.id} (${f.title}) has no data points`);
      if (f.ink < 50) fail(`${rep.name}: ${f.id} (${f.title}) canvas is blank (${f.ink} painted pixels)`);
      // Every numeric axis reads: at least two labels, no two alike (a log axis of small values
      // once labelled every decade "0").
      f.ticks.forEach((t, k) => {
        if (t === null) return;  // an axis of names (the box plots' groups)
        const labels = t.split(" ").filter((x) => x !== "");
        if (labels.length < 2 || new Set(labels).size !== labels.length)
          fail(`${rep.name}: ${f.id} (${f.title}): its ${"xy"[k]} axis reads '${t}'`);
      });
    }
    // Box plots: each expected figure drew one box per mode, in the order the modes were given.
    for (const title of rep.boxes || []) {
      const f = figures.find((x) => x.title === title);
      if (!f) fail(`${rep.name}: no box plot '${title}'`);
      else if (JSON.stringify(f.boxes) !== JSON.stringify(cellModes))
        fail(`${rep.name}: '${title}' drew boxes ${JSON.stringify(f.boxes)}, expected one per mode ${JSON.stringify(cellModes)}`);
      else cellModes.forEach((m, k) => {
        if (f.colourInk[k] < 60) fail(`${rep.name}: '${title}': the ${m} box has ${f.colourInk[k]} pixels of its colour`);
      });
    }
    for (const title of rep.scatters || []) {
      const f = figures.find((x) => x.title === title);
      if (!f) fail(`${rep.name}: no scatter figure '${title}'`);
      else [0, 1].forEach((k) => {
        if (f.colourInk[k] < 200) fail(`${rep.name}: '${title}': series ${k}'s points have ${f.colourInk[k]} pixels of its colour`);
      });
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
