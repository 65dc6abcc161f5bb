-- The Lua half of the `pitwall` module, loaded into every run before the script.
-- See docs/lua-api.md.
local pitwall = pitwall

--- Waits inside a task until cond() is true, checking every `step` seconds (default 0.01) of
--- engine time. Returns true when it became true, false when `timeout` seconds passed first.
function pitwall.waitUntil(cond, timeout, step)
  if type(cond) ~= "function" then
    error("pitwall.waitUntil needs a function that returns true when done, got " .. type(cond), 2)
  end
  step = step or 0.01
  local deadline = timeout and pitwall.now() + timeout
  while not cond() do
    if deadline and pitwall.now() >= deadline then return false end
    pitwall.sleep(step)
  end
  return true
end

--- A shallow copy of a table: event tables are reused, so keep a copy to store one.
function pitwall.copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = v end
  return c
end

local sim = pitwall.sim
if sim then
  --- Adds a simulated car; inside a task it waits until the car is connected.
  function sim.addCar(spec)
    local car = sim._addCar(spec)
    if coroutine.isyieldable() then
      if not pitwall.waitUntil(function() return car.connected end, 5) then
        error("simulated car " .. tostring(car) .. " did not connect within 5 s", 2)
      end
    end
    return car
  end
  --- Runs the world for `seconds` of engine time (inside a task).
  sim.run = pitwall.sleep
  --- Runs until cond() holds; false if `timeout` seconds passed first.
  sim.runUntil = pitwall.waitUntil
  package.loaded["pitwall.sim"] = sim
else
  package.preload["pitwall.sim"] = function()
    error("pitwall.sim is only available when the run uses the built-in simulator", 2)
  end
end

return pitwall
