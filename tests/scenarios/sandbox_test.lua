-- What a script may touch (docs/safety.md): code loads as text only, nothing can block the loop or
-- disarm the callback budget, and the memory a world holds is counted.
-- tags: errors

-- Lua does not verify bytecode: a patched binary chunk crashes the process. Every way in refuses
-- binary chunks with a sentence that says so.
local dumped = string.dump(function() return 42 end)
local patched = dumped:sub(1, 20) .. string.rep("\255", 64) .. dumped:sub(85)
for _, chunk in ipairs { dumped, patched } do
  local fn, err = load(chunk)
  expect.eq(fn, nil, "load of a binary chunk gives no function")
  expect.truthy(err:find("precompiled (binary) chunks are refused", 1, true), err)
  fn, err = load(chunk, "=x", "b")
  expect.eq(fn, nil, "mode \"b\" does not let a binary chunk in")
  local pieces = { chunk:sub(1, 3), chunk:sub(4) }
  fn, err = load(function() return table.remove(pieces, 1) end)
  expect.eq(fn, nil, "a reader function's binary chunk is refused too")
  expect.truthy(err:find("binary", 1, true), err)
end
expect.eq(load("return 6 * 7")(), 42, "source still loads")
expect.eq(load("return x", "=env", "t", { x = 5 })(), 5, "load keeps its environment argument")

local path = os.tmpname()
local f = assert(io.open(path, "wb"))
f:write(patched)
f:close()
local fn, err = loadfile(path)
expect.eq(fn, nil, "loadfile refuses a binary file")
expect.truthy(err:find("binary", 1, true), err)
expect.fails(function() dofile(path) end, "binary")
os.remove(path)
-- require, through a module file that holds bytecode
local dir = path:match("^(.*)/[^/]*$")
package.path = dir .. "/?.lua;" .. package.path
local modname = "pitwall_sandbox_" .. tostring(os.time()) .. tostring(math.random(1000000))
f = assert(io.open(dir .. "/" .. modname .. ".lua", "wb"))
f:write(dumped)
f:close()
local ok, rerr = pcall(require, modname)
os.remove(dir .. "/" .. modname .. ".lua")
expect.falsy(ok, "require refuses a binary module")
expect.truthy(tostring(rerr):find("binary", 1, true), tostring(rerr))

-- The callback budget cannot be disarmed, and nothing reads the terminal or runs a program.
expect.eq(debug.sethook, nil, "debug.sethook is not there")
expect.eq(debug.getregistry, nil, "debug.getregistry is not there")
expect.eq(debug.debug, nil, "debug.debug is not there")
expect.eq(type(debug.traceback), "function", "debug.traceback stays")
expect.eq(package.loaded.debug, debug, "require 'debug' gives the same reduced library")
expect.fails(function() io.read() end, "io.read is not available to scripts")
expect.fails(function() io.lines() end, "would read the terminal")
expect.fails(function() os.execute("true") end, "would block the engine")
expect.fails(function() io.popen("true") end, "would block the engine")

-- Files stay: scripts write results.
local out = os.tmpname()
f = assert(io.open(out, "w"))
f:write("lap,time\n1,9.5\n")
f:close()
local lines = {}
for line in io.lines(out) do lines[#lines + 1] = line end
os.remove(out)
expect.eq(#lines, 2, "io.lines(file) reads a file")

-- Nothing reaches past the sandbox: no upvalue or stack slot of the engine's C functions (where the
-- unrestricted functions would be), no library's exports, no finalizer.
expect.eq(debug.getupvalue, nil, "debug.getupvalue is not there")
expect.eq(debug.getlocal, nil, "debug.getlocal is not there")
-- Inside a reader function, the C function on the stack is the sandbox's own load: Lua's, which
-- takes binary chunks, is nowhere to be found.
local cFrames = {}
load(function()
  for level = 1, 10 do
    local info = debug.getinfo(level, "fS")
    if info and info.what == "C" then cFrames[#cFrames + 1] = info.func end
  end
  return nil
end)
expect.eq(#cFrames, 1, "one C function under the reader")
expect.eq(cFrames[1], load, "and it is the sandbox's load")
expect.fails(function() package.loadlib("libc.so.6", "abort") end, "package.loadlib is not available")
expect.fails(function() setmetatable({}, { __gc = function() end }) end, "__gc finalizer is refused")
expect.eq(getmetatable(setmetatable({}, { __index = { x = 1 } })).__index.x, 1, "other metatables work")
expect.eq(io.stdin, nil, "io.stdin is not there")
expect.fails(function() io.input() end, "io.input is not available")

-- xpcall: handlers and yields work as in Lua
local ok, msg = xpcall(error, function(m) return "handled: " .. m end, "x")
expect.falsy(ok)
expect.eq(msg, "handled: x")
local r = table.pack(xpcall(function(a, b) return a + b, "two" end, debug.traceback, 2, 3))
expect.eq(r.n, 3)
expect.eq(r[2], 5)
local slept
pitwall.spawn(function()
  slept = table.pack(xpcall(function() pitwall.sleep(0.5) return "woke" end, debug.traceback))
end)
pitwall.sleep(1)
expect.eq(slept and slept[2], "woke", "a task may sleep inside xpcall")

-- A timer period the clock cannot tell from zero is refused.
expect.fails(function() pitwall.every(1e-12, function() end) end, "at least 0.001 seconds")
pitwall.cancel(pitwall.every(0.001, function() end))
