-- Calls os.exit: a driver cannot end the run; out.
return { update = function() os.exit(3) end }
