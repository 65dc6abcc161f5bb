// Two phones on the controller page (/drive) in headless Chromium against a run with --humans 2
// (tests/integration/drive_browser_test.sh; the DOM hooks are listed at the top of
// engine/view/page/drive.js; the messages in docs/view.md "The controller page").
//
//   node drive_check.mjs URL [--timeout SECONDS] [--chromium PATH] [--artifacts DIR] [--party]
//
// --party: against examples/party.lua (--humans 2, four cars): Anna and Ben take seats 1 and 2,
// wait for the green light with their fingers off the throttle, then drive (Anna flat out, Ben at
// four fifths) until the race is done; the race's rows must show both players as human drivers
// that finished without a false start, the two AI drivers finished, and the race view's
// leaderboard names the players.
//
// Checks: the race view links to /drive; page 1 takes seat 1; page 2 asks for seat 1 and is told
// it is taken, then takes seat 2; page 1 holds its throttle up → car 1 is commanded a speed and
// runs, while car 2 stays commanded 0 and stands; page 1 lets go → car 1 is commanded 0 (the
// dead man's handle); page 1 holds the throttle again, then closes while holding → the engine
// frees seat 1 and car 1 is commanded 0 and stops. Cars are read from URL/api/state (their
// commanded `targetSpeed` and reported `speed`).
// The phones are phone-sized and touch screens, one upright (390×844) and one on its side
// (844×390); at every state (the seat picker, free driving, the lights, the race, the finish, the
// result) each page must fit its screen: the document's scroll size is the viewport's, nothing
// of the page lies outside it, and a slide on the throttle or the race panel scrolls nothing. In
// the party the phones must show the start lights lit one by one with the countdown, "GO" at
// green, "P2 · lap 1/1" while racing, and after the flag "Finished — P1" (the place the race's
// rows give), the time, the results and no throttle. Screenshots of each state:
// drive-<state>-<portrait|landscape>.png in --artifacts.
// Prints one PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad arguments.
// Every wait polls with a deadline (--timeout, default 30 s); no fixed sleeps.
import { check, fail, finish, launch, parseArgs, pass, passWhen, settings, watchPage } from "./check_lib.mjs";

const { opts, positional } = parseArgs("drive_check",
  "URL [--timeout SECONDS] [--chromium PATH] [--artifacts DIR] [--party | --code CODE]",
  { "--artifacts": ["artifacts", String], "--party": ["party"], "--code": ["code", String] },
  [1, "give the view's URL"]);
const url = positional[0].endsWith("/") ? positional[0] : `${positional[0]}/`;
const timeoutMs = settings.timeoutMs;

async function state() {
  const r = await fetch(`${url}api/state`);
  return r.json();
}
const carOf = (s, n) => (s.cars || []).find((c) => c.number === n) || {};
const seatOf = (s, n) => (s.seats || []).find((x) => x.number === n) || {};
const show = (c) => `target ${c.targetSpeed}, speed ${c.speed}`;

// Polls /api/state until ok(state) (true) or the deadline (a FAIL naming the last state seen).
// `always(state)`, when given, must hold at every poll (a FAIL at the first that breaks it).
async function until(name, ok, describe, always) {
  const deadline = Date.now() + timeoutMs;
  let last = null, broken = false;
  for (;;) {
    try { last = await state(); } catch (e) { last = null; }
    if (last && always && !broken) {
      const why = always(last);
      if (why) { fail(name, why); broken = true; }
    }
    if (last && ok(last)) {
      if (!broken) pass(name, describe(last));
      return last;
    }
    if (Date.now() > deadline) {
      fail(name, `not within ${opts.timeout} s; last: ${last ? describe(last) : "no state"}`);
      return null;
    }
    await new Promise((r) => setTimeout(r, 100));  // a poll's pace, not a wait for an event
  }
}

const browser = await launch({ chromium: opts.chromium });

