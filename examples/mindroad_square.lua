-- Drives a MindRoad robot car (docs/robots.md) around a square — straight 2 s, turn right 1 s,
-- four times per square — and carries on through a dropped connection: while contact is lost
-- the square waits, and after onContact it finishes the side it was on with the time left.
--
--   build/pitwall sim-robot mindroad --listen 127.0.0.1:4000 &      # or a real robot
--   build/pitwall run examples/mindroad_square.lua
--
-- MINDROAD_HOST / MINDROAD_PORT say where the robot is (127.0.0.1:4000), MINDROAD_SIDES how
-- many sides to drive (8: two squares), MINDROAD_UDP=1 uses UDP instead of TCP.
local host = os.getenv("MINDROAD_HOST") or "127.0.0.1"
local port = tonumber(os.getenv("MINDROAD_PORT") or "4000")
local sides = tonumber(os.getenv("MINDROAD_SIDES") or "8")
local STRAIGHT, TURN = 2.0, 1.0 -- seconds; full right turns at about 90°/s on the sim robot

if pitwall.virtualTime then
  -- The robot is reached over a real socket, which virtual time would race past.
  print("mindroad_square drives a robot over the network in real time: run it without --fast")
  return
end

-- In the main chunk (a task) this waits for contact: the robot is ready on the next line.
local robot = pitwall.mindroad { host = host, port = port, udp = os.getenv("MINDROAD_UDP") == "1" }
print(tostring(robot) .. ": contact")

robot.onContact = function(r)
  print(tostring(r) .. ": contact")
end
robot.onLost = function(r, reason)
  print("lost contact: " .. reason .. " (the square waits; reconnecting)")
end

-- Holds a steering for `seconds` of contact. Steering is resent every 0.1 s: after a lost
-- connection the robot has stopped (its watchdog), and the next contact starts it again.
local function hold(x, y, seconds)
  local left = seconds
  while left > 1e-9 do
    if robot.connected and pcall(robot.steer, robot, x, y) then
      pitwall.sleep(0.1)
      left = left - 0.1
    else
      pitwall.waitUntil(function() return robot.connected end, 60)
    end
  end
end

for side = 1, sides do
  hold(127, 0, STRAIGHT) -- full forward
  hold(0, 127, TURN)     -- turn right on the spot
  print(("side %d of %d done"):format(side, sides))
end
if robot.connected then robot:stop() end
print("square done")
pitwall.stop()
