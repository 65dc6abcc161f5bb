// The code page (code.html; docs/classroom.md): a student joins with the lesson's code, takes a
// free car and edits its driver — Save races it (the old version drives on when the new one does
// not load), Test runs it alone on the simulator — beside their car's telemetry. With ?teacher=KEY
// it is the teacher's page: every desk, the lock, the start of a race, a car's reset.
// Its requests: engine/view/code_api.hpp. A student's credential is kept in the browser
// (localStorage), so a reload keeps the desk.
"use strict";

const $ = (id) => document.getElementById(id);
// The teacher's key comes in the address's fragment (#teacher=…, never sent in a request), is
// kept for the tab and taken out of the address bar: a projected screen shows no key.
const TEACHER_KEY = "pitwall.code.teacher";
let teacherKey = new URLSearchParams(location.hash.slice(1)).get("teacher");
try {
  if (teacherKey) sessionStorage.setItem(TEACHER_KEY, teacherKey);
  else teacherKey = sessionStorage.getItem(TEACHER_KEY);
} catch { /* storage off: this load only */ }
const TOKEN_KEY = "pitwall.code.token";
let token = null;
try { token = localStorage.getItem(TOKEN_KEY); } catch { /* storage off: the tab only */ }
// a desk the teacher gave: its credential in the link's fragment (never sent to the server in
// the address), kept like a join's and taken out of the address bar
const given = new URLSearchParams(location.hash.slice(1)).get("desk");
if (location.hash.includes("teacher=")) history.replaceState(null, "", location.pathname + location.search);
if (given) {
  token = given;
  try { localStorage.setItem(TOKEN_KEY, token); } catch { /* the tab only */ }
  history.replaceState(null, "", location.pathname + location.search);
}
let editor = null, me = null, completions = {}, testing = false;

async function api(method, path, body, key = token) {
  const headers = {};
  if (key) headers.Authorization = "Bearer " + key;
  if (body !== undefined) headers["Content-Type"] = "application/json";
  let r;
  try {
    r = await fetch("/api/code/" + path, {
      method, headers, cache: "no-store",
      body: body === undefined ? undefined : JSON.stringify(body),
    });
  } catch (e) {
    return { ok: false, status: 0, data: { error: "the engine cannot be reached (" + e.message + ")" } };
  }
  // (a refusal before the code page — a body too large, another site's page — is plain text)
  const text = await r.text();
  let data = {};
  try { data = JSON.parse(text); } catch { data = r.ok ? {} : { error: text.trim() || r.statusText }; }
  return { ok: r.ok, status: r.status, data };
}

function notice(text) {
  $("notice").textContent = text || "";
  $("notice").hidden = !text;
}

function status(el, text, kind) {
  el.textContent = text;
  el.className = "status" + (kind ? " " + kind : "");
}

function fixed(v, digits = 3) {
  return typeof v === "number" ? v.toFixed(digits) : "–";
}

// ---- joining ----
async function showJoin() {
  $("desk").hidden = true;
  $("join").hidden = false;
  const r = await api("GET", "desks", undefined, null);
  if (!r.ok) return notice(r.data.error || "the code page did not answer (" + r.status + ")");
  $("code-row").hidden = !r.data.codeNeeded;
  if (!$("code").value) $("code").value = pitwallJoinCode();
  const list = $("desks");
  list.textContent = "";
  for (const d of r.data.desks) {
    const li = document.createElement("li");
    const b = document.createElement("button");
    b.type = "button";
    b.dataset.car = d.car;
    b.textContent = "car " + d.car + " · " + d.carName + (d.taken ? " (taken)" : "");
    b.disabled = d.taken;
    b.addEventListener("click", () => join(d.car));
    li.append(b);
    list.append(li);
  }
}

async function join(car) {
  const r = await api("POST", "join", { code: $("code").value.trim(), car, name: $("name").value }, null);
  if (!r.ok) return notice(r.data.error || "could not join (" + r.status + ")");
  token = r.data.token;
  try { localStorage.setItem(TOKEN_KEY, token); } catch { /* the tab only */ }
  notice("");
  await loadDesk();
}

