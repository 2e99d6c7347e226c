// Open every page of the built book in a real headless Chromium, offline: every
// request is intercepted, and any that would leave the machine (anything but
// file:, data:, blob: and 127.0.0.1/localhost) is refused and reported. Used by
// tests/book_html.rs.
//
//   node tests/browser/book.mjs --book BOOK_DIR --shots SHOT_DIR \
//       [--chromium /usr/bin/chromium] [--size 1280x900] PAGE.html...
//
// Prints one JSON object on stdout: {pages: [{page, console: [{type, text}],
// pageErrors, failedRequests: [{url, error}], blocked: [url], badResponses,
// requests, maths: {count, display, fractions, flatFractions, scripts,
// flatScripts, width0}, screenshot}]}. Each page's screenshot (SHOT_DIR/NAME.png,
// the window's size; notes/a.html gives notes-a.png) shows its first displayed
// formula, or its top if it has none.

import path from "node:path";
import { pathToFileURL } from "node:url";
import { launch, watch } from "./chromium.mjs";

function parseArguments(argv) {
  const options = { chromium: "/usr/bin/chromium", size: "1280x900", pages: [] };
  for (let i = 0; i < argv.length; i++) {
    const arg = argv[i];
    if (arg.startsWith("--")) {
      options[arg.slice(2)] = argv[++i];
    } else {
      options.pages.push(arg);
    }
  }
  if (!options.book || !options.shots || options.pages.length === 0) {
    throw new Error("usage: book.mjs --book BOOK_DIR --shots SHOT_DIR PAGE.html...");
  }
  const [width, height] = options.size.split("x").map(Number);
  options.viewport = { width, height };
  return options;
}

// A request that stays on this machine.
function local(url) {
  const { protocol, hostname } = new URL(url);
  if (["file:", "data:", "blob:"].includes(protocol)) {
    return true;
  }
  return ["http:", "https:", "ws:"].includes(protocol) && ["127.0.0.1", "localhost", "[::1]"].includes(hostname);
}

// How the browser laid the formulas out: a fraction whose numerator is not above
// its denominator, or a superscript not raised above its base, is drawn flat
// (MathML not typeset).
function measureMaths() {
  const box = (el) => el.getBoundingClientRect();
  const maths = [...document.querySelectorAll("math")];
  const fractions = [...document.querySelectorAll("mfrac")];
  const scripts = [...document.querySelectorAll("msup")];
  return {
    count: maths.length,
    display: maths.filter((m) => m.getAttribute("display") === "block").length,
    fractions: fractions.length,
    flatFractions: fractions.filter((f) => !(box(f.children[0]).bottom <= box(f.children[1]).top + 1)).length,
    scripts: scripts.length,
    flatScripts: scripts.filter((s) => !(box(s.children[1]).top < box(s.children[0]).top)).length,
    width0: maths.filter((m) => box(m).width === 0).length,
  };
}

async function visit(context, options, name) {
  const report = { page: name, console: [], pageErrors: [], failedRequests: [], blocked: [], badResponses: [], requests: 0 };
  const page = await context.newPage();
  // A request blocked for leaving the machine is noted in `blocked` instead.
  watch(page, report, (request) => report.blocked.includes(request.url()));
  page.on("response", (response) => {
    if (response.status() >= 400) {
      report.badResponses.push({ url: response.url(), status: response.status() });
    }
  });
  await page.route("**/*", (route) => {
    const url = route.request().url();
    report.requests++;
    if (local(url)) {
      return route.continue();
    }
    report.blocked.push(url);
    return route.abort("blockedbyclient");
  });
  await page.goto(pathToFileURL(path.join(options.book, name)).href, { waitUntil: "load" });
  await page.evaluate(() => document.fonts.ready);
  await page.waitForFunction(() => [...document.images].every((img) => img.complete));
  report.maths = await page.evaluate(measureMaths);
  // The first displayed formula (else the first inline one) in the middle of the window.
  await page.evaluate(() => {
    const formula = document.querySelector("math[display=block]") ?? document.querySelector("math");
    formula?.scrollIntoView({ block: "center" });
  });
  report.screenshot = path.join(options.shots, name.replace(/\.html$/, ".png").replaceAll("/", "-"));
  await page.screenshot({ path: report.screenshot });
  await page.close();
  return report;
}

async function main() {
  const options = parseArguments(process.argv.slice(2));
  const browser = await launch(options.chromium);
  const pages = [];
  try {
    const context = await browser.newContext({ viewport: options.viewport, deviceScaleFactor: 1 });
    for (const name of options.pages) {
      pages.push(await visit(context, options, name));
    }
  } finally {
    await browser.close();
  }
  process.stdout.write(JSON.stringify({ pages }) + "\n");
}

main().catch((error) => {
  console.error(error);
  process.exit(1);
});
