-- Annotations of the robots (pitwall.mindroad, pitwall.alphabot metatables; docs/robots.md) and
-- their options, for the LuaLS definitions (scripts/pitwall/types.lua).
return {
  {
    text = [[
---Options of pitwall.mindroad{…}; an unknown key is an error.
---@class pitwall.MindroadOptions
---@field host? string default "127.0.0.1"
---@field port? integer 1..65535, default 4000
---@field udp? boolean default false (TCP)
---@field watchdog? number the robot's watchdog period, s, 0.03..60 (default 0.5)
---@field contactTimeout? number how long a handshake or contact probe waits for K, s, 0.1..600 (default 3)

---Options of pitwall.alphabot{…}: host and port (WLAN, TCP) or ble; an unknown key is an error.
---@class pitwall.AlphabotOptions
---@field host? string
---@field port? integer 1..65535
---@field ble? string the robot's Bluetooth address
---@field connectTimeout? number s per attempt (default 3)

---@class pitwall.AlphabotDistanceEvent: pitwall.Event
---@field degree integer
---@field distance integer cm

---@class pitwall.AlphabotPositionEvent: pitwall.Event
---@field x integer cm
---@field y integer cm

---@class pitwall.AlphabotCompassEvent: pitwall.Event
---@field degree integer

---@class pitwall.AlphabotObstacleEvent: pitwall.Event
---@field id integer
---@field x integer
---@field y integer
---@field width integer
---@field height integer

---@class pitwall.AlphabotPathEvent: pitwall.Event
---@field waypoints {x: integer, y: integer}[] ending at the target
---@field reachable boolean

---@class pitwall.AlphabotMapSizeEvent: pitwall.Event
---@field length integer
---@field width integer

---@class pitwall.AlphabotAnchorEvent: pitwall.Event
---@field id integer
---@field x integer
---@field y integer]],
  },
  {
    metatable = "pitwall.mindroad",
    class = "pitwall.Mindroad",
    localName = "Mindroad",
    self = "robot",
    doc = [[A MindRoad robot car (pitwall.mindroad{…}; docs/robots.md). It belongs to the Lua world
that made it; a script may store its own fields on it.]],
    fields = {
      connected = { "boolean", "in contact" },
      host = { "string", "" },
      port = { "integer", "" },
      udp = { "boolean", "" },
      watchdog = { "number", "the robot's watchdog period, s" },
      phase = { "\"connecting\"|\"waiting for contact\"|\"contact\"|\"reconnecting\"|\"closed\"", "" },
      lastError = { "string?", "the last reason; nil while in contact" },
      contacts = { "integer", "handshakes that succeeded" },
    },
    events = {
      onContact = { "", "contact (the handshake's K)" },
      onLost = { "reason: string", "the link was lost (once per outage)" },
    },
    methods = {
      steer = [[Steers: x forward (+)/backward (−), y right (+)/left (−).
@param x integer −128..127
@param y integer −128..127]],
      click = [[A click in the 160×120 picture.
@param x integer 1..160
@param y integer 1..120]],
      buttons = [[Presses buttons: one button's name, a list of names (a bit mask), or the raw byte 0..255.
@param buttons string|string[]|integer]],
      pictureMode = [[The picture mode.
@param mode "rgb"|"hsv"|"filter"]],
      stop = [[The stop instruction.]],
      ping = [[An extra ping (pitwall pings by itself).]],
      shutdown = [[Turns the robot off; true when sent (at the REPL the first call only warns).
@return boolean sent]],
      close = [[Sends stop and closes the link; no more events.]],
    },
  },
  {
    metatable = "pitwall.alphabot",
    class = "pitwall.Alphabot",
    localName = "Alphabot",
    self = "robot",
    doc = [[An Alphabot (pitwall.alphabot{…}; docs/robots.md). It belongs to the Lua world that made it;
a script may store its own fields on it.]],
    fields = {
      connected = { "boolean", "" },
      x = { "integer?", "last reported position, cm" },
      y = { "integer?", "last reported position, cm" },
      heading = { "integer?", "last compass degree" },
      address = { "string", "tcp:HOST:PORT or ble:ADDR" },
      lastPing = { "number?", "round-trip time of the last answered ping, s" },
      pings = { "integer", "ping replies" },
      lastError = { "string?", "why it is not connected; nil when connected" },
      toggles = { "table<string, boolean>", "every toggle name → its value as last set (a new table)" },
      malformed = { "integer", "packets that did not decode" },
      path = { "{x: integer, y: integer}[]", "the last path" },
    },
    events = {
      onDistance = { "e: pitwall.AlphabotDistanceEvent", "answer to measureDistance" },
      onPosition = { "e: pitwall.AlphabotPositionEvent", "the robot's position" },
      onCompass = { "e: pitwall.AlphabotCompassEvent", "a compass reading" },
      onObstacle = { "e: pitwall.AlphabotObstacleEvent", "an obstacle was registered" },
      onPath = { "e: pitwall.AlphabotPathEvent", "the path to a navigateTo target" },
      onPing = { "e: pitwall.PingEvent", "a ping reply" },
      onConnect = { "e: pitwall.Event", "" },
      onDisconnect = { "e: pitwall.DisconnectEvent", "only after a connection was up" },
      onMalformed = { "e: pitwall.MalformedEvent", "a packet that does not decode" },
      onMapSize = { "e: pitwall.AlphabotMapSizeEvent", "BLE only" },
      onAnchor = { "e: pitwall.AlphabotAnchorEvent", "BLE only" },
      onCalibrated = { "e: pitwall.Event", "BLE only" },
    },
    methods = {
      drive = [[Drives; negative: backwards / left.
@param speed integer −128..127
@param steer integer −128..127]],
      stop = [[= drive(0, 0).]],
      measureDistance = [[Measures the distance at `degree` relative to the heading; answered by onDistance.
@param degree integer −360..360]],
      calibrateSteering = [[Calibrates the steering.]],
      calibrateCompass = [[Calibrates the compass; answered by onCompass.]],
      set = [[Sets toggles by name; names not given keep their last value.
@param toggles table<string, boolean>]],
      ping = [[In a task: waits for the reply and returns the round-trip time (nil and a message after `timeout`); elsewhere it only sends.
@param timeout? number s (default 2)
@return number? rtt
@return string? err]],
      setAnchor = [[Sets anchor `id` at (x, y).
@param id integer 0..255
@param x integer cm
@param y integer cm]],
      navigateTo = [[Drives to (x, y); onPath, then onPosition as it drives.
@param x integer cm
@param y integer cm]],
      addObstacle = [[Registers an obstacle; answered by onObstacle.
@param x integer corner nearest the origin, cm
@param y integer
@param width integer 1..65535
@param height integer 1..65535]],
      removeObstacle = [[Removes obstacle `id`, or with two arguments the obstacles containing (x, y).
@param idOrX integer
@param y? integer]],
      clearObstacles = [[Removes every obstacle.]],
      close = [[Stops a connected robot and closes the link; no more events.]],
    },
  },
}