const log = { errors: [], requests: [] };  // of every phone
// A phone held upright and one on its side (a touch screen, the page's own viewport meta).
const PORTRAIT = { width: 390, height: 844, deviceScaleFactor: 1, isMobile: true, hasTouch: true };
const LANDSCAPE = { width: 844, height: 390, deviceScaleFactor: 1, isMobile: true, hasTouch: true };
const held = (viewport) => (viewport.width > viewport.height ? "landscape" : "portrait");
const viewports = new Map();  // page → its viewport
async function phone(name, query = "", viewport = PORTRAIT) {
  // each phone a browser of its own (its own storage), phone-sized
  const context = await browser.createBrowserContext();
  const page = await context.newPage();
  await page.setViewport(viewport);
  viewports.set(page, viewport);
  watchPage(page, log, name);
  const response = await page.goto(`${url}drive${query}`, { waitUntil: "load", timeout: timeoutMs });
  check(`${name}: /drive loads`, response && response.ok(), `HTTP ${response && response.status()}`);
  return page;
}

// The page fits its screen as it is now: the document scrolls by nothing (its scroll size is the
// viewport's, the body's content is not cut off below), no shown part of the page lies outside
// the viewport, and the page has not moved.
async function fits(page, name, what) {
  const r = await page.evaluate(() => {
    const d = document.documentElement, b = document.body;
    const W = window.innerWidth, H = window.innerHeight;
    const name = (el) => (el.id ? `#${el.id}` : `${el.tagName.toLowerCase()}.${[...el.classList].join(".")}`);
    const out = [];
    const parts = "header, #notice, #pair, #pick, #pick > *, #seats li, #drive, #drive > *, " +
      "#controls > *, #lights, #countdown, #headline, #subline, #standings li";
    for (const el of document.querySelectorAll(parts)) {
      if (!el.getClientRects().length) continue;  // not shown
      const box = el.getBoundingClientRect();
      if (box.left < -0.5 || box.top < -0.5 || box.right > W + 0.5 || box.bottom > H + 0.5)
        out.push(`${name(el)} at ${Math.round(box.left)},${Math.round(box.top)}..${Math.round(box.right)},${Math.round(box.bottom)}`);
    }
    // and nothing cut off, nor to be scrolled to, inside the parts that clip (a list too wide or
    // too long for its panel)
    for (const el of document.querySelectorAll("#pick, #seats, #drive, #race, #result, #standings, #controls")) {
      if (!el.getClientRects().length) continue;
      if (el.scrollWidth > el.clientWidth + 1 || el.scrollHeight > el.clientHeight + 1)
        out.push(`${name(el)} holds ${el.scrollWidth}×${el.scrollHeight} px in ${el.clientWidth}×${el.clientHeight}`);
    }
    return { W, H, sw: d.scrollWidth, sh: d.scrollHeight, bsh: b.scrollHeight, bch: b.clientHeight,
      x: window.scrollX, y: window.scrollY, out };
  });
  return check(`${name}: ${what} fits ${r.W}×${r.H} without scrolling`,
    r.sw === r.W && r.sh === r.H && r.bsh <= r.bch && r.x === 0 && r.y === 0 && r.out.length === 0,
    `document ${r.sw}×${r.sh}, body content ${r.bsh} of ${r.bch}, scrolled ${r.x},${r.y}` +
      (r.out.length ? `; outside the screen: ${r.out.join(", ")}` : ""));
}

// A screenshot of the page's state in --artifacts: drive-STATE-portrait.png / -landscape.png.
async function shot(page, state) {
  if (opts.artifacts)
    await page.screenshot({ path: `${opts.artifacts}/drive-${state}-${held(viewports.get(page))}.png` });
}

