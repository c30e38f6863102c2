-- flags.lua -- the "--name VALUE" options of a stand-alone experiment script
-- (one that does not run shadowlab.experiment's sweep): flags.parse(arg,
-- {out = "reports/x", ["map-size"] = 1024}, "x") returns the values, numbers
-- where the default is a number; an unknown name or a missing or non-numeric
-- value is an error naming the script and its options.
local flags = {}

function flags.parse(argv, defaults, script)
  local names, o = {}, {}
  for k, v in pairs(defaults) do o[k] = v; names[#names + 1] = "--" .. k end
  table.sort(names)
  local function fail(msg) error(string.format("%s: %s (options: %s)", script, msg, table.concat(names, ", ")), 0) end
  local i = 1
  while argv[i] do
    local name = argv[i]:match("^%-%-([%w_-]+)$")
    if not name or defaults[name] == nil then fail("unknown argument " .. argv[i]) end
    local v = argv[i + 1]
    if v == nil then fail("--" .. name .. " expects a value") end
    if type(defaults[name]) == "number" then v = tonumber(v) or fail("--" .. name .. " expects a number") end
    o[name] = v
    i = i + 2
  end
  return o
end

return flags
