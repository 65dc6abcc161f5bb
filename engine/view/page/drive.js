// The controller page (docs/view.md "The controller page (/drive)"): a phone takes a seat of a
// run started with --humans N and drives its car over the race view's WebSocket (/ws):
//   → {"type":"seat","seat":N (0: any free),"player":"name","code":"123456"}
//                                                     ← {"type":"seat","seat":N} or error
//   → {"type":"drive","throttle":0..1,"lane":-1|0|1}            10 a second, and on each change
//   → {"type":"leave"}
// Pairing (docs/view.md "Pairing"): off loopback the engine takes a seat only with the join
// code. The page reads it from its address (/drive?code=…), keeps it for the tab (so a
// reconnection pairs again), opens /ws?code=… and sends it with every seat message; a page
// without it asks for it (#pair).
// The engine stops the car when this page goes silent for 1 s or disconnects; the page itself
// returns the throttle to 0 whenever the finger leaves the bar (dead man's handle).
//
// Stable DOM hooks (tests/view/drive_check.mjs relies on them):
//   #connection                      "live" when connected, "connection lost" when not
//   #notice                          what went wrong (driving is off, seat taken, …); hidden if none
//   #notice[data-kind]               "off", "taken", "lost", "error"
//   #pick                            the seat picker (shown while no seat is held)
//   #seats button[data-number="N"]   one per seat; class `free` or `held`
//   #player                          the player's name
//   #any-seat                        takes the first free seat
//   #drive[data-seat="N"]            the controls, shown while seat N is held
//   #throttle[data-value]            the throttle bar (0..1 as sent); pointer events
//   #lane-left, #lane-right, #leave  buttons
//   #position, #lap, #gap, #speed    the car's place in the race
//   #race[data-phase]                what the race is for this player: "free" (no race), "scan",
//                                    "grid", "lights", "go" (the first 2 s of green), "held" (a
//                                    jump start waiting out its penalty), "racing", "finished"
//                                    (this car took the flag), "over" (the race ended without it)
//   #lights .light[.on|.go]          the start lights (during the lights and at GO)
//   #countdown                       the lights counting down (5 … 1), "GO", a penalty's seconds
//   #headline, #subline              "P2 · lap 3/5", "Finished — P1", what to do now
//   #controls[.off]                  lane buttons and throttle; `off` (disabled) while the race
//                                    drives the car (scan, grid); hidden once the flag has fallen
//   #result, #standings li[.me]      the race's order after the flag (this player's row: `me`)
//   #pair, #code, #pair-go           asks for the join code when the engine wants one
"use strict";

const HEARTBEAT_MS = 100;     // 10 drive messages a second keep the seat live
const MIN_GAP_MS = 34;        // and at most ~30 a second with changes (the server allows 40)
const GO_SECONDS = 2;         // "GO" stays up this long after green

const $ = (sel) => document.querySelector(sel);
const page = {
  socket: null,
  live: false,
  seats: [],          // the feed's seats
  cars: new Map(),    // number → car
  race: null,
  time: null,         // the engine's time in the last message (s), and when it came (ms)
  timeAt: 0,
  seat: null,         // the seat number this page holds
  after: null,        // the seat whose result stays shown after the engine went (the run ended)
  armed: true,        // the throttle drives (false while the race drives the car, or after it)
  wanted: null,       // the seat to take again after a reconnection
  asked: null,        // the seat last asked for (taken again once the code is given)
  throttle: 0,
  lastSent: 0,
  pending: null,      // a timer for a change sent a little later
  heartbeat: null,
  code: pitwallJoinCode(),   // the join code from the address or this tab's memory; "" if none
};

function setCode(code) {
  page.code = code.trim();
  try { sessionStorage.setItem("pitwall.code", page.code); } catch { /* storage off */ }
}

// ---------------------------------------------------------------------------------------------
// Messages.

function send(msg) {
  if (page.socket && page.socket.readyState === WebSocket.OPEN) {
    page.socket.send(JSON.stringify(msg));
    return true;
  }
  return false;
}