// A finger slides up the throttle to `fraction` of its height and stays down (a touch screen's
// touch, as a phone's); the page must not have scrolled. The throttle's value is returned.
async function slideThrottle(page, name, fraction) {
  await page.bringToFront();
  const box = await (await page.$("#throttle")).boundingBox();
  const x = box.x + box.width / 2, from = box.y + box.height - 4;
  await page.touchscreen.touchStart(x, from);
  for (let k = 1; k <= 8; k++) await page.touchscreen.touchMove(x, from - (box.height * fraction - 4) * k / 8);
  const r = await page.evaluate(() => ({ y: window.scrollY, x: window.scrollX,
    value: Number(document.querySelector("#throttle").dataset.value) }));
  check(`${name}: a slide up the throttle moves the throttle, not the page`,
    r.value >= fraction - 0.1 && r.x === 0 && r.y === 0, `throttle ${r.value}, scrolled ${r.x},${r.y}`);
  return r.value;
}

// A slide on the race panel (no control there) scrolls nothing either.
async function slidePanel(page, name) {
  const box = await (await page.$("#race")).boundingBox();
  const x = box.x + box.width / 2, y = box.y + box.height / 2;
  await page.touchscreen.touchStart(x, y);
  for (let k = 1; k <= 6; k++) await page.touchscreen.touchMove(x, y - 40 * k);
  await page.touchscreen.touchEnd();
  const r = await page.evaluate(() => ({ x: window.scrollX, y: window.scrollY }));
  check(`${name}: a slide on the race panel scrolls nothing`, r.x === 0 && r.y === 0, `scrolled ${r.x},${r.y}`);
}

// What the page shows of the race now (null for what the page does not have).
const shown = (page) => page.evaluate(() => {
  const $ = (sel) => document.querySelector(sel);
  const visible = (el) => !!el && !el.hidden && el.getClientRects().length > 0;
  return {
    phase: $("#race")?.dataset.phase ?? null,
    headline: $("#headline")?.textContent ?? null,
    subline: $("#subline")?.textContent ?? "",
    countdown: visible($("#countdown")) ? $("#countdown").textContent : null,
    lit: document.querySelectorAll("#lights .light.on").length,
    lights: visible($("#lights")) ? document.querySelectorAll("#lights .light").length : 0,
    // the throttle is there and takes a finger
    throttle: visible($("#throttle")) && !$("#throttle").closest(".off") && $("#throttle").getAttribute("aria-disabled") !== "true",
    result: visible($("#result"))
      ? [...document.querySelectorAll("#standings li")].map((li) => `${li.classList.contains("me") ? "*" : ""}${li.textContent}`)
      : null,
  };
});

// Holds the throttle bar at `fraction` of its height (a finger down and moved up, kept down).
async function holdThrottle(page, fraction) {
  await page.bringToFront();
  const box = await (await page.$("#throttle")).boundingBox();
  const x = box.x + box.width / 2;
  await page.mouse.move(x, box.y + box.height - 4);
  await page.mouse.down();
  await page.mouse.move(x, box.y + box.height * (1 - fraction), { steps: 8 });
  return page.$eval("#throttle", (el) => Number(el.dataset.value));
}

// Takes seat `n` on `page` as `player`.
async function takeSeat(page, name, n, player) {
  if (await passWhen(page, `${name}: live, seats to pick`,
      () => document.querySelector("#connection")?.textContent === "live" &&
        document.querySelectorAll("#seats button[data-number]").length >= 2 && !document.querySelector("#pick").hidden))
    await fits(page, name, "the seat picker");
  await page.type("#player", player);
  await page.click(`#seats button[data-number="${n}"]`);
  return passWhen(page, `${name} holds seat ${n}`,
    (k) => !document.querySelector("#drive").hidden && document.querySelector("#drive").dataset.seat === String(k), n);
}

