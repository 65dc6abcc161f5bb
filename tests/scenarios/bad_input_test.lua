-- Bad input from scripts gets a clear error naming the value and what is accepted, and changes
-- nothing: pitwall.sim set-up, car commands and timers.
-- tags: errors
local sim = require "pitwall.sim"

-- The track: by name, by layout text, refused when it does not close or is unknown.
expect.eq(sim.setTrack("kidney").name, "kidney")
expect.eq(#sim.setTrack("start S L L S S L L").pieces, 9)
expect.fails(function() sim.setTrack("start S L L") end, "close")
expect.fails(function() sim.setTrack("nowhere") end, "nowhere")
expect.eq(sim.track().name, "custom", "a refused track leaves the last good one")

-- Cars: every field of sim.addCar is checked.
expect.fails(function() sim.addCar { lane = 5 } end, "1..4")
expect.fails(function() sim.addCar { piece = 0 } end, "out of range 1..9")
expect.fails(function() sim.addCar { offset = 150 } end, "offset 150 mm is off the road (-70..70 mm)")
expect.fails(function() sim.addCar { offset = -71 } end, "offset -71 mm is off the road (-70..70 mm)")
expect.fails(function() sim.addCar { model = "batmobile" } end, "batmobile")
expect.fails(function() sim.addCar { battery = 9000 } end, "3000..4300")
expect.fails(function() sim.addCar { piece = 2, distance = 5000 } end, "outside the piece")
expect.fails(function() sim.addCar(42) end, "takes a table")
expect.eq(#pitwall.cars(), 0, "no car was added by a refused call")

local car = sim.addCar { name = "one", model = "skull" }
expect.eq(car.model, "Skull")
expect.fails(function() sim.addCar { name = "one" } end, "already in the run")
expect.fails(function() sim.setTrack("oval") end, "once cars are on it")
expect.fails(function() sim.place(car, 99) end, "out of range 1..9")
expect.fails(function() sim.place(car, 1, 80) end, "offset 80 mm is off the road (-70..70 mm)")
expect.fails(function() sim.noise { drop = 2 } end, "0..1")
expect.eq(sim.noise().drop, 0, "a refused noise setting changes nothing")
expect.fails(function() sim.sensor { model = "perfect" } end,
  "sensor model 'perfect' is not one the simulator has; use \"real\"")
expect.fails(function() sim.sensor { model = string.rep("\xff", 100000) } end, "is not one the simulator has")
expect.fails(function() sim.sensor { modle = "real" } end, "modle")
expect.fails(function() sim.sensor { model = 1e308 } end, "sensor model")
expect.fails(function() sim.sensor("real") end, "sim.sensor takes a table")
expect.eq(sim.sensor().model, "real", "a refused sensor setting changes nothing")
expect.fails(function() sim.truth("car") end, "expected a car")
expect.fails(function() pitwall.car("nobody") end, "pitwall.car: no car named 'nobody'; the ")
expect.fails(function() pitwall.car(7) end, "pitwall.car: no car 7; the ")
expect.fails(function() pitwall.car(2 ^ 32 + 1) end, "pitwall.car: no car 4294967297; the ")

-- Car commands: types and ranges, and nothing sent.
local frames = car.frames
expect.fails(function() car:setSpeed(1500.5) end, "1501") -- rounded, then range-checked
expect.fails(function() car:setSpeed(-1) end, "0..1500")
expect.fails(function() car:setSpeed(600, 30000) end, "0..25000")
expect.fails(function() car:setOffset(0 / 0) end, "finite")
expect.fails(function() car:lights(256) end, "0..255")
expect.fails(function() car:lightsPattern {} end, "1 to 3 channels")
expect.fails(function() car:lightsPattern { { channel = "purple" } } end, "red, tail")
expect.fails(function() car:lightsPattern { { channel = 0, effect = 9 } } end, "0..4")
expect.fails(function() car:lightsPattern { { channel = 0, from = 15 } } end, "0..14")
expect.fails(function() car:turn("left", "someday") end, "immediate or intersection")
expect.eq(car.frames, frames, "refused commands sent nothing")

-- The same commands in range go out.
car:lightsPattern { { channel = "red", effect = "throb", from = 0, to = 14, cycles = 5 } }
car:lights { headlights = true, brake = false }
car:turn("left", "intersection")
expect.eq(car.frames, frames + 3)

-- Timers and tasks.
expect.fails(function() pitwall.after(-1, print) end, "must be ≥ 0 seconds, got -1")
expect.fails(function() pitwall.after(1, "print") end, "must be a function")
expect.fails(function() pitwall.spawn(nil) end, "must be a function")
expect.fails(function() car.onPosition = "nope" end, "function or nil")
