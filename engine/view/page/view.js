// The race view (docs/view.md): reads the feed at ws://<host>/ws and draws the track, the cars,
// the leaderboard, the charts, the race's state and the event log. Plain JS, no build step;
// uPlot (vendor/uPlot.iife.min.js) draws the charts.
//
// Stable DOM hooks (tests/view/browser_check.mjs relies on them):
//   #track svg                      the track; road `path.road`, lanes `path.lane`,
//                                   finish line `#finish-line`
//   g.car-marker[data-number="N"]   one per car; contains `text.car-name` (the car's name);
//                                   `data-x` / `data-y`: where it is drawn, mm in the track
//                                   frame (y up), updated every animation frame;
//                                   class `off-track` when not placed on the track
//                                   (no position, delocalized, off the road), `disconnected`
//                                   when the car is not connected
//   #leaderboard tbody tr           one per car (race.rows when a race runs, else the cars)
//   #leaderboard td.delta           the live delta to the reference lap (the ghost's, else the
//                                   session's best or the track's personal best): "+0.123" behind, "-0.045" ahead; its
//                                   title names the lap; `data-delta` the number
//   g.car-marker.ghost              a ghost (sim.addGhost): drawn translucent
//   g.car-marker[data-number="view-ghost"]  the view's ghost (state.viewGhost): the reference
//                                   lap driven from the leader's last crossing; its title
//                                   names the lap (`data-follows`: the leader's number)
//   #compare-open, #lap-compare     "Compare laps…" and its dialog: #lap-a, #lap-b (options
//                                   "CAR:LAP"), #lap-compare-go; the answer in
//                                   #lap-compare-result (table.sections and svg.compare) and
//                                   #lap-compare-how. Two clicks on the lap-time chart pick A
//                                   and B and open it
//   #leaderboard td.link            the car's link: "down", else its RSSI and drops ("ok" when
//                                   nothing to tell); `data-drops`, and the whole story in
//                                   its title (connections, last drop, failed writes, stalls)
//   #race-phase                     the race's phase (scan, grid, lights, racing, ending, done)
//   #connection                     exactly "live" when connected, "engine gone" when not
//   #events li                      the event log, newest first
//   #lap-chart, #speed-chart        the uPlot charts
//   #replay                         replay controls, shown only when `replay` is non-null
//   #podium                         the first three over the track once the race is done
//                                   (li[data-position]), hidden before
//   #drive-link                     the link to the controller page (/drive), shown only when
//                                   the state has seats (a run with --humans N)
//   #join, #join-code, #join-url    the join code and the controller page's address with it,
//                                   shown to a browser on the engine's machine (or one that
//                                   came with the code) when the engine needs one
//   #join-qr                        that address as a QR code (vendor/qrcode.js,
//                                   qrcode-generator), for a phone's camera
//
// Pairing (docs/view.md "Pairing"): off loopback, replay controls need the join code too; the
// page takes it from its address (?code=…), keeps it for the tab and opens /ws?code=….
"use strict";

const SVG_NS = "http://www.w3.org/2000/svg";
const EXTRAPOLATE_MAX_S = 0.5;   // never guess further than this past the last position update
const SPEED_WINDOW_S = 60;
const SPEED_GAP_S = 2.5;         // more than this between two samples of a car: a gap (the feed
                                 // sends an update at least every second)
const EVENTS_MAX = 200;

// ---------------------------------------------------------------------------------------------
// Geometry: the same as engine/view/geometry.hpp. Frame: x right, y up, headings in degrees
// counter-clockwise from +x; offsets are mm right of the driving direction.

function pieceAngle(piece) {  // radians turned over the piece (signed, + left)
  return piece.turn && piece.radius ? (piece.turn * piece.length) / piece.radius : 0;
}

// Length of piece `p` along the lane at `offset`: curves are longer on the outside.
function laneLength(p, offset) {
  if (!p.turn || !p.radius) return p.length;
  return Math.abs(pieceAngle(p)) * (p.radius + p.turn * offset);
}

// The point `fraction` (0…1) along piece `index`, `offset` mm right of the centre line, and the
// heading there: {x, y, heading}.
function pointOnTrack(track, index, fraction, offset) {
  const p = track.pieces[index];
  const h = (p.heading * Math.PI) / 180;
  let cx, cy, hd;
  if (!p.turn || !p.radius) {
    cx = p.x + Math.cos(h) * p.length * fraction;
    cy = p.y + Math.sin(h) * p.length * fraction;
    hd = h;
  } else {
    // Centre of the curve: `radius` to the left (turn +1) or right (turn −1) of the start.
    const ox = p.x - p.turn * Math.sin(h) * p.radius;
    const oy = p.y + p.turn * Math.cos(h) * p.radius;
    const a = pieceAngle(p) * fraction;
    const dx = p.x - ox, dy = p.y - oy;
    cx = ox + dx * Math.cos(a) - dy * Math.sin(a);
    cy = oy + dx * Math.sin(a) + dy * Math.cos(a);
    hd = h + a;
  }
  // Right of the driving direction is (sin h, −cos h).
  return { x: cx + Math.sin(hd) * offset, y: cy - Math.cos(hd) * offset,
           heading: (hd * 180) / Math.PI };
}

