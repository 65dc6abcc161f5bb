-- The Lua half of `pitwall repl`: how values are shown, what Tab completes, the `cars` global,
-- what help says, and the prompt's globals (where `help` lives). The C++ prompt calls these;
-- nothing here reads input or writes output but help() itself.
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
  bound = bound or {}
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
-- help

-- What help says comes from what the editor definitions are generated from
-- (scripts/pitwall/types.lua): the live metadata — an object type's __methods, __fields and
-- __events, a module's own table — and the annotations in scripts/pitwall/types/*.lua for the
-- words. Nothing here describes the API a second time.

local annotationParts  -- every part of every annotation module, loaded at the first help

local function parts()
  if annotationParts == nil then
    annotationParts = {}
    local types = require "pitwall.types"
    for _, name in ipairs(types.sources) do
      for _, part in ipairs(require(name)) do annotationParts[#annotationParts + 1] = part end
    end
  end
  return annotationParts
end

local function sortedNames(t)
  local out = {}
  for k in next, t do
    if type(k) == "string" then out[#out + 1] = k end
  end
  table.sort(out)
  return out
end

-- An annotation's text as {desc = the lines before the first @-line, as one line, params =
-- {{name, rest}}, returns = {rest}}.
local function parseDoc(text)
  local doc = { params = {}, returns = {} }
  local desc = {}
  for line in ((text or "") .. "\n"):gmatch("(.-)\n") do
    line = line:gsub("^%s+", ""):gsub("%s+$", "")
    local tag, rest = line:match("^@(%w+)%s*(.*)$")
    if tag == "param" then
      local name, after = rest:match("^(%S+)%s*(.*)$")
      if name then doc.params[#doc.params + 1] = { name, after } end
    elseif tag == "return" then
      doc.returns[#doc.returns + 1] = rest
    elseif tag == nil and line ~= "" and #doc.params == 0 and #doc.returns == 0 then
      desc[#desc + 1] = line
    end
  end
  doc.desc = table.concat(desc, " ")
  return doc
end

-- "after(delay, fn)", and with `results` "after(delay, fn) -> pitwall.Timer"
local function signature(prefix, name, text, results)
  local doc = parseDoc(text)
  local names = {}
  for i, p in ipairs(doc.params) do names[i] = p[1] end
  local sig = prefix .. name .. "(" .. table.concat(names, ", ") .. ")"
  local returns = {}
  for i, r in ipairs(doc.returns) do returns[i] = r:match("^(%S+)") end
  if results and #returns > 0 then sig = sig .. " -> " .. table.concat(returns, ", ") end
  return sig, doc
end

-- The width help's lines are cut to: what describe() was given (the prompt's terminal; none
-- when the output is not one), else pitwall.terminal()'s.
local helpColumns
local function width()
  if helpColumns == false then return math.huge end
  local columns = helpColumns
  if columns == nil then
    local ok, term = pcall(function() return pitwall.terminal() end)
    columns = ok and type(term) == "table" and tonumber(term.columns) or 100
  end
  return math.max(60, columns)
end

-- Rows {left, right} as two columns, each row one line: the right column cut to the width.
local function columns(rows, indent)
  local left = 0
  for _, r in ipairs(rows) do left = math.max(left, textWidth(r[1])) end
  left = math.min(left, 40)
  local limit = width()
  local out = {}
  for _, r in ipairs(rows) do
    local line = indent .. r[1]
    local text = r[2] or ""
    if text ~= "" then
      line = line .. string.rep(" ", math.max(2, left - textWidth(r[1]) + 2)) .. text
      local cut = textWidth(line) > limit and utf8.offset(line, limit)
      if cut then line = line:sub(1, cut - 1) .. "…" end
    end
    out[#out + 1] = line
  end
  return table.concat(out, "\n")
end

-- The first sentence of a description.
local function firstSentence(text)
  local desc = parseDoc(text).desc
  return desc:match("^(.-%.)%s") or desc
end

-- What `declare` makes: "pitwall.sim" for "pitwall.sim", "race" for "local race".
local function declared(part)
  return part.declare and (part.declare:gsub("^local ", "")) or nil
end

-- How a part's names are written: "car:" for an object's methods, "pitwall.after" for a module.
local function objectSelf(part)
  return part.self or (part.class:match("([%w_]+)$"):lower())
end

-- The names of an object type from its metatable (what the binary has).
local function objectNames(mt)
  local methods = rawget(mt, "__methods")
  if methods == nil and type(rawget(mt, "__index")) == "table" then methods = rawget(mt, "__index") end
  local names = { methods = {}, fields = {}, events = {} }
  for k, v in next, (type(methods) == "table" and methods or {}) do
    if type(k) == "string" and type(v) == "function" and k:sub(1, 1) ~= "_" then names.methods[k] = v end
  end
  for _, which in ipairs({ "fields", "events" }) do
    local list = rawget(mt, "__" .. which)
    if type(list) == "table" then
      for _, k in ipairs(list) do names[which][k] = true end
    end
  end
  return names
end

-- A titled section of `lines`: one row(name) → {left, right} per name, sorted; none when empty.
local function addSection(lines, title, names, row)
  local rows = {}
  for _, name in ipairs(sortedNames(names)) do rows[#rows + 1] = row(name) end
  if #rows > 0 then
    lines[#lines + 1] = title
    lines[#lines + 1] = columns(rows, "  ")
  end
end

-- A field's annotation {type, doc} as one text: "integer  last reported speed, mm/s".
local function fieldText(f)
  f = f or {}
  return (f[1] and (f[1] .. "  ") or "") .. (f[2] or "")
end

-- An object type's listing: its methods, fields and events, one line each.
local function describeObject(part, mt, shown)
  local live = mt and objectNames(mt) or nil
  local me = objectSelf(part)
  local lines = { (shown and (shown .. ": ") or "") .. part.class .. " — " .. firstSentence(part.doc) }
  local function section(title, names, row) addSection(lines, title, names, row) end
  local methods = live and live.methods or part.methods or {}
  section(string.format("methods (%s:name(…)):", me), methods, function(name)
    local text = (part.methods or {})[name] or ""
    local sig, doc = signature("", name, text)
    return { sig, doc.desc }
  end)
  section(string.format("fields (%s.name, read only):", me), live and live.fields or part.fields or {},
    function(name) return { name, fieldText((part.fields or {})[name]) } end)
  section(string.format("events (%s.onX = function(%s, e) … end):", me, me),
    live and live.events or part.events or {}, function(name)
      local e = (part.events or {})[name] or {}
      return { name, (e[2] or "") .. ((e[1] and e[1] ~= "") and (" (" .. e[1] .. ")") or "") }
    end)
  lines[#lines + 1] = string.format("help(%s.name) or help \"name\" shows one in full", me)
  return table.concat(lines, "\n")
end

-- A table of functions (pitwall, pitwall.sim, a library module): functions, fields, handlers.
local function describeModule(part, live)
  local target = declared(part)
  local lines = { target .. " — " .. firstSentence(part.doc) }
  local settable = part.settable or {}
  local functions, fields = {}, {}
  if type(live) == "table" then
    for k, v in next, live do
      if type(k) == "string" and k:sub(1, 1) ~= "_" and not settable[k] then
        if type(v) == "function" then functions[k] = true else fields[k] = true end
      end
    end
  else
    for k in next, part.functions or {} do functions[k] = true end
    for k in next, part.methods or {} do functions[k] = true end
    for k in next, part.fields or {} do fields[k] = true end
  end
  local function section(title, names, row) addSection(lines, title, names, row) end
  section("functions:", functions, function(name)
    local text = (part.functions or {})[name]
    local sep = "."
    if text == nil and (part.methods or {})[name] then text, sep = part.methods[name], ":" end
    local sig, doc = signature(target .. sep, name, text or "")
    return { sig, doc.desc }
  end)
  section("fields:", fields, function(name)
    return { target .. "." .. name, fieldText((part.fields or {})[name]) }
  end)
  section(string.format("handlers a script may set (%s.onX = function(…) end):", target), settable,
    function(name)
      local h = settable[name]
      return { target .. "." .. name, (h[2] ~= "" and h[2] or h[1]) }
    end)
  lines[#lines + 1] = string.format("help(%s.name) or help \"name\" shows one in full", target)
  return table.concat(lines, "\n")
end

-- One function in full: its signature, its description, its parameters and results.
local function describeFunction(title, text)
  local doc = parseDoc(text)
  local lines = { title }
  if doc.desc ~= "" then lines[#lines + 1] = "  " .. doc.desc end
  local rows = {}
  for _, p in ipairs(doc.params) do rows[#rows + 1] = { p[1], p[2] } end
  for _, r in ipairs(doc.returns) do rows[#rows + 1] = { "returns", r } end
  if #rows > 0 then lines[#lines + 1] = columns(rows, "  ") end
  return table.concat(lines, "\n")
end

-- The classes written out as text in the annotations (event tables, a session, a tracker):
-- className → {doc = …, fields = {{name, rest}}, methods = {name → text}}.
local textClassCache
local function textClasses()
  if textClassCache then return textClassCache end
  textClassCache = {}
  for _, part in ipairs(parts()) do
    if part.text then
      local current, pending, locals = nil, {}, {}
      for line in (part.text .. "\n"):gmatch("(.-)\n") do
        local class = line:match("^%-%-%-@class%s+([%w_%.]+)")
        local field, rest = line:match("^%-%-%-@field%s+([%w_%[%]]+%??)%s*(.*)$")
        local localName = line:match("^local%s+([%w_]+)%s*=%s*{}")
        local owner, method = line:match("^function%s+([%w_]+)[:.]([%w_]+)%(")
        if class then
          current = { doc = table.concat(pending, "\n"), fields = {}, methods = {} }
          textClassCache[class] = current
          pending = {}
        elseif field and current then
          current.fields[#current.fields + 1] = { field, rest }
        elseif localName and current then
          locals[localName] = current
          pending = {}
        elseif owner and locals[owner] then
          locals[owner].methods[method] = table.concat(pending, "\n")
          pending = {}
        elseif line:match("^%-%-%-") and not line:match("^%-%-%-@class") then
          pending[#pending + 1] = (line:gsub("^%-%-%-", ""))
        else
          pending = {}
        end
      end
    end
  end
  return textClassCache
end

local function describeTextClass(name, class)
  local lines = { name .. (class.doc ~= "" and (" — " .. firstSentence(class.doc)) or "") }
  if #class.fields > 0 then  -- in the annotation's order
    lines[#lines + 1] = "fields:"
    lines[#lines + 1] = columns(class.fields, "  ")
  end
  addSection(lines, "methods:", class.methods, function(m)
    local sig, doc = signature(":", m, class.methods[m])
    return { sig, doc.desc }
  end)
  return table.concat(lines, "\n")
end

-- The registry key of an object's metatable ("pitwall.car"), from the object types the prompt
-- was given (bindings/object_types.cpp).
local function objectTypeOf(value, objectTypes)
  local mt = debug.getmetatable(value)
  if type(mt) ~= "table" or type(objectTypes) ~= "table" then return nil end
  for key, candidate in next, objectTypes do
    if rawequal(candidate, mt) then return key, mt end
  end
  return nil
end

local function objectPart(key)
  for _, part in ipairs(parts()) do
    if part.metatable == key then return part end
  end
end

local function tablePartOf(value)
  local types = require "pitwall.types"
  for _, part in ipairs(parts()) do
    if part.declare and rawequal(types.live(part, false), value) then return part end
  end
end

-- Every annotated function or method called `name`, or equal to the function `fn`:
-- {{title, text}}.
local function functionsNamed(name, fn, objectTypes)
  local types = require "pitwall.types"
  local found = {}
  for _, part in ipairs(parts()) do
    if part.metatable then
      local mt = type(objectTypes) == "table" and objectTypes[part.metatable] or nil
      local live = type(mt) == "table" and objectNames(mt).methods or {}
      for m, text in next, part.methods or {} do
        if m == name or (fn ~= nil and rawequal(live[m], fn)) then
          local sig = signature(objectSelf(part) .. ":", m, text, true)
          found[#found + 1] = { sig .. "  (" .. part.class .. ")", text }
        end
      end
    elseif part.declare then
      local live = types.live(part, false)
      for _, kind in ipairs({ "functions", "methods" }) do
        for f, text in next, part[kind] or {} do
          if f == name or (fn ~= nil and type(live) == "table" and rawequal(rawget(live, f), fn)) then
            local sep = kind == "methods" and ":" or "."
            found[#found + 1] = { (signature(declared(part) .. sep, f, text, true)), text }
          end
        end
      end
    end
  end
  if name then
    for class, c in next, textClasses() do
      if c.methods[name] then
        found[#found + 1] = { (signature(class .. ":", name, c.methods[name], true)), c.methods[name] }
      end
    end
  end
  table.sort(found, function(a, b) return a[1] < b[1] end)
  return found
end

-- The standard library's name for a function of it ("string.format"), or nil.
local STANDARD = { "string", "table", "math", "os", "io", "coroutine", "utf8", "debug" }
local function standardName(fn)
  for k, v in next, _G do
    if rawequal(v, fn) and type(k) == "string" then return k end
  end
  for _, lib in ipairs(STANDARD) do
    local t = rawget(_G, lib)
    if type(t) == "table" then
      for k, v in next, t do
        if rawequal(v, fn) then return lib .. "." .. tostring(k) end
      end
    end
  end
end

local NOTHING = "; help() says what help knows"

local function describeString(s, objectTypes)
  local types = require "pitwall.types"
  local short = s:gsub("^pitwall%.", "")
  for _, part in ipairs(parts()) do
    if part.metatable and (part.class == s or part.metatable == s
        or part.metatable == "pitwall." .. short) then
      local mt = type(objectTypes) == "table" and objectTypes[part.metatable] or nil
      return describeObject(part, type(mt) == "table" and mt or nil)
    elseif part.declare and (part.module == s or part.module == "pitwall." .. short
        or part.class == s or declared(part) == s or declared(part) == "pitwall." .. short) then
      return describeModule(part, types.live(part, false))
    end
  end
  local class = textClasses()[s] or textClasses()["pitwall." .. short]
  if class then return describeTextClass(textClasses()[s] and s or "pitwall." .. short, class) end
  local found = functionsNamed(s, nil, objectTypes)
  if #found > 0 then
    local out = {}
    for i, f in ipairs(found) do out[i] = describeFunction(f[1], f[2]) end
    return table.concat(out, "\n\n")
  end
  return string.format("help: nothing in pitwall's API is called %s%s", quote(s), NOTHING)
end

local function describeValue(value, objectTypes)
  local t = type(value)
  if t == "nil" then
    return "help: that is nil (a name not set? the library's modules are not globals: "
      .. "help(require \"pitwall.race\") or help \"pitwall.race\")" .. NOTHING
  elseif t == "string" then
    return describeString(value, objectTypes)
  elseif t == "userdata" then
    local key, mt = objectTypeOf(value, objectTypes)
    local part = key and objectPart(key)
    if part then return describeObject(part, mt, scalar(value)) end
  elseif t == "table" then
    local part = tablePartOf(value)
    if part then return describeModule(part, value) end
    -- an object of a library class (a board): its class's module is annotated
    local mt = debug.getmetatable(value)
    if type(mt) == "table" then
      for _, candidate in ipairs({ mt, rawget(mt, "__index") }) do
        part = type(candidate) == "table" and tablePartOf(candidate)
        if part then return describeModule(part, candidate) end
      end
    end
    for _, name in ipairs({ "string", "table", "math", "io", "os", "coroutine", "utf8", "debug",
      "package" }) do
      if rawget(_G, name) == value then
        return string.format("help: %s is Lua's own library: the Lua 5.4 manual, §6 "
          .. "(https://www.lua.org/manual/5.4/manual.html#6)", name)
      end
    end
    return string.format("help: no help for this table (%s): it is not part of pitwall's API; Tab "
      .. "after its name and a dot lists its keys%s", scalar(value):sub(1, 40), NOTHING)
  elseif t == "function" then
    local found = functionsNamed(nil, value, objectTypes)
    if #found > 0 then
      local out = {}  -- one function may have two names (pitwall.sim.run is pitwall.sleep)
      for i, f in ipairs(found) do out[i] = describeFunction(f[1], f[2]) end
      return table.concat(out, "\n\n")
    end
    if value == PROMPT_NAMES.help then
      return "help: help() says where to start; help(x) lists what x has, one line each; help(f) "
        .. "or help \"name\" shows one in full (docs/repl.md)"
    end
    local std = standardName(value)
    if std then
      return string.format("help: %s is Lua's own: the Lua 5.4 manual, §6 "
        .. "(https://www.lua.org/manual/5.4/manual.html#6)", std)
    end
    return string.format("help: no help for %s: it is not part of pitwall's API%s",
      formatFunction(value), NOTHING)
  end
  return string.format("help: no help for %s %s: help describes pitwall's objects, tables and "
    .. "functions%s", t, scalar(value), NOTHING)
end

--- describe(value [, objectTypes [, columns]]) -> what help(value) prints: for a car, a robot,
--- a timer, pitwall, pitwall.sim or a library module its methods, fields and events one line
--- each; for one of their functions (or a string naming it, or naming a module or class) that
--- one in full; otherwise one line saying there is none. `objectTypes` (registry key →
--- metatable, as the prompt gets them) lets objects be recognised; lines are cut to `columns`
--- (default: pitwall.terminal().columns; 0: never). Never raises.
function M.describe(value, objectTypes, cols)
  helpColumns = cols ~= 0 and tonumber(cols)  -- false: no cut, nil: the terminal's
  local ok, text = pcall(describeValue, value, objectTypes)
  if ok then return text end
  return "help: cannot describe that value: " .. tostring(text)
end

--- overview([columns]) -> what help() prints: the names to start from, help(x), Tab and the
--- commands; lines cut to `columns` as describe's.
function M.overview(cols)
  helpColumns = cols ~= 0 and tonumber(cols)
  local modules = {}
  for _, part in ipairs(parts()) do
    if part.module and part.module ~= "pitwall.repl" and not part.module:find("drivers%.") then
      modules[#modules + 1] = part.module
    end
  end
  local rows = {
    { "cars[1], cars.skull", "the cars: help(cars[1]) lists what a car does" },
    { "pitwall", "the engine: timers, tasks, the clock: help(pitwall)" },
  }
  if rawget(pitwall, "sim") ~= nil then
    rows[#rows + 1] = { "pitwall.sim", "the simulator: help(pitwall.sim)" }
  end
  rows[#rows + 1] = { "require \"pitwall.race\"", "the race library: help \"pitwall.race\"" }
  rows[#rows + 1] = { "", "(also " .. table.concat(modules, ", "):gsub("pitwall%.race, ", "") .. ")" }
  rows[#rows + 1] = { "help(x)", "what x has, one line each; help(f) or help \"name\" shows one in full" }
  rows[#rows + 1] = { "Tab", "completes names: cars[1]:<Tab><Tab> lists a car's methods" }
  rows[#rows + 1] = { "pitwall.sleep(2)", "a line runs as a task: it may wait; Ctrl-C ends it" }
  rows[#rows + 1] = { ":help :cars :quit", "the prompt's commands and keys" }
  return "pitwall at the prompt (docs/repl.md; every object: docs/lua-api.md)\n" .. columns(rows, "  ")
end

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
