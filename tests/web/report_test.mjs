// Browser test of the study report (`mmm report`), run by CTest (label
// "web") on the finished default study of the end-to-end test (tests/e2e):
// a real headless Chromium (Debian's) driven by playwright-core opens
// report/index.html from disk with the network cut off and checks
//   - every expected figure is on the page, PNGs decoded (natural size > 0),
//     SVGs laid out (bounding box > 0);
//   - every section is there and none says "Not computed yet";
//   - no request left file:// and the page logged no error;
// then screenshots the top of the page (the README's picture).
//
// node report_test.mjs --report DIR [--screenshot PNG]
// Exit 0: passed, 1: failed, 77: skipped (no Chromium or playwright-core).
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { pathToFileURL } from "node:url";
import { chromiumOrSkip, parseArgs } from "./browser.mjs";

const args = parseArgs(["report"], "node report_test.mjs --report DIR [--screenshot PNG]");
const launchChromium = await chromiumOrSkip();

const index = path.resolve(args.report, "index.html");
assert.ok(fs.existsSync(index), `no report at ${index}: run the end-to-end test first (tests/e2e)`);
const expectedFigures = ["overlay", "angles", "wrapping", "fibre_picture", "fibre_lengths"];
const expectedSections = ["landmarks", "scaling", "motion", "wrapping", "fibres", "provenance"];

let browser = null;
try {
  browser = await launchChromium();
  const context = await browser.newContext({ offline: true, viewport: { width: 1200, height: 900 } });
  const page = await context.newPage();
  const problems = [];
  page.on("console", (message) => {
    if (message.type() === "error") problems.push(`console error: ${message.text()}`);
  });
  page.on("pageerror", (error) => problems.push(`page error: ${error.message}`));
  page.on("request", (request) => {
    if (!request.url().startsWith("file://")) problems.push(`network request: ${request.url()}`);
  });
  page.on("requestfailed", (request) => problems.push(`failed to load: ${request.url()}`));
  await page.goto(pathToFileURL(index).href, { waitUntil: "load" });

  const figures = await page.$$eval("figure[data-figure]", (nodes) =>
    nodes.map((figure) => {
      const img = figure.querySelector("img");
      const svg = figure.querySelector("svg");
      const box = svg ? svg.getBoundingClientRect() : null;
      return {
        name: figure.dataset.figure,
        kind: img ? "png" : svg ? "svg" : "none",
        ok: img ? img.complete && img.naturalWidth > 0 && img.naturalHeight > 0
          : svg ? box.width > 0 && box.height > 0 && svg.querySelectorAll("polyline, path, line").length > 0
            : false,
        size: img ? `${img.naturalWidth} x ${img.naturalHeight}` : box ? `${Math.round(box.width)} x ${Math.round(box.height)}` : "-",
      };
    }));
  for (const figure of figures) console.log(`figure ${figure.name}: ${figure.kind} ${figure.size} ${figure.ok ? "rendered" : "NOT RENDERED"}`);
  for (const name of expectedFigures) {
    const figure = figures.find((f) => f.name === name);
    assert.ok(figure, `figure '${name}' is missing from the report (has: ${figures.map((f) => f.name).join(", ")})`);
    assert.ok(figure.ok, `figure '${name}' (${figure.kind}) did not render`);
  }
  const sections = await page.$$eval("section[id]", (nodes) => nodes.map((s) => s.id));
  for (const id of expectedSections) assert.ok(sections.includes(id), `section '${id}' is missing`);
  const pending = await page.$$eval(".pending", (nodes) => nodes.map((n) => n.textContent));
  assert.deepEqual(pending, [], `a finished study's report says: ${pending.join(" | ")}`);
  assert.deepEqual(problems, [], problems.join("\n"));

  if (args.screenshot) {
    fs.mkdirSync(path.dirname(args.screenshot), { recursive: true });
    await page.screenshot({ path: args.screenshot });
    console.log(`screenshot: ${args.screenshot}`);
  }
  console.log(`passed: ${figures.length} figures rendered, ${sections.length} sections, offline`);
} catch (error) {
  console.error(error.message || error);
  process.exitCode = 1;
} finally {
  if (browser) await browser.close();
}