function sendDrive(lane = 0) {
  if (page.seat == null) return;
  if (page.pending) { clearTimeout(page.pending); page.pending = null; }
  page.lastSent = performance.now();
  send({ type: "drive", throttle: Math.round(page.throttle * 1000) / 1000, lane });
}

// A change of the throttle: sent at once, or as soon as the rate allows.
function driveChanged() {
  const wait = page.lastSent + MIN_GAP_MS - performance.now();
  if (wait <= 0) sendDrive();
  else if (!page.pending) page.pending = setTimeout(() => { page.pending = null; sendDrive(); }, wait);
}

function startHeartbeat() {
  stopHeartbeat();
  page.heartbeat = setInterval(() => {
    if (performance.now() - page.lastSent >= HEARTBEAT_MS - 5) sendDrive();
  }, HEARTBEAT_MS);
}
function stopHeartbeat() {
  if (page.heartbeat) clearInterval(page.heartbeat);
  page.heartbeat = null;
  if (page.pending) clearTimeout(page.pending);
  page.pending = null;
}

function playerName() {
  return $("#player").value.trim().slice(0, 24);
}

function takeSeat(number) {
  try { localStorage.setItem("pitwall.player", $("#player").value); } catch { /* private mode */ }
  page.asked = number;
  const msg = { type: "seat", seat: number, player: playerName() };
  if (page.code) msg.code = page.code;
  send(msg);
}

function holding(number) {
  page.seat = number;
  page.wanted = number;
  page.after = null;
  setThrottle(0);
  notice(null);
  startHeartbeat();
  sendDrive();
  render();
}

function letGo() {
  page.seat = null;
  stopHeartbeat();
  setThrottle(0, false);
  render();
}

// ---------------------------------------------------------------------------------------------
// Showing.

function notice(text, kind = "error") {
  const el = $("#notice");
  el.hidden = !text;
  el.textContent = text || "";
  el.dataset.kind = text ? kind : "";
  el.classList.toggle("info", kind === "info");
}

function carName(number) {
  const seat = page.seats.find((s) => s.number === number);
  const car = page.cars.get(number);
  return (seat && seat.car) || (car && car.name) || `car ${number}`;
}

function renderSeats() {
  const list = $("#seats");
  const want = page.seats.map((s) => s.number).join(",");
  if (list.dataset.numbers !== want) {
    list.textContent = "";
    for (const s of page.seats) {
      const li = document.createElement("li");
      const b = document.createElement("button");
      b.type = "button";
      b.dataset.number = s.number;
      b.innerHTML = '<span class="seat-number"></span><span class="swatch"></span>' +
        '<span class="seat-car"></span><span class="seat-state"></span>';
      b.addEventListener("click", () => takeSeat(s.number));
      li.append(b);
      list.append(li);
    }
    list.dataset.numbers = want;
  }
  for (const s of page.seats) {
    const b = list.querySelector(`button[data-number="${s.number}"]`);
    const car = page.cars.get(s.number);
    b.style.setProperty("--car", (car && car.color) || "#888");
    b.querySelector(".seat-number").textContent = s.number;
    b.querySelector(".seat-car").textContent = carName(s.number);
    b.querySelector(".seat-state").textContent = s.held
      ? `${s.player || s.holder || "taken"}${s.live ? "" : " (no input)"}` : "free";
    b.classList.toggle("free", !s.held);
    b.classList.toggle("held", !!s.held);
  }
  $("#any-seat").disabled = !page.seats.some((s) => !s.held);
}

function fmtGap(row) {
  if (!row) return "–";
  if (row.lapsBehind > 0) return `+${row.lapsBehind} lap${row.lapsBehind > 1 ? "s" : ""}`;
  if (row.gap == null) return "–";
  return row.gap === 0 ? "leader" : `+${Number(row.gap).toFixed(1)}`;
}

// Seconds as the race's board writes them: 12.345, 1:02.345.
function fmtTime(s) {
  if (typeof s !== "number" || !Number.isFinite(s)) return "–";
  if (s < 60) return s.toFixed(3);
  const m = Math.floor(s / 60);
  return `${m}:${(s - 60 * m).toFixed(3).padStart(6, "0")}`;
}

