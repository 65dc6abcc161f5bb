-- The live board (pitwall.board): formatting, the table's lines, redrawing in place on a
-- terminal, and only the final table elsewhere.
-- tags: ui
local Board = require "pitwall.board"

expect.eq(Board.time(4.125), "4.125")
expect.eq(Board.time(62.3456), "1:02.346")
expect.eq(Board.time(nil), "-")
expect.eq(Board.time(math.huge), "-")
expect.eq(Board.gap(0), "", "the leader has no gap")
expect.eq(Board.gap(1.5), "+1.500")
expect.eq(Board.gap(3, 1), "+1 lap")
expect.eq(Board.gap(3, 2), "+2 laps")

-- an output that keeps what is written
local function sink()
  local s = { text = "" }
  function s:write(...)
    for _, part in ipairs({ ... }) do self.text = self.text .. part end
  end
  function s:flush() end
  return s
end

local columns = {
  { key = "position", title = "POS", align = "right" },
  { key = "name", title = "CAR" },
  { key = "best", title = "BEST", align = "right", format = Board.time },
}
local rows = {
  { position = 1, name = "skull", best = 4.125 },
  { position = 2, name = "groundshock", best = 62.5 },
  { position = 10, name = "nuke" },
}

local board = Board.new { title = "Race", columns = columns, out = sink(), tty = true }
local lines = board:render(rows)
expect.eq(#lines, 5)
expect.eq(lines[1], "Race")
expect.eq(lines[2], "POS  CAR              BEST")
expect.eq(lines[3], "  1  skull           4.125")
expect.eq(lines[4], "  2  groundshock  1:02.500")
expect.eq(lines[5], " 10  nuke                -")

-- on a terminal: the first drawing, then the next one over it (cursor up 5 lines)
board:show(rows)
local first = board.out.text
expect.eq(first:find("\27[", 1, true), 1, "starts by clearing its first line")
expect.falsy(first:find("\27[5A", 1, true), "nothing to move over yet")
board:show(rows)
expect.truthy(board.out.text:find("\27[5A", #first, true), "moves up over the last drawing")

-- a shorter table clears the lines the longer one left
board.out.text = ""
board:show({ rows[1] })
expect.truthy(board.out.text:find("\27[5A", 1, true))
expect.truthy(board.out.text:find("\27[2A", 1, true), "back up over the two cleared lines")

-- elsewhere (a file, a CI log): show prints nothing, final prints the plain table
local plain = Board.new { columns = columns, out = sink(), tty = false }
plain:show(rows)
expect.eq(plain.out.text, "")
plain:final(rows)
expect.eq(plain.out.text, table.concat(plain:render(rows), "\n") .. "\n")
expect.falsy(plain.out.text:find("\27", 1, true), "no escapes in a file")

expect.fails(function() Board.new {} end, "needs {columns")
expect.fails(function() Board.new { columns = { { title = "X" } } } end, "column 1 has no key")
