-- the scene table itself has an __index that raises: refused before any read
return setmetatable({}, {__index = function() error("x") end})
