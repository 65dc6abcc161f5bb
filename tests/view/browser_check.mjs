// Loads the race view in headless Chromium (or Firefox) and checks what an audience would see
// (docs/view.md; the DOM hooks are listed at the top of engine/view/page/view.js).
//
//   node browser_check.mjs URL SCREENSHOT.png [--expect-cars N] [--kill PID]
//                          [--timeout SECONDS] [--chromium PATH] [--firefox PATH]
//
// --firefox PATH drives Debian's firefox-esr through WebDriver BiDi instead of Chromium.
// --restart "COMMAND" (with --kill): once the page says "engine gone", COMMAND starts an engine
// on the same address (sh -c) and the page must say "live" again by itself, with the cars back;
// that engine gets SIGINT at the end.
//
// Checks: the page loads without script errors or failed requests; "live"; the track is drawn
// (path.road with a path, lanes, the finish line); N car markers, each with a name; N rows in the
// leaderboard; the charts drawn; the markers move (one of them by more than 10 mm) within the
// timeout. Then it writes SCREENSHOT.png. With --kill PID it sends SIGINT to PID (the engine)
// and checks that the open page says "engine gone" (and writes SCREENSHOT-gone.png).
// Prints one PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad arguments.
// Every wait is bounded by --timeout (default 30 s); no fixed sleeps.
import { spawn } from "node:child_process";
import puppeteer from "puppeteer-core";

function usage(message) {
  if (message) console.error(`browser_check: ${message}`);
  console.error("usage: node browser_check.mjs URL SCREENSHOT.png [--expect-cars N] [--kill PID] " +
                "[--timeout SECONDS] [--chromium PATH] [--firefox PATH]");
  process.exit(2);
}

const args = process.argv.slice(2);
const opts = { cars: null, kill: null, timeout: 30, chromium: process.env.CHROMIUM || "/usr/bin/chromium",
  firefox: null };
const positional = [];
for (let i = 0; i < args.length; i++) {
  const a = args[i];
  const value = () => (i + 1 < args.length ? args[++i] : usage(`${a} needs a value`));
  if (a === "--expect-cars") opts.cars = Number(value());
  else if (a === "--kill") opts.kill = Number(value());
  else if (a === "--timeout") opts.timeout = Number(value());
  else if (a === "--chromium") opts.chromium = value();
  else if (a === "--firefox") opts.firefox = value();
  else if (a === "--restart") opts.restart = value();
  else if (a.startsWith("--")) usage(`unknown option ${a}`);
  else positional.push(a);
}
if (positional.length !== 2) usage("give the page's URL and the screenshot's path");
const [url, screenshot] = positional;
if (opts.cars != null && !(Number.isInteger(opts.cars) && opts.cars > 0)) usage("--expect-cars takes a number > 0");
if (opts.kill != null && !(Number.isInteger(opts.kill) && opts.kill > 0)) usage("--kill takes a process id");
if (!(opts.timeout > 0)) usage("--timeout takes seconds > 0");
const timeoutMs = opts.timeout * 1000;

let failures = 0;
function pass(name, detail) { console.log(`PASS: ${name}${detail ? ` (${detail})` : ""}`); }
function fail(name, detail) { failures++; console.log(`FAIL: ${name}${detail ? `: ${detail}` : ""}`); }
function check(name, ok, detail) { (ok ? pass : fail)(name, detail); return ok; }
// Waits for fn in the page; a timeout is a FAIL with `what` said, not an exception.
async function waitFor(page, name, fn, arg) {
  try {
    await page.waitForFunction(fn, { timeout: timeoutMs, polling: "raf" }, arg);
    return true;
  } catch (e) {
    fail(name, `not within ${opts.timeout} s (${String(e.message).split("\n")[0]})`);
    return false;
  }
}

const loopback = new Set(["127.0.0.1", "localhost", "[::1]", "::1"]);
let browser;
const browserName = opts.firefox ? "firefox" : "chromium";
try {
  browser = opts.firefox ? await puppeteer.launch({
    browser: "firefox",
    executablePath: opts.firefox,
    headless: true,
    defaultViewport: { width: 1600, height: 1000 },
    // no network but loopback: no updates, no telemetry, no first-run pages
    extraPrefsFirefox: { "network.proxy.type": 0, "app.update.enabled": false,
      "datareporting.policy.dataSubmissionEnabled": false, "toolkit.telemetry.enabled": false,
      "browser.shell.checkDefaultBrowser": false, "network.captive-portal-service.enabled": false,
      "network.connectivity-service.enabled": false },
    timeout: timeoutMs,
  }) : await puppeteer.launch({
    executablePath: opts.chromium,
    headless: true,  // the new headless mode
    args: [
      "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
      "--no-first-run", "--no-default-browser-check", "--disable-background-networking",
      "--disable-component-update", "--disable-sync", "--disable-extensions",
      "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE localhost, EXCLUDE 127.0.0.1",
    ],
    defaultViewport: { width: 1600, height: 1000 },
    timeout: timeoutMs,
  });
} catch (e) {
  fail(`${browserName} starts`, `${opts.firefox || opts.chromium}: ${e.message.split("\n")[0]}`);
  process.exit(1);
}