// Moves `distance` mm along the lane at `offset` from (index, fraction); backwards when
// `reverse`. Returns {index, fraction}.
function advance(track, index, fraction, offset, distance, reverse) {
  const n = track.pieces.length;
  let guard = 4 * n + 4;
  while (distance > 1e-6 && guard-- > 0) {
    const len = Math.max(1, laneLength(track.pieces[index], offset));
    const left = (reverse ? fraction : 1 - fraction) * len;
    if (distance < left) {
      fraction += ((reverse ? -1 : 1) * distance) / len;
      break;
    }
    distance -= left;
    index = reverse ? (index - 1 + n) % n : (index + 1) % n;
    fraction = reverse ? 1 : 0;
  }
  return { index, fraction };
}

// Centre-line distance from the finish line to (index, fraction), 0 … lapLength.
function lapProgress(track, index, fraction) {
  let at = 0, finishAt = 0;
  const finishIdx = track.pieces.findIndex((p) => p.id === 34);
  for (let i = 0; i < track.pieces.length; i++) {
    if (i === index) at += track.pieces[i].length * fraction;
    else if (i < index) at += track.pieces[i].length;
    if (i <= finishIdx) finishAt += track.pieces[i].length;
  }
  const lap = track.lapLength || track.pieces.reduce((s, p) => s + p.length, 0);
  return (((at - finishAt) % lap) + lap) % lap;
}

// ---------------------------------------------------------------------------------------------
// State of the page: reset by every "state" message.

const view = {
  track: null, cars: new Map(), race: null, replay: null, source: "", events: [],
  time: 0,             // engine time of the last message
  receivedAt: 0,       // performance.now() when it came
  speeds: new Map(),   // number → [[t, speed], …] (the last 60 s)
  markers: new Map(),  // number → {g, body, x, y, heading, placed}
  lapChart: null, lapKey: "", speedChart: null, speedKey: "",
  chartsDirty: true,
};

const $ = (sel) => document.querySelector(sel);
function svgEl(tag, attrs, parent) {
  const el = document.createElementNS(SVG_NS, tag);
  for (const [k, v] of Object.entries(attrs || {})) el.setAttribute(k, v);
  if (parent) parent.appendChild(el);
  return el;
}
const fmtTime = (s) => (s == null ? "–" : s.toFixed(3));
const fmtMm = (v) => (v == null ? "–" : (v > 0 ? "+" : "") + Math.round(v));

// ---------------------------------------------------------------------------------------------
// The track.

let svg = null, carLayer = null;

function drawTrack() {
  const host = $("#track");
  host.textContent = "";
  svg = svgEl("svg", { preserveAspectRatio: "xMidYMid meet", role: "img" }, host);
  const t = view.track;
  if (!t || !t.pieces || !t.pieces.length) {
    svg.setAttribute("viewBox", "0 0 1000 400");
    svgEl("text", { x: 500, y: 200, class: "no-track", "text-anchor": "middle" }, svg)
      .textContent = "no track known yet";
    carLayer = svgEl("g", { class: "cars" }, svg);
    view.markers.clear();
    return;
  }
  svg.setAttribute("aria-label", `track ${t.name || ""}`);
  const b = t.bounds, m = 140;
  // Screen coordinates: y flipped (the feed's y is up).
  svg.setAttribute("viewBox",
    `${b.minX - m} ${-b.maxY - m} ${b.maxX - b.minX + 2 * m} ${b.maxY - b.minY + 2 * m}`);

  const line = (offset) => {
    const pts = [];
    t.pieces.forEach((p, i) => {
      const steps = p.turn ? 24 : 1;
      for (let s = i === 0 ? 0 : 1; s <= steps; s++) pts.push(pointOnTrack(t, i, s / steps, offset));
    });
    const first = pts[0], last = pts[pts.length - 1];
    const closed = Math.hypot(first.x - last.x, first.y - last.y) < 5;
    return pts.map((q, i) => `${i ? "L" : "M"}${q.x.toFixed(1)},${(-q.y).toFixed(1)}`).join("") +
      (closed ? "Z" : "");
  };
  const w = 2 * (t.roadHalfWidth || 96);
  const centre = line(0);
  svgEl("path", { class: "road-edge", d: centre, "stroke-width": w + 14 }, svg);
  svgEl("path", { class: "road", d: centre, "stroke-width": w }, svg);
  for (const o of t.lanes || []) svgEl("path", { class: "lane", d: line(o), "data-offset": o }, svg);
  // Piece joins: faint ticks across the road.
  t.pieces.forEach((p, i) => {
    const a = pointOnTrack(t, i, 0, -w / 2), c = pointOnTrack(t, i, 0, w / 2);
    svgEl("line", { class: "joint", x1: a.x, y1: -a.y, x2: c.x, y2: -c.y }, svg);
  });
  if (t.finish) {
    const f = t.finish, h = (f.heading * Math.PI) / 180;
    const rx = Math.sin(h), ry = -Math.cos(h);     // across the road (right of travel)
    const half = w / 2;
    const g = svgEl("g", { id: "finish-line" }, svg);
    const pts = { x1: f.x - rx * half, y1: -(f.y - ry * half), x2: f.x + rx * half, y2: -(f.y + ry * half) };
    svgEl("line", { ...pts, class: "finish-back" }, g);
    svgEl("line", { ...pts, class: "finish-check" }, g);
    const lx = f.x - rx * (half + 60), ly = f.y - ry * (half + 60);
    svgEl("text", { x: lx, y: -ly, class: "finish-label", "text-anchor": "middle",
                    "dominant-baseline": "middle" }, g).textContent = "FINISH";
  }
  carLayer = svgEl("g", { class: "cars" }, svg);
  view.markers.clear();
}

