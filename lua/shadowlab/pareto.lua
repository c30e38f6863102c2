-- pareto.lua -- the Pareto front of (time, error) points: the configurations
-- no other one beats on both, the answer to "what is the least error I can
-- have for this much time". Both coordinates are minimised.
local pareto = {}

-- True when a is at least as good as b in both and better in one.
function pareto.dominates(a, b)
  return a.x <= b.x and a.y <= b.y and (a.x < b.x or a.y < b.y)
end

-- points: list of {x = time, y = error, ...}; returns the non-dominated ones
-- sorted by x (ties in x keep the lowest y; equal points are all kept).
function pareto.front(points)
  local sorted = {}
  for i, p in ipairs(points) do
    if type(p.x) ~= "number" or type(p.y) ~= "number" then
      error(string.format("pareto.front: point %d needs numeric x and y", i), 2)
    end
    sorted[#sorted + 1] = p
  end
  table.sort(sorted, function(a, b)
    if a.x ~= b.x then return a.x < b.x end
    return a.y < b.y
  end)
  local front, best_y = {}, math.huge
  for _, p in ipairs(sorted) do
    local last = front[#front]
    if p.y < best_y or (last and p.x == last.x and p.y == last.y) then
      front[#front + 1] = p
      best_y = math.min(best_y, p.y)
    end
  end
  return front
end

return pareto
