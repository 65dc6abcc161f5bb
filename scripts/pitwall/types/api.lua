-- Annotations of the `pitwall` table, its timers and listeners, pitwall.view and `expect`, for
-- the LuaLS definitions (scripts/pitwall/types.lua, docs/editor.md). Each function: its doc
-- line(s), then @param/@return lines; each field: {type, doc}. Every name here must exist in
-- the binary and every name there must be here: the generator says which do not.
return {
  {
    metatable = "pitwall.timer",
    class = "pitwall.Timer",
    localName = "Timer",
    doc = "A timer from pitwall.after or pitwall.every.",
    methods = {
      cancel = [[Stops the timer; false if it had already fired or was cancelled.
@return boolean cancelled]],
    },
  },
  {
    text = [[
---A subscription from pitwall.listen.
---@class pitwall.Listener
---@field car pitwall.Car|pitwall.Mindroad|pitwall.Alphabot the object listened to
---@field event string the event's name ("onPosition", …)
local Listener = {}

---Ends the subscription; true if it was active.
---@return boolean
function Listener:cancel() end

---What pitwall.terminal() returns.
---@class pitwall.Terminal
---@field tty boolean stdout is a terminal a script may redraw (false while a REPL prompt is on it)
---@field columns integer its width (COLUMNS, else 80)
---@field output integer how many writes reached the terminal so far

---What pitwall.piece(id) returns.
---@class pitwall.PieceInfo
---@field id integer road piece id
---@field type "start-long"|"start-short"|"straight"|"curve"|"intersection"|string
---@field length number centre-line length, mm
---@field radius? number centre radius of a curve, mm
---@field angle? number how far a curve turns, degrees
---@field custom? boolean a custom piece of the track in use (docs/tracks.md)

---A file-like object for the console (pitwall.stdout).
---@class pitwall.Stdout
local Stdout = {}

---Writes strings and numbers to the console (stdout, or above the REPL's prompt).
---@param ... string|number
---@return pitwall.Stdout
function Stdout:write(...) end

---@return pitwall.Stdout
function Stdout:flush() end

---The second argument of pitwall.onReload.
---@class pitwall.ReloadInfo
---@field reloads integer how many times the script was reloaded
---@field files string[] the files that changed]],
  },
  {
    class = "pitwall",
    declare = "pitwall",
    returns = "pitwall", -- require "pitwall" gives it too
    live = function() return pitwall end,
    doc = [[The engine: cars, timers, tasks, the clock (docs/lua-api.md).]],
    fields = {
      virtualTime = { "boolean", "true when the clock is virtual (--fast, tests)" },
      seed = { "integer", "the run's seed (--seed); math.random is seeded with it" },
      persist = { "table", "survives hot reloads: plain data and cars, copied into each new version" },
      reloads = { "integer", "how many times the script was reloaded: 0 in the first version" },
      resultsFile = { "string?", "the --results FILE of the run, or nil", sometimes = true },
      stdout = { "pitwall.Stdout", "a file-like object (:write, :flush) for the console" },
      sim = { "pitwall.sim?", "the simulator's API: present when the run uses the built-in simulator" },
      view = { "pitwall.view", "what the race view shows (docs/view.md)" },
      classroom = { "pitwall.classroom", "the view's code page's classroom (--code FOLDER; docs/classroom.md)" },
      driverFiles = { "table<integer, string>", "the run's --driver CAR=FILE: car number → driver file, each raced in a Lua world of its own (docs/drivers.md)" },
    },
    settable = {
      onCar = { "fun(car: pitwall.Car)", "called when a car joins after the script started" },
      onError = { "fun(message: string, where: string)",
        "takes the errors raised in callbacks, timers and tasks instead of the log" },
      onUnload = { "fun(persist: table)",
        "with --watch: called in the running version before a new one starts" },
      onReload = { "fun(persist: table, info: pitwall.ReloadInfo)",
        "with --watch: called in a new version after its main chunk first ran; an error refuses it" },
    },
    functions = {
      cars = [[A new list of every car of the run, in join order (cars[1] is car number 1).
@return pitwall.Car[] ]],
      car = [[The car with that number or name; one that is not there is an error naming the cars.
@param which integer|string a car number or name
@return pitwall.Car]],
      now = [[Engine clock, seconds since the run started.
@return number seconds]],
      after = [[Calls fn() once after `delay` ≥ 0 seconds.
@param delay number seconds
@param fn fun()
@return pitwall.Timer]],
      every = [[Calls fn() every `period` ≥ 0.001 seconds (no drift; missed ticks are skipped).
@param period number seconds
@param fn fun()
@return pitwall.Timer]],
      cancel = [[Stops a timer; false if it had already fired or was cancelled.
@param timer pitwall.Timer
@return boolean cancelled]],
      spawn = [[Starts a task (a coroutine) now; it runs until its first pitwall.sleep.
@param fn fun()
@param name? string how errors name the task (default: the file and line)]],
      sleep = [[Inside a task: resumes after `seconds` ≥ 0 of engine time. Outside a task it raises an error.
@param seconds number]],
      waitUntil = [[Inside a task: checks cond() every `step` (0.01) s; true once it holds, false after `timeout` s.
@param cond fun(): any
@param timeout? number seconds (default: no limit)
@param step? number seconds between checks (default 0.01)
@return boolean held]],
      stop = [[Ends the run: stops every car, then exits (status 0).]],
      log = [[A log line on stderr with the script's file and line; a first argument "debug", "info", "warn" or "error" sets the level.
@param ... any]],
      copy = [[A shallow copy of a table (event tables are reused: keep a copy to store one).
@generic T: table
@param t T
@return T]],
      listen = [[Calls fn(object, ev) on every `event` of a car or robot, before its own handler. Not "onMessage".
@param object pitwall.Car|pitwall.Mindroad|pitwall.Alphabot
@param event string an event name: "onPosition", …
@param fn fun(object: any, ev: any, ...: any)
@return pitwall.Listener]],
      seats = [[The seats of human drivers, in number order (empty: the run has none; docs/racing.md "Human drivers").
@return pitwall.Seat[] ]],
      seat = [[Seat n, or nil.
@param n integer
@return pitwall.Seat?]],
      piece = [[What a road piece is, or nil for an unknown id.
@param id integer road piece id
@return pitwall.PieceInfo?]],
      layout = [[The layout the cars are on, as sim.track() gives it: the simulator's track, or with --ble the layout given with --track; nil when none is known.
@return pitwall.sim.Track?]],
      writeResults = [[Writes rows (tables) with the fields named in `columns` as JSON or CSV (by the extension) to `path` or --results FILE.
@param rows table[]
@param columns string[]
@param path? string
@return string path]],
      keepResults = [[Keeps a race's results in the run's standings database (--db; docs/league.md "Standings"): {kind, number, track, laps, green?, entries = {{number, driver, car, file?, position, finished, status, reason?, laps, bestLap, totalTime, lapTimes}}} (green: the engine time of the green light, from which each entry's best lap is kept as a personal best). The race library calls it when a race ends.
@param race table
@return boolean kept false when the run keeps no standings, or when they were held or saved beside the database
@return string? why not now]],
      terminal = [[The console: is it a terminal that may be redrawn, and how wide.
@return pitwall.Terminal]],
      mindroad = [[A MindRoad robot car over TCP or UDP (docs/robots.md); in a task it waits for contact.
@param options? pitwall.MindroadOptions
@return pitwall.Mindroad]],
      alphabot = [[An Alphabot over WLAN (TCP) or Bluetooth LE (docs/robots.md); in a task it waits until connected.
@param options pitwall.AlphabotOptions
@return pitwall.Alphabot]],
    },
  },
  {
    metatable = "pitwall.driverworld",
    class = "pitwall.DriverWorld",
    localName = "DriverWorld",
    doc = [[A driver file's Lua world of its own, as drivers.world makes it (docs/drivers.md): it drives one car, reads no file, and is out at its first failure.]],
    fields = {
      failure = { "string?", "why it is out (its car stopped), nil while it drives" },
      file = { "string", "the driver file, absolute" },
      version = { "integer", "1 for its first world, +1 for each reload" },
      cpu = { "number", "seconds of CPU time its calls used" },
    },
    methods = {
      call = [[Calls the driver's `method` with the values after it copied in (what drivers.world sends: the car, its limit and piece limits, the period, the race view or nil, whether that is the one sent last, the map or nil); false once the world has failed.
@param method "start"|"update"|"finish"|"waiting"
@param ... any
@return boolean ok]],
      reload = [[Loads the file again into a new world, as a save does with --watch; false when the new one fails (the car is out).
@return boolean loaded]],
      tryReload = [[Loads the file again into a new world that replaces the one driving only when it loads and sets its driver up (a code editor's save): true, its version +1 (the director starts it; a driver that was out is back); else false and the engine's sentence ("alice.lua:3: …"), the world driving going on as it was.
@return boolean replaced
@return string? why]],
      close = [[Ends the world for good (its session ended, as the race director does at the end): it follows no car any more; later calls return false. Its car is left as it is.]],
    },
  },
  {
    metatable = "pitwall.seat",
    class = "pitwall.Seat",
    localName = "Seat",
    doc = [[A human driver's seat (docs/racing.md "Human drivers"): --humans N opens cars 1..N; a phone (/drive), a gamepad, the keyboard or a script holds it.]],
    fields = {
      number = { "integer", "the seat's number: it drives the car of that number" },
      car = { "pitwall.Car?", "the car it drives (nil until the car is there)" },
      held = { "boolean", "someone holds the seat" },
      live = { "boolean", "held, and its input is fresh (a phone or script silent for 1 s is not)" },
      holder = { "\"phone\"|\"gamepad\"|\"keyboard\"|\"script\"|nil", "what holds it" },
      player = { "string?", "the name its holder gave" },
      throttle = { "number", "0..1 as asked; 0 while not live" },
    },
    methods = {
      lanes = [[The lane steps asked since the last call: − left, + right (at most 3 either way).
@return integer]],
      feed = [[The script holds the seat and asks for this (scripted input; feed at least every second, or the seat loses its input and the car is stopped).
@param throttle number 0..1
@param lane? integer -1 (left), 0, 1 (right)]],
      release = [[The script lets go of the seat: its car slows to a stop.]],
      driving = [[A driver drives the car from the seat now (call it at every update): for the next second a lost holder stops the car.]],
    },
  },
  {
    class = "pitwall.view",
    declare = "pitwall.view",
    live = function() return pitwall.view end,
    doc = [[What the race view shows (docs/view.md); without --view the calls do nothing visible.]],
    fields = {
      active = { "boolean", "true when the run serves the race view (--view)" },
      recording = { "boolean", "true when the run keeps a record (--record): pitwall.view.race goes into it too, for a replay's view" },
    },
    functions = {
      race = [[The race's state for the view: a table of plain data (at most 16 deep), or nil for none.
@param state table?]],
      track = [[Draws a pitwall.track map (real cars; the simulator's layout stays).
@param map pitwall.track.Map]],
      event = [[A line in the view's event log.
@param text string
@param level? "info"|"warn"|"error" (default "info")]],
    },
  },
  {
    class = "pitwall.classroom",
    declare = "pitwall.classroom",
    live = function() return pitwall.classroom end,
    doc = [[The classroom of the view's code page (--code FOLDER, docs/classroom.md): a desk for each
car, each desk's driver file pitwall.driverFiles[car]. Without --code it is not active.]],
    fields = {
      active = { "boolean", "true when the run has a classroom (--code)" },
      folder = { "string?", "the desks' folder (absolute); nil without --code", sometimes = true },
    },
    functions = {
      nextStart = [[The race the teacher started on their page, taken once: its laps; nil when none waits.
@return integer? laps]],
      desks = [[The desks in car order (empty without --code).
@return {car: integer, student: string, joined: boolean, saves: integer}[] ]],
    },
  },
  {
    class = "pitwall.expect",
    declare = "expect",
    live = function() return expect end,
    doc = [[Expectations for scenario tests (`pitwall test` only): each failure names the file and
line of the expectation and the values compared, then ends the scenario. `what` names the value.]],
    functions = {
      eq = [[actual == expected.
@param actual any
@param expected any
@param what? string]],
      ne = [[actual ~= other.
@param actual any
@param other any
@param what? string]],
      near = [[|actual − expected| ≤ tolerance.
@param actual number
@param expected number
@param tolerance number
@param what? string]],
      lt = [[a < b.
@param a number
@param b number
@param what? string]],
      le = [[a <= b.
@param a number
@param b number
@param what? string]],
      gt = [[a > b.
@param a number
@param b number
@param what? string]],
      ge = [[a >= b.
@param a number
@param b number
@param what? string]],
      truthy = [[v is neither false nor nil.
@param v any
@param what? string]],
      falsy = [[v is false or nil.
@param v any
@param what? string]],
      fails = [[fn() must raise an error whose message contains `pattern` (plain text); returns the error.
@param fn fun()
@param pattern? string
@param what? string
@return any err]],
    },
  },
}
