-- Reads a file: a driver reads no file; out.
return { update = function() return io.open("/etc/hostname"):read("a") end }
