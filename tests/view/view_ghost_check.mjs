// The view's own ghost (docs/view.md "Ghosts and deltas"): with no simulated ghost racing, the
// reference lap — here the track's personal best from the standings — is drawn as a translucent
// car driven from the leader's last line crossing; it moves, names its lap, has no row of its
// own, and car 1's delta is against it.
//
//   node view_ghost_check.mjs VIEW-URL SHOT.png [--timeout SECONDS] [--chromium PATH]
//
// One PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad arguments.
import { check, fail, finish, launch, parseArgs, pass, passWhen, settings } from "./check_lib.mjs";

const { opts, positional: [viewUrl, png] } = parseArgs("view_ghost_check",
  "VIEW-URL SHOT.png [--timeout SECONDS] [--chromium PATH]", {},
  [2, "give the view's URL and the screenshot's path"]);

const browser = await launch({ chromium: opts.chromium,
  viewport: { width: 1600, height: 1000, deviceScaleFactor: 1 } });
try {
  const page = await browser.newPage();
  await page.goto(viewUrl, { waitUntil: "load", timeout: settings.timeoutMs });
  const ghost = '#track g.car-marker[data-number="view-ghost"]';
  await passWhen(page, "the view's ghost is drawn on the track once car 1 crossed the line",
    (sel) => { const g = document.querySelector(sel); return g && g.dataset.x != null && !g.classList.contains("unseen"); }, ghost);
  const looks = await page.$eval(ghost, (g) => ({ ghost: g.classList.contains("ghost"),
    opacity: Number(getComputedStyle(g).opacity), follows: g.dataset.follows,
    title: g.querySelector("title")?.textContent ?? "" }));
  check("translucent, as a ghost", looks.ghost && looks.opacity > 0 && looks.opacity < 0.7,
    JSON.stringify(looks));
  check("it follows car 1, the leader", looks.follows === "1", looks.follows);
  check("it names the personal best it drives", /'s personal best in /.test(looks.title), looks.title);
  const at = await page.$eval(ghost, (g) => [Number(g.dataset.x), Number(g.dataset.y)]);
  await passWhen(page, "the view's ghost moves", ([sel, x, y]) => {
    const g = document.querySelector(sel);
    return Math.hypot(Number(g.dataset.x) - x, Number(g.dataset.y) - y) > 200;
  }, [ghost, ...at]);
  await page.screenshot({ path: png, fullPage: true });  // (on its way, ahead of car 1)
  pass("screenshot written", png);
  const rows = await page.$$eval("#leaderboard tbody tr", (r) => r.length);
  check("it has no row of its own on the leaderboard", rows === 1, `${rows} rows`);
  const row = '#leaderboard tbody tr[data-number="1"] td.delta';
  await passWhen(page, "car 1's delta is against the personal best, and says so",
    (sel) => { const c = document.querySelector(sel); return c && c.dataset.delta != null && /^against .*'s personal best in /.test(c.title); }, row);
  const first = await page.$eval(row, (c) => Number(c.dataset.delta));
  await passWhen(page, "car 1, slower than the personal best, falls behind it: its delta grows",
    ([sel, d]) => { const c = document.querySelector(sel); return Number(c.dataset.delta) > d + 0.3 && c.classList.contains("behind"); }, [row, first]);
  // the ghost is ahead of car 1 on the track: it started at the line with car 1 and is faster
  const apart = await page.evaluate((sel) => {
    const g = document.querySelector(sel);
    const c = document.querySelector('#track g.car-marker[data-number="1"]');
    return Math.hypot(Number(g.dataset.x) - Number(c.dataset.x), Number(g.dataset.y) - Number(c.dataset.y));
  }, ghost);
  check("it is not where car 1 is", apart > 50, `${apart.toFixed(0)} mm apart`);
} catch (e) {
  fail("view ghost check ran", e.stack || String(e));
} finally {
  await browser.close().catch(() => {});
}
finish("view ghost check");
