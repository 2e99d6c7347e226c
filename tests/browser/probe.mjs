// Drive the page `raystep stages` writes (index.html) in a real headless Chromium,
// as a person would: click a picture in the grid, move the mouse over the large
// picture to a pixel, and read what the page shows. Used by tests/page.rs.
//
//   node tests/browser/probe.mjs --page OUT/index.html --screenshot SHOT.png \
//       [--chromium /usr/bin/chromium] [--size 1400x1000] STAGE:BUFFER:X:Y...
//
// e.g. 06-plane:beauty:150:80. Prints one JSON object on stdout:
//   {console: [{type, text}], pageErrors: [...], failedRequests: [...],
//    probes: [{stage, buffer, x, y, readout: {...}, fields: {R: {value, text, computed}, ...}}],
//    screenshot: {path, width, height}}
// The screenshot is taken after the last probe.

import { pathToFileURL } from "node:url";
import { launch, watch } from "./chromium.mjs";

function parseArguments(argv) {
  const options = { chromium: "/usr/bin/chromium", size: "1400x1000", probes: [] };
  for (let i = 0; i < argv.length; i++) {
    const arg = argv[i];
    if (arg.startsWith("--")) {
      options[arg.slice(2)] = argv[++i];
    } else {
      const [stage, buffer, x, y] = arg.split(":");
      options.probes.push({ stage, buffer, x: Number(x), y: Number(y) });
    }
  }
  if (!options.page || !options.screenshot || options.probes.length === 0) {
    throw new Error("usage: probe.mjs --page INDEX.html --screenshot OUT.png STAGE:BUFFER:X:Y...");
  }
  const [width, height] = options.size.split("x").map(Number);
  options.viewport = { width, height };
  return options;
}

// Click the grid's cell of `stage` × `buffer`, point at pixel (x, y) of the large
// picture with the real mouse, and read the readout once it shows that pixel.
async function probe(page, { stage, buffer, x, y }) {
  await page.click(`button.cell[data-stage="${stage}"][data-buffer="${buffer}"]`);
  const src = `${stage}/${buffer}.png`;
  await page.waitForFunction((src) => {
    const large = document.getElementById("large");
    return large.getAttribute("src") === src && large.complete && large.naturalWidth > 0;
  }, src);
  const large = page.locator("#large");
  await large.scrollIntoViewIfNeeded();
  const box = await large.boundingBox();
  const size = await large.evaluate((img) => ({ width: img.naturalWidth, height: img.naturalHeight }));
  // The centre of pixel (x, y) on the screen.
  const px = box.x + ((x + 0.5) * box.width) / size.width;
  const py = box.y + ((y + 0.5) * box.height) / size.height;
  await page.mouse.move(px, py, { steps: 4 });
  await page.waitForFunction(
    ({ stage, x, y }) => {
      const r = document.getElementById("readout").dataset;
      return r.stage === stage && r.x === String(x) && r.y === String(y) && r.state === "ready";
    },
    { stage, x, y },
    { timeout: 15000 },
  );
  const readout = await page.locator("#readout").evaluate((el) => ({ ...el.dataset }));
  const fields = await page.locator("#readout [data-field]").evaluateAll((els) =>
    Object.fromEntries(
      els.map((el) => [
        el.dataset.field,
        { value: el.dataset.value, text: el.textContent, computed: el.dataset.computed },
      ]),
    ),
  );
  return { stage, buffer, x, y, readout, fields };
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  const browser = await launch(options.chromium);
  const report = { console: [], pageErrors: [], failedRequests: [], probes: [] };
  try {
    const context = await browser.newContext({ viewport: options.viewport, deviceScaleFactor: 1 });
    const page = await context.newPage();
    watch(page, report);
    await page.goto(pathToFileURL(options.page).href, { waitUntil: "load" });
    for (const p of options.probes) {
      report.probes.push(await probe(page, p));
    }
    // Every thumbnail drawn before the picture is taken.
    await page.waitForFunction(() => [...document.images].every((img) => img.complete));
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