function markerFor(car) {
  let m = view.markers.get(car.number);
  if (m) return m;
  const g = svgEl("g", { class: "car-marker", "data-number": car.number }, carLayer);
  const body = svgEl("g", { class: "car-body" }, g);
  svgEl("rect", { x: -46, y: -26, width: 92, height: 52, rx: 16, class: "car-shape" }, body);
  svgEl("path", { d: "M20,-16 L44,0 L20,16 Z", class: "car-nose" }, body);
  svgEl("text", { class: "car-number", "text-anchor": "middle", "dominant-baseline": "central" }, g)
    .textContent = car.number;
  svgEl("text", { class: "car-name", y: -52, "text-anchor": "middle" }, g);
  m = { g, body, x: null, y: null, heading: 0, placed: false };
  view.markers.set(car.number, m);
  return m;
}

// A car that has not reported a position yet: connected, on the track as far as it says. Real
// cars report nothing until they move, and before the race they stand on the grid: the page
// draws them there (gridSpot), not as lost — also in the moment after green before their first
// report.
function waiting(c) {
  return c.x == null && c.positionTime == null && c.connected !== false && !c.delocalized &&
    c.onTrack !== false;
}

// Where a waiting car is drawn: behind the finish line in its lane, one car length and a gap
// apart in the order of the cars' numbers (the grid of docs/racing.md), so no two overlap.
function gridSpot(car) {
  const t = view.track;
  if (!t || !t.pieces || !t.pieces.length) return null;
  const queue = [...view.cars.values()].filter(waiting).sort((a, b) => a.number - b.number);
  const k = Math.max(0, queue.indexOf(car));
  const line = t.pieces.findIndex((p) => p.id === 34);
  const from = line >= 0 ? line : t.pieces.length - 1;
  const at = advance(t, from, 1, car.offset || 0, 100 + 170 * k, true);
  const p = pointOnTrack(t, at.index, at.fraction, car.offset || 0);
  p.moving = false;
  return p;
}

// Where the car is now: its last position update moved on by speed × time since (≤ 0.5 s).
function targetOf(car, now) {
  const t = view.track;
  if (waiting(car)) return gridSpot(car);
  if (!t || !t.pieces || !t.pieces.length || car.x == null || car.delocalized || !car.onTrack) {
    return car.x == null ? null : { x: car.x, y: car.y, heading: car.heading || 0, moving: false };
  }
  if (car.pieceIndex == null || !t.pieces[car.pieceIndex])
    return { x: car.x, y: car.y, heading: car.heading || 0, moving: false };
  // from where the feed estimated the car (`at`), else from its last report
  const from = car.at ?? car.positionTime ?? now;
  const dt = Math.min(EXTRAPOLATE_MAX_S, Math.max(0, now - from));
  const at = advance(t, car.pieceIndex, car.fraction || 0, car.offset || 0,
                     Math.max(0, car.speed || 0) * dt, !!car.reverse);
  const p = pointOnTrack(t, at.index, at.fraction, car.offset || 0);
  if (car.reverse) p.heading += 180;
  p.moving = true;
  return p;
}

// Engine time now, estimated from the last message and the wall clock (replays at their speed).
function engineNow() {
  let rate = 1;
  if (view.replay) rate = view.replay.paused ? 0 : view.replay.speed || 1;
  return view.time + ((performance.now() - view.receivedAt) / 1000) * rate;
}

// The view's ghost (docs/view.md "Ghosts and deltas") as a car the markers draw: the feed says
// where it is and how fast it goes there, and the page moves it on between updates as it moves
// the cars.
function viewGhostCar() {
  const g = view.viewGhost;
  if (!g) return null;
  return { number: "view-ghost", name: "ghost", color: "#888888", ghost: true, connected: true,
    onTrack: true, x: g.x, y: g.y, heading: g.heading, pieceIndex: g.pieceIndex,
    fraction: g.fraction, offset: g.offset, speed: g.speed, at: g.at, positionTime: g.at,
    label: g.label, follows: g.follows };
}

function drawnCars() {
  const ghost = viewGhostCar();
  return ghost ? [...view.cars.values(), ghost] : [...view.cars.values()];
}

let lastFrame = performance.now();
function frame(ts) {
  const dt = Math.min(0.1, Math.max(0, (ts - lastFrame) / 1000));
  lastFrame = ts;
  const now = engineNow();
  for (const car of drawnCars()) {
    if (!carLayer) break;
    const m = markerFor(car);
    const target = targetOf(car, now);
    const placed = !!target && car.x != null && car.onTrack !== false && !car.delocalized;
    if (target) {
      if (m.x == null || !m.placed || !placed) {
        m.x = target.x; m.y = target.y; m.heading = target.heading;
      } else {
        // Ease towards the target so a fresh update never makes the marker jump.
        const k = 1 - Math.exp(-dt * 18);
        const far = Math.hypot(target.x - m.x, target.y - m.y) > 400;
        m.x = far ? target.x : m.x + (target.x - m.x) * k;
        m.y = far ? target.y : m.y + (target.y - m.y) * k;
        let dh = ((target.heading - m.heading + 540) % 360) - 180;
        m.heading = far ? target.heading : m.heading + dh * k;
      }
    }
    m.placed = placed;
    m.g.classList.toggle("off-track", !placed && !waiting(car));
    m.g.classList.toggle("waiting", waiting(car));
    m.g.classList.toggle("disconnected", car.connected === false);
    m.g.classList.toggle("unseen", m.x == null);
    m.g.classList.toggle("ghost", !!car.ghost);
    if (m.x != null) {
      m.g.setAttribute("transform", `translate(${m.x.toFixed(1)},${(-m.y).toFixed(1)})`);
      m.body.setAttribute("transform", `rotate(${(-m.heading).toFixed(1)})`);
      m.g.dataset.x = m.x.toFixed(1);
      m.g.dataset.y = m.y.toFixed(1);
    }
  }
  placeLabels();
  requestAnimationFrame(frame);
}

