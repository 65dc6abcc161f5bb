-- The Lua half of `pitwall repl`: how values are shown, what Tab completes, the `cars` global,
-- and the prompt's globals (where `help` lives; what it says is pitwall.help's). The C++ prompt
-- calls these; nothing here reads input or writes output but help() itself.
--
-- Showing and completing must never run the user's code: a REPL that calls `__index`, `__pairs`
-- or `__len` while printing or completing can change state, raise, or hang (Hammerspoon's console
-- completes from metatables for the same reason). So tables are read with next/rawget/rawlen and
-- debug.getmetatable; the only metamethods called are `__tostring`/`__name` (through tostring) on
-- values that define them, and the car's `__index`, whose fields are plain C reads of its state.
local pitwall = require "pitwall"

local M = {}

local KEYWORDS = {
  "and", "break", "do", "else", "elseif", "end", "false", "for", "function", "goto", "if", "in",
  "local", "nil", "not", "or", "repeat", "return", "then", "true", "until", "while",
}
local isKeyword = {}
for _, k in ipairs(KEYWORDS) do isKeyword[k] = true end

local function isIdentifier(s)
  return type(s) == "string" and s:match("^[%a_][%w_]*$") ~= nil and not isKeyword[s]
end

local function metafield(v, name)
  local mt = debug.getmetatable(v)
  if type(mt) ~= "table" then return nil end
  return rawget(mt, name)
end

local function isCar(v)
  return type(v) == "userdata" and metafield(v, "__name") == "car"
end

-- tostring, which may run a value's own __tostring: that one is allowed, but it may raise.
local function safeToString(v)
  local ok, s = pcall(tostring, v)
  if ok and type(s) == "string" then return s end
  return string.format("<%s: __tostring failed: %s>", type(v), tostring(ok and "not a string" or s))
end

---------------------------------------------------------------------------------------------------
-- pretty

-- Numbers as Lua writes them (lua_Number "%.14g", ".0" on integral floats), without tostring,
-- which would honour a __tostring set on the number type.
local function formatNumber(n)
  if math.type(n) == "integer" then return string.format("%d", n) end
  local s = string.format("%.14g", n)
  if s:find("^[-0-9]*$") then s = s .. ".0" end
  return s
end

-- Like %q, but one line and readable: \n, \t, \r instead of a backslash-newline or \9; other
-- control bytes as \ddd (three digits, so a following digit cannot join the escape); UTF-8 as is.
local ESCAPES = { ["\n"] = "\\n", ["\t"] = "\\t", ["\r"] = "\\r", ['"'] = '\\"', ["\\"] = "\\\\" }
local function quote(s)
  return '"' .. s:gsub('[%c"\\]', function(c)
    return ESCAPES[c] or string.format("\\%03d", c:byte())
  end) .. '"'
end

local function formatFunction(f)
  local info = debug.getinfo(f, "S")
  if not info or info.what == "C" then return "function: [C]" end
  return string.format("function: %s:%d", info.short_src, info.linedefined)
end

-- One decimal at most, none when it would be ".0": "-23.5", "-68", "600".
local function short(n)
  if math.type(n) == "integer" then return string.format("%d", n) end
  return (string.format("%.1f", n):gsub("%.0$", ""))
end

