// Opens adit view's page in Debian's chromium (headless, software GL), waits until the map has points, the
// trajectory has poses and the STATUS panel has rows, prints window.aditState as JSON and saves a screenshot.
//   node view_page.js URL SCREENSHOT.png [TIMEOUT_S]      ($CHROMIUM: the browser, default /usr/bin/chromium)
"use strict";
const puppeteer = require("puppeteer-core");

async function main() {
  const [url, screenshot, timeout_s = "90"] = process.argv.slice(2);
  const browser = await puppeteer.launch({
    executablePath: process.env.CHROMIUM || "/usr/bin/chromium",
    headless: true,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--window-size=1280,800"],
    defaultViewport: { width: 1280, height: 800 },
  });
  try {
    const page = await browser.newPage();
    const errors = [];
    page.on("pageerror", (e) => errors.push(String(e)));
    page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
    await page.goto(url, { waitUntil: "load" });
    try {
      await page.waitForFunction(
        () => window.aditState && aditState.map_points > 0 && aditState.trajectory.odometry > 10 && aditState.status.length > 0 && aditState.sweep_points > 0,
        { timeout: Number(timeout_s) * 1000, polling: 250 });
    } catch (e) {
      const partial = await page.evaluate(() => window.aditState || null);
      console.error("view_page: the page did not fill in time: " + JSON.stringify(partial) + " " + errors.join(" | "));
      await page.screenshot({ path: screenshot });
      process.exit(1);
    }
    await new Promise((r) => setTimeout(r, 1500));  // a few more frames drawn
    const state = await page.evaluate(() => JSON.parse(JSON.stringify(window.aditState)));
    state.page_errors = errors;
    await page.screenshot({ path: screenshot });
    console.log(JSON.stringify(state));
  } finally {
    await browser.close();
  }
}

main().catch((e) => { console.error("view_page: " + (e.stack || e)); process.exit(1); });
