-- The Lua half of the `pitwall` module, loaded into every run before the script.
-- See docs/lua-api.md.
local pitwall = pitwall

-- Errors the library raises name the script's line that called into it, never a line of the
-- library: pitwall._raise(message) (C++, bindings/lua_args.hpp pushUserWhere) walks out of
-- scripts/pitwall/ however deep the library called itself. raise is the library's error().
local raise = pitwall._raise

--- Re-raises `err` (an error caught inside the library) with `prefix`, naming the script's line:
--- the position it carried (a line of the library, or the script's already) is dropped.
function pitwall._rethrow(prefix, err)
  if type(err) == "string" then err = err:gsub("^[^\n]-:%d+: ", "", 1) end
  raise((prefix or "") .. tostring(err))
end

--- Checks the option table `options` of `fnName` ("race.laps"): every key must be one of
--- `known`, else an error on the script's line: "race.laps: unknown option lapz; did you mean
--- laps? (the options are …)". A non-table `options` is left to the caller.
function pitwall._checkOptionsOf(fnName, options, known)
  if type(options) == "table" then pitwall._checkOptions(fnName, options, known) end
  return options
end

--- Waits inside a task until cond() is true, checking every `step` seconds (default 0.01) of
--- engine time. Returns true when it became true, false when `timeout` seconds passed first.
function pitwall.waitUntil(cond, timeout, step)
  if type(cond) ~= "function" then
    raise("pitwall.waitUntil needs a function that returns true when done, got " .. type(cond))
  end
  step = step or 0.01
  local deadline = timeout and pitwall.now() + timeout
  while not cond() do
    if deadline and pitwall.now() >= deadline then return false end
    pitwall.sleep(step)
  end
  return true
end

-- Listeners: pitwall.listen(car, "onPosition", fn) lets libraries (and scripts) follow a car's
-- events without taking its `car.onPosition` slot. Each car and event has one hub function in
-- the engine, which runs that event's listeners in subscription order before the car's own
-- handler. The lists are copied on write: a listener added or cancelled while an event is
-- being delivered takes effect from the next event.
local listeners = setmetatable({}, { __mode = "k" }) -- car → { [event] = { entry, … } }

local Subscription = {}
Subscription.__index = Subscription
Subscription.__name = "listener"

--- Ends the subscription; true if it was active.
function Subscription:cancel()
  local entry = self.entry
  if not entry.active then return false end
  entry.active = false
  local byEvent = listeners[self.car]
  local old = byEvent[self.event]
  local new = {}
  for _, e in ipairs(old) do
    if e ~= entry then new[#new + 1] = e end
  end
  if #new == 0 then
    byEvent[self.event] = nil
    pitwall._setHub(self.car, self.event, nil)
  else
    byEvent[self.event] = new
  end
  return true
end

function Subscription:__tostring()
  return string.format("listener of %s %s%s", tostring(self.car), self.event,
    self.entry.active and "" or " (cancelled)")
end

--- Calls fn(car, ev) on every `event` of `car` ("onPosition", …; not "onMessage"), before the
--- car's own handler. Returns a subscription: sub:cancel() ends it.
function pitwall.listen(car, event, fn)
  if type(event) ~= "string" then
    raise("pitwall.listen: the event is a name such as \"onPosition\", got " .. type(event))
  end
  if type(fn) ~= "function" then
    raise("pitwall.listen: the listener must be a function, got " .. type(fn))
  end
  local byEvent = listeners[car]
  local list = byEvent and byEvent[event]
  if not list then
    -- raises for something that is not a car, and for unknown events
    local ok, err = pcall(pitwall._setHub, car, event, function(c, ev)
      local current = listeners[c][event]
      for i = 1, #current do
        local e = current[i]
        if e.active then
          local fine, message = xpcall(e.fn, pitwall._traceback, c, ev)
          if not fine then
            pitwall._reportError(event .. " listener of " .. tostring(c), message)
          end
        end
      end
    end)
    if not ok then pitwall._rethrow("pitwall.listen: ", err) end
    byEvent = byEvent or {}
    listeners[car] = byEvent
    list = {}
  end
  local entry = { fn = fn, active = true }
  local new = table.move(list, 1, #list, 1, {})
  new[#new + 1] = entry
  byEvent[event] = new
  return setmetatable({ car = car, event = event, entry = entry }, Subscription)
end

-- What the library carries into the next version of the script (docs/hot-reload.md "A race
-- survives a reload"). A module registers a function that returns its state; at a reload the
-- engine calls pitwall._saveCarried() in the running version and copies the result into the new
-- one as pitwall._carried — plain data and cars; functions and metatables stay behind, and the
-- module of the new version takes the data up again. (pitwall.persist is the script's own.)
local carriers = {}
pitwall._carried = {}

--- Registers `save`, which returns module `name`'s state for the next version.
function pitwall._carry(name, save)
  if carriers[name] then raise("pitwall._carry: '" .. tostring(name) .. "' is carried already") end
  carriers[name] = save
end

--- The carried state of module `name` from the version before, or nil (first version).
function pitwall._takeCarried(name)
  return pitwall._carried[name]
end

-- The user code a carrier needs (a driver's handover) runs after every carrier has saved its own
-- data, each piece in an engine call of its own (pitwall._runHandover, called by the reloader
-- until it returns false): one that fails or runs over the callback budget costs only its own
-- piece, never the library's state.
local handovers = {}

--- Queues fn() to run after the carriers, in an engine call of its own.
function pitwall._afterCarry(fn)
  handovers[#handovers + 1] = fn
end

function pitwall._runHandover(i)
  local fn = handovers[i]
  if fn == nil then
    handovers = {}
    return false
  end
  handovers[i] = false
  if fn then
    local ok, err = xpcall(fn, pitwall._traceback)
    if not ok then pitwall._reportError("handing over into the new version", err) end
  end
  return true
end

function pitwall._saveCarried()
  handovers = {}
  local out = {}
  -- what this version did not take up (a version that never loaded the module: a save that
  -- briefly emptied the script) goes on to the next as it came
  for name, state in pairs(pitwall._carried) do
    if not carriers[name] then out[name] = state end
  end
  for name, save in pairs(carriers) do
    local ok, state = xpcall(save, pitwall._traceback)
    if ok then
      out[name] = state
    else
      pitwall._reportError("carrying " .. name .. " into the new version", state)
    end
  end
  return out
end

-- The library's last words (ScriptHost::lastWords): after the run's end has shut the script down
-- and stopped the cars, a module may still say where things stood — a race cut short prints its
-- final table and writes its results. Nothing can drive a car or start a timer by then.
local lastWords = {}

--- Registers fn() to run once at the end of the run, after the cars are stopped.
function pitwall._atRunEnd(fn)
  lastWords[#lastWords + 1] = fn
end

function pitwall._lastWords()
  for _, fn in ipairs(lastWords) do
    local ok, err = xpcall(fn, pitwall._traceback)
    if not ok then pitwall._reportError("the end of the run", err) end
  end
end

--- A shallow copy of a table: event tables are reused, so keep a copy to store one.
function pitwall.copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = v end
  return c
end

-- Robots ready when made: inside a task (the main chunk, pitwall.spawn) pitwall.mindroad{…} and
-- pitwall.alphabot{…} wait until the robot is connected (a MindRoad robot: in contact), up to
-- its timeout (contactTimeout, connectTimeout; 3 s by default), then close it and raise an error
-- naming the robot, its address and why. In a callback or at the REPL they return at once.
local function readyWhenMade(make, timeoutKey, notReady)
  return function(options)
    local ok, robot = pcall(make, options)
    -- (its error already names the script's line: the binding walks out of the library)
    if not ok then error(robot, 0) end
    if not coroutine.isyieldable() then return robot end
    local timeout = type(options) == "table" and options[timeoutKey] or 3
    if pitwall.waitUntil(function() return robot.connected end, timeout, 0.005) then
      return robot
    end
    local what = notReady(robot)
    robot:close()
    raise(string.format("%s after %g s (%s): %s", what.name, timeout, timeoutKey, what.why))
  end
end
if pitwall.mindroad then
  pitwall.mindroad = readyWhenMade(pitwall.mindroad, "contactTimeout", function(r)
    return {
      name = string.format("mindroad %s %s:%d has no contact", r.udp and "udp" or "tcp", r.host, r.port),
      why = r.lastError or ("still " .. r.phase),
    }
  end)
end
if pitwall.alphabot then
  pitwall.alphabot = readyWhenMade(pitwall.alphabot, "connectTimeout", function(r)
    return { name = "alphabot " .. r.address .. " is not connected", why = r.lastError or "no answer" }
  end)
end

local sim = pitwall.sim
if sim then
  --- Adds a simulated car; inside a task it waits until the car is connected.
  local function connected(car)
    if coroutine.isyieldable() then
      if not pitwall.waitUntil(function() return car.connected end, 5) then
        raise("simulated car " .. tostring(car) .. " did not connect within 5 s")
      end
    end
    return car
  end
  function sim.addCar(spec) return connected(sim._addCar(spec)) end
  --- The ghost of a recorded lap (docs/simulator.md "Ghosts"); waits as addCar does.
  function sim.addGhost(spec) return connected(sim._addGhost(spec)) end
  --- Runs the world for `seconds` of engine time (inside a task).
  sim.run = pitwall.sleep
  --- Runs until cond() holds; false if `timeout` seconds passed first.
  sim.runUntil = pitwall.waitUntil
  package.loaded["pitwall.sim"] = sim
else
  package.preload["pitwall.sim"] = function()
    raise("pitwall.sim is only available when the run uses the built-in simulator")
  end
end

return pitwall