// The engine's time now (s): the last message's, moved on by this page's clock; null if unknown.
function engineNow() {
  return page.time == null ? null : page.time + (performance.now() - page.timeAt) / 1000;
}

function rowsOf(race) {
  return race && Array.isArray(race.rows) ? race.rows : [];
}

// "P2 · lap 3/5" (a race of laps), "P2 · lap 3" (a timed one).
function placeLine(race, row) {
  if (!row || row.position == null) return race.title || "Racing";
  const lap = row.lap ? ` · lap ${row.lap}${race.laps ? `/${race.laps}` : ""}` : "";
  return `P${row.position}${lap}`;
}

function gapLine(race, row) {
  if (!row) return race.status || "";
  const rows = rowsOf(race);
  const tail = race.seconds && race.status ? ` · ${race.status}` : "";
  if (row.position === 1) return `Leading${rows.length > 1 ? ` ${rows.length} cars` : ""}${tail}`;
  if (row.lapsBehind > 0) return `${fmtGap(row)} behind the leader${tail}`;
  if (row.gap != null) return `+${Number(row.gap).toFixed(1)} s behind the leader${tail}`;
  return tail.slice(3);
}

// What the race is for the player of seat `n`, from the feed's race (docs/view.md "race"):
// {phase, lights: [k lit of N] | null, countdown, headline, subline, armed, over}.
function racePicture(n) {
  const race = page.race;
  if (!race || typeof race !== "object") {
    return { phase: "free", headline: "Free driving", armed: true,
      subline: "No race is running: the throttle drives your car." };
  }
  const rows = rowsOf(race);
  const row = rows.find((r) => r.number === n) || null;
  const now = engineNow();
  const penalty = typeof race.penalty === "number" ? race.penalty : 5;
  const phase = String(race.phase || "");
  if (row && row.finished) {
    const laps = row.laps != null ? `${row.laps} lap${row.laps === 1 ? "" : "s"}` : "";
    const time = row.totalTime != null ? `${laps ? `${laps} in ` : ""}${fmtTime(row.totalTime)} s` : laps;
    const best = row.bestLap != null ? `best lap ${fmtTime(row.bestLap)} s` : "";
    const more = phase === "done" ? "" : "the others are still racing";
    return { phase: "finished", headline: `Finished — P${row.position}`, armed: false, over: true,
      subline: [time, best, more].filter(Boolean).join(" · ") };
  }
  switch (phase) {
    case "scan":
      return { phase: "scan", headline: "Scan lap", armed: false,
        subline: "The cars learn the track. Hands off: the race drives your car." };
    case "grid":
      return { phase: "grid", headline: "To the grid", armed: false,
        subline: "The race drives your car to its place on the grid." };
    case "lights": {
      const count = Math.max(1, Math.min(12, Number(race.lights) || 5));
      const lit = Math.max(0, Math.min(count, Number(race.light) || 0));
      const jumped = row && row.falseStart;
      return { phase: "lights", lights: [lit, count], armed: true,
        countdown: lit > 0 ? String(count - lit + 1) : "",
        headline: jumped ? "Jump start!" : lit > 0 ? "Wait for green" : "Get ready",
        subline: jumped ? `You moved before green: you start ${penalty} s after it.`
          : `Go on green. Move before it and you are held ${penalty} s.` };
    }
    case "racing": {
      const green = typeof race.green === "number" ? race.green : null;
      if (row && row.falseStart && green != null && now != null && now < green + penalty) {
        return { phase: "held", headline: "Jump start!", armed: true,
          countdown: String(Math.max(1, Math.ceil(green + penalty - now))),
          subline: `You moved before green: held ${penalty} s at the line.` };
      }
      const go = green != null && now != null && now - green < GO_SECONDS;
      return { phase: go ? "go" : "racing", headline: placeLine(race, row), armed: true,
        lights: go ? [-1, Math.max(1, Math.min(12, Number(race.lights) || 5))] : null,
        countdown: go ? "GO" : "",
        subline: [row && row.falseStart ? `Jump start: held ${penalty} s.` : "", gapLine(race, row)]
          .filter(Boolean).join(" ") };
    }
    case "ending":
    case "done":
      return { phase: "over", armed: false, over: true,
        headline: row && row.position != null ? `Race over — P${row.position}` : "Race over",
        subline: !row ? (phase === "done" ? "Results" : "")
          : /disconnected/.test(row.status || "") ? "You did not finish (the car disconnected)."
            : "You did not finish." };
    default:
      return { phase: phase || "free", headline: race.title || phase, subline: race.status || "",
        armed: true };
  }
}

