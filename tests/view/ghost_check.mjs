// The ghost on the race view (docs/view.md "Ghosts and deltas"): the ghost of a recorded lap is
// drawn translucent and moves; car 1's live delta to it is shown on the leaderboard, named, and
// grows while car 1 is slower than the lap.
//
//   node ghost_check.mjs VIEW-URL SHOT.png [--timeout SECONDS] [--chromium PATH]
//
// One PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad arguments.
import { check, fail, finish, launch, parseArgs, pass, passWhen, settings } from "./check_lib.mjs";

const { opts, positional: [viewUrl, png] } = parseArgs("ghost_check",
  "VIEW-URL SHOT.png [--timeout SECONDS] [--chromium PATH]", {},
  [2, "give the view's URL and the screenshot's path"]);

const browser = await launch({ chromium: opts.chromium,
  viewport: { width: 1600, height: 1000, deviceScaleFactor: 1 } });
try {
  const page = await browser.newPage();
  await page.goto(viewUrl, { waitUntil: "load", timeout: settings.timeoutMs });
  const ghost = "#track g.car-marker.ghost";
  await passWhen(page, "the ghost is drawn on the track",
    (sel) => { const g = document.querySelector(sel); return g && g.dataset.x != null && !g.classList.contains("unseen"); }, ghost);
  const opacity = await page.$eval(ghost, (g) => Number(getComputedStyle(g).opacity));
  check("translucent", opacity > 0 && opacity < 0.7, `opacity ${opacity}`);
  const normal = await page.$$eval("#track g.car-marker:not(.ghost)", (gs) => gs.length);
  check("the other cars are not ghosts", normal === 4, `${normal} cars`);
  const at = await page.$eval(ghost, (g) => [Number(g.dataset.x), Number(g.dataset.y)]);
  await passWhen(page, "the ghost moves", ([sel, x, y]) => {
    const g = document.querySelector(sel);
    return Math.hypot(Number(g.dataset.x) - x, Number(g.dataset.y) - y) > 200;
  }, [ghost, ...at]);
  const row = '#leaderboard tbody tr[data-number="1"] td.delta';
  await passWhen(page, "car 1's delta to the ghost is shown",
    (sel) => { const c = document.querySelector(sel); return c && c.dataset.delta != null && /^[+-]\d+\.\d{3}$/.test(c.textContent); }, row);
  // the session's best lap until the ghost has driven a whole lap of its own, then the ghost's
  await passWhen(page, "the delta is to the ghost's lap once it drove one, and says so",
    (sel) => /^against the ghost \(ghost lap \d+\)$/.test(document.querySelector(sel).title), row);
  const first = await page.$eval(row, (c) => Number(c.dataset.delta));
  await passWhen(page, "car 1, slower than the lap, falls behind it: its delta grows",
    ([sel, d]) => { const c = document.querySelector(sel); return Number(c.dataset.delta) > d + 0.3 && c.classList.contains("behind"); }, [row, first]);
  const ghostRow = await page.$eval("#leaderboard tbody tr.ghost td.delta", (c) => c.textContent);
  check("the ghost's own row says ghost", ghostRow === "ghost", ghostRow);
  await page.screenshot({ path: png, fullPage: true });
  pass("screenshot written", png);

  // two laps compared by distance (docs/view.md "Comparing two laps"): car 1's and the ghost's
  await page.click("#compare-open");
  await passWhen(page, "the dialog lists car 1's and the ghost's whole laps",
    () => { const o = [...document.querySelectorAll("#lap-a option")].map((o) => o.value);
            return o.some((v) => v.startsWith("1:")) && o.some((v) => v.startsWith("5:")); });
  await page.evaluate(() => {
    const pick = (sel, car) => { const s = document.querySelector(sel);
      s.value = [...s.options].find((o) => o.value.startsWith(car + ":")).value; };
    pick("#lap-a", 5); pick("#lap-b", 1);
  });
  await page.click("#lap-compare-go");
  await passWhen(page, "the comparison is drawn: the section table and the three charts",
    () => document.querySelectorAll("#lap-compare-result table.sections tr").length === 7 &&
      ["speed", "delta", "lane"].every((c) => document.querySelector(`#lap-compare-result svg.${c} polyline.lap`)));
  const how = await page.$eval("#lap-compare-how", (p) => p.textContent);
  check("it says how the laps were aligned", /^(aligned by distance|per piece): /.test(how), how);
  const lost = await page.$$eval("#lap-compare-result table.sections tr", (rows) =>
    rows.slice(1).map((r) => Number(r.cells[3].querySelector("span").textContent)));
  // (per piece, in real time: a transition read late moves time between two neighbouring
  // sections — docs/racing.md "Comparing laps" — so one short section may show a gain; the lap
  // and the sections' sum may not)
  const sections = lost.slice(0, -1), lap = lost[lost.length - 1];
  const sum = sections.reduce((a, d) => a + d, 0);
  check("car 1 (600 mm/s) lost time to the ghost (800 mm/s): the lap, the sections' sum, and all "
    + "sections but one at most",
    lost.length === 6 && lap > 0.5 && Math.abs(sum - lap) < 0.02 &&
      sections.filter((d) => d > 0).length >= sections.length - 1, lost.join(" "));
  const shot = png.replace(/(\.png)?$/i, "-compare.png");
  await page.screenshot({ path: shot, fullPage: true });
  pass("screenshot written", shot);
} catch (e) {
  fail("ghost check ran", e.stack || String(e));
} finally {
  await browser.close().catch(() => {});
}
finish("ghost check");
