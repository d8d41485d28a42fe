// Browser test of a recording a crash left unfinished, as the operator meets it: a `serve
// --record` is killed (-9) while it records; the next `serve` on the same --out recovers it at
// start, and its console lists it among the recordings tagged "recovered" (with the tag's
// explanation), next to the new session's own recording, which is not. Screenshots of the
// recordings' table at 1400x950 and 1024x768 go to MC_ARTIFACTS.
import { spawn } from "node:child_process";
import { mkdtempSync, readdirSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { createInterface } from "node:readline";
import { startConsole, withoutCamera } from "./console_session.mjs";

// The crashed session: recording, without the camera, killed 3 s after its console is up.
const out = mkdtempSync(join(tmpdir(), "mc-recovered-"));
const cameraless = withoutCamera(out);
{
  const p = spawn(process.env.MC_CLI, ["serve", "--listen", "127.0.0.1:0", "--record", "--out", out, ...cameraless],
                  { stdio: ["ignore", "pipe", "inherit"] });
  await new Promise((resolve, reject) => {
    createInterface({ input: p.stdout }).once("line", resolve);
    p.once("exit", () => reject(new Error("the first serve exited before printing its URL")));
  });
  await new Promise((r) => setTimeout(r, 3000));
  const exited = new Promise((resolve) => p.on("exit", resolve));
  p.kill("SIGKILL");
  await exited;
}
const left = readdirSync(out).filter((f) => f.startsWith(".recording-"));
if (left.length !== 1) {
  console.error(`FAIL: the killed serve left ${left.length} temporaries in ${out}: ${left.join(", ")}`);
  process.exit(1);
}

const s = await startConsole("console_recovered", ["--record", "--out", out, ...cameraless], 120,
                             { viewport: { width: 1400, height: 950 } });
const { page, until, shot, fail, log, url } = s;
await s.run(async () => {
  await page.goto(url, { waitUntil: "domcontentloaded" });
  await until("connected", () => window.mc.connected && window.mc.telemetry, 20);
  // The table lists the recovered file and the session's own recording (the page refreshes it).
  await until("two recordings listed", () => document.querySelectorAll("#recordings tr").length >= 2, 20);
  const rows = await page.$$eval("#recordings tr", (trs) => trs.map((tr) => ({
    text: tr.textContent,
    tag: tr.querySelector(".recovered") ? tr.querySelector(".recovered").textContent.trim() : null,
    title: tr.querySelector(".recovered") ? tr.querySelector(".recovered").title : null,
  })));
  log(`recordings: ${rows.map((r) => r.text.replace(/\s+/g, " ").trim()).join(" | ")}`);
  const tagged = rows.filter((r) => r.tag === "recovered");
  if (tagged.length !== 1) fail(`${tagged.length} rows tagged recovered (want 1)`);
  else if (!/crash/.test(tagged[0].title)) fail(`the tag does not say why: ${tagged[0].title}`);
  if (!rows.some((r) => r.tag === null && /recording…/.test(r.text))) fail("the session's own recording is not listed as recording");
  if (readdirSync(out).some((f) => f.startsWith(".recording-") && left.includes(f)))
    fail("the crashed session's temporary is still there");
  const table = page.locator("#recordings");
  await table.scrollIntoViewIfNeeded();
  await shot("01-recovered-1400x950");
  await page.setViewportSize({ width: 1024, height: 768 });
  await table.scrollIntoViewIfNeeded();
  await shot("02-recovered-1024x768");
}, "a recording a crash left is recovered at start and tagged in the console");