// The party race (examples/party.lua): two phones and two AI drivers, to the finish; Anna's phone
// upright, Ben's on its side.
async function party() {
  const one = await phone("Anna's phone", "", PORTRAIT);
  const two = await phone("Ben's phone", "", LANDSCAPE);
  const phones = [["Anna's phone", one, 1], ["Ben's phone", two, 2]];
  const both = (fn) => Promise.all(phones.map(([name, page, n]) => fn(name, page, n)));
  await takeSeat(one, "Anna's phone", 1, "Anna");
  await shot(one, "pick");
  await takeSeat(two, "Ben's phone", 2, "Ben");
  await shot(two, "pick");
  // the race starts once both seats are held: a scan lap, the grid, the lights; no finger on
  // the throttle until green (a jump start would be caught). The phones show the lights lit one
  // by one and the countdown (5 lights: 5 … 1), and say what a jump start costs.
  await both((name, page) => passWhen(page, `${name}: the start lights and the countdown`, () => {
    const c = document.querySelector("#countdown");
    const lit = document.querySelectorAll("#lights .light.on").length;
    const all = document.querySelectorAll("#lights .light").length;
    return document.querySelector("#race").dataset.phase === "lights" && !document.querySelector("#lights").hidden &&
      lit >= 1 && all === 5 && !c.hidden && c.getClientRects().length > 0 && c.textContent === String(all - lit + 1) &&
      document.querySelector("#headline").textContent === "Wait for green";
  }));
  await both(async (name, page) => {
    const s = await shown(page);
    check(`${name}: during the lights it warns of the jump start`, /held 5 s/.test(s.subline), s.subline);
    await fits(page, name, "the lights");
    await shot(page, "lights");
  });
  await both((name, page) => passWhen(page, `${name}: GO at green`,
    () => document.querySelector("#race").dataset.phase === "go" && document.querySelector("#countdown").textContent === "GO" &&
      document.querySelectorAll("#lights .light.go").length === 5));
  await shot(one, "go");
  const racing = await until("the race goes green", (s) => s.race && s.race.phase === "racing",
    (s) => `phase ${s.race && s.race.phase}`);
  if (!racing) return;
  await slideThrottle(one, "Anna's phone", 1.0);
  await slideThrottle(two, "Ben's phone", 0.8);
  await until("car 1 and car 2 are driven by their phones",
    (s) => carOf(s, 1).targetSpeed >= 300 && carOf(s, 2).targetSpeed >= 300,
    (s) => `car 1 ${show(carOf(s, 1))}; car 2 ${show(carOf(s, 2))}`);
  // racing: the player's place and lap
  await both((name, page) => passWhen(page, `${name}: racing, "P<n> · lap 1/1"`,
    () => document.querySelector("#race").dataset.phase === "racing" &&
      /^P[1-4] · lap 1\/1$/.test(document.querySelector("#headline").textContent)));
  await both(async (name, page) => {
    await fits(page, name, "the race with a finger on the throttle");
    await shot(page, "racing");
  });
  const view = await (await browser.createBrowserContext()).newPage();
  await view.goto(url, { waitUntil: "load", timeout: timeoutMs });
  // each phone, once its car took the flag: "Finished — P<n>", no throttle, the results
  await both(async (name, page, n) => {
    if (!await passWhen(page, `${name}: "Finished — P<n>" and no throttle once car ${n} took the flag`,
        () => document.querySelector("#race").dataset.phase === "finished" &&
          /^Finished — P[1-4]$/.test(document.querySelector("#headline").textContent) &&
          document.querySelector("#controls").hidden && document.querySelector("#throttle").getClientRects().length === 0 &&
          !document.querySelector("#result").hidden)) return;
    const value = await page.$eval("#throttle", (el) => Number(el.dataset.value));
    check(`${name}: the throttle let go at the flag`, value === 0, `data-value ${value}`);
    await fits(page, name, "the finish");
    await shot(page, "finished");
    await page.touchscreen.touchEnd();
  });
  const done = await until("the race is done", (s) => s.race && s.race.phase === "done",
    (s) => `phase ${s.race && s.race.phase}, laps ${(s.race && s.race.rows || []).map((r) => r.lap).join("/")}`);
  if (!done) return;
  const rows = done.race.rows || [];
  check("four cars in the results", rows.length === 4, JSON.stringify(rows.map((r) => r.car)));
  for (const [n, player] of [[1, "Anna"], [2, "Ben"]]) {
    const r = rows.find((x) => x.number === n) || {};
    check(`${player} raced car ${n} as a human driver and finished, no false start`,
      r.player === player && r.driver === "human" && r.finished === true && r.falseStart !== true,
      JSON.stringify(r));
  }
  const ai = rows.filter((r) => r.number > 2);
  check("the two AI drivers finished", ai.length === 2 && ai.every((r) => r.finished === true && r.driver !== "human"),
    JSON.stringify(ai));
  // the result on each phone: its place as the race's rows give it, its time, every car in order
  await both(async (name, page, n) => {
    const r = rows.find((x) => x.number === n) || {};
    const ok = await passWhen(page, `${name}: the results`,
      () => document.querySelector("#result-title").textContent === "Results" &&
        document.querySelectorAll("#standings li").length === 4 && !/still racing/.test(document.querySelector("#subline").textContent));
    const s = await shown(page);
    check(`${name}: "Finished — P${r.position}" as the race's results say`, s.headline === `Finished — P${r.position}`, s.headline);
    const t = r.totalTime;  // as the board writes it: 12.345, 1:02.345
    const time = typeof t !== "number" ? "(no time)"
      : t < 60 ? t.toFixed(3) : `${Math.floor(t / 60)}:${(t % 60).toFixed(3).padStart(6, "0")}`;
    check(`${name}: the time ${time} s is shown`, s.subline.includes(`${time} s`), s.subline);
    check(`${name}: the results list every car in order, this player's marked`, ok && s.result.length === 4 &&
      s.result.every((t, k) => t.replace("*", "").startsWith(`P${k + 1}`)) &&
      s.result.filter((t) => t.startsWith("*")).length === 1 && s.result[r.position - 1].startsWith("*") &&
      s.result[r.position - 1].includes(n === 1 ? "Anna" : "Ben"), JSON.stringify(s.result));
    check(`${name}: no throttle after the flag`, !s.throttle);
    await fits(page, name, "the result");
    await slidePanel(page, name);
    await shot(page, "result");
  });
  await passWhen(view, "the race view's leaderboard names both players",
    () => { const t = document.body.innerText; return t.includes("Anna (human)") && t.includes("Ben (human)"); });
  if (opts.artifacts) await view.screenshot({ path: `${opts.artifacts}/drive-party.png` });
  check("no script errors or failed requests", log.errors.length + log.requests.length === 0,
    [...log.errors, ...log.requests].join("; "));
}