// Names of cars close together must not cover each other: each name goes above its marker,
// else below, else further out, the first place free of the names placed before it.
const LABEL_PLACES = [-52, 88, -100, 136];   // the name's baseline, mm below the marker's centre
const LABEL_HEIGHT = 44;
function placeLabels() {
  const taken = [];
  const markers = [...view.markers.values()].filter((m) => m.x != null)
    .sort((a, b) => b.y - a.y || a.x - b.x);
  for (const m of markers) {
    const text = m.g.querySelector("text.car-name");
    if (m.labelText !== text.textContent) {
      m.labelText = text.textContent;
      m.labelWidth = (text.getComputedTextLength && text.getComputedTextLength()) ||
        23 * m.labelText.length;
    }
    const w = m.labelWidth + 12;
    let chosen = LABEL_PLACES[0];
    for (const dy of LABEL_PLACES) {
      const box = { l: m.x - w / 2, r: m.x + w / 2, t: -m.y + dy - LABEL_HEIGHT + 8, b: -m.y + dy + 8 };
      if (!taken.some((o) => box.l < o.r && o.l < box.r && box.t < o.b && o.t < box.b)) {
        chosen = dy;
        break;
      }
    }
    taken.push({ l: m.x - w / 2, r: m.x + w / 2, t: -m.y + chosen - LABEL_HEIGHT + 8, b: -m.y + chosen + 8 });
    if (m.labelY !== chosen) {
      m.labelY = chosen;
      text.setAttribute("y", chosen);
    }
  }
}

function syncMarkers() {
  const ghost = viewGhostCar();
  for (const [num, m] of view.markers) {
    if (!view.cars.has(num) && !(ghost && num === ghost.number)) {
      m.g.remove(); view.markers.delete(num);
    }
  }
  for (const car of view.cars.values()) {
    const m = markerFor(car);
    m.g.style.setProperty("--car", car.color || "#888");
    m.g.querySelector("text.car-name").textContent = car.name || `car ${car.number}`;
  }
  if (ghost) {
    const m = markerFor(ghost);
    m.g.style.setProperty("--car", ghost.color);
    m.g.querySelector("text.car-number").textContent = "";
    m.g.querySelector("text.car-name").textContent = "ghost";
    m.g.dataset.follows = ghost.follows;
    let title = m.g.querySelector("title");
    if (!title) title = svgEl("title", {}, m.g);
    if (title.textContent !== ghost.label) title.textContent = ghost.label;
  }
  const why = (c) => (c.connected === false ? "disconnected" : c.delocalized ? "delocalized"
    : c.onTrack === false ? "off the track" : c.x == null && !waiting(c) ? "no position yet" : "");
  const off = [...view.cars.values()].filter((c) => why(c));
  const el = $("#off-track");
  el.hidden = off.length === 0;
  el.textContent = off.length
    ? "Not on the track: " + off.map((c) => `${c.name || c.number} (${why(c)})`).join(", ") : "";
}

// ---------------------------------------------------------------------------------------------
// Leaderboard, race state, events.

function boardRows() {
  if (view.race && Array.isArray(view.race.rows) && view.race.rows.length) return view.race.rows;
  const t = view.track;
  const progress = (c) => (t && c.pieceIndex != null && t.pieces[c.pieceIndex]
    ? lapProgress(t, c.pieceIndex, c.fraction || 0) : -1);
  const cars = [...view.cars.values()].sort((a, b) =>
    (b.lap || 0) - (a.lap || 0) || progress(b) - progress(a) || a.number - b.number);
  return cars.map((c, i) => ({
    position: i + 1, number: c.number, car: c.name, driver: null, lap: c.lap || 0,
    lastLap: c.lastLap, bestLap: c.bestLap, gap: null, speed: c.speed, lane: c.offset,
  }));
}

// The feed's speed of the car (a car told to stop and silent shows 0 there), else the row's.
function speedOf(r, car) {
  const v = car.speed ?? r.speed;
  return v == null ? "–" : Math.round(v);
}

