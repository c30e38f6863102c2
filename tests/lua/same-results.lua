-- same-results.lua A.jsonl B.jsonl -- do two results files hold the same
-- configurations with the same outcomes, apart from what differs between
-- runs (timings, resources built or reused, cache states, machine)? Prints
-- "same N rows" and returns 0, or the first difference and returns 1.
local json = require "shadowlab.json"
local records = require "shadowlab.records"

local function keyed(path)
  local header, rows = records.read(path)
  if not header then error(path .. ": no such results file", 0) end
  local by_key, n = {}, 0
  for _, row in ipairs(rows) do
    if by_key[row.key] then error(path .. ": configuration " .. row.key .. " appears twice", 0) end
    by_key[row.key] = json.encode(records.comparable(row))
    n = n + 1
  end
  return header, by_key, n
end

local ha, a, na = keyed(arg[1])
local hb, b, nb = keyed(arg[2])
if ha.fingerprint ~= hb.fingerprint then
  print(string.format("different experiments: %s vs %s", ha.fingerprint, hb.fingerprint))
  return 1
end
for key, text in pairs(a) do
  if b[key] ~= text then
    print("differs: " .. key .. "\n  " .. text .. "\n  " .. tostring(b[key]))
    return 1
  end
end
if na ~= nb then
  print(string.format("%s has %d rows, %s has %d", arg[1], na, arg[2], nb))
  return 1
end
print(string.format("same %d rows", na))
return 0
