// Drive the studio's page (raystep serve) in a real headless Chromium, as a
// person would: switch a stage off and on, switch off one the others need (the
// page must show the command line's refusal), pick a buffer and show it in false
// colour, click a pixel and read its story, zoom in to single pixels and click
// the next one, pin the settings as A and compare B with it, drag the light and
// save the scene as a file, then save a new scene file and see the page follow.
// Used by tests/serve.rs.
//
//   node tests/browser/studio.mjs --url http://127.0.0.1:PORT/ --screenshot SHOT.png \
//       --scene SCENE.toml --new-scene NEW.toml --broken-scene BROKEN.toml --shots DIR --download FILE \
//       [--chromium /usr/bin/chromium] [--size 1400x1000] --pixel X,Y
//
// Writes the book's screenshots into DIR (studio-*.png) and the scene the page
// saves as FILE. Prints one JSON object on stdout:
//   {console, pageErrors, failedRequests, steps: [{action, query, state}],
//    refusal, story: {x, y, json}, zoom: {zoom, x, y}, ab: {figures, a, b},
//    light: {before, after, sent, zoom, rule}, camera: {zoom, shown, sent}, saved,
//    version, screenshot, shots}

import { copyFileSync, mkdirSync } from "node:fs";
import { join } from "node:path";
import { launch, watch } from "./chromium.mjs";

