-- What `help` says at the prompt (docs/repl.md "help"), for pitwall.repl, which gives it how
-- values are shown (help.use) and the prompt's help function (help.helpFunction).
local pitwall = require "pitwall"

local H = {}

-- pitwall.repl's ways of showing a value, set by H.use
local scalar, quote, formatFunction, textWidth

--- use{scalar, quote, formatFunction, textWidth}: how values and text widths are shown.
function H.use(show)
  scalar, quote, formatFunction, textWidth = show.scalar, show.quote, show.formatFunction,
    show.textWidth
end

H.helpFunction = nil  -- the prompt's help: help(help) says what it does

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
    if value == H.helpFunction then
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
function H.describe(value, objectTypes, cols)
  helpColumns = cols ~= 0 and tonumber(cols)  -- false: no cut, nil: the terminal's
  local ok, text = pcall(describeValue, value, objectTypes)
  if ok then return text end
  return "help: cannot describe that value: " .. tostring(text)
end

--- overview([columns]) -> what help() prints: the names to start from, help(x), Tab and the
--- commands; lines cut to `columns` as describe's.
function H.overview(cols)
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

return H