try {
  const page = await browser.newPage();
  const pageErrors = [], badRequests = [];
  page.on("pageerror", (e) => pageErrors.push(String(e.message || e).split("\n")[0]));
  page.on("console", (m) => { if (m.type() === "error" && !/WebSocket|ERR_CONNECTION_REFUSED/.test(m.text())) pageErrors.push(`console: ${m.text()}`); });
  page.on("requestfailed", (r) => { if (!r.url().startsWith("ws")) badRequests.push(`${r.url()} ${r.failure()?.errorText}`); });
  page.on("response", (r) => { if (r.status() >= 400) badRequests.push(`${r.url()} HTTP ${r.status()}`); });
  await page.setRequestInterception(true);
  page.on("request", (r) => {
    const u = new URL(r.url());
    if (u.protocol === "data:" || loopback.has(u.hostname)) r.continue();
    else { badRequests.push(`${r.url()} (not loopback, blocked)`); r.abort(); }
  });

  const response = await page.goto(url, { waitUntil: "load", timeout: timeoutMs });
  check("page loads", response && response.ok(), `${url} HTTP ${response && response.status()}`);

  if (await waitFor(page, "connection says live",
      () => document.querySelector("#connection")?.textContent === "live"))
    pass("connection says live");

  if (await waitFor(page, "track drawn",
      () => [...document.querySelectorAll("#track svg path.road")].some((p) => (p.getAttribute("d") || "").length > 10))) {
    const t = await page.evaluate(() => ({
      roads: document.querySelectorAll("#track svg path.road").length,
      lanes: document.querySelectorAll("#track svg path.lane").length,
      finish: !!document.querySelector("#track svg #finish-line"),
      d: document.querySelector("#track svg path.road").getAttribute("d").length,
    }));
    pass("track drawn", `${t.roads} road path(s), d of ${t.d} characters`);
    check("lanes drawn", t.lanes > 0, `${t.lanes} lane(s)`);
    check("finish line drawn", t.finish);
  }

  const n = opts.cars;
  if (n != null) {
    if (await waitFor(page, `${n} car markers`,
        (k) => document.querySelectorAll("#track g.car-marker").length === k, n)) {
      const names = await page.$$eval("#track g.car-marker", (gs) =>
        gs.map((g) => `${g.dataset.number}:${g.querySelector("text.car-name")?.textContent ?? ""}`));
      pass(`${n} car markers`, names.join(", "));
      const unnamed = names.filter((s) => s.split(":")[1].trim() === "");
      check("every marker has a name", unnamed.length === 0, unnamed.length ? `unnamed: ${unnamed}` : "");
    }
    if (await waitFor(page, `leaderboard has ${n} rows`,
        (k) => document.querySelectorAll("#leaderboard tbody tr").length === k, n))
      pass(`leaderboard has ${n} rows`);
  }

  // Movement: the first position seen of each marker, then until one moved by > 10 mm.
  if (await waitFor(page, "a marker is placed on the track",
      () => [...document.querySelectorAll("#track g.car-marker")].some((g) => g.dataset.x != null && !g.classList.contains("off-track"))))
    pass("a marker is placed on the track");
  await page.evaluate(() => { window.__start = {}; });
  if (await waitFor(page, "markers move (> 10 mm)", () => {
    for (const g of document.querySelectorAll("#track g.car-marker")) {
      if (g.dataset.x == null) continue;
      const p = [Number(g.dataset.x), Number(g.dataset.y)];
      const s = (window.__start[g.dataset.number] ??= p);
      if (Math.hypot(p[0] - s[0], p[1] - s[1]) > 10) return true;
    }
    return false;
  })) {
    const moved = await page.evaluate(() => [...document.querySelectorAll("#track g.car-marker")]
      .map((g) => { const s = window.__start[g.dataset.number]; return s ? `${g.dataset.number}: ${Math.round(Math.hypot(g.dataset.x - s[0], g.dataset.y - s[1]))} mm` : null; })
      .filter(Boolean).join(", "));
    pass("markers move (> 10 mm)", moved);
  }

  if (await waitFor(page, "race phase shown",
      () => (document.querySelector("#race-phase")?.textContent || "").trim() !== ""))
    pass("race phase shown", await page.$eval("#race-phase", (e) => e.textContent));
  if (await waitFor(page, "charts drawn",
      () => document.querySelector("#lap-chart canvas") && document.querySelector("#speed-chart canvas")))
    pass("charts drawn");
  const events = await page.$$eval("#events li", (l) => l.length);
  check("event log shown", events > 0, `${events} line(s)`);

  check("no script errors", pageErrors.length === 0, pageErrors.join("; "));
  check("no failed requests", badRequests.length === 0, badRequests.join("; "));

  await page.screenshot({ path: screenshot, fullPage: true });
  pass("screenshot written", screenshot);

  if (opts.kill != null) {
    try {
      process.kill(opts.kill, "SIGINT");
      pass(`SIGINT sent to ${opts.kill}`);
      if (await waitFor(page, "page says engine gone",
          () => document.querySelector("#connection")?.textContent === "engine gone"))
        pass("page says engine gone");
      const gone = screenshot.replace(/(\.png)?$/i, "-gone.png");
      await page.screenshot({ path: gone, fullPage: true });
      pass("screenshot written", gone);
      if (opts.restart) {
        const engine = spawn("sh", ["-c", `exec ${opts.restart}`], { stdio: "ignore" });
        try {
          if (await waitFor(page, "live again after the engine restarted",
              () => document.querySelector("#connection")?.textContent === "live"))
            pass("live again after the engine restarted");
          if (opts.cars != null && await waitFor(page, "the cars back",
              (k) => document.querySelectorAll("#track g.car-marker").length === k &&
                document.querySelectorAll("#leaderboard tbody tr").length === k, opts.cars))
            pass("the cars back", `${opts.cars} markers and rows`);
        } finally {
          engine.kill("SIGINT");
        }
      }
    } catch (e) {
      fail(`SIGINT to ${opts.kill}`, e.message);
    }
  }
} catch (e) {
  fail("browser check ran", e.stack || String(e));
} finally {
  await browser.close().catch(() => {});
}
console.log(failures ? `browser check: ${failures} check(s) failed` : "browser check: all passed");
process.exit(failures ? 1 : 0);
