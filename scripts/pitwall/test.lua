-- Expectations for scenario tests (`pitwall test`). Each failure names the file and line of the
-- expectation and the values compared, then ends the scenario. Available as the global `expect`.
local expect = {}

local function show(v)
  if type(v) == "string" then return string.format("%q", v) end
  return tostring(v)
end

-- The runner tells a failed expectation from any other error by the message kept here.
local function fail(message, level)
  expect._failed = message
  -- where, for a failure the script's own pitwall.onError or pcall took (the runner still fails it)
  local info = debug.getinfo((level or 2) + 1, "Sl")
  expect._failedAt = info and info.currentline > 0 and (info.short_src .. ":" .. info.currentline .. ": " .. message)
    or message
  error(message, (level or 2) + 1)
end

function expect.eq(actual, expected, what)
  if actual ~= expected then
    fail(string.format("%sexpected %s, got %s", what and (what .. ": ") or "", show(expected), show(actual)), 2)
  end
end

function expect.ne(actual, other, what)
  if actual == other then
    fail(string.format("%sexpected something other than %s", what and (what .. ": ") or "", show(other)), 2)
  end
end

function expect.near(actual, expected, tolerance, what)
  if type(actual) ~= "number" or math.abs(actual - expected) > tolerance then
    fail(string.format("%sexpected %s ± %s, got %s", what and (what .. ": ") or "", show(expected),
      show(tolerance), show(actual)), 2)
  end
end

local function compare(name, op, sym)
  expect[name] = function(a, b, what)
    if type(a) ~= "number" or type(b) ~= "number" or not op(a, b) then
      fail(string.format("%sexpected %s %s %s", what and (what .. ": ") or "", show(a), sym, show(b)), 2)
    end
  end
end
compare("lt", function(a, b) return a < b end, "<")
compare("le", function(a, b) return a <= b end, "<=")
compare("gt", function(a, b) return a > b end, ">")
compare("ge", function(a, b) return a >= b end, ">=")

function expect.truthy(v, what)
  if not v then fail(string.format("%sexpected a true value, got %s", what and (what .. ": ") or "", show(v)), 2) end
end

function expect.falsy(v, what)
  if v then fail(string.format("%sexpected false or nil, got %s", what and (what .. ": ") or "", show(v)), 2) end
end

--- fn() must raise an error whose message contains `pattern` (plain text).
function expect.fails(fn, pattern, what)
  local ok, err = pcall(fn)
  if ok then fail(string.format("%sexpected an error, but the call succeeded", what and (what .. ": ") or ""), 2) end
  if pattern and not tostring(err):find(pattern, 1, true) then
    fail(string.format("%sexpected an error containing %s, got %s", what and (what .. ": ") or "", show(pattern), show(err)), 2)
  end
  return err
end

return expect
