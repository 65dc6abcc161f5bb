-- A table on the terminal that redraws in place: the live leaderboard of a race.
--
--   local Board = require "pitwall.board"
--   local board = Board.new{
--     title = "Grand prix",
--     columns = {
--       { key = "position", title = "POS", align = "right" },
--       { key = "name", title = "CAR" },
--       { key = "best", title = "BEST", align = "right", format = Board.time },
--     },
--   }
--   board:show(rows)    -- on a terminal: replaces the previous drawing; elsewhere: nothing
--   board:final(rows)   -- prints the table wherever stdout goes, and ends the live drawing
--
-- A row is a table keyed like the columns; a missing value shows as "-". On a terminal the
-- board moves the cursor up over its last drawing (ANSI escapes) and redraws it; when anything
-- else reached the terminal in between (a log line, a print: pitwall.terminal().output moved),
-- drawing over it would erase it, so the next drawing starts anew below it. When
-- stdout is not a terminal (a file, a CI log) only `final` prints, so logs stay readable.
local Board = {}
Board.__index = Board
Board.__name = "board" -- (how errors name it: "board has no method …")

-- (nil, NaN and infinity are no time; whole minutes and the seconds left)
local function noTime(seconds) return seconds == nil or seconds ~= seconds or seconds == math.huge end
local function minutes(seconds)
  local m = math.floor(seconds / 60)
  return m, seconds - 60 * m
end

--- "1:02.345" from seconds (minutes only from a minute on: "4.125"); "-" for nil.
function Board.time(seconds)
  if noTime(seconds) then return "-" end
  if seconds >= 60 then return string.format("%d:%06.3f", minutes(seconds)) end
  return string.format("%.3f", seconds)
end

--- A duration with its unit: "9.215 s", "1 min 2.345 s"; "-" for nil.
function Board.duration(seconds)
  if noTime(seconds) then return "-" end
  if seconds >= 60 then return string.format("%d min %.3f s", minutes(seconds)) end
  return string.format("%.3f s", seconds)
end

--- The gap to the leader: "+1.234" (seconds) or "+1 lap" / "+2 laps" when laps behind;
--- "" for the leader itself (gap 0 and no laps).
function Board.gap(seconds, laps)
  if laps and laps > 0 then return string.format("+%d lap%s", laps, laps == 1 and "" or "s") end
  if seconds == nil then return "-" end
  if seconds <= 0 then return "" end
  return "+" .. Board.time(seconds)
end

--- A board with `spec.columns` ({key, title, align = "left"|"right", format = fn(value, row)})
--- and an optional `spec.title`. `spec.out` (default pitwall.stdout) and `spec.tty` (default: ask
--- pitwall.terminal()) are for tests.
function Board.new(spec)
  if type(spec) ~= "table" or type(spec.columns) ~= "table" or #spec.columns == 0 then
    pitwall._raise("Board.new needs {columns = {{key = …, title = …}, …}}")
  end
  pitwall._checkOptions("Board.new", spec, { "title", "columns", "out", "tty" })
  for i, c in ipairs(spec.columns) do
    if type(c) ~= "table" or type(c.key) ~= "string" then
      pitwall._raise("Board.new: column " .. i .. " has no key")
    end
    pitwall._checkOptions("Board.new: column " .. i, c, { "key", "title", "align", "format" })
  end
  local tty = spec.tty
  if tty == nil then tty = pitwall.terminal().tty end
  return setmetatable({
    title = spec.title,
    columns = spec.columns,
    out = spec.out or pitwall.stdout,
    tty = tty,
    drawn = 0, -- lines of the last live drawing
  }, Board)
end

local function cell(column, row)
  local v = row[column.key]
  if column.format then v = column.format(v, row) end
  if v == nil then return "-" end
  return tostring(v)
end

--- The board's lines for `rows`, as plain text (no escapes).
function Board:render(rows)
  local cells, widths = {}, {}
  for i, c in ipairs(self.columns) do widths[i] = utf8.len(c.title or c.key) or #(c.title or c.key) end
  for r, row in ipairs(rows) do
    cells[r] = {}
    for i, c in ipairs(self.columns) do
      local text = cell(c, row)
      cells[r][i] = text
      widths[i] = math.max(widths[i], utf8.len(text) or #text)
    end
  end
  local function line(texts)
    local parts = {}
    for i, c in ipairs(self.columns) do
      local text = texts[i]
      local pad = string.rep(" ", widths[i] - (utf8.len(text) or #text))
      parts[i] = c.align == "right" and pad .. text or text .. pad
    end
    return (table.concat(parts, "  "):gsub("%s+$", ""))
  end
  local lines = {}
  if self.title then lines[#lines + 1] = self.title end
  local titles = {}
  for i, c in ipairs(self.columns) do titles[i] = c.title or c.key end
  lines[#lines + 1] = line(titles)
  for r = 1, #rows do lines[#lines + 1] = line(cells[r]) end
  return lines
end

local function write(self, lines, live)
  local out = self.out
  if live and self.drawn > 0 then
    out:write(string.format("\27[%dA", self.drawn)) -- up to the last drawing's first line
  end
  for _, l in ipairs(lines) do out:write("\27[2K", l, "\n") end -- clear the line, write it
  if live and self.drawn > #lines then
    -- the table shrank: clear what is left of the old drawing, then come back up
    for _ = #lines + 1, self.drawn do out:write("\27[2K\n") end
    out:write(string.format("\27[%dA", self.drawn - #lines))
  end
  out:flush()
end

-- How many writes reached the terminal (pitwall.terminal().output); a test's board has none.
local function output(self)
  if self.out ~= pitwall.stdout then return 0 end
  return pitwall.terminal().output
end

-- Something else was written since the last drawing: the next one starts anew below it.
local function fresh(self)
  if self.drawn > 0 and output(self) ~= self.mark then self.drawn = 0 end
end

--- Draws `rows` in place of the last drawing (terminals only; elsewhere it does nothing).
function Board:show(rows)
  if not self.tty then return end
  local lines = self:render(rows)
  fresh(self)
  write(self, lines, true)
  self.drawn = #lines
  self.mark = output(self)
end

--- Prints `rows` as the final table (on a terminal over the live drawing), wherever stdout goes.
function Board:final(rows)
  local lines = self:render(rows)
  if self.tty then
    fresh(self)
    write(self, lines, true)
  else
    for _, l in ipairs(lines) do self.out:write(l, "\n") end
    self.out:flush()
  end
  self.drawn = 0
end

return Board
