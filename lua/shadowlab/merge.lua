-- merge.lua -- `shadowlab merge [-o OUT] [--force] DIR...`: the results of a
-- sweep's shards (records*.jsonl in each DIR) merged into OUT/records.jsonl
-- and OUT/results.csv, with the shards' images copied into OUT/images.
-- Refuses files of different experiments (name or fingerprint, which covers
-- the configuration list), a shard given twice, shards of different splits
-- (0/2 with 1/3), missing shards (unless --partial), any configuration
-- recorded twice, and rows of different builds (commit, CPU, threads;
-- unless --mixed-builds). Afterwards
-- `shadowlab run SCRIPT --resume --out OUT` finds everything recorded and
-- writes the report.
local sl = package.loaded.shadowlab or require "shadowlab"
local json = require "shadowlab.json"
local records = require "shadowlab.records"

local merge = {}

local usage = "usage: shadowlab merge [-o OUT] [--force] [--partial] [--mixed-builds] DIR...\n" ..
              "  merges the records*.jsonl of the shard folders DIR... into OUT (default: the first DIR)\n" ..
              "  --partial: accept a set of shards with some missing (their configurations stay missing)\n" ..
              "  --mixed-builds: accept rows of different commits, CPUs or thread counts\n"

-- A refusal exits 1; a usage error (bad option, missing value or DIR) exits 2.
local function fail(msg) error({ message = msg, status = 1 }, 0) end
local function usage_fail(msg) error({ message = msg, status = 2 }, 0) end