function renderBoard() {
  const tbody = $("#leaderboard tbody");
  const rows = boardRows();
  const best = Math.min(...rows.map((r) => r.bestLap ?? Infinity));
  while (tbody.rows.length > rows.length) tbody.deleteRow(-1);
  while (tbody.rows.length < rows.length) {
    const tr = tbody.insertRow();
    for (let i = 0; i < 11; i++) tr.insertCell();
  }
  rows.forEach((r, i) => {
    const tr = tbody.rows[i];
    const car = view.cars.get(r.number) || {};
    tr.dataset.number = r.number;
    tr.style.setProperty("--car", car.color || "#888");
    tr.classList.toggle("disconnected", car.connected === false);
    tr.classList.toggle("off-track", (car.x == null && !waiting(car)) || !!car.delocalized ||
      car.onTrack === false);
    tr.classList.toggle("finished", !!r.finished);
    let gap = "–";
    if (r.lapsBehind > 0) gap = `+${r.lapsBehind} lap${r.lapsBehind > 1 ? "s" : ""}`;
    else if (r.gap != null) gap = r.gap === 0 ? "leader" : `+${r.gap.toFixed(3)}`;
    const cells = [
      r.position ?? i + 1,
      `<span class="swatch"></span>${escapeHtml(r.car ?? car.name ?? `car ${r.number}`)}`,
      escapeHtml(r.player ? `${r.player} (${r.driver ?? "human"})` : (r.driver ?? "–")),
      r.lap ?? "–", fmtTime(r.lastLap), fmtTime(r.bestLap), gap,
      speedOf(r, car), fmtMm(r.lane),
    ];
    cells.forEach((c, k) => {
      const td = tr.cells[k];
      if (k === 1) { if (td.innerHTML !== c) td.innerHTML = c; } else if (td.textContent !== String(c)) td.textContent = c;
      if (k > 2 && k !== 1) td.className = "num";
    });
    tr.cells[5].classList.toggle("best", r.bestLap != null && r.bestLap === best);
    renderLink(tr.cells[9], car);
    renderDelta(tr.cells[10], car);
    tr.classList.toggle("ghost", !!car.ghost);
  });
}

// The Δ cell: the live delta to the reference lap (docs/view.md "Ghosts and deltas").
function renderDelta(td, car) {
  td.className = "num delta";
  const d = car.delta;
  const text = car.ghost ? "ghost" : d == null ? "–" : (d >= 0 ? "+" : "") + d.toFixed(3);
  if (td.textContent !== text) td.textContent = text;
  td.classList.toggle("behind", d != null && d > 0);
  td.classList.toggle("ahead", d != null && d < 0);
  td.title = d == null ? "" : `against ${car.deltaTo}`;
  if (d == null) delete td.dataset.delta; else td.dataset.delta = d;
}

// The Link cell: what a racer needs at a glance (down; RSSI; how often it dropped), and the rest
// in its title. A car of the feed without link health (an older engine) shows "–".
function renderLink(td, car) {
  const l = car.link;
  let text = "–", title = "";
  if (car.connected === false) {
    text = "down";
  } else if (l) {
    const parts = [];
    if (l.rssi != null) parts.push(`${l.rssi} dBm`);
    if (l.drops > 0) parts.push(`${l.drops} drop${l.drops > 1 ? "s" : ""}`);
    text = parts.join(" · ") || "ok";
  }
  if (l) {
    title = `${l.connects} connection${l.connects === 1 ? "" : "s"}, ${l.drops} drop${l.drops === 1 ? "" : "s"}` +
      (l.lastDrop ? ` (last: ${l.lastDrop})` : "") +
      `, ${l.writeFailures} failed write${l.writeFailures === 1 ? "" : "s"}, ${l.stalls} stall${l.stalls === 1 ? "" : "s"}` +
      (l.rssi != null ? `, RSSI ${l.rssi} dBm` : "") +
      (l.silences ? `, ${l.silences} silence${l.silences === 1 ? "" : "s"} (longest ${l.longestSilence} s)` : "") +
      (l.roundTrip != null ? `, round trip ${Math.round(l.roundTrip * 1000)} ms` : "");
  }
  td.className = "link";
  td.classList.toggle("troubled", car.connected === false || !!(l && (l.drops || l.writeFailures || l.stalls)));
  if (td.textContent !== text) td.textContent = text;
  if (td.title !== title) td.title = title;
  td.dataset.drops = l ? l.drops : "";
}

function escapeHtml(s) {
  return String(s).replace(/[&<>"']/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" }[c]));
}

function renderRace() {
  const r = view.race;
  const phase = $("#race-phase");
  // (a replay of a record without the race's lines: it is a replay, not "no race")
  phase.textContent = r ? r.phase || "" : view.replay ? "replay" : "no race";
  phase.className = `phase phase-${r ? r.phase : view.replay ? "replay" : "none"}`;
  $("#race-title").textContent = r ? r.title || "" : "";
  $("#race-status").textContent = r ? r.status || "" : "";
  const lights = $("#race-lights");
  lights.hidden = !(r && r.phase === "lights");
  if (!lights.hidden) {
    const on = r.light || 0, total = Math.max(5, on);
    if (lights.childElementCount !== total) {
      lights.textContent = "";
      for (let i = 0; i < total; i++) lights.appendChild(document.createElement("i"));
    }
    [...lights.children].forEach((el, i) => el.classList.toggle("on", i < on));
  }
  $("#source").textContent = view.source ? `· ${view.source}` : "";
  renderPodium(r);
  renderReplay();
}

// Over the track once a race is over: the first three, each with its driver and time (or DNF).
function renderPodium(r) {
  const el = $("#podium");
  const rows = r && r.phase === "done" && Array.isArray(r.rows) ? r.rows.slice(0, 3) : [];
  el.hidden = rows.length === 0;
  if (el.hidden) return;
  const who = (row) => row.player ? `${row.player} in ${row.car}` : `${row.car}${row.driver ? ` (${row.driver})` : ""}`;
  const time = (row) => row.status && row.status !== "finished" ? row.status
    : row.totalTime != null ? `${row.totalTime.toFixed(3)} s` : "";
  const html = `<h3>${escapeHtml(r.title || "Results")}</h3><ol>` + rows.map((row, i) =>
    `<li data-position="${i + 1}"><span class="place">${i + 1}</span><span class="who">${escapeHtml(who(row))}</span>` +
    `<span class="time">${escapeHtml(time(row))}</span></li>`).join("") + "</ol>";
  if (el.innerHTML !== html) el.innerHTML = html;
}

