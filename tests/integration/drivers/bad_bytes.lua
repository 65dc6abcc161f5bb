-- Fails with bytes that are not UTF-8 in its message: its reason keeps the rest; the heat, the
-- results and the report are whole.
return { update = function() error("bad \xff\xfe bytes, <b>and markup</b>") end }
