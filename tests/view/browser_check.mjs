// Loads the race view in headless Chromium (or Firefox) and checks what an audience would see
// (docs/view.md; the DOM hooks are listed at the top of engine/view/page/view.js).
//
//   node browser_check.mjs URL SCREENSHOT.png [--expect-cars N] [--kill PID] [--restart COMMAND]
//                          [--race-start] [--timeout SECONDS] [--chromium PATH] [--firefox PATH]
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
// --race-start (with --expect-cars N; the page opened before the race's scan): from the page's
// first moments to 8 s of racing, sampled ten times a second and on every change of the
// leaderboard: during the scan, the grid and the lights every car is drawn on the track (none
// greyed, none hidden), listed, and none named "not on the track"; two seconds into the lights,
// every car (standing on the grid) shows 0 mm/s; while racing, the gaps never decrease down the
// table. Screenshots SCREENSHOT-scan.png, -lights.png and -racing.png.
// Prints one PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad arguments.
// Every wait is bounded by --timeout (default 30 s); no fixed sleeps.
import { spawn } from "node:child_process";
import { check, fail, finish, launch, parseArgs, pass, passWhen, settings, waitFor, watchPage } from "./check_lib.mjs";

const { opts, positional: [url, screenshot], usage } = parseArgs("browser_check",
  "URL SCREENSHOT.png [--expect-cars N] [--kill PID] [--restart COMMAND] [--timeout SECONDS] " +
  "[--chromium PATH] [--firefox PATH]",
  { "--expect-cars": ["cars", Number], "--kill": ["kill", Number], "--firefox": ["firefox", String],
    "--restart": ["restart", String], "--race-start": ["raceStart"] },
  [2, "give the page's URL and the screenshot's path"]);
if (opts.cars != null && !(Number.isInteger(opts.cars) && opts.cars > 0)) usage("--expect-cars takes a number > 0");
if (opts.kill != null && !(Number.isInteger(opts.kill) && opts.kill > 0)) usage("--kill takes a process id");