// The two-phone checks against tests/view/drive_race.lua (the header says which).
async function twoPhones() {
  // The race view links to the controller page (the run has seats).
  const viewPage = await (await browser.createBrowserContext()).newPage();
  await viewPage.goto(url, { waitUntil: "load", timeout: timeoutMs });
  await passWhen(viewPage, "the race view shows a link to /drive",
    () => { const a = document.querySelector("#drive-link"); return a && !a.hidden && a.getAttribute("href") === "/drive"; });
  await viewPage.close();

  const one = await phone("page 1", "", PORTRAIT);
  const two = await phone("page 2", "", LANDSCAPE);
  for (const [name, page] of [["page 1", one], ["page 2", two]])
    if (await passWhen(page, `${name}: live, two seats to pick`,
        () => document.querySelector("#connection")?.textContent === "live" &&
          document.querySelectorAll("#seats button[data-number]").length === 2 && !document.querySelector("#pick").hidden))
      await fits(page, name, "the seat picker");

  // page 1 takes seat 1
  await one.type("#player", "Anna");
  await one.click('#seats button[data-number="1"]');
  await passWhen(one, "page 1 holds seat 1: the controls are shown",
    () => !document.querySelector("#drive").hidden && document.querySelector("#drive").dataset.seat === "1");

  // page 2 sees it taken, asks for it anyway, is refused, takes seat 2
  await passWhen(two, "page 2 sees seat 1 held",
    () => document.querySelector('#seats button[data-number="1"]')?.classList.contains("held"));
  await two.type("#player", "Ben");
  await two.click('#seats button[data-number="1"]');
  if (await passWhen(two, "page 2 is told seat 1 is taken",
      () => { const n = document.querySelector("#notice"); return !n.hidden && n.dataset.kind === "taken"; })) {
    const text = await two.$eval("#notice", (n) => n.textContent);
    check("the refusal names the holder", /seat 1 is held by another phone \(Anna\)/.test(text), text);
  }
  check("page 2 holds no seat after the refusal", await two.$eval("#drive", (d) => d.hidden));
  if (opts.artifacts) await two.screenshot({ path: `${opts.artifacts}/drive-page-taken.png` });
  await two.click('#seats button[data-number="2"]');
  await passWhen(two, "page 2 holds seat 2",
    () => !document.querySelector("#drive").hidden && document.querySelector("#drive").dataset.seat === "2");
  // no race in this run: free driving, the throttle live
  for (const [name, page] of [["page 1", one], ["page 2", two]]) {
    const s = await shown(page);
    check(`${name}: no race: "Free driving", the throttle live`, s.phase === "free" && s.headline === "Free driving" && s.throttle,
      JSON.stringify(s));
    await fits(page, name, "free driving");
  }
  await shot(two, "free");

  await until("the state shows seat 1 held by Anna and seat 2 by Ben",
    (s) => seatOf(s, 1).player === "Anna" && seatOf(s, 2).player === "Ben" && seatOf(s, 1).live && seatOf(s, 2).live,
    (s) => JSON.stringify(s.seats));

  // page 1 drives: car 1 is commanded a speed and runs; car 2 stays put
  const car2Still = (s) => {
    const c = carOf(s, 2);
    return (c.targetSpeed || 0) === 0 && (c.speed || 0) === 0 ? null : `car 2 moved: ${show(c)}`;
  };
  let value = await holdThrottle(one, 0.9);
  check("page 1's throttle is up", value >= 0.8, `data-value ${value}`);
  await fits(one, "page 1", "free driving with the throttle held");
  await until("car 1 is commanded a speed and runs", (s) => carOf(s, 1).targetSpeed >= 300 && carOf(s, 1).speed >= 300,
    (s) => `car 1 ${show(carOf(s, 1))}; car 2 ${show(carOf(s, 2))}`, car2Still);
  await until("seat 1's throttle is in the state", (s) => seatOf(s, 1).throttle >= 0.8,
    (s) => `throttle ${seatOf(s, 1).throttle}`);
  if (opts.artifacts) await one.screenshot({ path: `${opts.artifacts}/drive-page.png` });

  // letting go is 0 (the dead man's handle)
  await one.mouse.up();
  value = await one.$eval("#throttle", (el) => Number(el.dataset.value));
  check("page 1's throttle falls to 0 when the finger lets go", value === 0, `data-value ${value}`);
  await until("car 1 is commanded 0 after the finger let go", (s) => carOf(s, 1).targetSpeed === 0,
    (s) => `car 1 ${show(carOf(s, 1))}`, car2Still);

  // drive again, then the phone goes away while the finger is down
  value = await holdThrottle(one, 0.9);
  await until("car 1 runs again", (s) => carOf(s, 1).targetSpeed >= 300 && carOf(s, 1).speed >= 300,
    (s) => `car 1 ${show(carOf(s, 1))}`, car2Still);
  await one.close();
  await until("closing page 1 frees seat 1", (s) => !seatOf(s, 1).held, (s) => JSON.stringify(seatOf(s, 1)));
  // the car is commanded 0; stopped: its reported speed 0, or no position for a second (a car
  // that stands reports nothing; its last reported speed stays)
  let since = null, pos = null;
  await until("car 1 is commanded 0 and stops", (s) => {
    const c = carOf(s, 1);
    if (c.positionTime !== pos) { pos = c.positionTime; since = Date.now(); }
    return c.targetSpeed === 0 && (c.speed === 0 || Date.now() - since > 1000);
  }, (s) => `car 1 ${show(carOf(s, 1))}`, car2Still);
  await until("seat 2 is still held by page 2", (s) => seatOf(s, 2).held && seatOf(s, 2).player === "Ben",
    (s) => JSON.stringify(seatOf(s, 2)));
  if (opts.artifacts) await two.screenshot({ path: `${opts.artifacts}/drive-page-2.png` });

  check("no script errors or failed requests", log.errors.length + log.requests.length === 0,
    [...log.errors, ...log.requests].join("; "));
}

