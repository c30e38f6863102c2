-- fusion.lua -- occluder fusion (course §1, Fig. 1.6, Eq. 1.5): how the
-- shadows of two occluders combine, and which combination a technique's
-- answer is closest to. Visibilities are fractions of the light in [0, 1]
-- (the reference's quantity); occlusions are 1 - visibility, the terms
-- Eq. 1.5 bounds (catalogue ch. 1-3 [OWN]: it holds for occlusion, not
-- visibility): max_i O_i <= O <= sum_i O_i.
--   local c = fusion.combine(v1, v2)   -- c.sum, c.product, c.max: visibilities
--   local label, rmse, n = fusion.classify(samples)
-- A sample is { estimate =, truth =, sum =, product =, max = }. NaN or
-- infinite inputs are refused with an error naming the field, never folded
-- into a mean (math.max and math.min would swallow them).
local fusion = {}

-- The combinations, in the order ties are named.
fusion.KINDS = { "truth", "sum", "product", "max" }

local function finite(x) return type(x) == "number" and x == x and x ~= math.huge and x ~= -math.huge end

local function check(x, what)
  if not finite(x) then error(string.format("fusion: %s is %s, expected a finite visibility", what, tostring(x)), 3) end
  return x
end

-- The visibility each rule of Fig. 1.6 gives from the two occluders' own
-- visibilities v1, v2 (each the reference with the other occluder removed):
-- sum: occlusions added (disjoint projections on the light, Eq. 1.5's upper
-- bound; clamped at no light left); product: visibilities multiplied
-- (independent coverage, "closer to the truth" for a partial overlap);
-- max: the larger occlusion (one projection inside the other, the lower bound).
function fusion.combine(v1, v2)
  check(v1, "v1"); check(v2, "v2")
  local o1, o2 = 1 - v1, 1 - v2
  local o_sum = o1 + o2
  return { sum = o_sum < 1 and 1 - o_sum or 0, product = v1 * v2, max = v1 < v2 and v1 or v2 }
end

-- Is a sample in the fusion region: each occluder alone leaves it in
-- penumbra (lo < v_i < hi)? Only there can the rules differ: where either
-- occluder alone leaves the point lit (v_i = 1) or in umbra (v_i = 0), sum,
-- product and max agree with each other and with the truth.
function fusion.in_region(v1, v2, lo, hi)
  lo, hi = lo or 0.01, hi or 0.99
  check(v1, "v1"); check(v2, "v2")
  return v1 > lo and v1 < hi and v2 > lo and v2 < hi
end

-- classify(samples [, tie]): the RMSE of the estimate against each of
-- truth, sum, product and max over the samples, and the label of the
-- nearest; rules within `tie` of the nearest (RMSE <= min * 1.1 + tie,
-- default 0.005 visibility) are named with it, "truth=sum", because there
-- the scene cannot tell them apart. Also returns the count and the signed
-- mean error against the truth (estimate - truth: negative is too dark).
-- No samples: label "-", RMSEs NaN (not measured, never 0).
function fusion.classify(samples, tie)
  tie = tie or 0.005
  local sq, bias = {}, 0
  for _, k in ipairs(fusion.KINDS) do sq[k] = 0 end
  for i, s in ipairs(samples) do
    local e = check(s.estimate, "samples[" .. i .. "].estimate")
    for _, k in ipairs(fusion.KINDS) do
      local d = e - check(s[k], "samples[" .. i .. "]." .. k)
      sq[k] = sq[k] + d * d
    end
    bias = bias + (e - s.truth)
  end
  local n, rmse = #samples, {}
  if n == 0 then
    for _, k in ipairs(fusion.KINDS) do rmse[k] = 0 / 0 end
    return "-", rmse, 0, 0 / 0
  end
  local best
  for _, k in ipairs(fusion.KINDS) do
    rmse[k] = math.sqrt(sq[k] / n)
    if not best or rmse[k] < rmse[best] then best = k end
  end
  local names = {}
  for _, k in ipairs(fusion.KINDS) do
    if rmse[k] <= rmse[best] * 1.1 + tie then names[#names + 1] = k end
  end
  return table.concat(names, "="), rmse, n, bias / n
end

return fusion