// The start of a race as the audience sees it (--race-start).
async function watchRaceStart(page, n, screenshot) {
  await page.evaluate((n) => {
    const o = window.__start = { phases: {}, hidden: [], gaps: [], speeds: [], lightsAt: null, racingAt: null };
    const phase = () => (document.querySelector("#race-phase")?.textContent || "").trim().toLowerCase();
    const cell = (tr, k) => tr.cells[k]?.textContent.trim() ?? "";
    const look = () => {
      const p = phase(), now = performance.now();
      o.phases[p] = (o.phases[p] || 0) + 1;
      if (p === "lights" && o.lightsAt == null) o.lightsAt = now;
      if (p === "racing" && o.racingAt == null) o.racingAt = now;
      if (["scan", "grid", "lights"].includes(p) && document.querySelector("#track svg path.road")) {
        const shown = [...document.querySelectorAll("#track g.car-marker:not([data-number=view-ghost])")].filter((g) =>
          g.dataset.x != null && !g.classList.contains("unseen") && !g.classList.contains("off-track"));
        const rows = [...document.querySelectorAll("#leaderboard tbody tr")];
        const warned = rows.filter((tr) => tr.classList.contains("off-track")).length;
        const list = document.querySelector("#off-track");
        if (shown.length !== n || rows.length !== n || warned || (list && !list.hidden))
          o.hidden.push(`${p}: ${shown.length}/${n} drawn, ${rows.length} rows, ${warned} warned` +
            (list && !list.hidden ? `, "${list.textContent}"` : ""));
      }
      if (p === "lights" && now - o.lightsAt > 2000) {
        const moving = [...document.querySelectorAll("#leaderboard tbody tr")]
          .filter((tr) => cell(tr, 7) !== "0").map((tr) => `${cell(tr, 1)} ${cell(tr, 7)}`);
        if (moving.length) o.speeds.push(moving.join(", "));
      }
      if (p === "racing") {
        // "leader", "+0.366", "+1 lap": laps behind first, then seconds
        let last = [-1, -1];
        for (const tr of document.querySelectorAll("#leaderboard tbody tr")) {
          const g = cell(tr, 6);
          const laps = /^\+(\d+) laps?$/.exec(g), secs = /^\+(\d+\.\d+)$/.exec(g);
          const key = g === "leader" ? [0, 0] : laps ? [Number(laps[1]), 0] : secs ? [0, Number(secs[1])] : null;
          if (!key) continue;
          if (key[0] < last[0] || (key[0] === last[0] && key[1] < last[1]))
            o.gaps.push([...document.querySelectorAll("#leaderboard tbody tr")].map((r) => cell(r, 6)).join(" "));
          last = key;
        }
      }
    };
    setInterval(look, 100);
    new MutationObserver(look).observe(document.querySelector("#leaderboard tbody"),
      { childList: true, subtree: true, characterData: true });
  }, n);
  const shot = async (phase) => {
    const path = screenshot.replace(/(\.png)?$/i, `-${phase}.png`);
    await page.screenshot({ path, fullPage: true });
    pass("screenshot written", path);
  };
  const inPhase = (p) => (document.querySelector("#race-phase")?.textContent || "").trim().toLowerCase() === p;
  const seen = {};
  for (const p of ["scan", "lights"]) {
    seen[p] = await waitFor(page, `phase ${p} shown`, inPhase, p);
    if (seen[p]) {
      if (p === "lights") await new Promise((r) => setTimeout(r, 2500)); // (the lights last 5 s)
      await shot(p);
    }
  }
  if (await waitFor(page, "phase racing shown", inPhase, "racing")) {
    await page.waitForFunction(() => performance.now() - window.__start.racingAt > 8000,
      { timeout: settings.timeoutMs, polling: 200 });
    await shot("racing");
  }
  const o = await page.evaluate(() => window.__start);
  check("scan, grid and lights seen", o.phases.scan > 0 && o.phases.grid > 0 && o.phases.lights > 0,
    JSON.stringify(o.phases));
  check("every car drawn and listed, none warned, through scan, grid and lights", o.hidden.length === 0,
    o.hidden.slice(0, 3).join("; "));
  check("cars standing on the grid show 0 mm/s", o.speeds.length === 0, o.speeds.slice(0, 3).join("; "));
  check("gaps never decrease down the table while racing", o.gaps.length === 0,
    `${o.gaps.length} bad table(s): ${o.gaps.slice(0, 3).join("; ")}`);
}

const loopback = new Set(["127.0.0.1", "localhost", "[::1]", "::1"]);
const browser = await launch({ chromium: opts.chromium, firefox: opts.firefox,
  viewport: { width: 1600, height: 1000 } });