// ---- the desk ----
async function loadDesk() {
  const r = await api("GET", "me");
  if (r.status === 401) {
    token = null;
    try { localStorage.removeItem(TOKEN_KEY); } catch { /* */ }
    notice(r.data.error);
    return showJoin();
  }
  if (!r.ok) return notice(r.data.error || "the desk did not load (" + r.status + ")");
  me = r.data;
  $("join").hidden = true;
  $("desk").hidden = false;
  $("who").textContent = me.student + " · car " + me.car + " (" + me.carName + ")";
  $("car-name").textContent = "car " + me.car + " · " + me.carName;
  if (!editor) {
    try {
      const c = await fetch("vendor/pitwall-completions.json");
      if (c.ok) completions = await c.json();
    } catch { /* no completions: the editor still edits */ }
    editor = window.PitwallEditor.create($("editor"), {
      doc: me.text, completions, onChange: () => editor.showErrors([]),
    });
    window.codePageEditor = editor;  // (the page's tests reach it here)
  } else {
    editor.setText(me.text);
  }
  showDesk(me);
  await loadHistory();
  watchCar();
  setInterval(refreshDesk, 3000);
}

function showDesk(d) {
  $("lock").hidden = !d.locked;  // (Save stays: pressed, it says why nothing was saved)
  let driver = "no race yet: it drives when one starts";
  if (d.raceOn) driver = d.failure ? "out: " + d.failure : "version " + d.driving + " driving";
  $("t-driver").textContent = driver;
  $("t-driver").className = d.failure ? "bad" : "";
}

async function refreshDesk() {
  const r = await api("GET", "me");
  if (r.status === 401) return location.reload();
  if (r.ok) showDesk(r.data);
}

async function save() {
  if (!editor) return;
  const r = await api("POST", "save", { text: editor.text() });
  const el = $("status");
  if (!r.ok) return status(el, r.data.error || "not saved (" + r.status + ")", "bad");
  const d = r.data;
  if (d.error) {
    editor.showErrors(d.line > 0 ? [{ line: d.line, message: d.error }] : []);
    status(el, "Saved as save " + d.version + ", but it does not load: " + d.error +
      "\nYour car drives on with the version before.", "bad");
  } else if (d.driving) {
    editor.showErrors([]);
    status(el, "Saved as save " + d.version + ": it drives your car now.", "good");
  } else {
    editor.showErrors([]);
    status(el, "Saved as save " + d.version + ": it drives your car in the next race.", "good");
  }
  await loadHistory();
  refreshDesk();
}

async function test() {
  if (!editor || testing) return;
  testing = true;
  $("test").disabled = true;
  const out = $("test-result");
  out.className = "test-result muted";
  out.textContent = "testing…";
  const started = performance.now();
  const r = await api("POST", "test", { text: editor.text() });
  testing = false;
  $("test").disabled = false;
  $("test-when").textContent = ((performance.now() - started) / 1000).toFixed(1) + " s";
  if (!r.ok) {
    out.className = "test-result bad";
    out.textContent = r.data.error || "the test did not run (" + r.status + ")";
    return;
  }
  const d = r.data;
  const lines = [];
  (d.laps || []).forEach((t, i) => lines.push("lap " + (i + 1) + "  " + fixed(t) + " s" +
    (d.bestLap === i + 1 ? "  best" : "")));
  if (d.status !== "finished") {
    const none = d.status === "error" || !(d.laps || []).length;
    lines.push((none ? "it did not run: " : "out: ") + (d.reason || d.status));
    if (d.line > 0) editor.showErrors([{ line: d.line, message: d.reason }]);
  }
  out.className = "test-result" + (d.status === "finished" ? "" : " bad");
  out.textContent = lines.join("\n");
  chart(d.trace || []);
}

// Speed against distance along the lap, one line per lap.
let plot = null;
function chart(trace) {
  const laps = [...new Set(trace.map((s) => s.lap).filter((l) => l >= 1))];
  const box = $("chart");
  if (plot) { plot.destroy(); plot = null; }
  if (!laps.length || !window.uPlot) return;
  const xs = [...new Set(trace.filter((s) => s.lap >= 1).map((s) => Math.round(s.distance / 10) * 10))].sort((a, b) => a - b);
  const series = laps.map((lap) => {
    const at = new Map(trace.filter((s) => s.lap === lap).map((s) => [Math.round(s.distance / 10) * 10, s.speed]));
    return xs.map((x) => at.has(x) ? at.get(x) : null);
  });
  const colours = ["#f5c518", "#3ecf8e", "#4da3ff", "#ff5d5d", "#c77dff"];
  plot = new uPlot({
    width: box.clientWidth || 290, height: 180,
    scales: { x: { time: false } },
    axes: [{ stroke: "#8a94a3", label: "mm along the lap" }, { stroke: "#8a94a3", label: "mm/s" }],
    series: [{}, ...laps.map((lap, i) => ({ label: "lap " + lap, stroke: colours[i % colours.length], spanGaps: true }))],
  }, [xs.map((x) => x), ...series], box);
}

