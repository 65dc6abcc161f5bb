-- The adversary of the stop tests (stop_test.sh, ble_stop_test.sh, mqtt_fleet_test.sh): a script
-- that never stops commanding. Every 20 ms, from a timer, from a timer it schedules, and on every
-- position event, it sets every car's speed again, and once more from the run's last words. MODE picks how the run ends after 1 s, and
-- the script commands again right after asking for the end:
--   none    (the default) never: --duration, a signal or the test ends it
--   stop    pitwall.stop(), then commands from the same task (in pcall) and from a new task
--   error   the main chunk dies
--   exit    os.exit(3) inside pcall, then a command
--   memory  an allocation loop behind pcall (run it with --lua-memory and --budget 0)
--   wedge   C code that never returns: a pattern that backtracks for hours (the watchdog and
--           the last-resort exit, ble_way_out_test.sh)
local mode = os.getenv("MODE") or "none"
local cars = pitwall.cars()
local function command()
  for _, car in ipairs(cars) do car:setSpeed(800) end
end
pitwall.every(0.02, command)
pitwall.every(0.02, function() pitwall.after(0, command) end)
-- CHATTY=1: a line on every position update too, as a script that reports laps prints
-- (way_out_test.sh pipes it into head)
local chatty = os.getenv("CHATTY")
for _, car in ipairs(cars) do
  car.onPosition = function(_, ev)
    car:setSpeed(800)
    if chatty then print(car.name, ev.piece, ev.speed) end
  end
end
-- It claims the library's last words too (run after the stops, ScriptHost::lastWords): one more
-- command, then it hogs the loop (not in the memory mode, which runs without a budget).
pitwall._lastWords = function()
  print("last words:", pcall(command))
  if mode ~= "memory" then while true do end end
end
command()
print("driving")
io.stdout:flush()
if mode == "wedge" then
  print("wedging")
  io.stdout:flush()
  string.find(string.rep("a", 5000), ".-.-.-.-.-b")
end
pitwall.sleep(1)
if mode == "stop" then
  pitwall.stop()
  local ok, err = pcall(command)
  print("after stop:", ok, err)
  pitwall.spawn(function() while true do command(); pitwall.sleep(0.01) end end)
elseif mode == "error" then
  error("the strategy crashed")
elseif mode == "exit" then
  pcall(os.exit, 3)
  command()
elseif mode == "memory" then
  local keep = {}
  while true do
    pcall(function() keep[#keep + 1] = string.rep("x", 1 << 20) .. #keep end)
  end
end
