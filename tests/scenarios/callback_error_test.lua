-- An error in one callback is reported with a traceback; that car's other handlers, the other
-- cars and later events carry on.
-- tags: errors
local sim = require "pitwall.sim"

local errors = {}
pitwall.onError = function(message, where) errors[#errors + 1] = { message = message, where = where } end

local a = sim.addCar { lane = 1 }
local b = sim.addCar { lane = 4 }
local aPositions, aTransitions, bPositions = 0, 0, 0
a.onPosition = function(car, ev)
  aPositions = aPositions + 1
  if aPositions == 3 then error("boom in a handler") end
end
a.onTransition = function() aTransitions = aTransitions + 1 end
b.onPosition = function() bPositions = bPositions + 1 end
pitwall.after(0.5, function() local x = nil; return x.field end)  -- a timer that fails

a:setSpeed(600)
b:setSpeed(600)
sim.run(10)

expect.eq(#errors, 2, "errors reported")
-- in the order they came: the timer's (0.5 s) may come before or after the third position update
local handler, timer = errors[1], errors[2]
if handler.where:find("pitwall.after", 1, true) then handler, timer = timer, handler end
expect.truthy(handler.message:find("boom in a handler", 1, true), "the handler's message")
expect.truthy(handler.message:find("stack traceback", 1, true), "with a traceback")
expect.truthy(handler.where:find("onPosition handler of car 1", 1, true), "names the handler and car")
expect.truthy(timer.where:find("pitwall.after", 1, true), "names the timer")
expect.gt(aPositions, 20, "the failing handler is still called afterwards")
expect.gt(aTransitions, 5, "the same car's other handler carries on")
expect.gt(bPositions, 20, "the other car carries on")