try {
  const page = await browser.newPage();
  const log = { errors: [], requests: [] };
  watchPage(page, log);
  await page.setRequestInterception(true);
  page.on("request", (r) => {
    const u = new URL(r.url());
    if (u.protocol === "data:" || loopback.has(u.hostname)) r.continue();
    else { log.requests.push(`${r.url()} (not loopback, blocked)`); r.abort(); }
  });

  const response = await page.goto(url, { waitUntil: "load", timeout: settings.timeoutMs });
  check("page loads", response && response.ok(), `${url} HTTP ${response && response.status()}`);

  await passWhen(page, "connection says live",
      () => document.querySelector("#connection")?.textContent === "live");
  if (opts.raceStart) await watchRaceStart(page, opts.cars, screenshot);

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
        (k) => document.querySelectorAll("#track g.car-marker:not([data-number=view-ghost])").length === k, n)) {
      const names = await page.$$eval("#track g.car-marker:not([data-number=view-ghost])", (gs) =>
        gs.map((g) => `${g.dataset.number}:${g.querySelector("text.car-name")?.textContent ?? ""}`));
      pass(`${n} car markers`, names.join(", "));
      const unnamed = names.filter((s) => s.split(":")[1].trim() === "");
      check("every marker has a name", unnamed.length === 0, unnamed.length ? `unnamed: ${unnamed}` : "");
    }
    await passWhen(page, `leaderboard has ${n} rows`,
        (k) => document.querySelectorAll("#leaderboard tbody tr").length === k, n);
  }

  // Movement: the first position seen of each marker, then until one moved by > 10 mm.
  await passWhen(page, "a marker is placed on the track",
      () => [...document.querySelectorAll("#track g.car-marker:not([data-number=view-ghost])")].some((g) => g.dataset.x != null && !g.classList.contains("off-track")));
  await page.evaluate(() => { window.__start = {}; });
  if (await waitFor(page, "markers move (> 10 mm)", () => {
    for (const g of document.querySelectorAll("#track g.car-marker:not([data-number=view-ghost])")) {
      if (g.dataset.x == null) continue;
      const p = [Number(g.dataset.x), Number(g.dataset.y)];
      const s = (window.__start[g.dataset.number] ??= p);
      if (Math.hypot(p[0] - s[0], p[1] - s[1]) > 10) return true;
    }
    return false;
  })) {
    const moved = await page.evaluate(() => [...document.querySelectorAll("#track g.car-marker:not([data-number=view-ghost])")]
      .map((g) => { const s = window.__start[g.dataset.number]; return s ? `${g.dataset.number}: ${Math.round(Math.hypot(g.dataset.x - s[0], g.dataset.y - s[1]))} mm` : null; })
      .filter(Boolean).join(", "));
    pass("markers move (> 10 mm)", moved);
  }

  if (await waitFor(page, "race phase shown",
      () => (document.querySelector("#race-phase")?.textContent || "").trim() !== ""))
    pass("race phase shown", await page.$eval("#race-phase", (e) => e.textContent));
  await passWhen(page, "charts drawn",
      () => document.querySelector("#lap-chart canvas") && document.querySelector("#speed-chart canvas"));
  const events = await page.$$eval("#events li", (l) => l.length);
  check("event log shown", events > 0, `${events} line(s)`);

  check("no script errors", log.errors.length === 0, log.errors.join("; "));
  check("no failed requests", log.requests.length === 0, log.requests.join("; "));

  await page.screenshot({ path: screenshot, fullPage: true });
  pass("screenshot written", screenshot);

  // The page on a phone (390×844): the leaderboard fits the screen's width, none of it cut.
  await page.setViewport({ width: 390, height: 844, deviceScaleFactor: 1 });
  if (await waitFor(page, "the leaderboard fits a phone's width", () => {
    const panel = document.querySelector(".board-panel"), table = document.querySelector("#leaderboard");
    return panel && table && table.getBoundingClientRect().right <= panel.getBoundingClientRect().right + 1 &&
      document.documentElement.scrollWidth <= window.innerWidth + 1;
  })) pass("the leaderboard fits a phone's width");
  const phone = screenshot.replace(/(\.png)?$/i, "-phone.png");
  await page.screenshot({ path: phone, fullPage: true });
  pass("screenshot written", phone);
  await page.setViewport({ width: 1600, height: 1000, deviceScaleFactor: 1 });

  if (opts.kill != null) {
    try {
      process.kill(opts.kill, "SIGINT");
      pass(`SIGINT sent to ${opts.kill}`);
      await passWhen(page, "page says engine gone",
          () => document.querySelector("#connection")?.textContent === "engine gone");
      const gone = screenshot.replace(/(\.png)?$/i, "-gone.png");
      await page.screenshot({ path: gone, fullPage: true });
      pass("screenshot written", gone);
      if (opts.restart) {
        const engine = spawn("sh", ["-c", `exec ${opts.restart}`], { stdio: "ignore" });
        try {
          await passWhen(page, "live again after the engine restarted",
              () => document.querySelector("#connection")?.textContent === "live");
          if (opts.cars != null && await waitFor(page, "the cars back",
              (k) => document.querySelectorAll("#track g.car-marker:not([data-number=view-ghost])").length === k &&
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
finish("browser check");
