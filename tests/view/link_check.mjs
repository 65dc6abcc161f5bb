// A car's link on the race view (docs/view.md "Leaderboard"): a real car's link goes down and
// comes back (the fake BlueZ reboots it), and the leaderboard's Link cell says so — "down" while
// it is away, then the drop counted, with the last drop's reason in the cell's title.
//
//   node link_check.mjs VIEW-URL CAR-NUMBER SHOT.png [--timeout SECONDS] [--chromium PATH]
//
// One PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad arguments.
import { check, fail, finish, launch, parseArgs, pass, passWhen, settings } from "./check_lib.mjs";

const { opts, positional: [viewUrl, number, png] } = parseArgs("link_check",
  "VIEW-URL CAR-NUMBER SHOT.png [--timeout SECONDS] [--chromium PATH]", {},
  [3, "give the view's URL, the car's number and the screenshot's path"]);

const browser = await launch({ chromium: opts.chromium,
  viewport: { width: 1600, height: 1000, deviceScaleFactor: 1 } });
try {
  const page = await browser.newPage();
  await page.goto(viewUrl, { waitUntil: "load", timeout: settings.timeoutMs });
  await passWhen(page, `car ${number}'s link is shown, not yet dropped`,
    (n) => { const c = document.querySelector(`#leaderboard tbody tr[data-number="${n}"] td.link`); return c && c.dataset.drops === "0" && c.textContent !== "down"; }, number);
  await passWhen(page, `car ${number}'s link says down while the car is away`,
    (n) => { const c = document.querySelector(`#leaderboard tbody tr[data-number="${n}"] td.link`); return c && c.textContent === "down" && c.classList.contains("troubled"); }, number);
  await passWhen(page, `car ${number}'s link is back, the drop counted`,
    (n) => { const c = document.querySelector(`#leaderboard tbody tr[data-number="${n}"] td.link`); return c && c.dataset.drops === "1" && /\b1 drop\b/.test(c.textContent); }, number);
  const title = await page.$eval(`#leaderboard tbody tr[data-number="${number}"] td.link`, (c) => c.title);
  check("its title tells the story: two connections, the last drop's reason",
    /^2 connections, 1 drop \(last: .+\)/.test(title), title);
  await page.screenshot({ path: png, fullPage: true });
  pass("screenshot written", png);
} catch (e) {
  fail("link check ran", e.stack || String(e));
} finally {
  await browser.close().catch(() => {});
}
finish("link check");
