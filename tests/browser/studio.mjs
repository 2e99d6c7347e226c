// Drive the studio's page (raystep serve) in a real headless Chromium, as a
// person would: switch a stage off and on, switch off one the others need (the
// page must show the command line's refusal), pick a buffer, click a pixel and
// read its story, then save a new scene file and see the page follow. Used by
// tests/serve.rs.
//
//   node tests/browser/studio.mjs --url http://127.0.0.1:PORT/ --screenshot SHOT.png \
//       --scene SCENE.toml --new-scene NEW.toml [--chromium /usr/bin/chromium] \
//       [--size 1400x1000] --pixel X,Y
//
// Prints one JSON object on stdout:
//   {console, pageErrors, failedRequests, steps: [{action, query, state}],
//    refusal, story: {x, y, json}, version, screenshot}

import { copyFileSync } from "node:fs";
import { launch, watch } from "./chromium.mjs";

function parseArguments(argv) {
  const options = { chromium: "/usr/bin/chromium", size: "1400x1000" };
  for (let i = 0; i < argv.length; i += 2) {
    if (!argv[i].startsWith("--")) throw new Error(`unexpected ${argv[i]}`);
    options[argv[i].slice(2)] = argv[i + 1];
  }
  for (const key of ["url", "screenshot", "scene", "new-scene", "pixel"]) {
    if (!options[key]) throw new Error(`--${key} is needed`);
  }
  const [width, height] = options.size.split("x").map(Number);
  options.viewport = { width, height };
  const [x, y] = options.pixel.split(",").map(Number);
  options.target = { x, y };
  return options;
}

// Wait until the page has answered the latest change: rendered, or refused.
async function settled(page, state) {
  await page.waitForFunction((state) => document.body.dataset.state === state, state, { timeout: 15000 });
  return page.evaluate(() => ({ query: document.body.dataset.query, state: document.body.dataset.state }));
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  const browser = await launch(options.chromium);
  const report = { console: [], pageErrors: [], failedRequests: [], steps: [] };
  try {
    const context = await browser.newContext({ viewport: options.viewport, deviceScaleFactor: 1 });
    const page = await context.newPage();
    // A render that a newer one supersedes is aborted by the page on purpose,
    // and the event stream ends when the browser closes.
    watch(page, report, (_request, error) => error === "net::ERR_ABORTED");
    await page.goto(options.url, { waitUntil: "load" });
    report.steps.push({ action: "load", ...(await settled(page, "ready")) });

    const stage = (name) => page.locator(`#stages input[value="${name}"]`);
    await stage("shadow").uncheck();
    report.steps.push({ action: "shadow off", ...(await settled(page, "ready")) });
    await stage("shadow").check();
    report.steps.push({ action: "shadow on", ...(await settled(page, "ready")) });
    await stage("rays").uncheck();
    report.steps.push({ action: "rays off", ...(await settled(page, "refused")) });
    report.refusal = await page.locator("#refusal").textContent();
    await stage("rays").check();
    report.steps.push({ action: "rays on", ...(await settled(page, "ready")) });
    await page.selectOption("#buffer", "depth");
    await page.waitForFunction(() => (document.body.dataset.query || "").includes("buffer=depth"));
    report.steps.push({ action: "depth", ...(await settled(page, "ready")) });

    // Click the centre of the pixel on the screen.
    const picture = page.locator("#picture");
    const box = await picture.boundingBox();
    const size = await picture.evaluate((img) => ({ width: img.naturalWidth, height: img.naturalHeight }));
    const { x, y } = options.target;
    await page.mouse.click(
      box.x + ((x + 0.5) * box.width) / size.width,
      box.y + ((y + 0.5) * box.height) / size.height,
    );
    await page.waitForFunction(
      ({ x, y }) => {
        const story = document.getElementById("story").dataset;
        return story.state === "ready" && story.x === String(x) && story.y === String(y);
      },
      { x, y },
      { timeout: 15000 },
    );
    report.story = { x, y, json: await page.locator("#story-json").textContent() };
    report.storyText = await page.locator("#story-text").textContent();

    // Save a new scene file: the page reloads it through the event stream.
    copyFileSync(options["new-scene"], options.scene);
    await page.waitForFunction(
      () => document.body.dataset.sceneVersion === "2" && document.body.dataset.state === "ready",
      null,
      { timeout: 15000 },
    );
    report.steps.push({ action: "scene saved", ...(await settled(page, "ready")) });
    report.version = await page.evaluate(() => document.body.dataset.version);
    await page.waitForFunction(() => document.getElementById("story").dataset.state === "ready");
    await page.screenshot({ path: options.screenshot });
    report.screenshot = { path: options.screenshot, ...options.viewport };
  } finally {
    await browser.close();
  }
  process.stdout.write(JSON.stringify(report) + "\n");
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