function renderLights(lights) {
  const el = $("#lights");
  el.hidden = !lights;
  if (!lights) return;
  const [lit, count] = lights;
  if (el.children.length !== count) {
    el.textContent = "";
    for (let k = 0; k < count; k++) {
      const light = document.createElement("span");
      light.className = "light";
      el.append(light);
    }
  }
  [...el.children].forEach((light, k) => {
    light.classList.toggle("on", lit >= 0 && k < lit);
    light.classList.toggle("go", lit < 0);
  });
  el.setAttribute("aria-label", lit < 0 ? "start lights: green" : `start lights: ${lit} of ${count} on`);
}

function renderStandings(n, finished) {
  const race = page.race || {};
  const rows = rowsOf(race);
  $("#result-title").textContent = race.phase === "done" ? "Results" : "The race so far";
  const list = $("#standings");
  list.textContent = "";
  for (const r of rows) {
    const li = document.createElement("li");
    li.classList.toggle("me", r.number === n);
    const car = page.cars.get(r.number);
    li.style.setProperty("--car", (car && car.color) || "#888");
    let time;
    if (r.finished && r.position === 1) time = r.totalTime != null ? `${fmtTime(r.totalTime)} s` : "winner";
    else if (r.finished) time = r.lapsBehind > 0 || r.gap == null ? fmtGap(r) : `+${fmtTime(r.gap)}`;
    else if (race.phase === "done" || race.phase === "ending") time = "DNF";
    else time = r.lap ? `lap ${r.lap}` : "–";
    const who = r.player ? `${r.player} · ${r.car}` : `${r.car || `car ${r.number}`}${r.driver ? ` (${r.driver})` : ""}`;
    li.innerHTML = '<span class="pos"></span><span class="swatch"></span><span class="who"></span>' +
      '<span class="time"></span>';
    li.querySelector(".pos").textContent = `P${r.position}`;
    li.querySelector(".who").textContent = who;
    li.querySelector(".time").textContent = time;
    list.append(li);
  }
  $("#result").dataset.finished = finished ? "true" : "false";
}

function renderDriving() {
  const n = page.seat ?? page.after;
  $("#drive").dataset.seat = n;
  $("#seat-label").textContent = `${n} · ${carName(n)}`;
  const car = page.cars.get(n);
  $("#seat-swatch").style.setProperty("--car", (car && car.color) || "#888");
  const rows = rowsOf(page.race);
  const row = rows.find((r) => r.number === n);
  $("#position").textContent = row && row.position != null ? `${row.position}/${rows.length}` : "–";
  const lap = row ? row.lap : car ? car.lap : null;
  const laps = page.race && page.race.laps;
  $("#lap").textContent = lap == null ? "–" : laps ? `${lap}/${laps}` : String(lap);
  $("#gap").textContent = fmtGap(row);
  $("#speed").textContent = car && car.speed != null ? Math.round(car.speed) : "–";

  const p = racePicture(n);
  const box = $("#race");
  box.dataset.phase = p.phase;
  renderLights(p.lights);
  $("#countdown").hidden = !p.countdown;
  $("#countdown").textContent = p.countdown || "";
  $("#headline").textContent = p.headline || "";
  $("#subline").textContent = p.subline || "";
  // after the flag: no throttle, the result in its place
  $("#controls").hidden = !!p.over;
  $("#hint").hidden = !!p.over;
  $("#result").hidden = !p.over;
  if (p.over) renderStandings(n, p.phase === "finished");
  arm(p.armed && !p.over && page.seat != null);
  $("#hint").textContent = p.phase === "scan" || p.phase === "grid"
    ? "The throttle wakes up for the lights." : p.phase === "lights"
      ? "Hands off the bar until green!" : "Hold the bar and slide up to go faster; let go to stop.";
  $("#leave").hidden = page.seat == null;
}

