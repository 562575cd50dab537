// Browser test of the outline review page of the operator web UI (`mmm
// serve`), run by CTest (label "web"): a real headless Chromium (Debian's)
// driven by playwright-core.
//
//   study of schemas/examples/outline_review.yaml on synthetic patient 1 and
//   its own atlas; mmm run -> waits for the review (exit 3); mmm operator add
//   ana; mmm serve --port 0; the page: sign in, open the task, every bone's
//   outline listed, claim, click beside the femur's outline in the frontal
//   view (through the page's own image -> page transform), the correction
//   point is listed for the femur, a second one is added and removed,
//   submit corrections; accepted, the page shows the study done; the
//   accepted verdict (mmm task show --json) holds the point.
//
// node review_test.mjs --mmm BIN --source DIR --patient DIR --work DIR [--screenshot PNG]
// Exit 0: passed, 1: failed, 77: skipped (no Chromium or playwright-core).
import { execFileSync, spawn } from "node:child_process";
import assert from "node:assert/strict";
import fs from "node:fs";
import path from "node:path";
import { chromiumOrSkip, parseArgs } from "./browser.mjs";

const args = parseArgs(["mmm", "source", "patient", "work"], "node review_test.mjs --mmm BIN --source DIR --patient DIR --work DIR [--screenshot PNG]");
const launchChromium = await chromiumOrSkip();

const started = Date.now();
const elapsed = () => `${((Date.now() - started) / 1000).toFixed(1)} s`;
const log = (text) => console.log(`[${elapsed()}] ${text}`);

// Runs mmm; returns {code, stdout, stderr}.
function mmm(...argv) {
  try {
    const stdout = execFileSync(args.mmm, argv, { encoding: "utf8", stdio: ["ignore", "pipe", "pipe"], maxBuffer: 1 << 28 });
    return { code: 0, stdout, stderr: "" };
  } catch (error) {
    if (error.status === null || error.status === undefined) throw error;
    return { code: error.status, stdout: error.stdout, stderr: error.stderr };
  }
}

const root = path.resolve(args.work);
const study = path.join(root, "p1");
const radiographs = path.join(args.patient, "radiographs");
fs.rmSync(root, { recursive: true, force: true });
fs.mkdirSync(root, { recursive: true });

