// Opens adit view's page in Debian's chromium (headless, software GL), waits until the map has points, the
// trajectory has poses and the STATUS panel has rows, prints window.aditState as JSON and saves a screenshot.
//   node view_page.js URL SCREENSHOT.png [TIMEOUT_S [MEASURE_S]]   ($CHROMIUM: the browser, default /usr/bin/chromium;
//   $ADIT_VIEW_MODE: top or follow for the screenshot; $ADIT_VIEW_SETTLE_S: seconds to let the run play on before
//   the state and screenshot are taken, default 1.5; $ADIT_SAVE_MAP: see below)
// MEASURE_S: for a log started --paused, press play once connected and measure the stream's bytes per second
// over that many seconds (state.measured), before the checks (which then need no STATUS row).
"use strict";
const puppeteer = require("puppeteer-core");

async function main() {
  const [url, screenshot, timeout_s = "90", measure_s = "0"] = process.argv.slice(2);
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
    let measured = null;
    if (Number(measure_s) > 0) {
      await page.waitForFunction(() => window.aditState && aditState.info && aditState.info.log, { timeout: 30000 });
      await page.click("#play");
      const start = await page.evaluate(() => ({ bytes: aditState.bytes, t: performance.now() }));
      await new Promise((r) => setTimeout(r, Number(measure_s) * 1000));
      const end = await page.evaluate(() => ({ bytes: aditState.bytes, t: performance.now(), frame_ms: aditState.frame_ms }));
      measured = { bytes_per_s: ((end.bytes - start.bytes) * 1000) / (end.t - start.t), seconds: (end.t - start.t) / 1000,
                   bytes: end.bytes - start.bytes, frame_ms: end.frame_ms };
    }
    try {
      await page.waitForFunction(
        (needStatus) => window.aditState && aditState.map_points > 0 && aditState.trajectory.odometry > 10 &&
          (aditState.status.length > 0 || !needStatus) && aditState.sweep_points > 0,
        { timeout: Number(timeout_s) * 1000, polling: 250 }, !measured);
    } catch (e) {
      const partial = await page.evaluate(() => window.aditState || null);
      console.error("view_page: the page did not fill in time: " + JSON.stringify(partial) + " " + errors.join(" | "));
      await page.screenshot({ path: screenshot });
      process.exit(1);
    }
    if (process.env.ADIT_VIEW_MODE) await page.click(`#view-${process.env.ADIT_VIEW_MODE}`);  // orbit, top, follow
    // $ADIT_SAVE_MAP=a,b: type each name into the page's save-map field and press the button (--allow-commands).
    for (const name of (process.env.ADIT_SAVE_MAP || "").split(",").filter((n) => n)) {
      await page.$eval("#map-name", (el, v) => { el.value = v; }, name);
      await page.click("#save-map");
      await new Promise((r) => setTimeout(r, 500));
    }
    const settle_s = Number(process.env.ADIT_VIEW_SETTLE_S || "1.5");  // a few more frames drawn, or more of the run
    await new Promise((r) => setTimeout(r, settle_s * 1000));
    const state = await page.evaluate(() => JSON.parse(JSON.stringify(window.aditState)));
    state.page_errors = errors;
    state.speed_menu = await page.$eval("#speed", (el) => el.value);  // what the playback speed menu shows
    if (measured) state.measured = measured;
    await page.screenshot({ path: screenshot });
    console.log(JSON.stringify(state));
  } finally {
    await browser.close();
  }
}

main().catch((e) => { console.error("view_page: " + (e.stack || e)); process.exit(1); });
