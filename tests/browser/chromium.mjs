// What every browser test here shares: Chromium started headless with a fresh
// profile and nothing that talks to the network by itself, and a page watched for
// console errors and warnings, uncaught errors and failed requests.
import { chromium } from "playwright-core";

// Start Debian's Chromium (or the one at `executablePath`) headless. Playwright
// gives it a fresh profile in a temporary folder.
export function launch(executablePath) {
  return chromium.launch({
    executablePath,
    headless: true,
    args: [
      "--no-sandbox",
      "--disable-gpu",
      "--disable-quic",
      "--no-first-run",
      "--disable-background-networking",
      "--disable-component-update",
      "--disable-sync",
    ],
  });
}

// Note into `report.console`, `report.pageErrors` and `report.failedRequests`
// what goes wrong on `page`; a failed request for which `expected(request, error)`
// is true is left out.
export function watch(page, report, expected = () => false) {
  page.on("console", (message) => {
    if (["error", "warning", "warn"].includes(message.type())) {
      report.console.push({ type: message.type(), text: message.text() });
    }
  });
  page.on("pageerror", (error) => report.pageErrors.push(String(error)));
  page.on("requestfailed", (request) => {
    const error = request.failure()?.errorText;
    if (!expected(request, error)) report.failedRequests.push({ url: request.url(), error });
  });
}
