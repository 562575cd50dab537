// Shared by the browser tests: their command-line options and Debian's
// Chromium driven by playwright-core, or exit 77 (CTest: skipped) naming
// what is missing.
import fs from "node:fs";

// --name value pairs; exits 2 with `usage` when one of `required` is missing.
export function parseArgs(required, usage) {
  const args = {};
  for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, "")] = process.argv[i + 1];
  if (required.some((name) => !args[name])) {
    console.error(`usage: ${usage}`);
    process.exit(2);
  }
  return args;
}

// Checks for Chromium ($MMM_CHROMIUM or /usr/bin/chromium) and
// playwright-core; returns a function that launches it headless.
export async function chromiumOrSkip() {
  const executablePath = process.env.MMM_CHROMIUM || "/usr/bin/chromium";
  if (!fs.existsSync(executablePath)) {
    console.log(`skipped: no Chromium at ${executablePath} (apt-get install chromium; or set MMM_CHROMIUM)`);
    process.exit(77);
  }
  let chromium;
  try {
    ({ chromium } = await import("playwright-core"));
  } catch {
    console.log("skipped: playwright-core is not installed (cd tests/web && npm ci)");
    process.exit(77);
  }
  return () => chromium.launch({ executablePath, args: ["--no-sandbox"] });
}