local function parse(argv)
  local o, i = { dirs = {} }, 1
  while argv[i] do
    local a = argv[i]
    if a == "-o" or a == "--out" then
      o.out = argv[i + 1]
      if not o.out or o.out:sub(1, 1) == "-" then usage_fail(a .. " expects a folder") end
      i = i + 1
    elseif a == "--force" then o.force = true
    elseif a == "--partial" then o.partial = true
    elseif a == "--mixed-builds" then o.mixed_builds = true
    elseif a == "--help" or a == "-h" then o.help = true
    elseif a:sub(1, 1) == "-" then usage_fail("unknown option '" .. a .. "'")
    else o.dirs[#o.dirs + 1] = (a:gsub("/+$", "")) end
    i = i + 1
  end
  if not o.help and #o.dirs == 0 then usage_fail("no DIR given") end
  o.out = o.out and o.out:gsub("/+$", "") or o.dirs[1]
  return o
end

-- Every results file of the DIRs except OUT/records.jsonl itself.
local function input_files(o)
  local files = {}
  for _, dir in ipairs(o.dirs) do
    local names, msg = sl.dir(dir)
    if not names then fail(msg) end
    for _, name in ipairs(names) do
      local path = dir .. "/" .. name
      if name:match("^records.*%.jsonl$") and not (dir == o.out and name == "records.jsonl") then
        files[#files + 1] = path
      end
    end
  end
  if #files == 0 then fail("no records*.jsonl in " .. table.concat(o.dirs, ", ")) end
  return files
end

local function same_experiment(a, b) return a.name == b.name and a.fingerprint == b.fingerprint end

local function read_all(files)
  local inputs, first = {}, nil
  local shards = {}
  for _, path in ipairs(files) do
    local header, rows, dropped = records.read(path)
    if dropped > 0 then
      io.stderr:write(string.format("merge: %s: dropped a half-written last row (an interrupted shard: " ..
                                    "--resume it to finish)\n", path))
    end
    first = first or { header = header, path = path }
    if not same_experiment(header, first.header) then
      fail(string.format("%s is experiment '%s' (fingerprint %s, settings %s) but %s is '%s' (%s, %s): " ..
                         "refusing to merge different experiments", path, tostring(header.name),
                         tostring(header.fingerprint), json.encode(header.settings or {}), first.path,
                         tostring(first.header.name), tostring(first.header.fingerprint),
                         json.encode(first.header.settings or {})))
    end
    local shard = header.shard or { index = 0, count = 1 }
    local tag = shard.index .. "/" .. shard.count
    if shards[tag] then fail(string.format("shard %s is given twice: %s and %s", tag, shards[tag], path)) end
    shards[tag] = path
    inputs[#inputs + 1] = { path = path, header = header, rows = rows, shard = shard }
  end
  return inputs, first.header
end

-- Every input splits the configurations the same way (--shard I/N with one
-- N), and every I of 0 .. N-1 is there unless --partial.
local function check_shard_set(o, inputs)
  local count = inputs[1].shard.count
  for _, input in ipairs(inputs) do
    if input.shard.count ~= count then
      fail(string.format("%s is shard %d/%d but %s is shard %d/%d: shards of different splits do not cover " ..
                         "the configurations once", input.path, input.shard.index, input.shard.count,
                         inputs[1].path, inputs[1].shard.index, count))
    end
  end
  local have, missing = {}, {}
  for _, input in ipairs(inputs) do have[input.shard.index] = true end
  for i = 0, count - 1 do
    if not have[i] then missing[#missing + 1] = i .. "/" .. count end
  end
  if #missing > 0 and not o.partial then
    fail(string.format("shard%s %s of %d missing: pass --partial to merge without %s", #missing > 1 and "s" or "",
                       table.concat(missing, ", "), count, #missing > 1 and "them" or "it"))
  end
end

-- All rows come from one build, unless --mixed-builds.
local function check_builds(o, rows)
  local builds = records.builds(rows)
  if #builds > 1 and not o.mixed_builds then
    local parts = {}
    for _, b in ipairs(builds) do parts[#parts + 1] = string.format("%d rows with %s", b.rows, b.text) end
    fail("rows of different builds: " .. table.concat(parts, "; ") .. ": pass --mixed-builds to merge them " ..
         "(results.csv's commit, cpu and threads columns tell them apart)")
  end
end

local function merged_rows(inputs)
  local seen, rows = {}, {}
  for _, input in ipairs(inputs) do
    for _, row in ipairs(input.rows) do
      if seen[row.key] then
        fail(string.format("configuration %s (%s) is recorded in both %s and %s: refusing duplicates", row.key,
                           tostring(row.label), seen[row.key], input.path))
      end
      seen[row.key] = input.path
      rows[#rows + 1] = row
    end
  end
  table.sort(rows, function(a, b) return a.index < b.index end)
  return rows
end

local function copy_file(from, to)
  local src = assert(io.open(from, "rb"))
  local data = src:read("a")
  src:close()
  sl.write_file(to, data)
end

-- DIR/images/*/* into OUT/images/ (names are configuration keys and
-- reference hashes: the same name is the same image).
local function copy_images(o)
  for _, dir in ipairs(o.dirs) do
    local images = dir .. "/images"
    if dir ~= o.out and sl.isdir(images) then
      for _, sub in ipairs(sl.dir(images)) do
        local target = o.out .. "/images/" .. sub
        sl.mkdir(target)
        for _, name in ipairs(sl.dir(images .. "/" .. sub) or {}) do
          local t = target .. "/" .. name
          local f = io.open(t, "rb")
          if f then f:close() else copy_file(images .. "/" .. sub .. "/" .. name, t) end
        end
      end
    end
  end
end

local function run(argv)
  local o = parse(argv)
  if o.help then
    io.stdout:write(usage)
    return 0
  end
  local out_path = o.out .. "/records.jsonl"
  local existing = io.open(out_path, "rb")
  if existing then
    existing:close()
    if not o.force then fail(out_path .. " exists: pass --force to replace it, or choose another -o") end
  end
  local inputs, header = read_all(input_files(o))
  check_shard_set(o, inputs)
  local rows = merged_rows(inputs)
  check_builds(o, rows)
  local out_header = {}
  for k, v in pairs(header) do out_header[k] = v end
  out_header.shard = { index = 0, count = 1 }
  out_header.merged_from = json.as_array({})
  for _, input in ipairs(inputs) do
    out_header.merged_from[#out_header.merged_from + 1] = { file = input.path, shard = input.shard, rows = #input.rows }
  end
  local lines = { json.encode(out_header) }
  for i, row in ipairs(rows) do lines[i + 1] = json.encode(row) end
  sl.mkdir(o.out)
  copy_images(o)
  sl.write_file(o.out .. "/results.csv", records.csv_text(header.columns, rows))
  sl.write_file(out_path, table.concat(lines, "\n") .. "\n")
  local total = header.configurations or #rows
  io.stderr:write(string.format("merge: %d of %d configurations from %d files -> %s%s\n", #rows, total, #inputs,
                                out_path, #rows < total and string.format(" (%d missing: shards not run or " ..
                                "not finished)", total - #rows) or ""))
  return 0
end

function merge.main(...)
  local ok, result = pcall(run, { ... })
  if ok then return result end
  if type(result) == "table" and result.message then
    io.stderr:write("shadowlab merge: ", result.message, "\n", result.status == 2 and usage or "")
    return result.status
  end
  error(result, 0)
end

return merge
