-- json.lua -- JSON for the lab's records: decode (the C side's run records,
-- the JSON Lines results files) and a deterministic encode (object keys
-- sorted, numbers in the shortest form that reads back to the same double),
-- so equal rows give equal lines. null decodes to json.null; arrays decode
-- with the json.array metatable so that an empty one encodes as [] again.
local json = {}

json.null = setmetatable({}, { __tostring = function() return "null" end })
json.array = { __name = "json.array" }

-- Mark a Lua table as a JSON array (for empty tables).
function json.as_array(t) return setmetatable(t or {}, json.array) end

---------------------------------------------------------------- encode

local escapes = { ['"'] = '\\"', ['\\'] = '\\\\', ['\b'] = '\\b', ['\f'] = '\\f',
                  ['\n'] = '\\n', ['\r'] = '\\r', ['\t'] = '\\t' }

local function encode_string(s)
  return '"' .. s:gsub('[%c"\\]', function(c)
    return escapes[c] or string.format("\\u%04x", c:byte())
  end) .. '"'
end

local function encode_number(x)
  if math.type(x) == "integer" then return string.format("%d", x) end
  if x ~= x or x == math.huge or x == -math.huge then return "null" end
  if x == math.floor(x) and math.abs(x) < 2^53 then return string.format("%.1f", x) end
  for digits = 15, 17 do
    local s = string.format("%." .. digits .. "g", x)
    if tonumber(s) == x then return s end
  end
end

local function is_array(t)
  if getmetatable(t) == json.array then return true end
  local n = #t
  if n == 0 then return false end
  for k in pairs(t) do
    if math.type(k) ~= "integer" or k < 1 or k > n then return false end
  end
  return true
end

local encode_value

local function encode_table(t, seen)
  if seen[t] then error("json.encode: a table contains itself", 0) end
  seen[t] = true
  local parts = {}
  if is_array(t) then
    for i = 1, #t do parts[i] = encode_value(t[i], seen) end
    seen[t] = nil
    return "[" .. table.concat(parts, ",") .. "]"
  end
  local keys = {}
  for k in pairs(t) do
    if type(k) ~= "string" then error("json.encode: object keys must be strings, got " .. type(k), 0) end
    keys[#keys + 1] = k
  end
  table.sort(keys)
  for i, k in ipairs(keys) do parts[i] = encode_string(k) .. ":" .. encode_value(t[k], seen) end
  seen[t] = nil
  return "{" .. table.concat(parts, ",") .. "}"
end

function encode_value(v, seen)
  local kind = type(v)
  if v == json.null or v == nil then return "null"
  elseif kind == "boolean" then return tostring(v)
  elseif kind == "number" then return encode_number(v)
  elseif kind == "string" then return encode_string(v)
  elseif kind == "table" then return encode_table(v, seen)
  end
  error("json.encode: cannot encode a " .. kind, 0)
end

-- One line of JSON (no newlines inside: strings escape them).
function json.encode(v) return encode_value(v, {}) end

---------------------------------------------------------------- decode

local function decode_error(text, pos, what)
  local line = select(2, text:sub(1, pos):gsub("\n", "")) + 1
  error(string.format("invalid JSON at line %d, character %d: %s", line, pos, what), 0)
end

local function skip(text, pos) return text:find("[^ \t\r\n]", pos) or #text + 1 end

local decode_value

local function utf8_of(code) return utf8.char(code) end

local function decode_string(text, pos)
  local parts, i = {}, pos + 1
  while true do
    local j = text:find('["\\%c]', i)
    if not j then decode_error(text, pos, "unterminated string") end
    parts[#parts + 1] = text:sub(i, j - 1)
    local c = text:sub(j, j)
    if c == '"' then return table.concat(parts), j + 1 end
    if c ~= "\\" then decode_error(text, j, "control character in a string") end
    local e = text:sub(j + 1, j + 1)
    local simple = { b = "\b", f = "\f", n = "\n", r = "\r", t = "\t", ['"'] = '"', ["\\"] = "\\", ["/"] = "/" }
    if simple[e] then
      parts[#parts + 1], i = simple[e], j + 2
    elseif e == "u" then
      local hex = text:match("^%x%x%x%x", j + 2)
      if not hex then decode_error(text, j, "bad \\u escape") end
      local code = tonumber(hex, 16)
      i = j + 6
      if code >= 0xD800 and code <= 0xDBFF then
        local low = text:match("^\\u(%x%x%x%x)", i)
        if not low then decode_error(text, j, "unpaired surrogate") end
        code = 0x10000 + (code - 0xD800) * 0x400 + (tonumber(low, 16) - 0xDC00)
        i = i + 6
      end
      parts[#parts + 1] = utf8_of(code)
    else
      decode_error(text, j, "bad escape \\" .. e)
    end
  end
end

local function decode_number(text, pos)
  local s = text:match("^-?%d+%.?%d*[eE]?[-+]?%d*", pos)
  if not s or s == "" or s == "-" then decode_error(text, pos, "unexpected character") end
  local v = (s:find("[.eE]") and tonumber(s)) or math.tointeger(tonumber(s)) or tonumber(s)
  if not v then decode_error(text, pos, "bad number " .. s) end
  return v, pos + #s
end

local function decode_list(text, pos, close, item)
  pos = skip(text, pos + 1)
  if text:sub(pos, pos) == close then return pos + 1 end
  while true do
    pos = skip(text, item(pos))
    local c = text:sub(pos, pos)
    if c == close then return pos + 1 end
    if c ~= "," then decode_error(text, pos, "expected ',' or '" .. close .. "'") end
    pos = skip(text, pos + 1)
  end
end

local literals = { ["true"] = true, ["false"] = false, ["null"] = json.null }

function decode_value(text, pos)
  pos = skip(text, pos)
  local c = text:sub(pos, pos)
  if c == "{" then
    local obj = {}
    local next_pos = decode_list(text, pos, "}", function(p)
      if text:sub(p, p) ~= '"' then decode_error(text, p, "expected a key string") end
      local key, q = decode_string(text, p)
      q = skip(text, q)
      if text:sub(q, q) ~= ":" then decode_error(text, q, "expected ':'") end
      local value
      value, q = decode_value(text, q + 1)
      obj[key] = value
      return q
    end)
    return obj, next_pos
  elseif c == "[" then
    local arr = json.as_array({})
    local next_pos = decode_list(text, pos, "]", function(p)
      local value, q = decode_value(text, p)
      arr[#arr + 1] = value
      return q
    end)
    return arr, next_pos
  elseif c == '"' then
    return decode_string(text, pos)
  elseif c == "" then
    decode_error(text, pos, "unexpected end")
  end
  for word, value in pairs(literals) do
    if text:sub(pos, pos + #word - 1) == word then return value, pos + #word end
  end
  return decode_number(text, pos)
end

-- Decode one JSON document; errors say where ("invalid JSON at line L, character C: ...").
function json.decode(text)
  local value, pos = decode_value(text, 1)
  pos = skip(text, pos)
  if pos <= #text then decode_error(text, pos, "trailing characters") end
  return value
end

return json