function addEvents(list, reset) {
  if (reset) view.events = [];
  const seen = new Set(view.events.map((e) => e.seq));
  for (const e of list || []) if (e.seq == null || !seen.has(e.seq)) view.events.push(e);
  if (view.events.length > EVENTS_MAX) view.events.splice(0, view.events.length - EVENTS_MAX);
  const ol = $("#events");
  ol.textContent = "";
  for (let i = view.events.length - 1; i >= 0; i--) {
    const e = view.events[i];
    const li = document.createElement("li");
    li.className = `level-${e.level || "info"}`;
    const t = document.createElement("span");
    t.className = "t";
    t.textContent = e.t == null ? "" : e.t.toFixed(1);
    li.append(t, document.createTextNode(e.text || ""));
    ol.appendChild(li);
  }
}

// ---------------------------------------------------------------------------------------------
// Replay controls.

let seeking = false;
function renderReplay() {
  const r = view.replay;
  $("#replay").hidden = !r;
  if (!r) return;
  $("#replay-play").textContent = r.paused ? "Play" : "Pause";
  const seek = $("#replay-seek");
  seek.max = r.duration || 0;
  if (!seeking) seek.value = r.position || 0;
  $("#replay-time").textContent = `${(r.position || 0).toFixed(1)} / ${(r.duration || 0).toFixed(1)} s`;
  const sel = $("#replay-speed");
  if (document.activeElement !== sel && r.speed != null) {
    // (a speed the menu does not list, --speed 5: listed, in order)
    if (![...sel.options].some((o) => Number(o.value) === r.speed)) {
      const o = new Option(`${r.speed}×`, String(r.speed));
      const after = [...sel.options].find((x) => Number(x.value) > r.speed);
      sel.add(o, after || null);
    }
    sel.value = [...sel.options].find((o) => Number(o.value) === r.speed).value;
  }
}

function control(msg) {
  if (socket && socket.readyState === WebSocket.OPEN)
    socket.send(JSON.stringify({ type: "control", ...msg, ...(joinCode ? { code: joinCode } : {}) }));
}
$("#replay-play").addEventListener("click", () => view.replay && control({ pause: !view.replay.paused }));
$("#replay-seek").addEventListener("input", () => { seeking = true; });
$("#replay-seek").addEventListener("change", (e) => { seeking = false; control({ seek: Number(e.target.value) }); });
$("#replay-speed").addEventListener("change", (e) => control({ speed: Number(e.target.value) }));

// ---------------------------------------------------------------------------------------------
// Charts (uPlot).

const chartAxes = (xLabel, yLabel, wholeX) => [
  { stroke: "#9aa4b2", grid: { stroke: "#2a313c" }, ticks: { stroke: "#2a313c" }, label: xLabel,
    ...(wholeX ? { incrs: [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000] } : {}) },
  { stroke: "#9aa4b2", grid: { stroke: "#2a313c" }, ticks: { stroke: "#2a313c" }, label: yLabel, size: 60 },
];

// (a quarter of the window's height at most, so that the track keeps the most of a screen)
function chartSize(el) {
  const tall = Math.min(260, Math.max(150, window.innerHeight * 0.24));
  return { width: Math.max(200, el.clientWidth), height: Math.max(140, Math.min(tall, el.clientWidth * 0.42)) };
}

function makeChart(el, cars, xLabel, yLabel, xFmt) {
  el.textContent = "";
  if (typeof uPlot === "undefined") { el.textContent = "charts unavailable (uPlot not loaded)"; return null; }
  const series = [{ label: xLabel, value: (u, v) => (v == null ? "–" : xFmt(v)) }];
  for (const c of cars) {
    // (undefined: no sample of this car at that time, joined over; null: a gap — a seek in a
    // replay, a car silent for seconds — where the line breaks)
    series.push({ label: c.name || `car ${c.number}`, stroke: c.color || "#888", width: 2,
                  spanGaps: false, points: { size: 5 } });
  }
  const opts = { ...chartSize(el), series, axes: chartAxes(xLabel, yLabel, xLabel === "lap"),
                 scales: { x: { time: false } }, legend: { live: false }, cursor: { drag: { x: false, y: false } } };
  return new uPlot(opts, [[], ...cars.map(() => [])], el);
}

function carKey() {
  return [...view.cars.values()].map((c) => `${c.number}:${c.name}:${c.color}`).join("|");
}