let server = null;
let browser = null;
try {
  // ---- the study, waiting for the review ------------------------------------------
  let result = mmm("study", "create", study,
    "--workflow", path.join(args.source, "schemas/examples/outline_review.yaml"),
    "--input", `calibration=${path.join(radiographs, "views.json")}`,
    "--input", `frontal=${path.join(radiographs, "frontal.png")}`,
    "--input", `lateral=${path.join(radiographs, "lateral.png")}`,
    "--input", `atlas=${path.join(args.patient, "atlas")}`,
    "--input", "patient=synthetic-1");
  assert.equal(result.code, 0, `mmm study create failed:\n${result.stderr}`);
  result = mmm("run", study, "--quiet");
  assert.equal(result.code, 3, `mmm run should wait for the outline review (exit 3), got ${result.code}:\n${result.stdout}${result.stderr}`);
  result = mmm("operator", "add", "ana", "--root", root);
  assert.equal(result.code, 0, `mmm operator add failed:\n${result.stderr}`);
  const token = (result.stdout.match(/\b[0-9a-f]{64}\b/) || [])[0];
  assert.ok(token, `no token in the output of mmm operator add:\n${result.stdout}`);
  log("study waiting for the outline review; operator ana added");

  // ---- the server --------------------------------------------------------------
  server = spawn(args.mmm, ["serve", "--root", root, "--port", "0", "--sweep", "5"], { stdio: ["ignore", "pipe", "pipe"] });
  let serverOutput = "";
  server.stderr.on("data", (chunk) => { serverOutput += chunk; });
  const base = await new Promise((resolve, reject) => {
    let text = "";
    const timer = setTimeout(() => reject(new Error(`mmm serve printed no address in 20 s:\n${text}${serverOutput}`)), 20000);
    server.stdout.on("data", (chunk) => {
      text += chunk;
      const match = text.match(/http:\/\/127\.0\.0\.1:(\d+)\//);
      if (match) { clearTimeout(timer); resolve(`http://127.0.0.1:${match[1]}`); }
    });
    server.on("exit", (code) => reject(new Error(`mmm serve exited (${code}):\n${text}${serverOutput}`)));
  });
  const auth = { Authorization: `Bearer ${token}` };
  const { tasks } = await (await fetch(`${base}/api/worklist`, { headers: auth })).json();
  assert.equal(tasks.length, 1, `one open task: ${JSON.stringify(tasks)}`);
  const task = tasks[0];
  assert.equal(task.node_type, "outline_review");
  log(`mmm serve at ${base}; task ${task.id} open`);

  // ---- the page ------------------------------------------------------------------
  browser = await launchChromium();
  const page = await browser.newPage({ viewport: { width: 1600, height: 1000 } });
  const pageErrors = [];
  page.on("pageerror", (error) => pageErrors.push(error.message));
  await page.goto(base);
  await page.fill("#token", token);
  await page.click("#token-form button");
  await page.click(`tr[data-task="${task.id}"]`);
  await page.waitForFunction(() => window.mmmStation && window.mmmStation.ready(), null, { timeout: 30000 });
  const request = await page.evaluate(() => window.mmmStation.station.request);
  assert.equal(request.kind, "outline_review");
  const listed = await page.$$eval("#bones li", (items) => items.map((item) => item.dataset.bone));
  assert.deepEqual(listed, request.bones.map((b) => b.name), "every bone is listed");
  assert.ok(await page.isHidden("#landmark-panel"), "no landmark panel for an outline review");
  await page.click("#claim");
  await page.waitForSelector("#accept-outlines:visible");
  log(`task page open, ${listed.length} bones outlined, images loaded, task claimed`);

  // A point 1 pixel beside the femur's frontal outline: it is the femur's.
  const femur = request.bones.find((b) => b.name === "femur_r");
  assert.ok(femur, "the atlas has femur_r");
  const outline = femur.outlines.frontal.reduce((a, b) => (b.length > a.length ? b : a));
  const [u, v] = outline[Math.floor(outline.length / 2)];
  const clickAt = async (pu, pv) => {
    const at = await page.evaluate(([pu2, pv2]) => window.mmmStation.imageToPage("frontal", pu2, pv2), [pu, pv]);
    await page.mouse.click(at.x, at.y);
  };
  await clickAt(u + 1, v);
  await page.waitForSelector('#corrections li[data-bone="femur_r"][data-view="frontal"]');
  await clickAt(u + 1, v + 20);
  await page.waitForFunction(() => document.querySelectorAll("#corrections .point").length === 2);
  await page.click('#corrections button.remove[data-index="1"]');
  await page.waitForFunction(() => document.querySelectorAll("#corrections .point").length === 1);
  assert.ok(await page.isDisabled("#accept-outlines"), "accepting as is waits until the points are removed");
  const points = await page.evaluate(() => window.mmmStation.station.submission().corrections);
  assert.equal(points.length, 1);
  // The click went through the screen -> image transform: within 2 image pixels.
  assert.ok(Math.hypot(points[0].points[0][0] - (u + 1), points[0].points[0][1] - v) < 2,
    `the page placed (${points[0].points[0]}) for (${u + 1}, ${v})`);
  log("a correction point placed beside the femur's outline, a second added and removed");

  await page.waitForSelector("#submit:enabled");
  await page.click("#submit");
  await page.waitForFunction(() => /^(Accepted|Rejected|Submitted)/.test(document.querySelector("#task-message").textContent),
    null, { timeout: 20000 });
  const verdict = await page.textContent("#task-message");
  assert.match(verdict, /^Accepted/, "the corrections are accepted");
  await page.waitForSelector('#task[data-study-state="done"]', { timeout: 120000 });
  log("accepted; the page shows the study done");
  if (args.screenshot) {
    fs.mkdirSync(path.dirname(args.screenshot), { recursive: true });
    await page.screenshot({ path: args.screenshot });
    log(`screenshot: ${args.screenshot}`);
  }
  assert.deepEqual(pageErrors, [], "no script errors on the page");

  // ---- the accepted verdict, from the command line --------------------------------
  result = mmm("task", "show", task.id, "--root", root, "--json");
  assert.equal(result.code, 0, `mmm task show failed:\n${result.stderr}`);
  const shown = JSON.parse(result.stdout);
  const accepted = shown.details.result;
  assert.equal(accepted.format, "mmm-outline-corrections");
  assert.equal(accepted.decision, "correct");
  assert.equal(accepted.corrections[0].bone, "femur_r");
  assert.equal(accepted.corrections[0].points_px.length, 1);
  log("mmm task show: the accepted verdict holds the femur's point");
  console.log("1 passed, 0 failed");
} catch (error) {
  console.error(error.stack || String(error));
  console.log("0 passed, 1 failed");
  process.exitCode = 1;
} finally {
  if (browser) await browser.close();
  if (server && server.exitCode === null) {
    const stopped = new Promise((resolve) => server.on("exit", resolve));
    server.kill("SIGTERM");
    await Promise.race([stopped, new Promise((resolve) => setTimeout(resolve, 10000))]);
    if (server.exitCode === null) server.kill("SIGKILL");
  }
}
