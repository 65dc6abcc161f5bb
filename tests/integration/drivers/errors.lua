-- Fails in every method: its first error puts it out.
local function broken() error("this driver is broken") end
return { start = broken, update = broken, finish = broken, waiting = broken }
