-- syntax.lua -- a script that does not parse: exit 1 naming the file and line.
local x = = 1