async function loadHistory() {
  const r = await api("GET", "history");
  if (!r.ok) return;
  const sel = $("history");
  sel.textContent = "";
  const now = new Option("the editor's text", "");
  sel.append(now);
  for (const s of r.data.saves) {
    sel.append(new Option("save " + s.version + " (" + s.bytes + " B, " + Math.round(s.age) + " s ago)", s.version));
  }
}

async function download() {
  const v = $("history").value;
  let text = editor ? editor.text() : "", name = "car-" + (me ? me.car : "") + "-driver.lua";
  if (v) {
    const r = await fetch("/api/code/history/" + encodeURIComponent(v), {
      headers: { Authorization: "Bearer " + token }, cache: "no-store" });
    if (!r.ok) return status($("status"), "save " + v + " could not be read (" + r.status + ")", "bad");
    text = await r.text();
    name = "car-" + me.car + "-save-" + v + ".lua";
  }
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([text], { type: "text/x-lua" }));
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 1000);
}

// The car's telemetry from the race view's feed (/ws: read-only, as a spectator's)
function watchCar() {
  const conn = $("connection");
  const ws = new WebSocket((location.protocol === "https:" ? "wss://" : "ws://") + location.host + "/ws");
  ws.onopen = () => { conn.textContent = "live"; conn.className = "connection live"; };
  ws.onclose = () => {
    conn.textContent = "engine gone"; conn.className = "connection gone";
    setTimeout(watchCar, 2000);
  };
  ws.onmessage = (m) => {
    let msg;
    try { msg = JSON.parse(m.data); } catch { return; }
    if (!me || !Array.isArray(msg.cars)) return;
    const car = msg.cars.find((c) => c.number === me.car);
    if (!car) return;
    $("t-speed").textContent = car.speed + " mm/s";
    $("t-lane").textContent = fixed(car.offset, 0) + " mm";
    $("t-piece").textContent = car.piece ?? "–";
    $("t-lap").textContent = car.lap ?? "–";
    $("t-last").textContent = car.lastLap != null ? fixed(car.lastLap) + " s" : "–";
    $("t-best").textContent = car.bestLap != null ? fixed(car.bestLap) + " s" : "–";
  };
}

// ---- the teacher ----
async function teacher() {
  $("teacher").hidden = false;
  $("who").textContent = "teacher";
  const code = pitwallJoinCode();
  $("race-view").src = "/" + (code ? "?code=" + encodeURIComponent(code) : "");
  $("lock-all").addEventListener("click", async () => {
    const locking = $("lock-all").dataset.locked !== "true";
    const r = await api("POST", "teacher", { action: locking ? "lock" : "unlock" }, teacherKey);
    status($("teacher-status"), r.ok ? (locking ? "editors locked" : "editors unlocked") : r.data.error, r.ok ? "good" : "bad");
    refreshTeacher();
  });
  $("start").addEventListener("click", async () => {
    const r = await api("POST", "teacher", { action: "start", laps: Number($("laps").value) }, teacherKey);
    status($("teacher-status"), r.ok ? "a race of " + r.data.started + " laps starts" : r.data.error, r.ok ? "good" : "bad");
  });
  $("league").addEventListener("click", league);
  await refreshTeacher();
  setInterval(refreshTeacher, 1000);
}

// A league of every desk's driver in the simulator (`pitwall league`, off the race's loop): its
// standings here, its report a click away.
async function league() {
  $("league").disabled = true;
  status($("teacher-status"), "the league is racing in the simulator…");
  const r = await api("POST", "teacher", { action: "league", laps: Number($("laps").value) }, teacherKey);
  $("league").disabled = false;
  if (!r.ok) return status($("teacher-status"), r.data.error || "no league (" + r.status + ")", "bad");
  status($("teacher-status"), "league " + r.data.league + " raced in " + r.data.seconds.toFixed(1) + " s", "good");
  const box = $("league-result");
  box.hidden = false;
  box.textContent = "";
  const table = document.createElement("table");
  table.innerHTML = "<thead><tr><th>pos</th><th>driver</th><th>points</th><th>wins</th><th>best lap</th></tr></thead>";
  const body = document.createElement("tbody");
  for (const s of r.data.standings) {
    const tr = document.createElement("tr");
    for (const v of [s.position, s.driver, s.points, s.wins, fixed(s.bestLap)]) {
      const td = document.createElement("td");
      td.textContent = v;
      tr.append(td);
    }
    body.append(tr);
  }
  table.append(body);
  const report = document.createElement("button");
  report.type = "button";
  report.id = "league-report";
  report.textContent = "Report";
  report.addEventListener("click", async () => {
    const page = await fetch(r.data.report, { headers: { Authorization: "Bearer " + teacherKey } });
    if (!page.ok) return status($("teacher-status"), "the report could not be read (" + page.status + ")", "bad");
    window.open(URL.createObjectURL(new Blob([await page.text()], { type: "text/html" })), "_blank",
      "noopener");
  });
  box.append(table, report);
}

