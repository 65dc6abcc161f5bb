-- The REPL's Lua half (pitwall.repl): values pretty-printed without running the user's
-- metamethods, Tab completion from raw keys and the car metatable, and the `cars` global.
-- tags: ui
local sim = require "pitwall.sim"
local repl = require "pitwall.repl"
local pretty, show, complete = repl.pretty, repl.show, repl.complete
-- the exact speed in what is printed (a real car's reading scatters: docs/simulator.md)
sim.sensor { model = "ideal" }

-- A table whose metamethods raise and count: showing or completing it must not trigger them.
local triggered = 0
local function trap(name)
  return function()
    triggered = triggered + 1
    error("metamethod " .. name .. " was called", 2)
  end
end
local function trapped(t)
  return setmetatable(t, {
    __index = trap("__index"), __newindex = trap("__newindex"), __pairs = trap("__pairs"),
    __len = trap("__len"), __eq = trap("__eq"), __lt = trap("__lt"), __le = trap("__le"),
    __concat = trap("__concat"), __call = trap("__call"),
  })
end

local function list(t) return table.concat(t, " ") end

---------------------------------------------------------------------------------------------------
-- pretty: scalars
expect.eq(pretty(42), "42")
expect.eq(pretty(1.5), "1.5")
expect.eq(pretty(2.0), "2.0", "a float stays a float, as Lua writes it")
expect.eq(pretty(-0.0), "-0.0")
expect.eq(pretty(1e100), "1e+100")
expect.eq(pretty(math.huge), "inf")
expect.eq(pretty(math.mininteger), "-9223372036854775808")
expect.eq(pretty(true), "true")
expect.eq(pretty(nil), "nil")
expect.eq(pretty("plain"), '"plain"')
expect.eq(pretty('say "hi"\nthen\tgo\\'), [["say \"hi\"\nthen\tgo\\"]], "quotes and newlines escaped")
expect.eq(pretty("\0" .. "1\27"), [["\0001\027"]], "control bytes: three digits, a digit after stays")
expect.eq(pretty("é ✓"), '"é ✓"', "UTF-8 as is")
expect.eq(pretty(print), "function: [C]")
local function here() end
expect.eq(pretty(here), "function: " .. debug.getinfo(1, "S").short_src .. ":" ..
  debug.getinfo(here, "S").linedefined)

-- pretty: tables, array part first, then numbers, strings, booleans
expect.eq(pretty({}), "{}")
expect.eq(pretty({ 1, 2, 3, x = 1, ["a b"] = 2 }), '{1, 2, 3, ["a b"] = 2, x = 1}')
expect.eq(pretty({ 10, 20, [5] = 50, [-1] = 0, [2.5] = 1, b = 1, a = 2, [true] = 3, ["end"] = 4 }),
  '{10, 20, [-1] = 0, [2.5] = 1, [5] = 50, a = 2, b = 1, ["end"] = 4, [true] = 3}',
  "key order; a keyword key is quoted")
expect.eq(pretty({ { 1, 2 }, { a = { b = true } } }), "{{1, 2}, {a = {b = true}}}")

-- depth
local deep = { 1, { 2, { 3, { 4, { 5 } } } } }
expect.eq(pretty(deep), "{1, {2, {3, {…}}}}", "three levels by default")
expect.eq(pretty(deep, { depth = 1 }), "{1, {…}}")
expect.eq(pretty(deep, { depth = 0 }), "{…}")
expect.eq(pretty({ {} }, { depth = 1 }), "{{}}", "an empty table hides nothing")
expect.eq(pretty(deep, { depth = 10 }), "{1, {2, {3, {4, {5}}}}}")

-- cycles, and a table seen twice without a cycle
local node = { name = "a" }
node.self = node
node.children = { node, { parent = node } }
expect.eq(pretty(node), '{children = {<cycle>, {parent = <cycle>}}, name = "a", self = <cycle>}')
local shared = { 1 }
expect.eq(pretty({ shared, shared }), "{{1}, {1}}", "shared, not cyclic")

-- wide: more than maxItems, and several lines when one is too wide
local wide = {}
for i = 1, 60 do wide[i] = i end
local w = pretty(wide)
expect.truthy(w:find("… (10 more)", 1, true), "the 10 beyond 50 are counted")
expect.truthy(w:find("50,", 1, true) and not w:find("51", 1, true), "items 1..50 only")
expect.eq(pretty({ 1, 2, 3, 4 }, { maxItems = 2 }), "{1, 2, … (2 more)}")
expect.eq(pretty({ a = 1, b = 2, c = 3 }, { maxItems = 1 }), "{a = 1, … (2 more)}")
for line in w:gmatch("[^\n]+") do expect.le(utf8.len(line), 100, "line width") end

local record = { name = string.rep("n", 60), inner = { x = 1, y = string.rep("y", 60) }, n = 1 }
local expected = table.concat({
  "{",
  "  inner = {x = 1, y = \"" .. string.rep("y", 60) .. "\"},",
  "  n = 1,",
  "  name = \"" .. string.rep("n", 60) .. "\",",
  "}",
}, "\n")
expect.eq(pretty(record), expected, "too wide for a line: one key a line, the inner fits")
expect.eq(pretty(record, { width = 200 }):find("\n"), nil, "fits in 200")
local nested = pretty({ inner = { a = string.rep("a", 50), b = string.rep("b", 50) } })
expect.eq(nested, table.concat({
  "{",
  "  inner = {",
  "    a = \"" .. string.rep("a", 50) .. "\",",
  "    b = \"" .. string.rep("b", 50) .. "\",",
  "  },",
  "}",
}, "\n"), "nested tables indented")

-- metamethods are not called; __tostring is used for tables that have it
local guarded = trapped({ 1, 2, key = "v" })
expect.eq(pretty(guarded), '{1, 2, key = "v"}')
expect.eq(pretty({ inner = guarded, [guarded] = 1 }):find("inner = {1, 2, key = \"v\"}", 1, true) ~= nil,
  true, "as a value and as a key")
expect.eq(triggered, 0, "no metamethod triggered while printing")
expect.eq(pretty(setmetatable({}, { __tostring = function() return "<vector 1 2>" end })), "<vector 1 2>")
expect.truthy(pretty(setmetatable({}, { __tostring = function() error("broken") end })):find("broken"),
  "a __tostring that raises is reported, not raised")

-- show: what a chunk returned
expect.eq(show(), nil, "no values")
expect.eq(show(nil), "nil")
expect.eq(show(1), "1")
expect.eq(show(1, "two", nil, { 3 }), '1\t"two"\tnil\t{3}')
expect.eq(show(nil, nil), "nil\tnil")

---------------------------------------------------------------------------------------------------
-- cars: bindCars, pretty, completion
expect.eq(rawget(_G, "cars"), nil)
local gs = sim.addCar { name = "groundshock", model = "groundshock", lane = 2 }
local sk = sim.addCar { name = "skull", model = "skull", lane = 3 }

local bound = repl.bindCars()
expect.eq(cars, bound, "the global is set")
expect.eq(cars[1], gs)
expect.eq(cars[2], sk)
expect.eq(cars.groundshock, gs)
expect.eq(cars.skull, sk)
expect.eq(#cars, 2)

local later = sim.addCar { name = "nuke", model = "nuke", lane = 4 }
cars.note = "mine"
repl.bindCars()
expect.eq(cars, bound, "refreshed in place")
expect.eq(cars[3], later, "a car that joined later")
expect.eq(cars.nuke, later)
expect.eq(cars.note, "mine", "what the operator stored is kept")

-- a car gone from the list is gone from the table
local realCars = pitwall.cars
pitwall.cars = function() return { sk } end
repl.bindCars()
pitwall.cars = realCars
expect.eq(cars[1], sk)
expect.eq(cars[2], nil)
expect.eq(cars.groundshock, nil)
expect.eq(cars.skull, sk)
repl.bindCars()
expect.eq(cars[1], gs)

-- a script's own `cars` is left alone
local mine = { "not", "cars" }
cars = mine
expect.eq(repl.bindCars(), nil)
expect.eq(cars, mine, "not clobbered")
expect.eq(cars[1], "not")
cars = nil
expect.eq(repl.bindCars(), bound, "bound again once the script's is gone")

-- a car, pretty-printed from its fields
expect.eq(pretty(gs), "<car 1 groundshock: speed 0 mm/s, offset -23 mm, connected>",
  "before its first position: where the simulator put it (lane 2)")
gs:setSpeed(600)
expect.truthy(sim.runUntil(function() return gs.piece ~= nil and gs.speed == 600 end, 10), "moving")
local function mm(n) return (string.format("%.1f", n):gsub("%.0$", "")) end
expect.eq(pretty(gs), string.format("<car 1 groundshock: speed 600 mm/s, piece %d, offset %s mm, connected>",
  gs.piece, mm(gs.offset)))
expect.truthy(pretty({ gs }):find("{<car 1 groundshock: speed 600 mm/s", 1, true), "inside a table")
expect.truthy(show(gs, 1):find("^<car 1 groundshock: .*>\t1$"), "show")
gs:stop()
later:disconnect()
expect.truthy(sim.runUntil(function() return not later.connected end, 5), "disconnected")
expect.truthy(pretty(later):find(", disconnected>$"), pretty(later))

-- other userdata (a timer) through its __tostring
local timer = pitwall.after(100, function() end)
expect.eq(pretty(timer), tostring(timer))

---------------------------------------------------------------------------------------------------
-- completion
expect.eq(list(complete("pitwa")), "pitwall")
expect.eq(list(complete("pitwall.af")), "pitwall.after")
expect.eq(list(complete("pitwall.ca")), "pitwall.cancel pitwall.car pitwall.cars")
expect.eq(list(complete("string.fo")), "string.format")
expect.eq(list(complete("cars[1]:setSp")), "cars[1]:setSpeed", "a car method")
expect.eq(list(complete("cars.groundshock.spe")), "cars.groundshock.speed", "a car field")
expect.eq(list(complete('cars["groundshock"]:chan')), 'cars["groundshock"]:changeLane')
expect.eq(list(complete("cars[1]:spe")), "", "after : only methods")
expect.eq(list(complete("cars[1]:s")), "cars[1]:setOffset cars[1]:setSpeed cars[1]:stop")
local offered = {}
for _, e in ipairs(complete("cars[1].on")) do offered[e] = true end
local eventNames = debug.getmetatable(gs).__events
expect.eq(#eventNames, 17)
for _, e in ipairs(eventNames) do expect.truthy(offered["cars[1]." .. e], "event " .. e .. " offered") end
expect.truthy(offered["cars[1].onPosition"])
expect.truthy(offered["cars[1].onTrack"] and offered["cars[1].onCharger"], "and the fields named on…")
expect.eq(#complete("cars[1].on"), 17 + 2, "nothing else")
expect.eq(complete("cars[1].on")[1], "cars[1].onBattery", "sorted")
gs.laps = 3
expect.eq(list(complete("cars[1].la")),
  "cars[1].laneChanging cars[1].laps cars[1].lastPing cars[1].lastPositionTime", "the car's own fields too")
expect.eq(list(complete('("x"):up')), '("x"):upper', "string methods on a literal")
expect.eq(list(complete("cars.groundshock.name:up")), "cars.groundshock.name:upper", "through a car field")
greeting = "hello"
expect.eq(list(complete("greeting:rev")), "greeting:reverse", "string methods on a string")
expect.eq(list(complete("ret")), "return", "a keyword")
expect.eq(list(complete("fun")), "function")
expect.eq(list(complete("local x = pitwall.no")), "local x = pitwall.now", "the line's start is kept")
expect.eq(list(complete("timer:ca")), "", "a local is not a global")
replTimer = timer
expect.eq(list(complete("replTimer:ca")), "replTimer:cancel", "userdata methods through an __index table")

-- nothing for what is unknown or not a name chain
expect.eq(#complete("nosuchname"), 0)
expect.eq(#complete("nosuch.thing"), 0)
expect.eq(#complete("pitwall.zzz"), 0)
expect.eq(#complete("cars[9]."), 0)
expect.eq(#complete("pitwall.cars():"), 0, "a call is never made")
expect.eq(#complete('pitwall.car("skull"):up'), 0, "a call with a string argument is not a string")
expect.eq(#complete("0x1f"), 0)
expect.eq(#complete(nil), 0, "not a string")

-- __index tables are followed, __index functions never called
local Class = { speak = function() end, shout = function() end }
Class.__index = Class
pet = setmetatable({ sound = "woof" }, Class)
expect.eq(list(complete("pet.s")), "pet.shout pet.sound pet.speak")
expect.eq(list(complete("pet:s")), "pet:shout pet:speak", "only functions after :")
expect.eq(list(complete("pet._")), "", "the class's metamethods are not the object's names")
Animal = Class
expect.eq(list(complete("Animal.__")), "Animal.__index", "but the class's own")
trap1 = trapped({ visible = 1, nested = trapped({ deeper = 2 }) })
expect.eq(list(complete("trap1.")), "trap1.nested trap1.visible")
expect.eq(list(complete("trap1.nested.d")), "trap1.nested.deeper")
expect.eq(#complete("trap1.hidden.x"), 0, "a missing key is not looked up through __index")
expect.eq(#complete("trap1:v"), 0)
expect.eq(triggered, 0, "no metamethod triggered while completing")

-- the API, not the internals: names starting with _ only once the underscore is typed
expect.falsy(list(complete("pitwall.")):find("_", 1, true), "pitwall.<Tab> offers no _name")
expect.eq(list(complete("pitwall._setH")), "pitwall._setHub", "typed: offered")
expect.truthy(#complete("pitwall._") >= 5, "pitwall._<Tab> lists the internals")
_hiddenGlobal = 1
expect.eq(list(complete("_hidden")), "_hiddenGlobal", "a global whose name starts with _, typed")
expect.falsy(list(complete("")):find("_hiddenGlobal", 1, true), "not among all the globals")

---------------------------------------------------------------------------------------------------
-- the prompt's globals: the world's, and help, which scripts do not see
local types = { ["pitwall.car"] = debug.getmetatable(gs), ["pitwall.timer"] = debug.getmetatable(timer) }
local env = repl.environment(types, 0)
expect.eq(rawget(_G, "help"), nil, "help is no global of the world")
expect.eq(type(env.help), "function", "but the prompt has it")
expect.eq(env.pitwall, pitwall, "the world's globals read through")
local chunk = load("promptMade = 42 return help, pitwall.now ~= nil", "=stdin", "t", env)
local promptHelp, readPitwall = chunk()
expect.eq(promptMade, 42, "a global made at the prompt is the world's")
expect.eq(promptHelp, env.help)
expect.truthy(readPitwall)
expect.eq(repl.environment(types, 0), env, "one environment per world")
expect.eq(list(complete("hel")), "help", "Tab offers help at the prompt")
rawset(_G, "help", function() return "the script's own" end)
expect.eq(env.help(), "the script's own", "a script's global help wins")
rawset(_G, "help", nil)

-- help(x): from the binding's metadata and the LuaLS annotations (scripts/pitwall/types/)
local carHelp = repl.describe(gs, types, 0)
local function has(text, needle, what)
  expect.truthy(text:find(needle, 1, true), (what or needle) .. " in:\n" .. text)
end
has(carHelp, "<car 1 groundshock", "the car itself")
has(carHelp, "pitwall.Car", "its class")
has(carHelp, "methods (car:name(…)):")
has(carHelp, "setSpeed(speed, accel?, respectLimit?)  Sets the speed (frame 0x24).")
has(carHelp, "changeLane(offset, speed?, accel?)")
has(carHelp, "fields (car.name, read only):")
has(carHelp, "offset            number  offset from the road centre")
has(carHelp, "events (car.onX = function(car, e) … end):")
has(carHelp, "onPosition  ")
-- one line each: every method, field and event of the metatable is there
local lines = 0
for _ in carHelp:gmatch("\n  ") do lines = lines + 1 end
local mt = debug.getmetatable(gs)
local expected = #mt.__fields + #mt.__events
for name in pairs(mt.__methods) do if not name:find("^_") then expected = expected + 1 end end
expect.eq(lines, expected, "one line per method, field and event")
expect.falsy(carHelp:find("_setHub", 1, true), "no internals")

local pitwallHelp = repl.describe(pitwall, types, 0)
has(pitwallHelp, "pitwall.after(delay, fn)  ")
has(pitwallHelp, "pitwall.sleep(seconds)")
has(pitwallHelp, "pitwall.onCar  ", "a handler a script may set")
expect.falsy(pitwallHelp:find("_raise", 1, true), "no internals")
has(repl.describe(pitwall.sim, types, 0), "pitwall.sim.addCar(spec?)")
local raceHelp = repl.describe(require "pitwall.race", types, 0)
has(raceHelp, "race.laps(options)")
expect.eq(repl.describe("pitwall.race", types, 0), raceHelp, "by its module name")
expect.eq(repl.describe("race", types, 0), raceHelp, "by its short name")
has(repl.describe(timer, types, 0), "cancel()  Stops the timer")

-- one function in full
local afterHelp = repl.describe(pitwall.after, types, 0)
has(afterHelp, "pitwall.after(delay, fn) -> pitwall.Timer")
has(afterHelp, "Calls fn() once after `delay` ≥ 0 seconds.")
has(afterHelp, "delay    number seconds")
has(repl.describe(gs.setSpeed, types, 0), "car:setSpeed(speed, accel?, respectLimit?)  (pitwall.Car)")
has(repl.describe("changeLane", types, 0), "−70..70 mm", "a method by name")
has(repl.describe("pitwall.PositionEvent", types, 0), "piece     integer road piece id", "an event table")

-- lines cut to the terminal's width
local narrow = repl.describe(gs, types, 60)
for line in narrow:gmatch("[^\n]+") do
  if line:find("^  ") then expect.le(utf8.len(line), 60, line) end
end
has(narrow, "…", "a long description is cut")

-- what help does not know: one clear line
local function oneLine(text, needle)
  expect.falsy(text:find("\n", 1, true), "one line: " .. text)
  has(text, needle)
end
oneLine(repl.describe(nil, types, 0), "help: that is nil")
oneLine(repl.describe(42, types, 0), "help: no help for number 42")
oneLine(repl.describe({ 1, 2 }, types, 0), "help: no help for this table")
oneLine(repl.describe(string.format, types, 0), "string.format is Lua's own")
oneLine(repl.describe(string, types, 0), "string is Lua's own library")
oneLine(repl.describe(env.help, types, 0), "help: help() says where to start")
oneLine(repl.describe(function() end, types, 0), "it is not part of pitwall's API")
oneLine(repl.describe("nosuchthing", types, 0), 'nothing in pitwall\'s API is called "nosuchthing"')
oneLine(repl.describe(gs, nil, 0), "help: no help for userdata")

-- help(): where to start
local overview = repl.overview(0)
has(overview, "help(cars[1])")
has(overview, "help(pitwall)")
has(overview, "help(pitwall.sim)")
has(overview, 'help "pitwall.race"')
has(overview, "pitwall.track")
has(overview, ":help :cars :quit")
