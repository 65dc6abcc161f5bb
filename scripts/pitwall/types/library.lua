-- Annotations of the Lua library's modules (scripts/pitwall/*.lua: track, localize, laps,
-- drivers, race, board, repl; docs/racing.md, docs/lua-api.md), for the LuaLS definitions
-- (scripts/pitwall/types.lua). Each module's functions are checked against the module table
-- `require` of its `module` returns; the classes of the values they return, and the option
-- tables, are written out here.

return {
  -- pitwall.track ---------------------------------------------------------------------------
  {
    file = "pitwall/track.lua",
    text = [[
---A piece of a track map, in driving order.
---@class pitwall.track.Piece
---@field index integer position in the map
---@field id? integer road piece id; nil when a scan never saw it (a loop mapped from transitions: the standard shape of its type)
---@field type string "start-short", "straight", "curve", "start-long", "intersection", … ("unknown")
---@field turn? "left"|"right" curves only
---@field centre number centre-line length, mm
---@field start number centre-line distance from the finish line to the piece's start, mm
---@field radius? number centre radius of a curve, mm
---@field angle? number how far a curve turns, degrees
---@field custom? boolean a custom piece (docs/tracks.md)
local Piece = {}

---Length in mm along the lane at `offset` (mm right of the centre; default 0).
---@param offset? number
---@return number
function Piece:length(offset) end

---A track map: one lap from the finish line.
---@class pitwall.track.Map
---@field pieces pitwall.track.Piece[] from the piece after the finish line (pieces[1] is 33, the last 34; on a track without them, from the line)
---@field finishIndex integer 1: the index of the piece after the finish line
---@field hasStart boolean the track has the start/finish piece (33, 34); false: laps are counted where the scan began or at the script's line
---@field source "scan"|"sim"
---@field scanOffset? number
---@field scanSpeed? number
---@field scannedBy? string
local Map = {}

---Length in mm of one lap along the lane at `offset` (default 0: the centre line).
---@param offset? number
---@return number
function Map:lapLength(offset) end

---The index after `i` driving forward (dir 1, default) or reversed (dir -1), wrapping around.
---@param i integer
---@param dir? 1|-1
---@return integer
function Map:next(i, dir) end

---The indices of every piece with road piece id `id`, in order.
---@param id integer
---@return integer[]
function Map:find(id) end

---Whether a car reporting road piece id `id` can be on piece `i`: the piece has that id, or its id is unknown and it is of the id's kind.
---@param i integer
---@param id integer
---@return boolean
function Map:fits(i, id) end

---The indices of every piece a car reporting `id` can be on (Map:fits), in order.
---@param id integer
---@return integer[]
function Map:candidates(id) end

---The same track with the finish line at the beginning of piece `index`: a new map whose piece 1 is this one's piece `index`.
---@param index integer
---@return pitwall.track.Map
function Map:withLine(index) end

---The map as simulator layout text ("start S L L S S L L"); with `ids`, "S:36 L:17 …".
---@param ids? boolean
---@return string
function Map:layout(ids) end

---Options of track.scan.
---@class pitwall.track.ScanOptions
---@field speed? number mm/s, 100..1000 (default 350)
---@field offset? number change to this lane (mm from the centre) first
---@field timeout? number s (default 120)
---@field stop? boolean stop the car once the map is complete (default true)
---@field line? integer a piece id: laps counted at the beginning of the first piece with it (default: the finish line, or where the scan began on a track without one)

---Options of track.learn.
---@class pitwall.track.LearnOptions
---@field timeout? number s (default 120)
---@field line? integer as track.scan's]],
  },
  {
    file = "pitwall/track.lua",
    class = "pitwall.track",
    declare = "local track",
    module = "pitwall.track",
    returns = "track",
    doc = [[Track mapping (require "pitwall.track"; docs/racing.md "Track mapping").]],
    functions = {
      scan = [[Drives `car` round the track in a fixed lane until its lap is known and returns the map, and the index of the map piece the car is on by then (inside a task only).
@param car pitwall.Car
@param options? pitwall.track.ScanOptions
@return pitwall.track.Map map
@return integer here]],
      learn = [[The map of the track `car` drives, learnt from its events as track.scan learns it but without commanding the car (a car someone else drives; a record replayed with --script), and the index of the map piece it is on by then (inside a task only).
@param car pitwall.Car
@param options? pitwall.track.LearnOptions
@return pitwall.track.Map map
@return integer here]],
      fromSim = [[The map of the simulator's track, without driving (simulator runs only).
@return pitwall.track.Map]],
      fromLayout = [[The map of the layout the cars are on, without driving: the simulator's track, or on real cars --track's layout; nil when none is known (scan the track).
@return pitwall.track.Map?]],
    },
  },
  -- pitwall.localize ------------------------------------------------------------------------
  {
    file = "pitwall/localize.lua",
    text = [[
---Where a car is on a map (localize.follow).
---@class pitwall.localize.Tracker
---@field car pitwall.Car
---@field map pitwall.track.Map
---@field localized boolean the tracker knows the car's piece
---@field anchored boolean the place within the piece comes from a transition
---@field index? integer the piece index in the map, as of the last event
---@field lane? number the lane nearest to the reported offset: −68, −23, 23 or 68
---@field offset? number last reported offset, mm
---@field speed? number last reported speed, mm/s
---@field reverse boolean driving reversed
---@field time? number time of the last event
---@field hitFromBehind? number time of the last report that another car ran into this one from behind
---@field ranInto? number time of the last report that this car ran into another
---@field seenAt? number time of the car's last position update or transition (when it last read the track)
local Tracker = {}

---Centre-line mm from the finish line, the piece index and the fraction of that piece at time t (default now); nil when not localized.
---@param t? number
---@return number? distance
---@return integer? index
---@return number? fraction
function Tracker:locate(t) end

---Centre-line mm from the finish line at time t (default now), or nil.
---@param t? number
---@return number?
function Tracker:distance(t) end

---The fraction of the lap from the finish line (0 … 1) at time t (default now), or nil.
---@param t? number
---@return number?
function Tracker:fraction(t) end

---Calls handlers.enter on each new piece and handlers.lost when the car is lost; returns a function that ends it.
---@param handlers {enter?: fun(loc: pitwall.localize.Tracker, index: integer, from: integer?, time: number), lost?: fun(loc: pitwall.localize.Tracker, time: number, why: string)}
---@return fun()
function Tracker:subscribe(handlers) end

---Stops following.
function Tracker:cancel() end]],
  },
  {
    file = "pitwall/localize.lua",
    class = "pitwall.localize",
    declare = "local localize",
    module = "pitwall.localize",
    returns = "localize",
    doc = [[Where a car is on a map (require "pitwall.localize"; docs/racing.md "Localization").]],
    functions = {
      follow = [[Follows `car` on `map` and returns its tracker; the same car and map give the same tracker.
@param car pitwall.Car
@param map pitwall.track.Map
@param options? {horizon?: number}
@return pitwall.localize.Tracker]],
      nearestLane = [[The lane offset (−68, −23, 23, 68 mm) nearest to `offset`.
@param offset number
@return number]],
    },
  },
  -- pitwall.laps ----------------------------------------------------------------------------
  {
    file = "pitwall/laps.lua",
    text = [[
---A lap, as onLap and onBestLap get it.
---@class pitwall.laps.Lap
---@field number integer 1, 2, …
---@field time number lap time, s
---@field start number engine time of the crossing that began it
---@field finish number engine time of the crossing that ended it
---@field sectors (number|false)[] time of each sector, s
---@field clean boolean the car stayed localized all lap

---Options of laps.timer.
---@class pitwall.laps.Options
---@field sectors? integer[] piece indices where sectors begin (default laps.sectors(map))
---@field minCoverage? number 0..1 (default 0.75)
---@field onLap? fun(car: pitwall.Car, lap: pitwall.laps.Lap)
---@field onBestLap? fun(car: pitwall.Car, lap: pitwall.laps.Lap)

---A lap timer (laps.timer).
---@class pitwall.laps.Timer
---@field count integer laps completed
---@field last? pitwall.laps.Lap
---@field best? pitwall.laps.Lap the fastest clean lap
---@field average? number mean time of the clean laps, s
---@field history pitwall.laps.Lap[]
---@field start? number engine time the lap under way began
---@field sectors integer[]
---@field localization pitwall.localize.Tracker
---@field onLap? fun(car: pitwall.Car, lap: pitwall.laps.Lap)
---@field onBestLap? fun(car: pitwall.Car, lap: pitwall.laps.Lap)
local Timer = {}

---Forgets every lap: the next finish crossing starts lap 1.
function Timer:reset() end

---Stops timing this car.
function Timer:cancel() end]],
  },
  {
    file = "pitwall/laps.lua",
    class = "pitwall.laps",
    declare = "local laps",
    module = "pitwall.laps",
    returns = "laps",
    doc = [[Lap timing (require "pitwall.laps"; docs/racing.md "Lap timing").]],
    settable = {
      onLap = { "fun(car: pitwall.Car, lap: pitwall.laps.Lap)", "every timer's laps, after the timer's own" },
      onBestLap = { "fun(car: pitwall.Car, lap: pitwall.laps.Lap)", "every timer's best laps" },
    },
    functions = {
      timer = [[A lap timer for `car` on `map`.
@param car pitwall.Car
@param map pitwall.track.Map
@param options? pitwall.laps.Options
@return pitwall.laps.Timer]],
      sectors = [[The default sectors of `map`: the piece indices where each sector begins.
@param map pitwall.track.Map
@return integer[] ]],
    },
  },
  -- pitwall.drivers -------------------------------------------------------------------------
  {
    file = "pitwall/drivers.lua",
    text = [[
---A driver: a table with methods, all optional except update (docs/racing.md "Drivers").
---@class pitwall.drivers.Driver
---@field name? string
local Driver = {}

---Once, when the car may drive (the green light).
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
function Driver:start(car, ctx) end

---Every ctx.period s while the car races; it commands the car itself.
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
function Driver:update(car, ctx) end

---Optional: every ctx.period s while the start lights are on (a human's throttle); a car that moves then jumps the start.
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
function Driver:waiting(car, ctx) end

---When the car's race is over.
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
function Driver:finish(car, ctx) end

---In the old version, just before a reload: plain data and cars for the new driver.
---@return table?
function Driver:handover() end

---In the new version, instead of start, for a car that is racing.
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
---@param state table? what the old driver handed over
---@param from string? the old driver's name
function Driver:takeover(car, ctx, state, from) end

---A driver class: drivers.load returns one; new makes a driver.
---@class pitwall.drivers.Class
---@field name string
---@field new fun(options?: table): pitwall.drivers.Driver

---A car near this one (ctx:ahead, ctx:nearby).
---@class pitwall.drivers.Other
---@field car pitwall.Car
---@field loc pitwall.localize.Tracker
---@field gap number centre-line mm (nearby: signed, + ahead)
---@field time? number gap / our speed, s (ahead only)
---@field lane number its offset, mm

---What a driver drives with (drivers.context).
---@class pitwall.drivers.Context
---@field car pitwall.Car
---@field map pitwall.track.Map
---@field loc pitwall.localize.Tracker
---@field period number s between updates
---@field limit? number a speed cap, mm/s: every driver respects it
local Context = {}

---The nearest car ahead in driving order on the same map, any lane, or nil.
---@return pitwall.drivers.Other?
function Context:ahead() end

---Every car within `range` mm along the centre line, sorted by gap.
---@param range number
---@return pitwall.drivers.Other[]
function Context:nearby(range) end

---The map pieces the car covers in the next `distance` mm, the piece it is on first.
---@param distance number
---@return pitwall.track.Piece[]
function Context:upcoming(distance) end

---What drivers.run returns.
---@class pitwall.drivers.Handle
---@field updates integer
---@field running boolean
local Handle = {}

---Stops calling the driver (calls finish; it does not stop the car).
function Handle:stop() end]],
  },
  {
    file = "pitwall/drivers.lua",
    class = "pitwall.drivers",
    declare = "local drivers",
    module = "pitwall.drivers",
    returns = "drivers",
    doc = [[Autonomous drivers and their context (require "pitwall.drivers"; docs/racing.md "Drivers").]],
    functions = {
      names = [=[The names of the drivers drivers.load finds (pitwall/drivers/*.lua along package.path), sorted.
@return string[]]=],
      checkOptions = [=[Checks a driver's options: every key must be one of `known`, else an error on the script's line naming `name` ("cruiser.new: unknown option spede; did you mean speed?").
@param name string
@param options table|nil
@param known string[]]=],
      pick = [=[The options of `options` that are in `known` (what a driver hands to the driver inside it).
@param options table
@param known string[]
@return table]=],
      optionList = [=[A list of the names in all the lists given, in order, each once.
@param ... string[]
@return string[]]=],
      load = [[The driver class named `x` (pitwall.drivers.<x>: "cruiser", "follower", "human", "lanekeeper", "overtaker"), or `x` itself when it is a table.
@param x string|pitwall.drivers.Class
@return pitwall.drivers.Class]],
      context = [[The context a driver drives `car` with; `field` lists every racing car ({car =, loc =} or a bare car).
@param car pitwall.Car
@param map pitwall.track.Map
@param field (pitwall.Car|{car: pitwall.Car, loc: pitwall.localize.Tracker})[]
@param options? {period?: number, limit?: number}
@return pitwall.drivers.Context]],
      run = [[Drives `car` with `driver` in a task of its own until handle:stop().
@param car pitwall.Car
@param driver pitwall.drivers.Driver
@param ctx pitwall.drivers.Context
@return pitwall.drivers.Handle]],
      world = [[A driver for `car` from the Lua file `file`, in a world of its own (docs/drivers.md): the file returns a driver class or a driver; the world commands `car` only and reads no file; its failure stops `car` and shows in `driver.world.failure`.
@param file string
@param car pitwall.Car
@return pitwall.drivers.Driver]],
      isFile = [[True for a driver given as a file name (a string ending in .lua), which a race runs with drivers.world.
@param spec any
@return boolean]],
      call = [[Calls driver[method] if it has one, reporting an error like drivers.run does.
@param driver pitwall.drivers.Driver
@param method string
@param car pitwall.Car
@param ctx pitwall.drivers.Context]],
      setSpeed = [[Sends setSpeed only when it changes something (by `step` mm/s, default 10); true when it sent.
@param car pitwall.Car
@param speed number mm/s
@param accel? number mm/s²
@param step? number mm/s
@return boolean sent]],
      cap = [[The speed cap of ctx applied to `v`.
@param ctx pitwall.drivers.Context
@param v number
@return number]],
      aheadIn = [[The nearest car ahead within `width` mm (45) of `lane`, within `range` mm, or nil; `skip(o)` true leaves a car out.
@param ctx pitwall.drivers.Context
@param lane number
@param range number
@param width? number
@param skip? fun(o: pitwall.drivers.Other): boolean
@return pitwall.drivers.Other?]],
      changing = [[A lane change is under way (unless the reported offset already reached the target).
@param car pitwall.Car
@return boolean]],
      moving = [[The car reported a position within `within` s (0.5) and a speed above 0.
@param car pitwall.Car
@param within? number
@return boolean]],
    },
  },
  -- the drivers shipped (pitwall.drivers.<name>) ------------------------------------------
  {
    file = "pitwall/drivers/cruiser.lua",
    text = [[
---Options of cruiser.new (every driver built on a cruiser takes them too).
---@class pitwall.drivers.CruiserOptions
---@field speed? number mm/s on straights (default 1000)
---@field lateral? number mm/s², the curve speed is at most √(lateral · r) (default 7000)
---@field accel? number mm/s² (default 2000)
---@field decel? number mm/s², braking before a curve (default 5000)

---A cruiser: its speed on straights, slower in curves, capped by ctx.limit.
---@class pitwall.drivers.Cruiser: pitwall.drivers.Driver
local Cruiser = {}

---The speed it would drive now, without sending it (for other drivers).
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
---@return number
function Cruiser:target(car, ctx) end]],
  },
  {
    file = "pitwall/drivers/cruiser.lua",
    class = "pitwall.drivers.cruiser",
    declare = "local cruiser",
    module = "pitwall.drivers.cruiser",
    returns = "cruiser",
    doc = [[Drives at a target speed, slower in curves (require "pitwall.drivers.cruiser", drivers.load "cruiser").]],
    fields = {
      name = { "string", "\"cruiser\"" },
      options = { "string[]", "the option names new takes (its own and those of the drivers inside it)" },
    },
    functions = {
      new = [[A cruiser.
@param options? pitwall.drivers.CruiserOptions
@return pitwall.drivers.Cruiser]],
    },
  },
  {
    file = "pitwall/drivers/human.lua",
    text = [[
---Options of human.new.
---@class pitwall.drivers.HumanOptions
---@field seat integer|pitwall.Seat the seat the person drives from
---@field max? number mm/s at full throttle (default 1200)
---@field min? number mm/s at the least throttle that moves (default 300)
---@field accel? number mm/s² (default 2500)
---@field decel? number mm/s² (default 4000)
---@field assist? boolean cap curve speeds at the cruiser's (default false)

---A human driver: the seat's throttle and lane steps, under ctx.limit.
---@class pitwall.drivers.Human: pitwall.drivers.Driver
---@field seat pitwall.Seat
local Human = {}

---The speed the seat asks for now, without sending it.
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
---@return number
function Human:target(car, ctx) end

---While the start lights are on: the throttle goes through (a jump start is caught).
---@param car pitwall.Car
---@param ctx pitwall.drivers.Context
function Human:waiting(car, ctx) end]],
  },
  {
    file = "pitwall/drivers/human.lua",
    class = "pitwall.drivers.human",
    declare = "local human",
    module = "pitwall.drivers.human",
    returns = "human",
    doc = [[A person drives, from a seat (require "pitwall.drivers.human", drivers.load "human"; docs/racing.md "Human drivers").]],
    fields = {
      name = { "string", "\"human\"" },
      options = { "string[]", "the option names new takes" },
    },
    functions = {
      new = [[A human driver.
@param options pitwall.drivers.HumanOptions
@return pitwall.drivers.Human]],
    },
  },
  {
    file = "pitwall/drivers/follower.lua",
    text = [[
---Options of follower.new; the cruiser's options go to its cruiser.
---@class pitwall.drivers.FollowerOptions: pitwall.drivers.CruiserOptions
---@field gap? number s kept behind the car ahead in its lane (default 1.0)
---@field margin? number (default 0.1)
---@field standstill? number mm (default 100)
---@field range? number mm

---@class pitwall.drivers.Follower: pitwall.drivers.Driver]],
  },
  {
    file = "pitwall/drivers/follower.lua",
    class = "pitwall.drivers.follower",
    declare = "local follower",
    module = "pitwall.drivers.follower",
    returns = "follower",
    doc = [[Cruises, but keeps at least `gap` seconds behind the car ahead in its lane (require "pitwall.drivers.follower").]],
    fields = {
      name = { "string", "\"follower\"" },
      options = { "string[]", "the option names new takes (its own and those of the drivers inside it)" },
    },
    functions = {
      new = [[A follower.
@param options? pitwall.drivers.FollowerOptions
@return pitwall.drivers.Follower]],
    },
  },
  {
    file = "pitwall/drivers/lanekeeper.lua",
    text = [[
---Options of lanekeeper.new; the rest go to the inner driver.
---@class pitwall.drivers.LanekeeperOptions: pitwall.drivers.CruiserOptions
---@field offset? number the lane, mm (default 23)
---@field tolerance? number mm (default 10)
---@field driver? string|pitwall.drivers.Class|pitwall.drivers.Driver the inner driver (default a cruiser)
---@field retry? number s between lane-change requests (default 1)
---@field lateralSpeed? number mm/s (default 300)

---@class pitwall.drivers.Lanekeeper: pitwall.drivers.Driver]],
  },
  {
    file = "pitwall/drivers/lanekeeper.lua",
    class = "pitwall.drivers.lanekeeper",
    declare = "local lanekeeper",
    module = "pitwall.drivers.lanekeeper",
    returns = "lanekeeper",
    doc = [[Keeps the car in a lane while an inner driver drives the speed (require "pitwall.drivers.lanekeeper").]],
    fields = {
      name = { "string", "\"lanekeeper\"" },
      options = { "string[]", "the option names new takes (its own and those of the drivers inside it)" },
    },
    functions = {
      new = [[A lane keeper.
@param options? pitwall.drivers.LanekeeperOptions
@return pitwall.drivers.Lanekeeper]],
    },
  },
  {
    file = "pitwall/drivers/overtaker.lua",
    text = [[
---Options of overtaker.new; the rest go to its follower.
---@class pitwall.drivers.OvertakerOptions: pitwall.drivers.FollowerOptions
---@field lanes? number[] its lane and the passing lane, mm (default {-68, 68})
---@field margin? number mm (default 250)
---@field range? number mm (default 900)
---@field slower? number mm/s (default 50)
---@field lateralSpeed? number mm/s (default 500)

---@class pitwall.drivers.Overtaker: pitwall.drivers.Driver
---@field passes integer passes so far]],
  },
  {
    file = "pitwall/drivers/overtaker.lua",
    class = "pitwall.drivers.overtaker",
    declare = "local overtaker",
    module = "pitwall.drivers.overtaker",
    returns = "overtaker",
    doc = [[Cruises in its lane and passes slower cars in another (require "pitwall.drivers.overtaker").]],
    fields = {
      name = { "string", "\"overtaker\"" },
      options = { "string[]", "the option names new takes (its own and those of the drivers inside it)" },
    },
    functions = {
      new = [[An overtaker.
@param options? pitwall.drivers.OvertakerOptions
@return pitwall.drivers.Overtaker]],
    },
  },
  -- pitwall.board ---------------------------------------------------------------------------
  {
    file = "pitwall/board.lua",
    text = [[
---A column of a board.
---@class pitwall.board.Column
---@field key string the row field shown
---@field title? string
---@field align? "left"|"right"
---@field format? fun(value: any, row: table): string

---What Board.new takes.
---@class pitwall.board.Spec
---@field title? string
---@field columns pitwall.board.Column[]
---@field out? pitwall.Stdout default pitwall.stdout (for tests)
---@field tty? boolean default: pitwall.terminal().tty (for tests)]],
  },
  {
    file = "pitwall/board.lua",
    class = "pitwall.Board",
    declare = "local Board",
    module = "pitwall.board",
    returns = "Board",
    doc = [[A table on the terminal that redraws in place (require "pitwall.board").]],
    functions = {
      new = [[A board with `spec.columns` and an optional `spec.title`.
@param spec pitwall.board.Spec
@return pitwall.Board]],
      time = [["1:02.345" from seconds (minutes only from a minute on: "4.125"); "-" for nil.
@param seconds number?
@return string]],
      duration = [[A duration with its unit: "9.215 s", "1 min 2.345 s"; "-" for nil.
@param seconds number?
@return string]],
      gap = [[The gap to the leader: "+1.234", or "+1 lap" / "+2 laps"; "" for the leader.
@param seconds number?
@param laps? integer laps behind
@return string]],
    },
    methods = {
      render = [[The board's lines for `rows`, as plain text (no escapes).
@param rows table[]
@return string[] ]],
      show = [[Draws `rows` in place of the last drawing (terminals only; elsewhere it does nothing).
@param rows table[] ]],
      final = [[Prints `rows` as the final table, wherever stdout goes.
@param rows table[] ]],
    },
  },
  -- pitwall.race ----------------------------------------------------------------------------
  {
    file = "pitwall/race.lua",
    text = [[
---A driver as race options take it: a name, a class, a driver, or nil for the default.
---@alias pitwall.race.DriverSpec string|pitwall.drivers.Class|pitwall.drivers.Driver

---Options of a session: race.laps{…}, race.timed{…}, race.qualifying{…}, race.practice{…}, race.new{…}.
---@class pitwall.race.Options
---@field mode? "laps"|"timed"|"qualifying"|"practice" race.new only (default "laps")
---@field laps? integer laps of a race (race.laps), or of qualifying / practice
---@field minutes? number length of a timed race, qualifying or practice
---@field seconds? number the same in seconds
---@field cars? pitwall.Car[] default pitwall.cars() but the ghosts, which drive from the green light
---@field map? pitwall.track.Map a track map to race on
---@field scan? boolean|pitwall.track.ScanOptions drive a scan lap with the first car (unless a map is known)
---@field drivers? pitwall.race.DriverSpec|pitwall.race.DriverSpec[]|table<pitwall.Car|string, pitwall.race.DriverSpec>|fun(car: pitwall.Car, i: integer): pitwall.race.DriverSpec default "cruiser"
---@field grid? pitwall.race.Session|(pitwall.Car|string)[] the start order
---@field lights? integer start lights (default 5; 0: none)
---@field lightInterval? number s between lights (default 1)
---@field hold? number s from the last light to green (default 0.5)
---@field falseStartPenalty? number s a car that jumped the start is held after green (default 5)
---@field safety? {distance?: number, speed?: number}|false cap cars behind one that left the track (default {distance = 1000, speed = 300})
---@field cooldown? number mm/s a finished car drives on at (default 300)
---@field finishTimeout? number s after the winner finished until the session ends (default 60)
---@field reconnectTimeout? number s a car whose link is down is waited for before the session may end without it (default 30)
---@field period? number s between driver updates (default 0.1)
---@field gridSpeed? number mm/s to the grid (default 500)
---@field gridTimeout? number s to reach the grid (default 90)
---@field board? boolean the live leaderboard (default true)
---@field title? string the board's title (default: the mode's name)
---@field redraw? number s between redraws (default 0.25)
---@field results? string|false the results file (default pitwall.resultsFile)
---@field marshal? boolean see slow laps, free cars stuck in a contact, drive thrown cars on slowly (default true)
---@field searchSpeed? number mm/s: the most a car thrown off a curve is driven until it is found again (default 400)
---@field onLap? fun(car: pitwall.Car, lap: pitwall.laps.Lap, session: pitwall.race.Session)
---@field onFinish? fun(car: pitwall.Car, rank: integer, session: pitwall.race.Session)
---@field onPositionChange? fun(car: pitwall.Car, position: integer, old: integer, session: pitwall.race.Session)
---@field onFalseStart? fun(car: pitwall.Car, session: pitwall.race.Session)
---@field onLights? fun(k: integer, session: pitwall.race.Session)
---@field onThrown? fun(car: pitwall.Car, info: {piece: integer, speed: number, limit: number, action: string}, session: pitwall.race.Session)
---@field onSlowLap? fun(car: pitwall.Car, info: {lap: integer, took: number, reference: number, action: string}, session: pitwall.race.Session)
---@field onEnd? fun(session: pitwall.race.Session)

---A row of session:results().
---@class pitwall.race.Result
---@field position integer
---@field car string the car's name
---@field number integer
---@field driver? string the driver's name ("cruiser", "human")
---@field player? string who drives a human's seat (a phone's player name, the gamepad's)
---@field laps integer
---@field totalTime? number green to its last counted crossing, s
---@field bestLap? number s
---@field lastLap? number s
---@field status "finished"|"running"|"DNF"|"DNF (disconnected)" running: the session, or the run, ended first
---@field finished boolean
---@field falseStart boolean
---@field gap? number s how long ago the leader was where this car is (a finisher: behind the winner's finish)
---@field lapsBehind? integer
---@field reason? string why the car's driver world failed (a DNF at once: docs/drivers.md); empty otherwise

---The director's record of a car (session:entry).
---@class pitwall.race.Entry
---@field car pitwall.Car
---@field driver pitwall.drivers.Driver
---@field ctx pitwall.drivers.Context
---@field loc pitwall.localize.Tracker
---@field timer pitwall.laps.Timer
---@field position integer
---@field progress number
---@field limit? number
---@field finished boolean
---@field falseStart boolean

---A session of the race director.
---@class pitwall.race.Session
---@field mode "laps"|"timed"|"qualifying"|"practice"
---@field options pitwall.race.Options
---@field cars pitwall.Car[]
---@field title string
---@field green? number engine time of green
---@field map? pitwall.track.Map
---@field state string "new", "lights", "racing", "done"
---@field resultsPath? string the file written
local Session = {}

---Runs the session to its end inside a task; returns the session.
---@return pitwall.race.Session
function Session:run() end

---The result rows, in finishing order (qualifying, practice: best lap first).
---@return pitwall.race.Result[]
function Session:results() end

---The cars in result order: a grid for the next session.
---@return pitwall.Car[]
function Session:grid() end

---The director's record of a car.
---@param car pitwall.Car
---@return pitwall.race.Entry?
function Session:entry(car) end

---Ends the session now (from a handler or another task).
function Session:abort() end

---The driver that holds one speed (under ctx.limit).
---@class pitwall.race.Steady: pitwall.drivers.Class
---@field new fun(options?: {speed?: number, accel?: number}): pitwall.drivers.Driver]],
  },
  {
    file = "pitwall/race.lua",
    class = "pitwall.race",
    declare = "local race",
    module = "pitwall.race",
    returns = "race",
    doc = [[The race director (require "pitwall.race"; docs/racing.md "Races"). Each session call
runs a whole session inside a task and returns it when every car has stopped.]],
    fields = {
      columns = { "string[]", "the columns written to the results file, in order" },
      options = { "string[]", "the option names a session takes (race.laps{…} and the others)" },
      Steady = { "pitwall.race.Steady", "a driver that holds one speed: race.Steady.new{speed =}" },
    },
    settable = {
      onLap = { "fun(car: pitwall.Car, lap: pitwall.laps.Lap, session: pitwall.race.Session)",
        "every session's laps, after the session's own" },
      onFinish = { "fun(car: pitwall.Car, rank: integer, session: pitwall.race.Session)", "" },
      onPositionChange = {
        "fun(car: pitwall.Car, position: integer, old: integer, session: pitwall.race.Session)", "" },
      onFalseStart = { "fun(car: pitwall.Car, session: pitwall.race.Session)", "" },
      onThrown = { "fun(car: pitwall.Car, info: {piece: integer, speed: number, limit: number, action: string}, session: pitwall.race.Session)", "" },
      onSlowLap = { "fun(car: pitwall.Car, info: {lap: integer, took: number, reference: number, action: string}, session: pitwall.race.Session)", "" },
    },
    functions = {
      laps = [[A race of `laps` laps: lights; ranked by laps, then time.
@param options pitwall.race.Options
@return pitwall.race.Session]],
      timed = [[A timed race (`minutes` or `seconds`): lights; ranked by laps, then time.
@param options pitwall.race.Options
@return pitwall.race.Session]],
      qualifying = [[Qualifying (`minutes`, `seconds` or `laps`): lights, every car on its own, ranked by best clean lap.
@param options pitwall.race.Options
@return pitwall.race.Session]],
      practice = [[Free practice (`minutes`, `seconds` or `laps`): no lights.
@param options pitwall.race.Options
@return pitwall.race.Session]],
      new = [[A session, not started yet (session:run() runs it).
@param options pitwall.race.Options
@return pitwall.race.Session]],
      time = [["1:02.345" from seconds (Board.time).
@param seconds number?
@return string]],
      duration = [["9.215 s", "1 min 2.345 s" from seconds (Board.duration).
@param seconds number?
@return string]],
      winner = [[The sentence naming a session's winner: "Winner: nuke (overtaker), 5 laps in 21.470 s"; nil when nobody finished.
@param session pitwall.race.Session
@return string?]],
    },
  },
  -- pitwall.repl ----------------------------------------------------------------------------
  {
    file = "pitwall/repl.lua",
    class = "pitwall.repl",
    declare = "local repl",
    module = "pitwall.repl",
    returns = "repl",
    doc = [[The REPL's Lua half (require "pitwall.repl"; docs/lua-api.md).]],
    functions = {
      pretty = [[A readable string of any value; opts.depth (3), opts.maxItems (50), opts.width (100).
@param value any
@param opts? {depth?: integer, maxItems?: integer, width?: integer}
@return string]],
      show = [[The values given, each through pretty, joined by tabs; nil when there are none.
@param ... any
@return string?]],
      complete = [[Tab completion: the sorted candidates for the name at the end of `text`.
@param text string
@return string[] ]],
      bindCars = [[Sets the global `cars` to every car, by number and by name; nil when the script made its own.
@return table?]],
      describe = [[What help(value) prints: an object's or a module's methods, fields and events one line each, one function in full, else one line saying there is no help.
@param value any a car, robot, timer, pitwall table, library module, function, or a string naming one
@param objectTypes? table registry key → metatable, to recognise objects
@param columns? integer cut lines to this width (default: the terminal's; 0: never)
@return string]],
      overview = [[What help() prints: where to start.
@param columns? integer cut lines to this width (default: the terminal's; 0: never)
@return string]],
      environment = [[The _ENV of chunks typed at the prompt: the world's globals, and `help` where the world has none.
@param objectTypes? table registry key → metatable, for help
@param columns? integer the terminal's width for help (0: none)
@return table]],
    },
  },
}
