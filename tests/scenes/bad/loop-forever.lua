-- a scene that never returns
while true do end