function parseArguments(argv) {
  const options = { chromium: "/usr/bin/chromium", size: "1400x1000" };
  for (let i = 0; i < argv.length; i += 2) {
    if (!argv[i].startsWith("--")) throw new Error(`unexpected ${argv[i]}`);
    options[argv[i].slice(2)] = argv[i + 1];
  }
  for (const key of ["url", "screenshot", "scene", "new-scene", "broken-scene", "pixel", "shots", "download"]) {
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

// Where pixel (x, y)'s centre is on the screen, from the page's zoom and pan.
async function screenPoint(page, x, y) {
  const frame = await page.locator("#frame").boundingBox();
  const box = await page.locator("#picture").boundingBox();
  const size = await page.locator("#picture").evaluate((c) => ({ width: c.width, height: c.height }));
  const px = box.x + ((x + 0.5) * box.width) / size.width;
  const py = box.y + ((y + 0.5) * box.height) / size.height;
  if (px < frame.x || py < frame.y || px > frame.x + frame.width || py > frame.y + frame.height) {
    throw new Error(`pixel (${x}, ${y}) is outside the frame`);
  }
  return { px, py };
}

// Move the exposure slider to `ev`, as a person dragging it would.
async function exposure(page, ev) {
  await page.locator("#exposure").evaluate((input, ev) => {
    input.value = String(ev);
    input.dispatchEvent(new Event("input", { bubbles: true }));
  }, ev);
  await page.waitForFunction((ev) => document.getElementById("exposure-value").textContent.startsWith(`${ev > 0 ? "+" : ""}${ev} EV`), ev);
}

async function storyOf(page, x, y) {
  await page.waitForFunction(
    ({ x, y }) => {
      const story = document.getElementById("story").dataset;
      return story.state === "ready" && story.x === String(x) && story.y === String(y);
    },
    { x, y },
    { timeout: 15000 },
  );
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  mkdirSync(options.shots, { recursive: true });
  const browser = await launch(options.chromium);
  const report = { console: [], pageErrors: [], failedRequests: [], steps: [], shots: [] };
  const shot = async (page, name) => {
    const path = join(options.shots, `studio-${name}.png`);
    await page.evaluate(() => window.scrollTo(0, 0));
    await page.screenshot({ path });
    report.shots.push(path);
  };
  try {
    const context = await browser.newContext({ viewport: options.viewport, deviceScaleFactor: 1, acceptDownloads: true });
    const page = await context.newPage();
    // A render that a newer one supersedes is aborted by the page on purpose,
    // and the event stream ends when the browser closes.
    watch(page, report, (_request, error) => error === "net::ERR_ABORTED");
    await page.goto(options.url, { waitUntil: "load" });
    report.steps.push({ action: "load", ...(await settled(page, "ready")) });
    await shot(page, "overview");

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

    // False colour: the depth's grey (the hits; misses are a blue checker)
    // becomes the ramp, drawn by the page.
    const greys = () =>
      page.locator("#picture").evaluate((c) => {
        const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
        let n = 0;
        for (let i = 0; i < d.length; i += 4) if (d[i] === d[i + 1] && d[i + 1] === d[i + 2]) n++;
        return n;
      });
    const grey = await greys();
    await page.check("#false-colour");
    const coloured = await greys();
    report.falseColour = { before: grey, after: coloured };

    // Click the centre of the pixel on the screen.
    const { x, y } = options.target;
    let at = await screenPoint(page, x, y);
    await page.mouse.click(at.px, at.py);
    await storyOf(page, x, y);
    report.story = { x, y, json: await page.locator("#story-json").textContent() };
    report.storyText = await page.locator("#story-text").textContent();
    report.storyBuffers = await page.locator("#story-buffers").textContent();
    await shot(page, "depth-false-colour");
    await page.uncheck("#false-colour");
    await page.selectOption("#buffer", "beauty");
    await page.waitForFunction(() => (document.body.dataset.query || "").includes("buffer=beauty"));
    report.steps.push({ action: "beauty", ...(await settled(page, "ready")) });

    // Zoom in on the pixel with the wheel until a pixel is 32 screen pixels
    // wide, then click the next pixel to its right.
    for (let i = 0; i < 8; i++) {
      const zoom = Number(await page.locator("#frame").getAttribute("data-zoom"));
      if (zoom >= 32) break;
      at = await screenPoint(page, x, y);
      await page.mouse.move(at.px, at.py);
      await page.mouse.wheel(0, -100);
      await page.waitForFunction((zoom) => Number(document.getElementById("frame").dataset.zoom) > zoom, zoom);
    }
    const zoom = Number(await page.locator("#frame").getAttribute("data-zoom"));
    at = await screenPoint(page, x + 1, y);
    await page.mouse.click(at.px, at.py);
    await storyOf(page, x + 1, y);
    report.zoom = { zoom, x: x + 1, y };
    await shot(page, "zoom");
    await page.click("#zoom-fit");

    // A/B: the beauty with every stage as A, without shadows as B.
    await page.click("#pin");
    await page.waitForFunction(() => document.getElementById("ab").dataset.state === "ready");
    const same = await page.locator("#ab").getAttribute("data-figures");
    await stage("shadow").uncheck();
    report.steps.push({ action: "B: shadow off", ...(await settled(page, "ready")) });
    await page.waitForFunction(
      () => document.getElementById("ab").dataset.state === "ready" && (document.getElementById("ab").dataset.b || "").includes("without=shadow"),
    );
    await page.check('#ab-show input[value="diff"]');
    await page.waitForFunction(() => document.getElementById("picture").dataset.drawn === "diff");
    report.ab = {
      same: JSON.parse(same),
      figures: JSON.parse(await page.locator("#ab").getAttribute("data-figures")),
      a: await page.locator("#ab").getAttribute("data-a"),
      b: await page.locator("#ab").getAttribute("data-b"),
      text: await page.locator("#ab-figures").textContent(),
    };
    // Their difference is faint: shown 8 times brighter (+3 EV).
    await exposure(page, 3);
    await shot(page, "ab");
    await exposure(page, 0);
    await page.click("#unpin");
    await stage("shadow").check();
    report.steps.push({ action: "shadow on again", ...(await settled(page, "ready")) });

    // Drag the light 80 screen pixels to the right.
    await page.check('#drag input[value="light"]');
    const before = await page.locator("#light-position").textContent();
    const frame = await page.locator("#frame").boundingBox();
    const from = { x: frame.x + frame.width / 2, y: frame.y + frame.height / 2 };
    await page.mouse.move(from.x, from.y);
    await page.mouse.down();
    for (let step = 1; step <= 8; step++) await page.mouse.move(from.x + step * 10, from.y);
    await page.mouse.up();
    await page.waitForFunction(() => (document.body.dataset.query || "").includes("light="));
    report.steps.push({ action: "light dragged", ...(await settled(page, "ready")) });
    report.light = {
      before,
      after: await page.locator("#light-position").textContent(),
      sent: await page.locator("#drag").getAttribute("data-light"),
      zoom: Number(await page.locator("#frame").getAttribute("data-zoom")),
      // The page's rule for other lights (30 pixels right, 20 down), for the
      // test to project: in front of the eye, beyond the screen and before it,
      // and level with the eye.
      rule: await page.evaluate(() => ({
        screen: current.screen,
        eye: current.eye,
        size: [current.width, current.height],
        moved: [[0.5, 0.5, -2], [-0.25, 0.1, 0.5], [1, 1, 1]].map((start) => ({
          start,
          end: moveBy("light", start, 30, 20),
        })),
        camera: moveBy("camera", [0, 0, 1], 30, 20),
      })),
    };
    await shot(page, "light");

    // Save as: the scene with the moved light, as a download.
    const [download] = await Promise.all([page.waitForEvent("download"), page.click("#save-as")]);
    await download.saveAs(options.download);
    report.saved = { file: options.download, name: download.suggestedFilename() };
    // Drag the camera 40 screen pixels up.
    await page.check('#drag input[value="camera"]');
    await page.mouse.move(from.x, from.y);
    await page.mouse.down();
    for (let step = 1; step <= 4; step++) await page.mouse.move(from.x, from.y - step * 10);
    await page.mouse.up();
    await page.waitForFunction(() => (document.body.dataset.query || "").includes("camera="));
    report.steps.push({ action: "camera dragged", ...(await settled(page, "ready")) });
    report.camera = {
      zoom: Number(await page.locator("#frame").getAttribute("data-zoom")),
      shown: await page.locator("#camera-position").textContent(),
      sent: await page.locator("#drag").getAttribute("data-camera"),
    };
    await page.click("#reset-moves");
    report.steps.push({ action: "reset", ...(await settled(page, "ready")) });
    await page.selectOption("#buffer", "depth");
    await page.waitForFunction(() => (document.body.dataset.query || "").includes("buffer=depth"));
    report.steps.push({ action: "depth again", ...(await settled(page, "ready")) });

    // Save a scene file that no longer loads: the page shows the command line's
    // message and keeps the last good picture.
    copyFileSync(options["broken-scene"], options.scene);
    await page.waitForFunction(
      () => document.body.dataset.version === "2" && !document.getElementById("scene-error").hidden,
      null,
      { timeout: 15000 },
    );
    report.broken = {
      error: await page.locator("#scene-error").textContent(),
      state: await page.evaluate(() => document.body.dataset.state),
    };

    // Save a new scene file: the page reloads it through the event stream.
    copyFileSync(options["new-scene"], options.scene);
    await page.waitForFunction(
      () => document.body.dataset.sceneVersion === "3" && document.body.dataset.state === "ready",
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