function render() {
  const off = page.live && page.seats.length === 0 && page.after == null;
  $("#pick").hidden = !page.live || off || page.seat != null || page.after != null;
  $("#drive").hidden = page.seat == null && page.after == null;
  if (off) {
    notice("Driving is off in this run: start pitwall with --humans N to open cars to phones.", "off");
    return;
  }
  if ($("#notice").dataset.kind === "off") notice(null);
  if (page.seat != null || page.after != null) renderDriving();
  else renderSeats();
}

// ---------------------------------------------------------------------------------------------
// The throttle: a tall bar; the finger's height on it is the throttle. Letting go (pointer up,
// cancelled, captured away, the page hidden) is 0.

function setThrottle(value, send = true) {
  const v = Math.min(1, Math.max(0, value));
  const changed = v !== page.throttle;
  page.throttle = v;
  const bar = $("#throttle");
  bar.dataset.value = String(Math.round(v * 1000) / 1000);
  bar.setAttribute("aria-valuenow", String(Math.round(v * 100)));
  $("#throttle-fill").style.height = `${v * 100}%`;
  $("#throttle-value").textContent = Math.round(v * 100);
  if (changed && send) driveChanged();
}

// The throttle takes input only while it drives the car: not while the race drives it (the scan
// lap, the drive to the grid) nor after the flag. Disarmed, a finger on it lets go (0).
function arm(on) {
  if (on === page.armed) return;
  page.armed = on;
  $("#controls").classList.toggle("off", !on);
  $("#throttle").setAttribute("aria-disabled", String(!on));
  $("#lane-left").disabled = !on;
  $("#lane-right").disabled = !on;
  if (!on) {
    if (finger != null) {
      try { bar.releasePointerCapture(finger); } catch { /* not captured */ }
      finger = null;
      bar.classList.remove("held");
    }
    setThrottle(0);
  }
}

function fromPointer(ev) {
  const r = $("#throttle").getBoundingClientRect();
  return (r.bottom - ev.clientY) / r.height;
}

const bar = $("#throttle");
let finger = null;
bar.addEventListener("pointerdown", (ev) => {
  ev.preventDefault();
  if (finger != null || !page.armed) return;
  finger = ev.pointerId;
  try { bar.setPointerCapture(ev.pointerId); } catch { /* not capturable: moves still arrive */ }
  bar.classList.add("held");
  setThrottle(fromPointer(ev));
});
bar.addEventListener("pointermove", (ev) => {
  if (ev.pointerId === finger) setThrottle(fromPointer(ev));
});
const release = (ev) => {
  if (ev.pointerId !== finger) return;
  finger = null;
  bar.classList.remove("held");
  setThrottle(0);
};
for (const type of ["pointerup", "pointercancel", "lostpointercapture"]) bar.addEventListener(type, release);
bar.addEventListener("contextmenu", (ev) => ev.preventDefault());
// (touch-action: none says it to browsers that read it; older mobile Safari wants it told)
for (const type of ["touchstart", "touchmove"])
  bar.addEventListener(type, (ev) => { if (ev.cancelable) ev.preventDefault(); }, { passive: false });
// keys for a desk: up/down in tenths, held; 0 on release of the last key
bar.addEventListener("keydown", (ev) => {
  if (!page.armed) return;
  if (ev.key === "ArrowUp") setThrottle(page.throttle + 0.1);
  else if (ev.key === "ArrowDown") setThrottle(page.throttle - 0.1);
  else return;
  ev.preventDefault();
});
bar.addEventListener("blur", () => { if (finger == null) setThrottle(0); });
document.addEventListener("visibilitychange", () => {
  if (document.hidden) { finger = null; bar.classList.remove("held"); setThrottle(0); }
});

