// The code editor as the page will load it (issue 39; engine/view/page/editor/pitwall_editor.js):
// the bundle the build made from the pinned CodeMirror packages, served by the race view's own
// server, loaded into a page of that server in headless Chromium.
//
//   node editor_check.mjs VIEW-URL EDITOR.png [--timeout SECONDS] [--chromium PATH]
//
// Checks: /vendor/pitwall-editor.js is served as JavaScript and sets window.PitwallEditor; an
// editor made with a driver's text shows it with Lua highlighting (a keyword coloured apart from a
// name); with the completions the build generated from the API's definitions
// (/vendor/pitwall-completions.json, `pitwall types --completions`), typing "car:se" offers
// car:setSpeed with its parameters and not what another prefix has (ctx:ahead);
// an error shown at line 2 is marked on line 2 and cleared by []; each change reaches onChange.
// Writes EDITOR.png. One PASS/FAIL line per check; exit status 1 when a check failed, 2 on bad
// arguments.
import { check, finish, launch, parseArgs, passWhen, settings, watchPage } from "./check_lib.mjs";

const { opts, positional: [viewUrl, png] } = parseArgs("editor_check",
  "VIEW-URL EDITOR.png [--timeout SECONDS] [--chromium PATH]", {},
  [2, "give the view's URL and the screenshot's path"]);

const DRIVER = "local function update(self, car, ctx)\n  car:setSpeed(500)\nend\nreturn { update = update }\n";
const browser = await launch({ chromium: opts.chromium, viewport: { width: 900, height: 500 } });
try {
  const page = await browser.newPage();
  const log = { errors: [], requests: [] };
  watchPage(page, log);
  const bundle = await page.goto(new URL("vendor/pitwall-editor.js", viewUrl).href,
    { timeout: settings.timeoutMs });
  check("the view serves the editor's bundle as JavaScript", bundle && bundle.ok() &&
    /javascript/.test(bundle.headers()["content-type"] || ""),
    `HTTP ${bundle && bundle.status()} ${bundle && bundle.headers()["content-type"]}`);
  // a page of its own on the view's origin — the bundle's own address, its text replaced (the race
  // view's page would go on drawing into what it no longer has)
  await page.evaluate(() => {
    document.documentElement.innerHTML = "<head><meta charset=utf-8></head>"
      + "<body><div id=ed style='height:300px'></div></body>";
  });
  await page.addScriptTag({ url: "/vendor/pitwall-editor.js" });
  check("it sets window.PitwallEditor", await page.evaluate(() =>
    typeof window.PitwallEditor?.create === "function"));
  const served = await page.evaluate(async () => {
    const r = await fetch("/vendor/pitwall-completions.json");
    window.completions = r.ok ? await r.json() : null;
    return { status: r.status, type: r.headers.get("content-type"),
      car: window.completions && (window.completions["car:"] || []).length,
      ctx: window.completions && (window.completions["ctx:"] || []).map((m) => m.label).join(" ") };
  });
  check("the view serves the completions made from the API's definitions", served.status === 200 &&
    /json/.test(served.type || "") && served.car > 5 && /ahead/.test(served.ctx), JSON.stringify(served));
  await page.evaluate((text) => {
    window.changes = [];
    window.ed = window.PitwallEditor.create(document.getElementById("ed"), {
      doc: text,
      completions: window.completions || {},
      onChange: (t) => window.changes.push(t),
    });
  }, DRIVER);
  check("the editor shows the text", await page.evaluate(() => window.ed.text()) === DRIVER);
  const colours = await page.evaluate(() => {
    const spans = [...document.querySelectorAll(".cm-content span")];
    const keyword = spans.find((s) => s.textContent === "function");
    const line = document.querySelector(".cm-line");
    return { keyword: keyword && getComputedStyle(keyword).color, plain: getComputedStyle(line).color };
  });
  check("Lua highlighting: a keyword coloured apart from the text",
    colours.keyword && colours.keyword !== colours.plain, JSON.stringify(colours));

  // typing "car:se" at the end of line 2 offers car:'s completions
  await page.evaluate(() => {
    const line = window.ed.view.state.doc.line(2);
    window.ed.view.dispatch({ selection: { anchor: line.to } });
    window.ed.view.focus();
  });
  await page.keyboard.press("Enter");
  await page.keyboard.type("  car:se");
  if (await passWhen(page, "typing car:se offers completions", () =>
    document.querySelectorAll(".cm-tooltip-autocomplete li").length > 0)) {
    const offered = await page.evaluate(() =>
      [...document.querySelectorAll(".cm-tooltip-autocomplete li")].map((li) => li.textContent));
    check("car:setSpeed with its parameters, not another prefix's (ctx:ahead)",
      offered.some((o) => o.startsWith("setSpeed") && o.includes("(speed, accel, respectLimit)")) &&
      !offered.some((o) => o.startsWith("ahead")), offered.join(" | "));
  }
  check("each change reaches onChange", await page.evaluate(() =>
    window.changes.length > 0 && window.changes[window.changes.length - 1] === window.ed.text()));

  await page.evaluate(() => window.ed.showErrors([{ line: 2,
    message: "drivers/alice.lua:2: attempt to call a nil value (method 'setSped')" }]));
  await passWhen(page, "an error shown at line 2 is marked there", () => {
    const marked = document.querySelector(".cm-lintRange-error");
    const line2 = document.querySelectorAll(".cm-line")[1];
    return marked && line2 && line2.contains(marked);
  });
  await page.screenshot({ path: png });
  check("screenshot written", true, png);
  await page.evaluate(() => window.ed.showErrors([]));
  await passWhen(page, "[] clears it", () => !document.querySelector(".cm-lintRange-error"));
  // (a page opened on a script's address asks for /favicon.ico, which the view does not serve)
  const requests = log.requests.filter((r) => !/\/favicon\.ico /.test(r));
  const errors = log.errors.filter((e) => !/404/.test(e) || requests.length > 0);
  check("no script errors or failed requests in the page", errors.length === 0 && requests.length === 0,
    [...errors, ...requests].join("; "));
} finally {
  await browser.close();
}
finish("editor_check");