function renderCharts() {
  const cars = [...view.cars.values()].sort((a, b) => a.number - b.number);
  const key = carKey();
  if (key !== view.lapKey || !view.lapChart) {
    view.lapChart?.destroy();
    view.lapChart = makeChart($("#lap-chart"), cars, "lap", "seconds", (v) => `lap ${v}`);
    const chart = view.lapChart;
    chart?.over.addEventListener("click", () => pickFromChart(chart, cars));
    view.lapKey = key;
  }
  if (key !== view.speedKey || !view.speedChart) {
    view.speedChart?.destroy();
    view.speedChart = makeChart($("#speed-chart"), cars, "time (s)", "mm/s", (v) => `${v.toFixed(1)} s`);
    view.speedKey = key;
  }
  // Lap times: x = lap number. The race's table has every lap of its session; a car's own list
  // (no race: a replay, a spectator) holds its latest laps, the first of them lap lapTimesFrom.
  const laps = cars.map((c) => {
    // (a record keeps each car's latest 100 race laps: lapTimesFrom numbers the first)
    const fromRace = view.race && view.race.lapTimes && view.race.lapTimes[String(c.number)];
    if (fromRace) return { from: (view.race.lapTimesFrom || {})[String(c.number)] || 1, times: fromRace };
    return { from: c.lapTimesFrom || 1, times: c.lapTimes || [] };
  });
  const first = Math.min(Infinity, ...laps.filter((l) => l.times.length).map((l) => l.from));
  const last = Math.max(0, ...laps.map((l) => l.from + l.times.length - 1));
  const maxLap = Number.isFinite(first) ? last : 0;
  const lx = maxLap ? Array.from({ length: last - first + 1 }, (_, i) => first + i) : [];
  view.lapChart?.setData([lx, ...laps.map((l) => lx.map((n) => l.times[n - l.from] ?? null))]);
  setEmpty("#lap-chart", maxLap ? "" : "no lap completed yet");
  // Speeds: one shared time axis, the union of every car's sample times.
  const since = view.time - SPEED_WINDOW_S;
  const hist = cars.map((c) => (view.speeds.get(c.number) || []).filter((s) => s[0] >= since));
  const times = [...new Set(hist.flatMap((h) => h.map((s) => s[0])))].sort((a, b) => a - b);
  const col = new Map(times.map((t, i) => [t, i]));
  const ys = hist.map((h) => {
    const y = new Array(times.length).fill(undefined);
    for (const [t, v] of h) y[col.get(t)] = v;
    return y;
  });
  view.speedChart?.setData([times, ...ys]);
  setEmpty("#speed-chart", times.length ? "" : "no speeds yet");
}

function setEmpty(sel, text) {
  const el = $(sel);
  if (text) el.dataset.empty = text; else delete el.dataset.empty;
}

function recordSpeed(car, t) {
  if (car.speed == null) return;
  let h = view.speeds.get(car.number);
  if (!h) view.speeds.set(car.number, (h = []));
  // back in time (a replay moved back): what lies after now is forgotten
  while (h.length && h[h.length - 1][0] > t + 0.5) h.pop();
  if (h.length && t - h[h.length - 1][0] < 0.1) return;  // at most 10 samples a second
  // a jump ahead (a seek, or no update for seconds): the line breaks there, it does not join
  if (h.length && t - h[h.length - 1][0] > SPEED_GAP_S) h.push([(h[h.length - 1][0] + t) / 2, null]);
  h.push([t, car.speed]);
  while (h.length && h[0][0] < t - SPEED_WINDOW_S) h.shift();
}

new ResizeObserver(() => {
  for (const [chart, sel] of [[view.lapChart, "#lap-chart"], [view.speedChart, "#speed-chart"]])
    if (chart) chart.setSize(chartSize($(sel)));
}).observe($("main"));
setInterval(() => { if (view.chartsDirty) { view.chartsDirty = false; renderCharts(); } }, 500);

// ---------------------------------------------------------------------------------------------
// The feed.

function onState(s) {
  view.track = s.track || null;
  view.cars = new Map((s.cars || []).map((c) => [c.number, c]));
  view.race = s.race || null;
  view.replay = s.replay || null;
  view.viewGhost = s.viewGhost || null;
  showDriveLink(s.seats);
  view.source = s.source || "";
  view.time = s.time || 0;
  view.receivedAt = performance.now();
  view.speeds = new Map();
  for (const c of s.cars || []) {
    const h = [];
    for (const [t, v] of c.speedHistory || []) {
      if (h.length && t - h[h.length - 1][0] > SPEED_GAP_S) h.push([(h[h.length - 1][0] + t) / 2, null]);
      h.push([t, v]);
    }
    view.speeds.set(c.number, h);
  }
  view.lapKey = view.speedKey = "";
  drawTrack();
  syncMarkers();
  renderRace();
  addEvents(s.events, true);
  renderBoard();
  renderCharts();
}

function onUpdate(u) {
  if (u.time != null) { view.time = u.time; view.receivedAt = performance.now(); }
  if (u.track !== undefined) { view.track = u.track; drawTrack(); }
  let changed = !!u.track;
  if (Array.isArray(u.cars)) {
    const before = carKey();
    for (const c of u.cars) {
      view.cars.set(c.number, c);
      recordSpeed(c, u.time ?? view.time);
    }
    changed = changed || carKey() !== before;
  }
  if (u.race !== undefined) view.race = u.race;
  if (u.replay !== undefined) view.replay = u.replay;
  if (u.viewGhost !== undefined) view.viewGhost = u.viewGhost;
  if (u.seats !== undefined) showDriveLink(u.seats);
  syncMarkers();
  renderRace();
  if (u.events && u.events.length) addEvents(u.events, false);
  renderBoard();
  view.chartsDirty = true;
  if (changed) renderCharts();
}

function showDriveLink(seats) {
  $("#drive-link").hidden = !(Array.isArray(seats) && seats.length > 0);
}

let socket = null;
let joinCode = pitwallJoinCode();