async function teacherAction(action, car) {
  const r = await api("POST", "teacher", { action, car }, teacherKey);
  status($("teacher-status"), r.ok ? (r.data.said || action + ": car " + car) : r.data.error, r.ok ? "good" : "bad");
  refreshTeacher();
}

const teacherRows = new Map();  // car → its row on the teacher's page
async function refreshTeacher() {
  const r = await api("GET", "teacher", undefined, teacherKey);
  const conn = $("connection");
  if (!r.ok) {
    conn.textContent = r.status === 0 ? "engine gone" : "refused"; conn.className = "connection gone";
    return notice(r.data.error);
  }
  conn.textContent = "live"; conn.className = "connection live";
  $("lock-all").dataset.locked = r.data.locked;
  $("lock-all").textContent = r.data.locked ? "Unlock editors" : "Lock editors";
  $("lock").hidden = !r.data.locked;
  // Each desk's row is made once and its cells updated in place: a name being typed to give a
  // desk to, or a button being pressed, is never swept away by the next refresh.
  const body = $("teacher-desks");
  for (const d of r.data.desks) {
    let row = teacherRows.get(d.car);
    if (!row) {
      const tr = document.createElement("tr");
      tr.dataset.car = d.car;
      const cells = [0, 1, 2, 3, 4, 5].map(() => tr.appendChild(document.createElement("td")));
      row = { tr, cells, joined: null };
      teacherRows.set(d.car, row);
      body.append(tr);
    }
    const [car, student, seen, saves, driverCell, actions] = row.cells;
    car.textContent = d.car + " · " + d.carName;
    student.textContent = d.joined ? d.student : "free";
    seen.textContent = d.seen == null ? "–" : d.seen < 10 ? "yes" : Math.round(d.seen) + " s ago";
    saves.textContent = String(d.saves);
    let driver = d.raceOn ? (d.failure ? "out: " + d.failure : "driving") : "no race";
    if (d.lastError && !d.failure) driver += " · last save: " + d.lastError;
    driverCell.textContent = driver;
    driverCell.className = d.failure ? "out" : "";
    if (row.joined !== d.joined) {  // the actions: Give on a free desk; Reset and Free
      row.joined = d.joined;
      actions.textContent = "";
      if (!d.joined) {
        const name = document.createElement("input");
        name.placeholder = "student's name";
        name.className = "give-name";
        const give = document.createElement("button");
        give.type = "button";
        give.textContent = "Give";
        give.dataset.action = "assign";
        give.addEventListener("click", async () => {
          const r = await api("POST", "teacher", { action: "assign", car: d.car, name: name.value }, teacherKey);
          if (!r.ok) return status($("teacher-status"), r.data.error, "bad");
          const link = new URL(r.data.link, location.href).href;
          status($("teacher-status"), "car " + d.car + " is " + name.value + "'s: give them " + link, "good");
          $("teacher-status").dataset.link = link;
          refreshTeacher();
        });
        actions.append(name, " ", give, " ");
      }
      for (const [label, action] of [["Reset", "reset"], ["Free", "free"]]) {
        const b = document.createElement("button");
        b.type = "button";
        b.textContent = label;
        b.dataset.action = action;
        b.addEventListener("click", () => teacherAction(action, d.car));
        actions.append(b, " ");
      }
    }
  }
}

$("save").addEventListener("click", save);
$("test").addEventListener("click", test);
$("download").addEventListener("click", download);
document.addEventListener("keydown", (e) => {
  if ((e.ctrlKey || e.metaKey) && e.key === "s" && !$("desk").hidden) {
    e.preventDefault();
    save();
  }
});

if (teacherKey) teacher();
else if (token) loadDesk();
else showJoin();