local function formatCar(car)
  local ok, s = pcall(function()
    local parts = {}
    if type(car.speed) == "number" then parts[#parts + 1] = "speed " .. short(car.speed) .. " mm/s" end
    if car.piece ~= nil then parts[#parts + 1] = "piece " .. tostring(car.piece) end
    if type(car.offset) == "number" then parts[#parts + 1] = "offset " .. short(car.offset) .. " mm" end
    parts[#parts + 1] = car.connected and "connected" or "disconnected"
    if car.delocalized then parts[#parts + 1] = "delocalized" end
    return string.format("<car %s %s: %s>", tostring(car.number), tostring(car.name),
      table.concat(parts, ", "))
  end)
  return ok and s or safeToString(car)
end

local scalar  -- forward: formats a value that is not expanded (leaf or key)

function scalar(v)
  local t = type(v)
  if t == "string" then return quote(v) end
  if t == "number" then return formatNumber(v) end
  if t == "function" then return formatFunction(v) end
  if t == "userdata" and isCar(v) then return formatCar(v) end
  return safeToString(v)
end

local function formatKey(k)
  if isIdentifier(k) then return k end
  return "[" .. scalar(k) .. "]"
end

-- Hash keys in a stable order: numbers, then strings, then the rest (booleans, tables, …) by type
-- and text; each group sorted within itself.
local RANK = { number = 1, string = 2, boolean = 3 }
local function keyLess(a, b)
  local ra, rb = RANK[type(a)] or 4, RANK[type(b)] or 4
  if ra ~= rb then return ra < rb end
  if ra <= 2 then return a < b end
  if ra == 3 then return (not a) and b end
  local ta, tb = type(a), type(b)
  if ta ~= tb then return ta < tb end
  return scalar(a) < scalar(b)
end

-- The entries of t in display order: the array part 1..n (raw, up to the first nil), then the
-- other keys sorted. Returns a list of {key, value, inArray}.
local function entries(t)
  local list, n = {}, 0
  while rawget(t, n + 1) ~= nil do
    n = n + 1
    list[n] = { n, rawget(t, n), true }
  end
  local keys = {}
  for k in next, t do
    if not (math.type(k) == "integer" and k >= 1 and k <= n) then keys[#keys + 1] = k end
  end
  -- keys that are tables order by their __tostring text, which need not be consistent: then
  -- unsorted rather than an error
  pcall(table.sort, keys, keyLess)
  for _, k in ipairs(keys) do list[#list + 1] = { k, rawget(t, k), false } end
  return list
end

local render  -- forward

local function textWidth(s)
  return utf8.len(s) or #s
end

-- A table's items, each already rendered, then one line if it fits and nothing inside broke
-- across lines, else several lines indented by two.
local function renderTable(t, opts, level, path, width)
  if level > opts.depth then return next(t) == nil and "{}" or "{…}" end
  path[t] = true
  local items, packable, list = {}, {}, entries(t)
  local shown = math.min(#list, opts.maxItems)
  for i = 1, shown do
    local k, v, inArray = list[i][1], list[i][2], list[i][3]
    local prefix = inArray and "" or (formatKey(k) .. " = ")
    items[i] = prefix .. render(v, opts, level + 1, path, width - 2 - #prefix - 1) .. ","
    packable[i] = inArray and not items[i]:find("\n", 1, true)
  end
  if #list > shown then items[#items + 1] = string.format("… (%d more)", #list - shown) end
  path[t] = nil

  if #items == 0 then return "{}" end
  local line = "{" .. table.concat(items, " "):gsub(",$", "") .. "}"
  if not line:find("\n", 1, true) and textWidth(line) <= width then return line end
  -- Several lines: keyed and multi-line items one per line; short array items share lines, so
  -- that a long list of numbers does not become a long column.
  local lines = {}
  for i, item in ipairs(items) do
    local last = lines[#lines]
    if packable[i] and packable[i - 1] and textWidth(last) + 1 + textWidth(item) <= width then
      lines[#lines] = last .. " " .. item
    else
      lines[#lines + 1] = "  " .. item:gsub("\n", "\n  ")
    end
  end
  return "{\n" .. table.concat(lines, "\n") .. "\n}"
end

function render(v, opts, level, path, width)
  if type(v) ~= "table" then return scalar(v) end
  if path[v] then return "<cycle>" end
  if metafield(v, "__tostring") ~= nil then return safeToString(v) end
  return renderTable(v, opts, level, path, width)
end

--- pretty(value [, opts]) -> string. opts.depth (3): tables nested deeper show as {…};
--- opts.maxItems (50) per table, the rest counted; opts.width (100): a table wider goes on
--- several lines.
function M.pretty(value, opts)
  if type(opts) ~= "table" then opts = {} end
  pitwall._checkOptions("repl.pretty", opts, { "width", "depth", "maxItems" })
  local o = {
    depth = tonumber(rawget(opts, "depth")) or 3,
    maxItems = tonumber(rawget(opts, "maxItems")) or 50,
    width = tonumber(rawget(opts, "width")) or 100,
  }
  return render(value, o, 1, {}, o.width)
end

--- show(...) -> the values a chunk returned, pretty, joined by tabs; nil when there are none.
function M.show(...)
  local n = select("#", ...)
  if n == 0 then return nil end
  local parts = {}
  for i = 1, n do parts[i] = M.pretty((select(i, ...))) end
  return table.concat(parts, "\t")
end

---------------------------------------------------------------------------------------------------
-- complete

-- A name looked up the way Lua would find it, but only through raw reads: the table itself, then
-- __index while that is a table. A function __index is never called (nothing found).
local function lookup(v, key)
  for _ = 1, 32 do  -- a bound, in case of an __index loop
    if type(v) == "table" then
      local found = rawget(v, key)
      if found ~= nil then return found end
    elseif isCar(v) then
      local methods = metafield(v, "__methods")
      if type(methods) == "table" and rawget(methods, key) ~= nil then return rawget(methods, key) end
      local fields = metafield(v, "__fields")
      local i = 1
      while type(fields) == "table" and rawget(fields, i) ~= nil do
        -- The car's state is a plain C read (docs/lua-api.md): no side effect.
        if rawget(fields, i) == key then return v[key] end
        i = i + 1
      end
      local own = debug.getuservalue(v, 1)
      return type(own) == "table" and rawget(own, key) or nil
    elseif type(v) ~= "string" and type(v) ~= "userdata" then
      return nil
    end
    local index = metafield(v, "__index")
    if type(index) ~= "table" then return nil end
    v = index
  end
  return nil
end

-- The names v offers after `.` (or `:`), each with its value, or `true` where the value is not
-- read (a car's fields and events: not methods).
local function namesOf(v)
  local names, seen = {}, {}
  -- A class reached through __index holds its metamethods too: not names to offer on an object.
  local function addKeys(t, inherited)
    for k, value in next, t do
      if isIdentifier(k) and names[k] == nil and not (inherited and k:find("^__")) then
        names[k] = value
      end
    end
  end
  local function addList(list)
    if type(list) ~= "table" then return end
    local i = 1
    while type(rawget(list, i)) == "string" do
      local k = rawget(list, i)
      if isIdentifier(k) and names[k] == nil then names[k] = true end
      i = i + 1
    end
  end
  local cur = v
  while cur ~= nil and not seen[cur] do
    seen[cur] = true
    if type(cur) == "table" then
      addKeys(cur, not rawequal(cur, v))
    elseif type(cur) == "userdata" then
      local methods = metafield(cur, "__methods")
      if type(methods) == "table" then addKeys(methods) end
      addList(metafield(cur, "__fields"))
      addList(metafield(cur, "__events"))
      if isCar(cur) then
        local own = debug.getuservalue(cur, 1)
        if type(own) == "table" then addKeys(own) end
      end
    elseif type(cur) ~= "string" then
      break
    end
    cur = metafield(cur, "__index")
    if type(cur) ~= "table" then break end
  end
  return names
end

local function readString(quoted)
  local body = quoted:sub(2, -2)
  if body:find("\\", 1, true) then return nil end  -- escapes: not worth guessing
  return body
end

-- Splits the end of `text` into the chain of keys leading to the value being completed (nil at
-- the top level), the separator (".", ":" or ""), the partial name, and what the chain starts
-- from ("global", or "string" and the string). Reads backwards: the partial name, then .name and
-- [literal] segments, down to a global name or a parenthesised string literal ("x"). Returns
-- nil when the end of text is not such a chain (a call, an expression: nothing to offer).
local function parse(text)
  local partial = text:match("[%a_][%w_]*$") or ""
  local i = #text - #partial  -- the last character before the partial name
  if partial ~= "" and text:sub(i, i):match("[%w_]") then return nil end  -- 0x1f, 2e5…
  local sep = text:sub(i, i)
  if sep ~= "." and sep ~= ":" then return nil, "", partial end
  if sep == "." and text:sub(i - 1, i - 1) == "." then return nil end  -- `..` concatenation
  i = i - 1

  local keys = {}
  while true do
    local before = text:sub(1, i)
    local name = before:match("[%a_][%w_]*$")
    if name then
      local j = i - #name
      if text:sub(j, j):match("[%w_]") then return nil end
      table.insert(keys, 1, name)
      if text:sub(j, j) == "." and text:sub(j - 1, j - 1) ~= "." then
        i = j - 1
      else
        if isKeyword[name] then return nil end
        return keys, sep, partial, "global"
      end
    elseif before:sub(-1) == "]" then
      local lit = before:match("%[%s*(%b\"\")%s*%]$") or before:match("%[%s*(%b'')%s*%]$")
      local key
      if lit then
        key = readString(lit)
      else
        lit = before:match("%[%s*(%-?[%d%.]+)%s*%]$")
        key = lit and math.tointeger(tonumber(lit)) or (lit and tonumber(lit))
      end
      if key == nil then return nil end
      table.insert(keys, 1, key)
      i = i - #before:match("%[[^%[]*%]$")
    elseif before:sub(-1) == ")" then
      local lit = before:match("%(%s*(%b\"\")%s*%)$") or before:match("%(%s*(%b'')%s*%)$")
      local s = lit and readString(lit)
      if not s then return nil end
      -- f("x"):m is a call whose result is unknown, not the string
      local j = i - #before:match("%([^%(]*%)$")
      if text:sub(1, j):match("[%w_%]%)%.:]%s*$") then return nil end
      return keys, sep, partial, "string", s
    else
      return nil
    end
  end
end

local PROMPT_NAMES = {}  -- the globals only the prompt has (help, below): name → value

local function completions(text)
  local keys, sep, partial, baseKind, base = parse(text)
  if sep == nil then return {} end

  local names = {}
  if keys == nil then  -- top level: globals, the prompt's own names (help) and keywords
    names = namesOf(_G)
    for k, v in next, PROMPT_NAMES do names[k] = names[k] or v end
    for _, k in ipairs(KEYWORDS) do names[k] = names[k] or true end
  else
    local v
    if baseKind == "global" then
      v = lookup(_G, keys[1])
    else
      v = base
    end
    for n = (baseKind == "global" and 2 or 1), #keys do
      if v == nil then return {} end
      v = lookup(v, keys[n])
    end
    if v == nil then return {} end
    names = namesOf(v)
  end

  -- The API, not the internals: names that start with `_` (pitwall._raise, pitwall._setHub)
  -- only once the underscore is typed.
  local internal = partial:sub(1, 1) == "_"
  local out = {}
  for name, value in next, names do
    if name:sub(1, #partial) == partial and (sep ~= ":" or type(value) == "function")
      and (internal or name:sub(1, 1) ~= "_") then
      out[#out + 1] = name
    end
  end
  table.sort(out)
  local before = text:sub(1, #text - #partial)
  for n, name in ipairs(out) do out[n] = before .. name end
  return out
end

--- complete(text) -> sorted candidates, each `text` with its last name completed:
--- "pitwall.af" -> {"pitwall.after"}, "cars[1]:setSp" -> {"cars[1]:setSpeed"}. `text` may be the
--- whole line up to the cursor. Never raises; nothing to offer gives {}.
function M.complete(text)
  if type(text) ~= "string" then return {} end
  local ok, out = pcall(completions, text)
  return ok and out or {}
end

---------------------------------------------------------------------------------------------------
-- bindCars

local bound           -- the table this module made the global `cars`
local boundKeys = {}  -- the keys it set there last time (the user's own keys are kept)

--- bindCars() -> the `cars` table: every car at cars[n] and cars[name], refreshed in place.
--- A global `cars` that a script made is left alone (returns nil).
function M.bindCars()
  local current = rawget(_G, "cars")
  if current ~= nil and not rawequal(current, bound) then return nil end
  -- a list from pitwall.cars(), refilled below: using cars[9] or cars.groundshok (nil) is an
  -- error that names the cars there are (bindings/car_lists.hpp)
  bound = bound or pitwall.cars()
  for key in next, boundKeys do rawset(bound, key, nil) end
  boundKeys = {}
  for n, car in ipairs(pitwall.cars()) do
    rawset(bound, n, car)
    boundKeys[n] = true
    local ok, name = pcall(function() return car.name end)
    if ok and type(name) == "string" and name ~= "" then
      rawset(bound, name, car)
      boundKeys[name] = true
    end
  end
  rawset(_G, "cars", bound)
  return bound
end

---------------------------------------------------------------------------------------------------
-- help (scripts/pitwall/help.lua)

local help = require "pitwall.help"
help.use { scalar = scalar, quote = quote, formatFunction = formatFunction, textWidth = textWidth }

--- describe(value [, objectTypes [, columns]]) -> what help(value) prints (pitwall.help).
M.describe = help.describe
--- overview([columns]) -> what help() prints (pitwall.help).
M.overview = help.overview

---------------------------------------------------------------------------------------------------
-- the prompt's globals

local promptTypes    -- the object types the prompt last gave (registry key → metatable)
local promptColumns  -- its terminal's width, 0 when there is none

--- help() or help(x) at the prompt: prints overview() or describe(x). A global of the prompt
--- only (scripts do not see it); a script's own global `help` wins.
PROMPT_NAMES.help = function(...)
  if select("#", ...) == 0 then
    print(M.overview(promptColumns))
  else
    print(M.describe((...), promptTypes, promptColumns))
  end
end
help.helpFunction = PROMPT_NAMES.help

local promptEnv

--- environment(objectTypes, columns) -> the _ENV of chunks typed at the prompt: the world's
--- globals (read and written through to _G), and where _G has no such name, the prompt's own
--- (help). `objectTypes` and `columns` are for help (describe).
function M.environment(objectTypes, cols)
  if type(objectTypes) == "table" then promptTypes = objectTypes end
  promptColumns = tonumber(cols)
  if promptEnv == nil then
    promptEnv = setmetatable({}, {
      __index = function(_, key)
        local v = rawget(_G, key)
        if v ~= nil then return v end
        v = PROMPT_NAMES[key]
        if v ~= nil then return v end
        return _G[key]
      end,
      __newindex = function(_, key, v) _G[key] = v end,
    })
  end
  return promptEnv
end

return M