// {"type":"pairing","code":"123456","drive":"http://…/drive?code=123456"}: shown by the title,
// for the players to type or open.
function showPairing(msg) {
  const code = String(msg.code || "");
  const url = String(msg.drive || "");
  $("#join").hidden = !code;
  $("#join-code").textContent = code;
  $("#join-url").textContent = url;
  $("#join-url").href = url;
  if (url) $("#drive-link").href = url;
  const qr = $("#join-qr");
  qr.hidden = true;
  if (url && typeof qrcode === "function") {
    const q = qrcode(0, "M");  // the smallest version that holds the address
    q.addData(url);
    q.make();
    qr.src = q.createDataURL(3, 2);
    qr.hidden = false;
  }
  if (code && !joinCode) joinCode = code;
}

function setConnection(live) {
  const el = $("#connection");
  el.textContent = live ? "live" : "engine gone";
  el.className = `connection ${live ? "live" : "gone"}`;
  document.body.classList.toggle("engine-gone", !live);
}

function connect() {
  const query = joinCode ? `?code=${encodeURIComponent(joinCode)}` : "";
  const ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/ws${query}`);
  socket = ws;
  let retried = false;
  const retry = () => {
    if (retried) return;
    retried = true;
    if (socket === ws) socket = null;
    setConnection(false);
    setTimeout(connect, 1000);
  };
  ws.onmessage = (ev) => {
    let msg;
    try { msg = JSON.parse(ev.data); } catch { return; }
    if (msg.type === "state") { onState(msg); setConnection(true); }
    else if (msg.type === "update") onUpdate(msg);
    else if (msg.type === "pairing") showPairing(msg);
    else if (msg.type === "error") addEvents([{ t: view.time, level: "error", text: msg.message }], false);
  };
  ws.onclose = retry;
  ws.onerror = () => { retry(); try { ws.close(); } catch { /* already closed */ } };
}

drawTrack();
connect();
requestAnimationFrame(frame);

// ---------------------------------------------------------------------------------------------
// Comparing two laps (docs/view.md "Comparing two laps"): the feed's lap traces, compared by
// distance by the engine (GET /api/laps/compare), drawn as `pitwall compare` draws them.

const lapPicks = [];

async function lapList() {
  const r = await fetch("api/laps");
  return r.ok ? (await r.json()).cars : [];
}

function fillLapSelects(cars) {
  for (const id of ["#lap-a", "#lap-b"]) {
    const sel = $(id);
    const keep = sel.value;
    sel.textContent = "";
    for (const c of cars) {
      for (const l of c.laps) {
        if (!l.clean) continue;
        const o = document.createElement("option");
        o.value = `${c.number}:${l.lap}`;
        o.textContent = `${c.name || "car " + c.number} lap ${l.lap} (${l.time.toFixed(3)} s)`;
        sel.append(o);
      }
    }
    if ([...sel.options].some((o) => o.value === keep)) sel.value = keep;
  }
}

async function openCompare(a, b) {
  fillLapSelects(await lapList());
  if (a) $("#lap-a").value = a;
  if (b) $("#lap-b").value = b;
  const dlg = $("#lap-compare");
  if (!dlg.open) dlg.showModal();
  if (a && b) runCompare();
}

async function runCompare() {
  const a = $("#lap-a").value, b = $("#lap-b").value;
  const out = $("#lap-compare-result"), how = $("#lap-compare-how");
  if (!a || !b) { how.textContent = "no whole lap yet to compare"; return; }
  const r = await fetch(`api/laps/compare?a=${a}&b=${b}`);  // (CAR:LAP: digits and a colon)
  const j = await r.json();
  if (!r.ok) { how.textContent = j.error || "the comparison failed"; out.textContent = ""; return; }
  how.textContent = j.how;
  const row = (name, mm, t) => {
    const d = t[1] - t[0];
    return `<tr><td>${escapeHtml(name)}</td><td>${mm}</td><td>${t[0].toFixed(3)}</td>` +
      `<td>${t[1].toFixed(3)} <span class="${d > 0 ? "lose" : "gain"}">${d >= 0 ? "+" : ""}${d.toFixed(3)}</span></td></tr>`;
  };
  const rows = j.sections.map((s) => row(s.name, `${Math.round(s.from)}–${Math.round(s.to)}`, s.times))
    .join("") + row("lap", "", j.laps.map((l) => l.time));
  const head = j.laps.map((l) => `<th>${escapeHtml(l.label)}</th>`).join("");
  out.innerHTML = `<table class="sections"><tr><th>section</th><th>mm</th>${head}</tr>${rows}</table>` + j.svg;
}

// A click on the lap-time chart picks the lap of the line nearest the pointer at that lap.
async function pickFromChart(u, cars) {
  const i = u.cursor.idx;
  if (i == null) return;
  const y = u.posToVal(u.cursor.top, "y");
  let best = null;
  for (let k = 1; k < u.series.length; k++) {
    const v = u.data[k][i];
    if (v == null) continue;
    if (!best || Math.abs(v - y) < Math.abs(best.v - y)) best = { k, v };
  }
  if (!best) return;
  const car = cars[best.k - 1];
  const listed = (await lapList()).find((c) => c.number === car.number);
  const lap = listed && listed.laps.find((l) => Math.abs(l.time - best.v) < 0.002);
  if (!lap) return;
  lapPicks.push(`${car.number}:${lap.lap}`);
  if (lapPicks.length === 2) openCompare(...lapPicks.splice(0, 2));
}

$("#compare-open").addEventListener("click", () => openCompare());
$("#lap-compare-go").addEventListener("click", () => runCompare());
