-- pitwall.track_loop: closing a loop of pieces from what a car saw lap after lap, for tracks
-- with no start/finish piece and cars that send few or no position updates (docs/racing.md
-- "Mapping any loop"). Used by pitwall.track; no I/O, no car.
--
-- The input is the scan's segments in driving order — what the car saw between two transitions:
-- the piece ids of its position updates (`ids`, `idCount`; often none: a real car at speed sends
-- none on a curve, one in lane 4 none at all) and the wheel distances of the piece left (`left`,
-- `right`, cm). A segment's `problem` other than a missing id (a lost transition) ends what can
-- be used: only the segments after the last such one count.
--
-- The lap is the smallest period P of that sequence such that
--   * every piece seen twice agrees with itself: the same id where both passes had one; no
--     pass clearly a curve (a wheel difference of 6 cm or more) where another is clearly not
--     (2 cm or less), and curves the same way;
--   * its curves turn ±360° in all (a simple loop; 0° with an intersection piece, a figure eight).
--     A piece is a curve by its id when a pass had one, otherwise when its passes' mean wheel
--     difference is over half a 90° curve's (4.25 cm: the wheels are ≈54 mm apart); it turns
--     toward the shorter wheel, by its id's angle (90° without one);
--   * it was seen a second time over max(3, P/4) pieces at least, so that a part of the lap
--     that happens to turn 360° and to repeat for a piece or two is not taken for the lap.
-- The total turn does the closing: repeating ids and shapes alone cannot tell an oval's half
-- from its whole. Wheel differences at speed are not to be trusted for the angle (at 750 mm/s
-- a real car's 180° turns read 25–29 cm where 17 cm is the geometry: the wheels slip), so only
-- their sign and whether a piece is a curve at all are taken from them.
local loop = {}

local CURVE_D = 4.25   -- cm: half the wheel difference of a 90° curve (wheels ≈ 54 mm apart)
local CLEAR_CURVE = 6      -- cm: a pass with a wheel difference this large is surely a curve
local CLEAR_STRAIGHT = 2   -- cm: one with at most this much surely is not
local START_SHORT = { 22, 4 } -- cm (mean, tolerance) of the start piece's halves, 33 and 34
local START_LONG = { 34, 5 }

local NO_POSITION = "no position update on it"
loop.NO_POSITION = NO_POSITION

--- The one piece id a segment saw, or nil (none, or more than one: a transition was lost).
function loop.segmentId(seg)
  if seg.idCount ~= 1 then return nil end
  return (next(seg.ids))
end
local segmentId = loop.segmentId

-- What is known of one piece from its passes `obs` (segments): its id (nil when no pass had
-- one, false when passes disagree), kind ("curve" or the id's type, "straight" when unknown),
-- direction, mean length (mm), and whether the passes agree with each other.
local function describe(obs)
  local id, d, m = nil, 0, 0
  for _, s in ipairs(obs) do
    local sid = segmentId(s)
    if sid then
      if id and id ~= sid then return nil end
      id = sid
    end
    d = d + (s.left - s.right)
    m = m + (s.left + s.right) * 5
  end
  d, m = d / #obs, m / #obs
  local spec = id and pitwall.piece(id)
  local curve
  if spec then curve = spec.type == "curve" else curve = math.abs(d) > CURVE_D end
  local piece = { id = id, measured = m, passes = #obs }
  -- Each pass on its own: clearly a curve (and which way), clearly straight, or either (a real
  -- car's curve at 750 mm/s read 4 cm once, its straights up to 5). Passes that clearly
  -- disagree are two different pieces.
  local right, left, straight = false, false, false
  for _, s in ipairs(obs) do
    local sd = s.left - s.right
    if sd >= CLEAR_CURVE then right = true
    elseif sd <= -CLEAR_CURVE then left = true
    elseif math.abs(sd) <= CLEAR_STRAIGHT then straight = true end
  end
  if (right and left) or ((right or left) and straight) then return nil end
  if curve then
    piece.type = "curve"
    piece.turn = d > 0 and "right" or "left" -- the left wheel outside: a right turn
    piece.angle = spec and spec.angle or 90
    if straight then return nil end
  else
    piece.type = spec and spec.type or "straight"
    if right or left then return nil end
  end
  return piece
end

-- The segments that can be used: those after the last one with a problem worse than a
-- missing id.
local function usable(segs)
  local from = 1
  for i, s in ipairs(segs) do
    if s.problem and s.problem ~= NO_POSITION then from = i + 1 end
  end
  return table.move(segs, from, #segs, 1, {}), from
end

-- The pieces of one lap if `run` repeats with period p, or nil.
local function tryPeriod(run, p)
  local pieces, turn, crossing = {}, 0, false
  for g = 1, p do
    local obs = {}
    for i = g, #run, p do obs[#obs + 1] = run[i] end
    local piece = describe(obs)
    if not piece then return nil end
    if piece.type == "curve" then
      turn = turn + (piece.turn == "left" and 1 or -1) * piece.angle
    elseif piece.type == "intersection" then
      crossing = true
    end
    pieces[g] = piece
  end
  local full = math.abs(math.abs(turn) - 360) < 1
  if not full and not (crossing and math.abs(turn) < 1) then return nil end
  return pieces, turn
end

-- The start piece's halves by their lengths, for a lap where neither sent a position update:
-- a short non-curve (≈22 cm) after a longer one (≈34 cm) is 34 → 33. Only when the lap has no
-- id 33 or 34 already and exactly one such pair.
local function startByLength(pieces)
  local n, found = #pieces, nil
  for g = 1, n do
    local p, before = pieces[g], pieces[(g - 2) % n + 1]
    if p.id == 33 or p.id == 34 then return end
    local function near(piece, want)
      return piece.id == nil and piece.type ~= "curve"
        and math.abs(piece.measured / 10 - want[1]) <= want[2]
    end
    if near(p, START_SHORT) and near(before, START_LONG) then
      if found then return end
      found = g
    end
  end
  if found then
    local p, before = pieces[found], pieces[(found - 2) % #pieces + 1]
    p.id, p.type, p.byLength = 33, "start-short", true
    before.id, before.type, before.byLength = 34, "start-long", true
  end
end

--- The lap in `segs` (closed scan segments in driving order), or nil while it is not closed.
--- Returns { pieces = {…}, first = k, period = P, seen, unknown, named } — pieces in driving
--- order beginning with the piece of segment `first` (each {id|nil, type, turn, angle,
--- measured, passes, byLength}); `seen` segments used, `unknown` pieces without an id, `named`
--- position updates among the segments.
function loop.close(segs)
  local run, from = usable(segs)
  local n = #run
  for p = 1, n - 3 do
    if n - p >= math.max(3, math.ceil(p / 4)) then
      local pieces = tryPeriod(run, p)
      if pieces then
        startByLength(pieces)
        local unknown, named = 0, 0
        for _, piece in ipairs(pieces) do
          if piece.id == nil then unknown = unknown + 1 end
        end
        for _, s in ipairs(run) do named = named + s.idCount end
        return { pieces = pieces, first = from, period = p, seen = n, unknown = unknown,
          named = named }
      end
    end
  end
  return nil
end

--- The index (1-based, in `lap.pieces`) of the piece the segment at `segIndex` of the scan was
--- on.
function loop.indexOf(lap, segIndex)
  return (segIndex - lap.first) % lap.period + 1
end

return loop
