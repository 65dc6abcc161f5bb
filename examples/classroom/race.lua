-- The classroom's race (docs/classroom.md): what `pitwall run --code FOLDER --view …` runs when no
-- script is given. Each car is a student's desk and drives the driver in FOLDER/car-N/driver.lua,
-- which the student edits on the view's code page (/code); a save reloads it while the car drives.
--
-- Between races the cars drive in free practice, each on its student's driver. When the teacher
-- starts a race on their page, practice ends, the cars go to the grid and race that many laps;
-- then practice again, until Ctrl-C.
local race = require "pitwall.race"

local room = pitwall.classroom
if not room.active then
  error("classroom/race.lua is the code page's race: run it with --code FOLDER "
    .. "--view 0.0.0.0:8080 (docs/classroom.md)")
end

local races = 0
while true do
  -- free practice until the teacher's start: every car on its student's driver
  local laps
  local practice = race.new {
    mode = "practice", minutes = 24 * 60, board = false,
    title = "Practice: waiting for the teacher's start",
  }
  pitwall.spawn(function()
    pitwall.waitUntil(function()
      laps = room.nextStart()
      return laps ~= nil
    end, nil, 0.1)
    practice:abort()
  end, "classroom start")
  practice:run()
  races = races + 1
  local title = string.format("Race %d, %d %s", races, laps, laps == 1 and "lap" or "laps")
  print(title)
  local session = race.laps { laps = laps, title = title, finishTimeout = 30 }
  print(race.winner(session) or "No winner: nobody finished")
end