// Pairing (--code CODE: a run on 0.0.0.0, docs/view.md "Pairing"): the race view on the
// engine's machine shows the code; a phone without it is refused a seat and asked for the code,
// and takes the seat once it is typed; a phone that came by /drive?code= takes a seat at once,
// and keeps the code for its tab (back on /drive without it, it takes its seat again).
async function pairing() {
  const viewPage = await (await browser.createBrowserContext()).newPage();
  await viewPage.goto(url, { waitUntil: "load", timeout: timeoutMs });
  if (await passWhen(viewPage, "the race view shows the join code",
      () => !document.querySelector("#join").hidden && document.querySelector("#join-code").textContent !== "")) {
    const shown = await viewPage.$eval("#join-code", (el) => el.textContent);
    const link = await viewPage.$eval("#join-url", (el) => el.textContent);
    check("the race view's code is the terminal's", shown === opts.code, `${shown} vs ${opts.code}`);
    check("the race view shows /drive?code= with it", link.endsWith(`/drive?code=${opts.code}`), link);
    await passWhen(viewPage, "the race view draws the address as a QR code",
      () => { const q = document.querySelector("#join-qr"); return !q.hidden && q.complete && q.naturalWidth > 60; });
  }
  if (opts.artifacts) await viewPage.screenshot({ path: `${opts.artifacts}/drive-join-code.png` });
  await viewPage.close();

  const stranger = await phone("a phone without the code");
  await passWhen(stranger, "a phone without the code: live, seats to pick",
    () => document.querySelector("#connection")?.textContent === "live" && !document.querySelector("#pick").hidden &&
      document.querySelectorAll("#seats button[data-number]").length === 2);
  await stranger.type("#player", "Eve");
  await stranger.click('#seats button[data-number="1"]');
  await passWhen(stranger, "a phone without the code is refused and asked for it",
    () => !document.querySelector("#pair").hidden && /join code/.test(document.querySelector("#notice").textContent));
  check("a phone without the code holds no seat", await stranger.$eval("#drive", (d) => d.hidden));
  await until("the refused phone took nothing", (s) => !seatOf(s, 1).held, (s) => JSON.stringify(seatOf(s, 1)));
  if (opts.artifacts) await stranger.screenshot({ path: `${opts.artifacts}/drive-asks-code.png` });
  await stranger.type("#code", opts.code);
  await stranger.click("#pair-go");
  await passWhen(stranger, "with the code typed, the phone holds seat 1",
    () => !document.querySelector("#drive").hidden && document.querySelector("#drive").dataset.seat === "1");

  const invited = await phone("a phone with the code", `?code=${opts.code}`);
  await takeSeat(invited, "a phone with the code", 2, "Ben");
  // reconnection: the same tab on /drive without the code still has it
  await invited.goto(`${url}drive`, { waitUntil: "load", timeout: timeoutMs });
  await takeSeat(invited, "the same tab on /drive, without ?code=", 2, "");
  await until("both seats are held by the paired phones",
    (s) => seatOf(s, 1).held && seatOf(s, 2).held, (s) => JSON.stringify(s.seats));
  check("no script errors or failed requests", log.errors.length + log.requests.length === 0,
    [...log.errors, ...log.requests].join("; "));
}

try {
  await (opts.party ? party() : opts.code ? pairing() : twoPhones());
} catch (e) {
  fail("drive check", String(e.stack || e));
} finally {
  await browser.close().catch(() => {});
}
finish("drive check");
