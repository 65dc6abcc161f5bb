// Shared by the checks in a browser (tests/view/browser_check.mjs, tests/view/drive_check.mjs; the
// tests in tests/integration copy it beside them): their options, the PASS/FAIL lines and their
// count, waits in a page with a deadline, the browser launched with no network but loopback, and
// a page's script errors and failed requests.
import puppeteer from "puppeteer-core";

// The deadline of every wait (--timeout), and how often a wait looks again in the page.
export const settings = { timeoutSeconds: 30, timeoutMs: 30000, polling: 50 };

// parseArgs(tool, synopsis, options, positionals): the options and positional arguments of
// process.argv. `options` maps "--name" to [key, parse] for an option with a value (parse: Number,
// String) or to [key] for a flag (true when given); --timeout SECONDS (default 30) and
// --chromium PATH (default $CHROMIUM or /usr/bin/chromium) are always known. `positionals` is how
// many positional arguments there must be and what they are ("give ..."). Wrong use prints the
// usage and exits with status 2; so does usage(message), returned for further checks.
export function parseArgs(tool, synopsis, options, [count, what]) {
  const usage = (message) => {
    if (message) console.error(`${tool}: ${message}`);
    console.error(`usage: node ${tool}.mjs ${synopsis}`);
    process.exit(2);
  };
  const known = { "--timeout": ["timeout", Number], "--chromium": ["chromium", String], ...options };
  const opts = { timeout: 30, chromium: process.env.CHROMIUM || "/usr/bin/chromium" };
  const positional = [];
  const args = process.argv.slice(2);
  for (let i = 0; i < args.length; i++) {
    const a = args[i];
    if (!a.startsWith("--")) { positional.push(a); continue; }
    if (!known[a]) usage(`unknown option ${a}`);
    const [key, parse] = known[a];
    if (!parse) opts[key] = true;
    else if (i + 1 < args.length) opts[key] = parse(args[++i]);
    else usage(`${a} needs a value`);
  }
  if (positional.length !== count) usage(what);
  if (!(opts.timeout > 0)) usage("--timeout takes seconds > 0");
  settings.timeoutSeconds = opts.timeout;
  settings.timeoutMs = opts.timeout * 1000;
  return { opts, positional, usage };
}

let failures = 0;
export function pass(name, detail) { console.log(`PASS: ${name}${detail ? ` (${detail})` : ""}`); }
export function fail(name, detail) { failures++; console.log(`FAIL: ${name}${detail ? `: ${detail}` : ""}`); }
export function check(name, ok, detail) { (ok ? pass : fail)(name, detail); return ok; }

// The last line: all passed or how many failed; exit status 1 when a check failed.
export function finish(tool) {
  console.log(failures === 0 ? `${tool}: all passed` : `${tool}: ${failures} check(s) failed`);
  process.exit(failures === 0 ? 0 : 1);
}

// Waits for fn(arg) in the page; a timeout is a FAIL with `name` said, not an exception.
export async function waitFor(page, name, fn, arg) {
  try {
    await page.waitForFunction(fn, { timeout: settings.timeoutMs, polling: settings.polling }, arg);
    return true;
  } catch (e) {
    fail(name, `not within ${settings.timeoutSeconds} s (${String(e.message).split("\n")[0]})`);
    return false;
  }
}

// waitFor, and a PASS named `name` when fn came true.
export async function passWhen(page, name, fn, arg) {
  const ok = await waitFor(page, name, fn, arg);
  if (ok) pass(name);
  return ok;
}

// Headless Chromium at `chromium`, or Firefox ESR at `firefox` (through WebDriver BiDi), with no
// network but loopback: no updates, no telemetry, no first-run pages. A browser that does not
// start is a FAIL and exit status 1.
// `allow`: hosts besides loopback that Chromium may resolve (a LAN address of this machine).
export async function launch({ chromium, firefox, viewport, allow = [] }) {
  try {
    if (firefox) {
      return await puppeteer.launch({
        browser: "firefox",
        executablePath: firefox,
        headless: true,
        defaultViewport: viewport,
        extraPrefsFirefox: { "network.proxy.type": 0, "app.update.enabled": false,
          "datareporting.policy.dataSubmissionEnabled": false, "toolkit.telemetry.enabled": false,
          "browser.shell.checkDefaultBrowser": false, "network.captive-portal-service.enabled": false,
          "network.connectivity-service.enabled": false },
        timeout: settings.timeoutMs,
      });
    }
    return await puppeteer.launch({
      executablePath: chromium,
      headless: true,  // the new headless mode
      args: [
        "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
        "--no-first-run", "--no-default-browser-check", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--disable-extensions",
        // pages side by side (two phones in one browser): no page's timers slowed as a background tab's
        "--disable-background-timer-throttling", "--disable-renderer-backgrounding",
        "--disable-backgrounding-occluded-windows",
        "--host-resolver-rules=MAP * ~NOTFOUND, EXCLUDE localhost, EXCLUDE 127.0.0.1" +
          allow.map((h) => `, EXCLUDE ${h}`).join(""),
      ],
      defaultViewport: viewport,
      timeout: settings.timeoutMs,
    });
  } catch (e) {
    fail(`${firefox ? "firefox" : "chromium"} starts`, `${firefox || chromium}: ${e.message.split("\n")[0]}`);
    process.exit(1);
  }
}

// Collects the page's script errors (uncaught, or logged as errors; a WebSocket that cannot
// connect is no error) in log.errors and its failed requests (WebSockets aside) and HTTP errors in
// log.requests, each led by `who` when given.
export function watchPage(page, log, who) {
  const by = who ? `${who}: ` : "";
  page.on("pageerror", (e) => log.errors.push(`${by}${String(e.message || e).split("\n")[0]}`));
  page.on("console", (m) => {
    if (m.type() === "error" && !/WebSocket|ERR_CONNECTION_REFUSED/.test(m.text()))
      log.errors.push(`${by}console: ${m.text()}`);
  });
  page.on("requestfailed", (r) => {
    if (!r.url().startsWith("ws")) log.requests.push(`${by}${r.url()} ${r.failure()?.errorText}`);
  });
  page.on("response", (r) => { if (r.status() >= 400) log.requests.push(`${by}${r.url()} HTTP ${r.status()}`); });
}
