-- Keeps 1 MB more at every update: past its memory cap (--driver-memory), out.
local kept = {}
return {
  update = function() kept[#kept + 1] = string.rep("x", 1 << 20) .. #kept end,
}
