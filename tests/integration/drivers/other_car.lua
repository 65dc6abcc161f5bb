-- Commands another car: refused (a driver commands only its own), and so out.
return {
  update = function(self, car)
    for _, other in ipairs(pitwall.cars()) do
      if other ~= car then other:setSpeed(1500) end
    end
  end,
}