$("#lane-left").addEventListener("click", () => sendDrive(-1));
$("#lane-right").addEventListener("click", () => sendDrive(1));
$("#leave").addEventListener("click", () => {
  send({ type: "leave" });
  page.wanted = null;
  letGo();
});
$("#any-seat").addEventListener("click", () => takeSeat(0));
try { $("#player").value = localStorage.getItem("pitwall.player") || ""; } catch { /* private mode */ }

// ---------------------------------------------------------------------------------------------
// The feed.

function takeFeed(msg) {
  if (typeof msg.time === "number") { page.time = msg.time; page.timeAt = performance.now(); }
  if (Array.isArray(msg.cars)) for (const c of msg.cars) page.cars.set(c.number, c);
  if (msg.race !== undefined) page.race = msg.race;
  if (msg.seats !== undefined) page.seats = Array.isArray(msg.seats) ? msg.seats : [];
  // our seat lost to the engine (a release we did not ask for): back to picking
  if (page.seat != null) {
    const s = page.seats.find((x) => x.number === page.seat);
    if (!s || !s.held) {
      const lost = page.seat;
      letGo();
      page.wanted = null;
      notice(`Seat ${lost} was freed by the engine: pick a car again.`);
    }
  }
}

function setConnection(live) {
  page.live = live;
  const el = $("#connection");
  el.textContent = live ? "live" : "connection lost";
  el.className = `connection ${live ? "live" : "gone"}`;
}

function connect() {
  const query = page.code ? `?code=${encodeURIComponent(page.code)}` : "";
  const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws${query}`);
  page.socket = ws;
  let retried = false;
  const retry = () => {
    if (retried) return;
    retried = true;
    if (page.socket === ws) page.socket = null;
    const held = page.seat;
    // a race that was over for this player: its result stays up (the run has likely ended)
    const over = held != null && racePicture(held).over;
    letGo();  // the engine has freed the seat and stops the car
    if (over) page.after = held;
    setConnection(false);
    notice(over ? "The race engine has gone: the race is over. Reconnecting…"
      : held != null ? `Connection lost: car ${held} is stopping. Reconnecting…`
        : page.after != null ? "The race engine has gone: the race is over. Reconnecting…"
          : "Connection lost: the race engine is not reachable. Reconnecting…", "lost");
    render();
    setTimeout(connect, 1000);
  };
  ws.onopen = () => { /* the state comes first */ };
  ws.onmessage = (ev) => {
    let msg;
    try { msg = JSON.parse(ev.data); } catch { return; }
    if (msg.type === "state") {
      page.cars = new Map();
      page.seats = [];
      page.after = null;  // a new state is the truth: no result of before kept up
      takeFeed(msg);
      const wasLost = !page.live;
      setConnection(true);
      if (wasLost && $("#notice").dataset.kind === "lost") notice(null);
      // taken again after a reconnection, at throttle 0
      if (page.wanted != null && page.seat == null && page.seats.length) takeSeat(page.wanted);
      render();
    } else if (msg.type === "update") {
      takeFeed(msg);
      render();
    } else if (msg.type === "seat") {
      holding(msg.seat);
    } else if (msg.type === "paired") {
      $("#pair").hidden = true;
    } else if (msg.type === "error") {
      const text = String(msg.message || "refused");
      if (/join code/.test(text)) $("#pair").hidden = false;
      const taken = /is held by|every seat is taken/.test(text);
      if (taken && page.seat == null) page.wanted = null;
      notice(taken ? `Seat taken: ${text}` : text, taken ? "taken" : /driving is off/.test(text) ? "off" : "error");
    }
  };
  ws.onclose = retry;
  ws.onerror = () => { retry(); try { ws.close(); } catch { /* already closed */ } };
}

$("#code").value = page.code;
$("#pair").addEventListener("submit", (ev) => {
  ev.preventDefault();
  setCode($("#code").value);
  takeSeat(page.asked ?? 0);
});

setThrottle(0, false);
// the countdowns and "GO" move on between messages
setInterval(() => { if (page.seat != null) renderDriving(); }, 250);
connect();
