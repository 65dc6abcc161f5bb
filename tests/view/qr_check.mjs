// The join code's QR as a phone's camera sees it (docs/view.md "Pairing"): the race view, opened
// on the engine's machine by a loopback address, shows the controller page's address as a QR
// code; a screenshot of it is decoded by a real decoder (Debian's zbarimg), and the address it
// carries is opened as a phone would: on a non-loopback address of the machine, paired by the
// code it carries.
//
//   node qr_check.mjs VIEW-URL CODE QR.png [--timeout SECONDS] [--chromium PATH]
//
// Checks: the QR is shown; zbarimg decodes it to http://ADDRESS:PORT/drive?code=CODE with the
// code the terminal printed and a non-loopback address of this machine; that address opens the
// controller page, paired (the seat picker, no question for the code). Writes QR.png (the
// screenshot decoded) and QR-drive.png (the page it opened). One PASS/FAIL line per check; exit
// status 1 when a check failed, 2 on bad arguments.
import { execFileSync } from "node:child_process";
import { networkInterfaces } from "node:os";
import { check, fail, finish, launch, parseArgs, pass, passWhen, settings, waitFor } from "./check_lib.mjs";

const { opts, positional: [viewUrl, code, png] } = parseArgs("qr_check",
  "VIEW-URL CODE QR.png [--timeout SECONDS] [--chromium PATH]", {},
  [3, "give the view's URL, the join code the terminal printed and the screenshot's path"]);

// this machine's own addresses (not loopback), which the QR's address must be one of
const mine = Object.values(networkInterfaces()).flat().filter((a) => !a.internal)
  .map((a) => (a.family === "IPv6" ? `[${a.address}]` : a.address));
const browser = await launch({ chromium: opts.chromium, allow: mine,
  viewport: { width: 1600, height: 1000, deviceScaleFactor: 2 } });
try {
  const page = await browser.newPage();
  await page.goto(viewUrl, { waitUntil: "load", timeout: settings.timeoutMs });
  if (await waitFor(page, "the QR is shown", () => {
    const qr = document.querySelector("#join-qr");
    return qr && !qr.hidden && qr.complete && qr.naturalWidth > 0;
  })) {
    pass("the QR is shown");
    const box = await (await page.$("#join-qr")).boundingBox();
    await page.screenshot({ path: png, clip: { x: box.x, y: box.y, width: box.width, height: box.height } });
    pass("screenshot written", png);
    let decoded = "";
    try {
      decoded = execFileSync("zbarimg", ["--quiet", "--raw", "-Sdisable", "-Sqrcode.enable", png],
        { encoding: "utf8", timeout: settings.timeoutMs }).trim();
    } catch (e) {
      fail("zbarimg decodes the QR", (e.stderr || e.message || "").toString().trim());
    }
    if (decoded) {
      pass("zbarimg decodes the QR", decoded);
      const u = new URL(decoded);
      check("it carries the join code", u.searchParams.get("code") === code && u.pathname === "/drive",
        `${u.pathname}?code=${u.searchParams.get("code")}, the terminal printed ${code}`);
      check("on a non-loopback address of this machine", mine.includes(u.hostname),
        `${u.hostname}; this machine's: ${mine.join(", ")}`);
      const phone = await browser.newPage();
      await phone.setViewport({ width: 390, height: 844, deviceScaleFactor: 1, isMobile: true, hasTouch: true });
      const r = await phone.goto(decoded, { waitUntil: "load", timeout: settings.timeoutMs });
      check("the address opens the controller page", r && r.ok(), `${decoded} HTTP ${r && r.status()}`);
      await passWhen(phone, "paired by it: seats to pick, no question for the code",
        () => document.querySelectorAll("#seats button[data-number]").length > 0 &&
          !document.querySelector("#pick").hidden && (document.querySelector("#pair")?.hidden ?? true));
      const drivePng = png.replace(/(\.png)?$/i, "-drive.png");
      await phone.screenshot({ path: drivePng });
      pass("screenshot written", drivePng);
    }
  }
} catch (e) {
  fail("QR check ran", e.stack || String(e));
} finally {
  await browser.close().catch(() => {});
}
finish("QR check");
