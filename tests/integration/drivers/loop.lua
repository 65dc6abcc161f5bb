-- Never returns from its update: past its budget (--driver-budget), out.
return { update = function() while true do end end }
