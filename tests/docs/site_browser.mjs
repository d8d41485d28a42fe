// The documentation site in Debian's headless Chromium (playwright-core): three pages and the
// search, at 1400x950 and 1024x768 (there the navigation folds behind the menu button),
// served from build/docs by a local HTTP server on 127.0.0.1
// (the search's web worker needs one) and opened as files (the pages alone). Fails on a request
// that leaves the machine, a console error, a page without its navigation or content, a search
// that finds nothing; writes a screenshot of each view to MC_ARTIFACTS.
// Run by CTest (`docs_browser`) after `docs_build`: node tests/docs/site_browser.mjs [SITE_DIR]
import { createServer } from "node:http";
import { existsSync, mkdirSync, readFileSync, statSync } from "node:fs";
import { extname, join, resolve } from "node:path";
import { chromium } from "playwright-core";

const site = resolve(process.argv[2] || "build/docs");
const artifacts = process.env.MC_ARTIFACTS || "build/artifacts/docs";
const chromiumPath = process.env.MC_CHROMIUM || "/usr/bin/chromium";
if (!existsSync(join(site, "index.html"))) {
  console.error(`site_browser: ${site}/index.html not found: run make docs first`);
  process.exit(2);
}
mkdirSync(artifacts, { recursive: true });
let failures = 0;
const fail = (msg) => { console.error("FAIL: " + msg); failures++; };

const types = { ".html": "text/html", ".js": "text/javascript", ".css": "text/css", ".json": "application/json",
                ".png": "image/png", ".svg": "image/svg+xml", ".woff2": "font/woff2", ".xml": "text/xml" };
const server = createServer((req, res) => {
  const path = join(site, decodeURIComponent(new URL(req.url, "http://x").pathname));
  if (!path.startsWith(site) || !existsSync(path) || statSync(path).isDirectory()) {
    res.writeHead(404).end();
    return;
  }
  res.writeHead(200, { "content-type": types[extname(path)] || "application/octet-stream" }).end(readFileSync(path));
});
await new Promise((r) => server.listen(0, "127.0.0.1", r));
const base = `http://127.0.0.1:${server.address().port}/`;

const pages = [
  { path: "index.html", text: "desktop micro-manipulation cobotic platform" },
  { path: "tutorials/identify-axis.html", text: "identify all" },
  { path: "reference/configuration.html", text: "stickslip_params_file" },
];
const viewports = [{ width: 1400, height: 950 }, { width: 1024, height: 768 }];

const t0 = Date.now();
const browser = await chromium.launch({
  executablePath: chromiumPath,
  args: ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--allow-file-access-from-files"],
});
try {
  for (const vp of viewports) {
    const context = await browser.newContext({ viewport: { width: vp.width, height: vp.height } });
    const offMachine = [];
    context.on("request", (r) => {
      const u = r.url();
      if (!(u.startsWith(base) || u.startsWith("file://") || u.startsWith("data:") || u.startsWith("blob:"))) offMachine.push(u);
    });
    const page = await context.newPage();
    const errors = [];
    page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
    page.on("pageerror", (e) => errors.push(String(e)));
    for (const p of pages) {
      await page.goto(base + p.path, { waitUntil: "load" });
      const body = (await page.textContent("article")) || "";
      if (!body.toLowerCase().includes(p.text.toLowerCase())) fail(`${p.path} at ${vp.width}: "${p.text}" not in the page`);
      const nav = await page.$$eval(".md-nav__link", (links) => links.length);
      if (nav < 20) fail(`${p.path} at ${vp.width}: the navigation has ${nav} links`);
      const file = join(artifacts, `${vp.width}x${vp.height}-${p.path.replace(/[/.]/g, "_")}.png`);
      await page.screenshot({ path: file });
      console.log(`ok ${p.path} at ${vp.width}x${vp.height} (${((Date.now() - t0) / 1000).toFixed(1)} s): ${file}`);
    }
    // The search: typed into the header's field (behind its button on narrow screens), answered
    // by the worker from the site's own index.
    await page.goto(base + "index.html", { waitUntil: "networkidle" });
    // On narrow screens the field is behind the header's button (hidden on wide ones, where a
    // click would wait for it to show).
    const button = page.locator("label.md-header__button[for='__search']");
    if (await button.isVisible()) await button.click();
    // The worker answers once it has built its index from search_index.json: type again until then.
    let results = 0;
    for (let t0 = Date.now(); results === 0 && Date.now() - t0 < 30000;) {
      await page.fill("input.md-search__input", "");
      await page.type("input.md-search__input", "stick-slip");
      await page.waitForSelector(".md-search-result__item", { timeout: 3000 }).catch(() => {});
      results = await page.$$eval(".md-search-result__item", (items) => items.length);
    }
    if (results < 3) fail(`search at ${vp.width}: ${results} results for "stick-slip"`);
    const meta = (await page.textContent(".md-search-result__meta").catch(() => "")) || "";
    const file = join(artifacts, `${vp.width}x${vp.height}-search.png`);
    await page.screenshot({ path: file });
    console.log(`ok search at ${vp.width}x${vp.height} (${((Date.now() - t0) / 1000).toFixed(1)} s): ${results} results (${meta.trim()}): ${file}`);
    if (offMachine.length) fail(`requests off the machine: ${[...new Set(offMachine)].join(", ")}`);
    if (errors.length) fail(`console errors at ${vp.width}: ${errors.join(" | ")}`);
    await context.close();
  }
  // Opened as files, without a server: the pages read (the search needs the server).
  const context = await browser.newContext({ viewport: { width: viewports[0].width, height: viewports[0].height } });
  const offMachine = [];
  context.on("request", (r) => { if (!r.url().startsWith("file://") && !r.url().startsWith("data:")) offMachine.push(r.url()); });
  const page = await context.newPage();
  await page.goto("file://" + join(site, "getting-started", "install.html"), { waitUntil: "load" });
  const next = await page.$eval("a[href$='console.html']", (a) => a.href).catch(() => null);
  if (!next || !next.startsWith("file://")) fail(`file://: the install page's link to the console is ${next}`);
  await page.goto(next, { waitUntil: "load" });
  const shot = await page.$eval("article img", (img) => img.complete && img.naturalWidth > 0).catch(() => false);
  if (!shot) fail("file://: the console page's screenshot did not load");
  await page.screenshot({ path: join(artifacts, "file-console.png") });
  console.log(`ok file:// install -> console, screenshot loaded`);
  if (offMachine.length) fail(`file://: requests off the machine: ${[...new Set(offMachine)].join(", ")}`);
  await context.close();
} finally {
  await browser.close();
  server.close();
}
if (failures) {
  console.error(`site_browser: ${failures} failure(s)`);
  process.exit(1);
}
console.log("site_browser: ok");
