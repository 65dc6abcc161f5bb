-- Annotations of pitwall.sim (bindings/sim_binding.cpp, script_under_test.cpp, core.lua; docs/
-- lua-api.md "pitwall.sim"), for the LuaLS definitions (scripts/pitwall/types.lua).
return {
  {
    text = [[
---What sim.addCar{…} takes (all optional). Without a place, cars go to the next grid slot.
---@class pitwall.sim.CarSpec
---@field name? string
---@field model? string|integer model name or id
---@field piece? integer 1-based index into the track
---@field distance? number mm into that piece
---@field lane? integer 1..4 = −68, −23, +23, +68 mm
---@field offset? number −70..70 mm
---@field battery? integer 3000..4300 mV
---@field firmware? integer firmware version, e.g. 0x266e (the older layouts) or 0x2b70 (the default)

---What sim.addGhost{…} takes.
---@class pitwall.sim.GhostSpec
---@field record string a --record file
---@field car? integer|string the recorded car's number or name (default: the record's first car)
---@field lap? integer|"best" the lap (default: the car's best)
---@field name? string default: ghost (ghost2, … when taken)

---@class pitwall.sim.Piece
---@field id integer road piece id
---@field type string
---@field turn integer +1 left, −1 right, 0 straight
---@field length number mm
---@field radius? number a curve's centre radius, mm
---@field angle? number how far a curve turns, degrees

---@class pitwall.sim.Track
---@field name string
---@field lapLength number mm
---@field finishIndex integer
---@field pieces pitwall.sim.Piece[]

---Ground truth of a simulated car.
---@class pitwall.sim.Truth
---@field pieceIndex integer
---@field piece integer
---@field pieceDistance number mm
---@field lapDistance number mm
---@field offset number mm
---@field speed number mm/s
---@field targetSpeed number mm/s
---@field laps integer finish lines crossed
---@field onTrack boolean
---@field delocalized boolean
---@field sdkMode boolean
---@field connected boolean
---@field battery integer mV
---@field collisions integer
---@field slides integer times thrown off a curve and slid on, still on the road
---@field speedCommands integer set-speed frames it received
---@field stopCommands integer those asking for 0 mm/s

---@class pitwall.sim.Noise
---@field drop? number frame loss probability 0..1
---@field late? number delay probability 0..1
---@field lateBy? number the delay's upper bound, s

---@class pitwall.sim.Sensor
---@field model? "real"|"ideal"|"transitions" real (the default): fitted to real cars, position updates thin out with speed; ideal: every code; transitions: no position update at all (the worst case)

---@class pitwall.sim.ScriptOptions
---@field results? string its pitwall.resultsFile
---@field name? string how source text is named in errors (default script_under_test.lua)]],
  },
  {
    metatable = "pitwall.script_under_test",
    class = "pitwall.sim.ScriptUnderTest",
    localName = "ScriptUnderTest",
    doc = [[A script under test (sim.script): read-only; reading a field it does not have is an error.]],
    fields = {
      started = { "boolean", "its first version was started (or refused)" },
      finished = { "boolean", "it called pitwall.stop() (or the scenario ended it)" },
      version = { "integer", "the version running: 1, then one more per reload" },
      reloads = { "integer", "versions that took over" },
      refused = { "integer", "versions refused" },
      refusal = { "string?", "why the last version was refused" },
      died = { "boolean", "its main chunk failed" },
      errors = { "integer", "errors its world reported" },
    },
  },
  {
    class = "pitwall.sim",
    declare = "pitwall.sim",
    live = function() return pitwall.sim end,
    doc = [[The simulator (present when the run uses the built-in simulator; require "pitwall.sim").
See docs/testing.md and docs/simulator.md.]],
    functions = {
      addCar = [[Adds a simulated car and returns it; inside a task it waits until it is connected.
@param spec? pitwall.sim.CarSpec
@return pitwall.Car]],
      addGhost = [[The ghost of a recorded lap (docs/simulator.md "Ghosts"): a car that drives the lap again, lap after lap, while a set-speed above 0 holds, touching no one; inside a task it waits until it is connected.
@param spec pitwall.sim.GhostSpec
@return pitwall.Car]],
      track = [[The track.
@return pitwall.sim.Track]],
      setTrack = [[Replaces the track (a layout name, a file or layout text); only before any car is added.
@param track string]],
      layouts = [[The names of the built-in layouts.
@return string[] ]],
      openSeats = [[Opens seats 1..n for human drivers, as --humans N does (scenario tests feed them with seat:feed). Not there when the run has seats from --humans.
@param n integer 1..64
@return pitwall.Seat[] ]],
      truth = [[Ground truth of a car.
@param car pitwall.Car
@return pitwall.sim.Truth]],
      lift = [[Takes the car off the track (it delocalizes).
@param car pitwall.Car]],
      reboot = [[The car resets (a tired cell): its connection drops, it stands with everything forgotten, and it can be connected again `seconds` later; the link connects it again then.
@param car pitwall.Car
@param seconds? number 0..600 (default 3)]],
      place = [[Puts the car back on piece `piece` (1-based index) at `offset` mm.
@param car pitwall.Car
@param piece integer
@param offset? number −70..70 (default 0)]],
      noise = [[Frame loss and delay; returns the current setting.
@param noise? pitwall.sim.Noise
@return pitwall.sim.Noise]],
      sensor = [[What the simulated cars' sensors report (docs/simulator.md "Sensor model"); returns the current setting.
@param sensor? pitwall.sim.Sensor
@return pitwall.sim.Sensor]],
      script = [[Runs a script under test in Lua worlds of its own, as `pitwall run --watch` does.
@param pathOrSource string
@param options? pitwall.sim.ScriptOptions
@return pitwall.sim.ScriptUnderTest]],
      reload = [[Replaces the script under test with a new version at engine time `at` (default: at once).
@param pathOrSource string
@param at? number]],
      run = [[= pitwall.sleep(seconds).
@param seconds number]],
      runUntil = [[= pitwall.waitUntil(cond, timeout).
@param cond fun(): any
@param timeout? number
@param step? number
@return boolean held]],
    },
  },
  {
    file = "pitwall/sim.lua",
    text = "---The simulator's API (pitwall.sim), as require \"pitwall.sim\" returns it.",
    returns = "pitwall.sim",
  },
}
