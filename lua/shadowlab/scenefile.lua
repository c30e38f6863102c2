-- scenefile.lua -- a scene file as a Lua table, and back: for experiments
-- that read a scene's geometry (distances for a closed form) or derive a
-- variant that overrides cannot express (another light type, which drops
-- keys the new type refuses), without a second copy of the scene.
--   local scene = scenefile.load(sl.root .. "/scenes/parallel-planes.lua")
--   scenefile.write(out .. "/bunny-rect.lua", scene)
-- load runs the file in an environment of math, string, table, pairs and
-- ipairs only (what scenes use); the engine's own reader (sandboxed,
-- validated, src/scene/scene_lua.c) still reads whatever is written back.
local sl = package.loaded.shadowlab or require "shadowlab"

local scenefile = {}

function scenefile.load(path)
  local env = { math = math, string = string, table = table, pairs = pairs, ipairs = ipairs }
  local chunk, err = loadfile(path, "t", env)
  if not chunk then error("scenefile.load: " .. err, 2) end
  local scene = chunk()
  if type(scene) ~= "table" then error("scenefile.load: " .. path .. " returns no table", 2) end
  return scene
end

-- The value as Lua source: numbers in the fewest of 15 to 17 significant
-- digits that read back exactly, strings quoted, tables with their array
-- part first, then keys in sorted order. Anything else (a function: an
-- elevation callback) is refused by its key path.
local function literal(v, path)
  local kind = type(v)
  if kind == "number" then
    if v ~= v or v == math.huge or v == -math.huge then error("scenefile.write: " .. path .. " is not finite", 0) end
    if math.type(v) == "integer" then return tostring(v) end
    for digits = 15, 16 do -- the fewest that read back exactly, as the engine records overrides (lua/llab.c)
      local text = string.format("%." .. digits .. "g", v)
      if tonumber(text) == v then return text end
    end
    return string.format("%.17g", v)
  elseif kind == "string" then return string.format("%q", v)
  elseif kind == "boolean" then return tostring(v)
  elseif kind ~= "table" then error("scenefile.write: " .. path .. " is a " .. kind .. ", which has no literal", 0) end
  local parts, keys = {}, {}
  for i = 1, #v do parts[#parts + 1] = literal(v[i], path .. "[" .. i .. "]") end
  for k in pairs(v) do
    if not (math.type(k) == "integer" and k >= 1 and k <= #v) then
      if type(k) ~= "string" or not k:match("^[%a_][%w_]*$") then
        error("scenefile.write: " .. path .. " has a key that is no name: " .. tostring(k), 0)
      end
      keys[#keys + 1] = k
    end
  end
  table.sort(keys)
  for _, k in ipairs(keys) do parts[#parts + 1] = k .. " = " .. literal(v[k], path == "" and k or path .. "." .. k) end
  return "{ " .. table.concat(parts, ", ") .. " }"
end

-- Write the scene as a file the engine reads (atomically, through sl.write_file).
function scenefile.write(path, scene, comment)
  local head = comment and "-- " .. comment:gsub("\n", "\n-- ") .. "\n" or ""
  sl.write_file(path, head .. "return " .. literal(scene, "") .. "\n")
end

return scenefile
