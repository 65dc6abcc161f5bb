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
//   #pair, #code, #pair-go           asks for the join code when the engine wants one
"use strict";

const HEARTBEAT_MS = 100;     // 10 drive messages a second keep the seat live
const MIN_GAP_MS = 34;        // and at most ~30 a second with changes (the server allows 40)

const $ = (sel) => document.querySelector(sel);
const page = {
  socket: null,
  live: false,
  seats: [],          // the feed's seats
  cars: new Map(),    // number → car
  race: null,
  seat: null,         // the seat number this page holds
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

function renderDriving() {
  const n = page.seat;
  $("#drive").dataset.seat = n;
  $("#seat-label").textContent = `${n} · ${carName(n)}`;
  const car = page.cars.get(n);
  $("#seat-swatch").style.setProperty("--car", (car && car.color) || "#888");
  const rows = page.race && Array.isArray(page.race.rows) ? page.race.rows : [];
  const row = rows.find((r) => r.number === n);
  $("#position").textContent = row && row.position != null ? `${row.position}/${rows.length}` : "–";
  const lap = row ? row.lap : car ? car.lap : null;
  const laps = page.race && page.race.laps;
  $("#lap").textContent = lap == null ? "–" : laps ? `${lap}/${laps}` : String(lap);
  $("#gap").textContent = fmtGap(row);
  $("#speed").textContent = car && car.speed != null ? Math.round(car.speed) : "–";
}

function render() {
  const off = page.live && page.seats.length === 0;
  $("#pick").hidden = !page.live || off || page.seat != null;
  $("#drive").hidden = page.seat == null;
  if (off) {
    notice("Driving is off in this run: start pitwall with --humans N to open cars to phones.", "off");
    return;
  }
  if ($("#notice").dataset.kind === "off") notice(null);
  if (page.seat != null) renderDriving();
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

function fromPointer(ev) {
  const r = $("#throttle").getBoundingClientRect();
  return (r.bottom - ev.clientY) / r.height;
}

const bar = $("#throttle");
let finger = null;
bar.addEventListener("pointerdown", (ev) => {
  if (finger != null) return;
  finger = ev.pointerId;
  try { bar.setPointerCapture(ev.pointerId); } catch { /* not capturable: moves still arrive */ }
  bar.classList.add("held");
  setThrottle(fromPointer(ev));
  ev.preventDefault();
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
// keys for a desk: up/down in tenths, held; 0 on release of the last key
bar.addEventListener("keydown", (ev) => {
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
    letGo();  // the engine has freed the seat and stops the car
    setConnection(false);
    notice(held != null
      ? `Connection lost: car ${held} is stopping. Reconnecting…`
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
connect();
