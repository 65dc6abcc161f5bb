-- Annotations of the car (the pitwall.car metatable: Anki cars, simulated, real and remote) and
-- of its event tables, for the LuaLS definitions (scripts/pitwall/types.lua, docs/lua-api.md
-- "Cars"). Methods: doc line(s), then @param/@return; fields: {type, doc}; events: {the
-- handler's arguments after the car, doc}.
return {
  {
    text = [[
---Every event table has `time`. Event tables are reused and read-only: keep pitwall.copy(ev).
---@class pitwall.Event
---@field time number engine seconds

---@class pitwall.PositionEvent: pitwall.Event
---@field piece integer road piece id
---@field location integer location id
---@field offset number mm from the road centre
---@field speed integer mm/s
---@field reverse boolean

---@class pitwall.TransitionEvent: pitwall.Event
---@field offset number mm
---@field leftWheel integer cm travelled on the piece left
---@field rightWheel integer cm travelled on the piece left
---@field drift integer px
---@field uphill integer
---@field downhill integer

---@class pitwall.IntersectionEvent: pitwall.Event
---@field piece integer
---@field offset number mm
---@field code integer 1 entry first, 2 exit first, 3 entry second, 4 exit second
---@field exiting boolean
---@field sinceTransition integer mm
---@field sinceIntersection? integer mm (newer firmware)

---@class pitwall.OffsetEvent: pitwall.Event
---@field offset number mm
---@field laneChangeId integer

---@class pitwall.BatteryEvent: pitwall.Event
---@field millivolts integer
---@field low boolean
---@field full boolean
---@field charging boolean

---@class pitwall.VersionEvent: pitwall.Event
---@field version integer

---@class pitwall.PingEvent: pitwall.Event
---@field rtt number round-trip time, s

---@class pitwall.StatusEvent: pitwall.Event
---@field onTrack boolean
---@field onCharger boolean
---@field lowBattery boolean
---@field fullyCharged boolean

---@class pitwall.CollisionEvent: pitwall.Event
---@field side integer
---@field where "front"|"back"

---@class pitwall.SpeedEvent: pitwall.Event
---@field desired integer mm/s
---@field accel? integer mm/s² (nil from firmware before 0x2b6e: its speed update says the desired speed only)
---@field actual? integer mm/s (nil from firmware before 0x2b6e)

---@class pitwall.LaneChangeEvent: pitwall.Event
---@field current number mm
---@field target number mm
---@field hSpeed integer
---@field vSpeed integer
---@field laneChangeId integer

---@class pitwall.RecoveryEvent: pitwall.Event
---@field succeeded boolean false: entered, true: succeeded

---@class pitwall.DisconnectEvent: pitwall.Event
---@field reason string

---@class pitwall.MalformedEvent: pitwall.Event
---@field error string names the id and the lengths
---@field hex string the frame

---Every decoded message, fields named as in `pitwall decode` (a fresh table each time).
---@class pitwall.MessageEvent: pitwall.Event
---@field name string
---@field id integer
---@field [string] any

---The lights by name: each one present is touched and set to its truth value.
---@class pitwall.Lights
---@field headlights? boolean
---@field brake? boolean
---@field front? boolean
---@field engine? boolean

---One channel of car:lightsPattern.
---@class pitwall.LightsChannel
---@field channel "red"|"tail"|"blue"|"green"|"front-left"|"front-right"|integer 0..5
---@field effect? "steady"|"fade"|"throb"|"flash"|"random"|integer 0..4 (default steady)
---@field from? integer intensity 0..14
---@field to? integer intensity 0..14
---@field cycles? integer per 10 s, 0..255]],
  },
  {
    metatable = "pitwall.car",
    class = "pitwall.Car",
    localName = "Car",
    self = "car",
    doc = [[A car: an Anki Overdrive car, simulated, real (BLE) or another host's (remote, over MQTT).
One object for the whole run (car == car holds); a script may store its own fields on it.
Commands check their arguments: out of range raises an error naming the range, and nothing is sent.]],
    fields = {
      name = { "string", "user name (simulated cars: the model's name, skull, skull-2, …)" },
      number = { "integer", "1-based number in join order" },
      model = { "string", "model name (Groundshock); unknown ids read model-<n>" },
      modelId = { "integer", "model id" },
      identifier = { "integer", "the car's 32-bit identifier from its advertisement" },
      ghost = { "boolean", "the simulator's ghost of a recorded lap (sim.addGhost)" },
      address = { "string", "sim:…, ble:ADDR or mqtt:CAR-ID" },
      connected = { "boolean", "link up" },
      onTrack = { "boolean", "from status reports and position updates" },
      onCharger = { "boolean", "from status reports" },
      delocalized = { "boolean", "the car lost the track" },
      reverse = { "boolean", "driving backwards" },
      speed = { "integer", "last reported speed, mm/s" },
      targetSpeed = { "integer", "last commanded speed, mm/s" },
      piece = { "integer?", "road piece id of the last position update" },
      location = { "integer?", "location id of the last position update" },
      prevPiece = { "integer?", "the piece of the position update before the last one" },
      offset = { "number", "offset from the road centre as the car believes it, mm (+ right)" },
      laneChanging = { "boolean", "a lane change is under way" },
      targetOffset = { "number?", "where the lane change under way goes, mm" },
      batteryLevel = { "integer?", "millivolts from the last battery answer" },
      batteryLow = { "boolean", "from status reports" },
      batteryFull = { "boolean", "from status reports" },
      firmware = { "integer?", "firmware version from the version answer" },
      lastPing = { "number?", "round-trip time of the last answered ping, s" },
      lastPositionTime = { "number?", "engine time of the last position update" },
      frames = { "integer", "frames in + out" },
      malformed = { "integer", "malformed frames received" },
      extraBytes = { "table<string, {frames: integer, last: string}>",
        "frames longer than their layout, by message name (a fresh table)" },
      link = { "{connects: integer, drops: integer, lastDrop: string?, writeFailures: integer, stalls: integer, rssi: integer?, silences: integer, longestSilence: number, roundTrip: number?}",
        "the link's health: connections made, drops and the last one's reason, refused writes, drops for writes that stalled, RSSI in dBm where the transport tells it, silences of a driving car (lost notifications) and the longest in s, the round trip of the last answered request in s (a fresh table)" },
    },
    events = {
      onPosition = { "e: pitwall.PositionEvent", "each location code the car reads" },
      onTransition = { "e: pitwall.TransitionEvent", "the car crosses a piece boundary" },
      onIntersection = { "e: pitwall.IntersectionEvent", "entering/leaving an intersection piece" },
      onDelocalized = { "e: pitwall.Event", "the car lost the track" },
      onOffset = { "e: pitwall.OffsetEvent", "a lane change finished / the offset was updated" },
      onBattery = { "e: pitwall.BatteryEvent", "answer to car:battery()" },
      onVersion = { "e: pitwall.VersionEvent", "answer to car:version()" },
      onPing = { "e: pitwall.PingEvent", "answer to car:ping()" },
      onStatus = { "e: pitwall.StatusEvent", "the car reports its status" },
      onCollision = { "e: pitwall.CollisionEvent", "the car ran into another" },
      onSpeed = { "e: pitwall.SpeedEvent", "speed update" },
      onLaneChange = { "e: pitwall.LaneChangeEvent", "lane-change progress" },
      onRecovery = { "e: pitwall.RecoveryEvent", "delocalization auto-recovery" },
      onConnect = { "e: pitwall.Event", "the link came up" },
      onDisconnect = { "e: pitwall.DisconnectEvent", "the link went down" },
      onMalformed = { "e: pitwall.MalformedEvent", "a frame that does not decode" },
      onMessage = { "e: pitwall.MessageEvent", "every decoded message (debugging; slower)" },
    },
    methods = {
      setSpeed = [[Sets the speed (frame 0x24).
@param speed integer mm/s, 0..1500
@param accel? integer mm/s², 0..25000 (default 1000)
@param respectLimit? boolean respect road-piece limits (default false)]],
      stop = [[Speed 0 at 12500 mm/s².]],
      changeLane = [[Changes lane to `offset` mm from the road centre; needs the car to be moving: refused while it stands, with what to do.
@param offset number −70..70 mm (lanes at about −68, −23, +23, +68)
@param speed? integer lateral mm/s, 0..1500 (default 300)
@param accel? integer lateral mm/s², 0..25000 (default 3000)]],
      setOffset = [[Tells the car where it is, so later lane changes are absolute.
@param offset number −70..70 mm]],
      cancelLaneChange = [[Cancels the lane change under way.]],
      uturn = [[A U-turn now.]],
      turn = [[Turns.
@param type "left"|"right"|"uturn"|"uturn-jump"|"none"
@param trigger? "immediate"|"intersection" (default "immediate")]],
      lights = [[Sets lights: a mask 0..255 (low nibble: lights touched, high nibble: their values) or a table of names.
@param lights integer|pitwall.Lights]],
      lightsPattern = [[Light effects on 1..3 channels.
@param channels pitwall.LightsChannel[] ]],
      ping = [[Asks for a ping; answered by onPing.]],
      battery = [[Asks for the battery level; answered by onBattery.]],
      version = [[Asks for the firmware version; answered by onVersion.]],
      disconnect = [[The car drops the connection.]],
    },
  },
}
