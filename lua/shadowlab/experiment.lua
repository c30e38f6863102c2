-- experiment.lua -- running a sweep: the configurations (scene variants x
-- techniques x parameter points, from the registry), a stable key for each
-- (the engine's hash of the scene's content, light, technique and every
-- parameter value), one Lab per scene variant so a technique's resources are
-- reused across its parameter points (and dropped before the next technique
-- or once they pass resource_budget_gib, so memory stays bounded), a warm-up
-- and N timed repeats per configuration (stopping early past a time budget),
-- and one record row each, appended durably (records.lua). --resume skips keys
-- already recorded; --shard I/N runs the configurations whose index modulo N
-- is I into their own files, for `shadowlab merge`.
local sl = package.loaded.shadowlab or require "shadowlab"
local json = require "shadowlab.json"
local records = require "shadowlab.records"
local inspector = require "shadowlab.inspector"

local experiment = {}
local Experiment = {}
Experiment.__index = Experiment

-- time_budget_s: the timed repeats of a configuration stop once they took
-- this long (at least one runs; lab.h RenderTiming), so a slow technique
-- does not hold a sweep up for `repeats` long evaluations; 0: no limit.
-- resource_budget_gib: once the resources held reach this, they are dropped
-- before the next configuration (a technique's points keep what they share,
-- but each of csm's term counts holds GiB of moments that no other uses).
-- It changes what is rebuilt, not the results: frame time counts a
-- resource's build time whether this run built or reused it.
-- error_scale: the signed error at full colour in every configuration's
-- error image (estimate - reference, visibility units), one scale for the
-- whole sweep so its images compare (0: each image its own, rounded up
-- from its largest |error|).
local defaults = { samples = 256, pattern = "r2", seed = 1, light = 1, repeats = 3, warmup = 1, images = true,
                   exr = false, time_budget_s = 1, resource_budget_gib = 2, error_scale = 0.5, error = "all.rmse" }
local spec_fields = { name = true, scenes = true, overrides = true, samples = true, pattern = true, seed = true,
                      light = true, repeats = true, warmup = true, images = true, exr = true, cache = true,
                      description = true, time_budget_s = true, resource_budget_gib = true, error_scale = true,
                      error = true }

local function merged(a, b)
  local m = {}
  for k, v in pairs(a or {}) do m[k] = v end
  for k, v in pairs(b or {}) do m[k] = v end
  return m
end

local function sorted_pairs_text(t)
  local keys, parts = {}, {}
  for k in pairs(t) do keys[#keys + 1] = k end
  table.sort(keys)
  for i, k in ipairs(keys) do
    local v = t[k]
    parts[i] = k .. "=" .. (type(v) == "table" and json.encode(v) or tostring(v))
  end
  return table.concat(parts, " ")
end

-- experiment.new{name = "pcf-kernel", scenes = {...}, samples = 256, repeats = 3, ...}
function experiment.new(spec)
  if type(spec) ~= "table" then error("experiment.new expects a table", 2) end
  for k in pairs(spec) do
    if not spec_fields[k] then error("experiment.new: unknown field '" .. tostring(k) .. "'", 2) end
  end
  if type(spec.name) ~= "string" or not spec.name:match("^[%w_.-]+$") then
    error("experiment.new: name must be letters, digits, '_', '-' or '.' (it names reports/NAME)", 2)
  end
  local self = setmetatable({ name = spec.name, description = spec.description, variants = {}, entries = {} },
                            Experiment)
  for k, v in pairs(defaults) do self[k] = spec[k] == nil and v or spec[k] end
  local metric_ok, why = records.metric_path(self.error)
  if not metric_ok then error("experiment.new: error: " .. why, 2) end -- before any row runs
  if type(self.error_scale) ~= "number" or not (self.error_scale >= 0 and self.error_scale <= 1e6) then
    error("experiment.new: error_scale must be a number in [0, 1e6] (0: each error image its own scale), got " ..
          tostring(self.error_scale), 2)
  end
  self.cache, self.overrides = spec.cache, spec.overrides or {}
  for _, s in ipairs(spec.scenes or {}) do
    if type(s) == "table" then self:scene(s[1], s[2]) else self:scene(s) end
  end
  return self
end

local function exists(path)
  local f = io.open(path, "rb")
  if f then f:close() end
  return f ~= nil
end

-- Scene variants: exp:scene(path) once, or with a list of override tables
-- (e.g. sweep.grid{["lights[1].radius"] = {0.1, 0.2}}), one variant each. A
-- relative path missing from the current folder is taken from the project.
function Experiment:scene(path, variants)
  if type(path) ~= "string" then error("experiment:scene expects a scene file path", 2) end
  if not path:match("^/") and not exists(path) and exists(sl.root .. "/" .. path) then path = sl.root .. "/" .. path end
  for _, o in ipairs(variants or { {} }) do
    local overrides = merged(self.overrides, o)
    self.variants[#self.variants + 1] = { file = path, overrides = overrides, swept = o,
                                          label = sorted_pairs_text(o) }
  end
  return self
end

-- exp:add("pcf", sweep.grid{K = {1, 3, 5}}): a technique at each point (nil:
-- its defaults; one table of parameters: that single point). Names and
-- ranges are checked now, against the registry.
function Experiment:add(technique, points)
  local desc = sl.technique(technique)
  if points and #points == 0 and next(points) ~= nil then points = { points } end
  for _, p in ipairs(points or { {} }) do
    local ok, full = pcall(sl.params, technique, p)
    if not ok then error(full, 2) end
    self.entries[#self.entries + 1] = { technique = desc, params = full, swept = p }
  end
  return self
end

-- Every registered technique (those that land later included), each at
-- points(t) (default: its defaults); filter(t) may leave some out.
function Experiment:add_registry(opts)
  opts = opts or {}
  for _, t in ipairs(sl.techniques()) do
    if not opts.filter or opts.filter(t) then self:add(t.name, opts.points and opts.points(t) or nil) end
  end
  return self
end

---------------------------------------------------------------- arguments

local usage = [[
experiment options:
  --out DIR        results folder (default reports/NAME)
  --resume         continue the results in --out, skipping configurations already recorded
  --fresh          discard the results in --out and start again
  --mixed-builds   let --resume add rows of this build (commit, CPU, threads) beside rows of another
  --shard I/N      run only configurations whose index modulo N is I (0 <= I < N), into their own files
  --threads N      worker threads
  --repeat N       timed evaluations per configuration (median and minimum recorded)
  --warmup N       untimed evaluations before them
  --samples N      reference light samples per view sample
  -s, --set K=V    scene override for every scene, e.g. --set camera.width=160 (repeatable)
  --param [T:]K=V  parameter K of technique T (no T: of every technique that has K) at V in every
                   configuration, e.g. --param map_size=256 (repeatable; points that become equal run once)
  --no-images      no PNG images per configuration (smaller, faster; the report shows plots only)
  --quiet          no progress lines
  -h, --help       this list (and the script's own options)]]
experiment.usage = usage -- `shadowlab run --help` prints it

local function extra_usage(extra)
  local names, lines = {}, {}
  for name in pairs(extra or {}) do names[#names + 1] = name end
  table.sort(names)
  for _, name in ipairs(names) do
    lines[#lines + 1] = string.format("  --%-14s %s (default %s)", name .. " V", extra[name].help, extra[name].default)
  end
  return #lines > 0 and "\nthis script's options:\n" .. table.concat(lines, "\n") or ""
end

local function usage_error(msg, extra)
  io.stderr:write("error: ", msg, "\n", usage, extra_usage(extra), "\n")
  os.exit(2)
end

local function int_arg(argv, i, name, lo, hi)
  local v = math.tointeger(tonumber(argv[i + 1] or ""))
  if not v or v < lo or v > hi then usage_error(string.format("%s expects an integer in [%d, %d]", name, lo, hi)) end
  return v
end

-- "160" -> 160, "0.3" -> 0.3, "true"/"false" -> booleans, else the text.
local function override_value(text)
  if text == "true" or text == "false" then return text == "true" end
  local n = tonumber(text)
  return n and (math.tointeger(n) or n) or text
end

-- Parse the script's arguments (arg); bad ones print usage and exit 2.
-- `extra` declares the script's own options, {name = {default =, help =}}:
-- their values (strings) are in o.extra. Pass the result to exp:run.
function experiment.parse_args(argv, extra)
  local o, i = { shard = { index = 0, count = 1 }, set = {}, params = {}, extra = {}, parsed = true }, 1
  for name, spec in pairs(extra or {}) do o.extra[name] = spec.default end
  while argv and argv[i] do
    local a = argv[i]
    if a == "--out" then o.out = argv[i + 1] or usage_error("--out expects a folder"); i = i + 1
    elseif a == "--resume" then o.resume = true
    elseif a == "--fresh" then o.fresh = true
    elseif a == "--mixed-builds" then o.mixed_builds = true
    elseif a == "--no-images" then o.images = false
    elseif a == "--quiet" then o.quiet = true
    elseif a == "--set" or a == "-s" then
      local k, v = (argv[i + 1] or ""):match("^([^=]+)=(.+)$")
      if not k then usage_error(a .. " expects KEY=VALUE, e.g. camera.width=160") end
      o.set[k] = override_value(v)
      i = i + 1
    elseif a == "--param" then
      local text = argv[i + 1] or ""
      local t, k, v = text:match("^([%w_]+):([%w_]+)=(.+)$")
      if not t then k, v = text:match("^([%w_]+)=(.+)$") end
      if not k then usage_error(a .. " expects [TECH:]KEY=VALUE, e.g. map_size=256 or pcf:K=5") end
      o.params[#o.params + 1] = { technique = t, key = k, value = override_value(v) }
      i = i + 1
    elseif a == "--shard" then
      local si, sn = (argv[i + 1] or ""):match("^(%d+)/(%d+)$")
      si, sn = math.tointeger(tonumber(si)), math.tointeger(tonumber(sn))
      if not si or sn < 1 or si >= sn then usage_error("--shard expects I/N with 0 <= I < N") end
      o.shard = { index = si, count = sn }
      i = i + 1
    elseif a == "--threads" then o.threads = int_arg(argv, i, a, 1, 1024); i = i + 1
    elseif a == "--repeat" then o.repeats = int_arg(argv, i, a, 1, 10000); i = i + 1
    elseif a == "--warmup" then o.warmup = int_arg(argv, i, a, 0, 1000); i = i + 1
    elseif a == "--samples" then o.samples = int_arg(argv, i, a, 1, 1048576); i = i + 1
    elseif a == "--help" or a == "-h" then io.stdout:write(usage, extra_usage(extra), "\n"); os.exit(0)
    elseif extra and extra[a:match("^%-%-(.+)$") or ""] then
      o.extra[a:sub(3)] = argv[i + 1] or usage_error(a .. " expects a value", extra)
      i = i + 1
    else usage_error("unknown argument '" .. tostring(a) .. "'", extra) end
    i = i + 1
  end
  if o.resume and o.fresh then usage_error("--resume and --fresh exclude each other") end
  return o
end

-- The set of technique names a script's --techniques option lists
-- ("all": every one, as {all = true}); an unknown name is a user error
-- naming the registered ones.
function experiment.technique_set(text)
  local set = {}
  for name in tostring(text):gmatch("[^,%s]+") do
    if name ~= "all" and not pcall(sl.technique, name) then
      local known = {}
      for _, t in ipairs(sl.techniques()) do known[#known + 1] = t.name end
      error(string.format("--techniques: unknown technique '%s' (registered: all, %s)", name,
                          table.concat(known, ", ")), 0)
    end
    set[name] = true
  end
  return set
end

---------------------------------------------------------------- configurations

-- Does the technique (a registry description) handle lights of this type?
function experiment.handles(desc, light_type)
  for _, l in ipairs(desc.lights) do
    if l == light_type then return true end
  end
  return false
end

local function point_label(entry)
  local text = sorted_pairs_text(entry.swept)
  return entry.technique.name .. (text ~= "" and " " .. text or "")
end

-- Open every variant's Lab and list the configurations in a fixed order
-- (techniques and their points, then variants): the Labs share one resource
-- manager, so a technique's points over every variant reuse what their keys
-- share (a light-radius sweep renders one shadow map). A technique is left
-- out of a variant whose light it does not handle (the registry says which);
-- a configuration listed twice (same key: a point equal to the defaults, a
-- repeated value) runs once.
function Experiment:configurations()
  local configs, seen = {}, {}
  for _, v in ipairs(self.variants) do
    v.lab = v.lab or sl.open(v.file, v.overrides)
    v.info = v.lab:info()
    if not v.info.lights[self.light] then error(string.format("%s has no light %d", v.file, self.light), 0) end
  end
  for _, e in ipairs(self.entries) do
    for vi, v in ipairs(self.variants) do
      local light = v.info.lights[self.light]
      local key = experiment.handles(e.technique, light.type) and v.lab:key(e.technique.name, e.params, self.light)
      if key and not seen[key] then
        seen[key] = true
        configs[#configs + 1] = { index = #configs, variant = v, variant_index = vi, entry = e, key = key,
                                  label = point_label(e) }
      end
    end
  end
  return configs
end

function Experiment:settings()
  return { samples = self.samples, pattern = self.pattern, seed = self.seed, light = self.light,
           repeats = self.repeats, warmup = self.warmup, time_budget_s = self.time_budget_s, measure = "visibility",
           error_scale = self.error_scale, overrides = self.overrides }
end

-- The CSV columns: the standard ones, then every parameter of the
-- techniques and every scene override that the experiment sets.
function Experiment:columns()
  local columns, seen = {}, {}
  for _, c in ipairs(records.standard_columns) do columns[#columns + 1] = c[1] end
  local function add(name)
    if not seen[name] then
      seen[name] = true
      columns[#columns + 1] = name
    end
  end
  for _, e in ipairs(self.entries) do
    for _, p in ipairs(e.technique.params) do add("param:" .. p.name) end
  end
  local keys = {}
  for _, v in ipairs(self.variants) do
    for k in pairs(v.overrides) do keys[#keys + 1] = k end
  end
  table.sort(keys)
  for _, k in ipairs(keys) do add("scene:" .. k) end
  return columns
end

---------------------------------------------------------------- running

local function file_names(out, shard)
  if shard.count == 1 then return out .. "/records.jsonl", out .. "/results.csv" end
  local tag = string.format("shard-%d-of-%d", shard.index, shard.count)
  return out .. "/records." .. tag .. ".jsonl", out .. "/results." .. tag .. ".csv"
end

function Experiment:open_results(o, configs)
  local jsonl, csv = file_names(o.out, o.shard)
  if exists(jsonl) and not o.resume then
    if not o.fresh then
      error(jsonl .. " exists: pass --resume to continue it, --fresh to start again, or another --out", 0)
    end
    os.remove(jsonl)
    os.remove(csv)
  end
  sl.mkdir(o.out)
  local settings = self:settings()
  -- The fingerprint covers the configurations themselves (their keys hash the
  -- scene's content, the technique and every parameter): a grid edited under
  -- the same name and settings, or a scene edited since, is another experiment.
  local keys = {}
  for i, c in ipairs(configs) do keys[i] = c.key end
  local header = { shadowlab_results = 1, name = self.name, settings = settings,
                   fingerprint = sl.hash(json.encode({ name = self.name, settings = settings, keys = keys })),
                   shard = o.shard, configurations = #configs, columns = self:columns() }
  return records.open(jsonl, csv, header, function(row) return row.status == "ok" end), header
end

-- A configuration's images, in a folder named by its key; the reference's in
-- one named by everything the reference depends on (the scene's content, the
-- light, samples, pattern, seed), so a --fresh run with other samples never
-- shows an older reference under its caption.
function Experiment:image_paths(config)
  local dir = "images/" .. config.key
  local t = config.entry.technique.name
  local ref = "images/ref-" .. sl.hash(json.encode({ scene = config.variant.info.hash, light = self.light,
                                                      samples = self.samples, pattern = self.pattern or json.null,
                                                      seed = self.seed or json.null }))
  return { dir = dir, visibility = dir .. "/" .. t .. ".png", shaded = dir .. "/" .. t .. "-shaded.png",
           error = dir .. "/" .. t .. "-error.png",
           reference = ref .. "/reference.png", reference_shaded = ref .. "/reference-shaded.png" }
end

function Experiment:compare_options(config, out_dir)
  return { technique = config.entry.technique.name, params = config.entry.params, light = self.light,
           repeats = self.repeats, warmup = self.warmup, samples = self.samples, pattern = self.pattern,
           seed = self.seed, cache = self.cache, out = out_dir, exr = self.exr, time_budget = self.time_budget_s,
           error_scale = self.error_scale }
end

-- The reference's images for a variant, once per results folder.
function Experiment:reference_images(config, out)
  local paths = self:image_paths(config)
  if exists(out .. "/" .. paths.reference) then return end
  config.variant.lab:reference{ light = self.light, samples = self.samples, pattern = self.pattern,
                                seed = self.seed, cache = self.cache, exr = false,
                                out = out .. "/" .. paths.reference:match("^(.*)/") }
end

-- The machine's load when a row was measured: the 1-minute load average
-- (/proc/loadavg) and the online CPU cores (/proc/cpuinfo); nil where they
-- cannot be read. A load above the cores means other processes shared
-- them while this row was timed.
local cores_online
local function machine_load()
  local f = io.open("/proc/loadavg", "r")
  if not f then return nil end
  local avg1 = tonumber((f:read("l") or ""):match("^(%S+)"))
  f:close()
  if not cores_online then
    local c = io.open("/proc/cpuinfo", "r")
    if c then
      cores_online = 0
      for line in c:lines() do if line:match("^processor%s*:") then cores_online = cores_online + 1 end end
      c:close()
    end
  end
  if not avg1 or not cores_online or cores_online == 0 then return nil end
  return { loadavg_1min = avg1, cores = cores_online }
end

function Experiment:run_one(config, o, header)
  local row = { index = config.index, key = config.key, label = config.label, experiment = header.fingerprint,
                lua_helpers = records.helpers_hash(),
                technique = config.entry.technique.name, params = config.entry.params,
                variant = { scene = config.variant.info.name, file = config.variant.file,
                            overrides = config.variant.overrides, label = config.variant.label } }
  local paths = o.images and self:image_paths(config) or nil
  local ok, run = pcall(function()
    local r = config.variant.lab:compare(self:compare_options(config, paths and o.out .. "/" .. paths.dir))
    if paths then
      self:reference_images(config, o.out)
      inspector.write(r, o.out .. "/" .. paths.dir, config.key) -- the report's pixel inspector
    end
    return r
  end)
  row.load = machine_load()
  if ok then
    row.status, row.record = "ok", run:record()
    if paths then row.images = paths; row.images.dir = nil end
  else
    row.status, row.error = "error", (tostring(run):gsub("^[^:\n]*experiment%.lua:%d+: ", ""))
  end
  return row
end

-- The value of a metric path "region.field" (exp.error, the one its report
-- plots) in a record's metrics: "-" for an empty region (null).
local function metric_text(metrics, path)
  local region, field = records.metric_path(path)
  local v = region and metrics[region] and metrics[region][field]
  return type(v) == "number" and string.format("%.5f", v) or "-"
end

local function progress(o, n, total, config, row)
  if o.quiet then return end
  local v = config.variant
  local where = v.info.name .. (v.label ~= "" and " [" .. v.label .. "]" or "")
  if row.status ~= "ok" then
    io.stderr:write(string.format("[%d/%d] %s on %s: ERROR %s\n", n, total, config.label, where, row.error))
    return
  end
  local t = row.record.timings_s
  io.stderr:write(string.format("[%d/%d] %s on %s: %s %s, frame %.3f ms (eval %.3f ms, %s)\n", n, total,
                                config.label, where, o.error, metric_text(row.record.metrics, o.error),
                                1e3 * t.frame, 1e3 * t.evaluate_median, row.record.resource_cache))
end

-- Rows measured by another build (commit, CPU, threads: records.build_of)
-- are not mixed with this run's: --resume that would compute new rows beside
-- them is refused unless --mixed-builds, and then results.csv's commit, cpu
-- and threads columns and the report's machine line tell them apart. A
-- resume that computes nothing (writing the report of merged shards) mixes
-- nothing and passes.
local function refuse_mixed_builds(o, writer, mine)
  if o.mixed_builds or #writer.rows == 0 then return end
  local pending = 0
  for _, c in ipairs(mine) do
    if not writer.done[c.key] then pending = pending + 1 end
  end
  if pending == 0 then return end
  local here = sl.machine()
  here.host, here.lua = nil, records.helpers_hash()
  local mine_text = records.build_text(here)
  for _, b in ipairs(records.builds(writer.rows)) do
    if b.text ~= mine_text then
      error(string.format("%s holds %d rows measured with %s; this run is %s: %d new rows would be mixed with " ..
                          "them. Use --fresh to start again, another --out, or --mixed-builds to keep both " ..
                          "(told apart by results.csv's commit, cpu and threads columns)", writer.path, b.rows,
                          b.text, mine_text, pending), 0)
    end
  end
end

-- --param (parse_args's o.params) for the techniques named: {name = {key =
-- value}}, each name's values checked against the registry's ranges. An
-- unknown technique, or a --param that no technique named has, is an error.
-- Scripts that run their own loop (soft-failures) pass these to lab:compare.
function experiment.fixed_params(fixed, names)
  local by_name = {}
  for _, f in ipairs(fixed or {}) do
    local flag = "--param " .. (f.technique and f.technique .. ":" or "") .. f.key
    if f.technique then
      local known, why = pcall(sl.technique, f.technique)
      if not known then error(flag .. ": " .. tostring(why), 0) end
    end
    local used = false
    for _, name in ipairs(names) do
      if (f.technique == nil or f.technique == name) and sl.technique(name).param[f.key] then
        by_name[name] = by_name[name] or {}
        by_name[name][f.key] = f.value
        local ok, err = pcall(sl.params, name, by_name[name])
        if not ok then error(flag .. ": " .. tostring(err), 0) end
        used = true
      end
    end
    if not used then error(flag .. ": no technique of this experiment has a parameter " .. f.key, 0) end
  end
  return by_name
end

-- Each entry's point with the --param values of its technique (a point that
-- becomes another's runs once: configurations() keeps one per key).
function Experiment:fix_params(fixed)
  local names = {}
  for _, e in ipairs(self.entries) do names[#names + 1] = e.technique.name end
  local by_name = experiment.fixed_params(fixed, names)
  for _, e in ipairs(self.entries) do
    local values = by_name[e.technique.name]
    if values then
      local p = {}
      for k, v in pairs(e.swept) do p[k] = v end
      for k, v in pairs(values) do p[k] = v end
      e.swept, e.params = p, sl.params(e.technique.name, p)
    end
  end
end

-- Run the experiment with the script's arguments (arg, or parse_args's
-- result). Returns a result table:
-- rows (this output's rows in configuration order), out, sharded, computed,
-- skipped, failed, the experiment and its header.
function Experiment:run(argv)
  local o = (type(argv) == "table" and argv.parsed) and argv or experiment.parse_args(argv)
  o.out = o.out or ("reports/" .. self.name)
  o.error = self.error -- the metric progress lines print: the one the report plots by default
  if o.images == nil then o.images = self.images end
  for _, k in ipairs({ "repeats", "warmup", "samples" }) do
    if o[k] then self[k] = o[k] end
  end
  if o.threads then sl.threads(o.threads) end
  for k, v in pairs(o.set) do
    self.overrides[k] = v
    for _, variant in ipairs(self.variants) do variant.overrides[k] = v end
  end
  if #self.entries == 0 then error("experiment " .. self.name .. ": no techniques added", 0) end
  self:fix_params(o.params)
  if #self.variants == 0 then error("experiment " .. self.name .. ": no scenes", 0) end
  local configs = self:configurations()
  local writer, header = self:open_results(o, configs)
  local result = { experiment = self, header = header, out = o.out, sharded = o.shard.count > 1, rows = {},
                   quiet = o.quiet,
                   computed = 0, skipped = 0, failed = 0, dropped = writer.dropped }
  if writer.dropped > 0 and not o.quiet then
    io.stderr:write(string.format("%s: dropped a half-written last row\n", writer.path))
  end
  if writer.retried > 0 and not o.quiet then
    io.stderr:write(string.format("%s: retrying %d configurations that failed before\n", writer.path, writer.retried))
  end
  local mine = {}
  for _, c in ipairs(configs) do
    if c.index % o.shard.count == o.shard.index then mine[#mine + 1] = c end
  end
  refuse_mixed_builds(o, writer, mine)
  local last_use, last_of_technique = {}, {}
  for i, c in ipairs(mine) do
    last_use[c.variant] = i
    last_of_technique[c.entry.technique.name] = i
  end
  for i, c in ipairs(mine) do
    local row = writer.done[c.key]
    if row then
      result.skipped = result.skipped + 1
    else
      local held = c.variant.lab:info().resource_bytes
      if held >= self.resource_budget_gib * 2 ^ 30 then c.variant.lab:drop_resources() end
      row = self:run_one(c, o, header)
      writer:append(row)
      result.computed = result.computed + 1
      progress(o, i, #mine, c, row)
      if self.on_row then self.on_row(row) end
    end
    if row.status ~= "ok" then result.failed = result.failed + 1 end
    result.rows[#result.rows + 1] = row
    if last_of_technique[c.entry.technique.name] == i then
      c.variant.lab:drop_resources() -- the next technique shares little: memory stays bounded
    end
    if last_use[c.variant] == i then
      c.variant.lab:close()
      c.variant.lab = nil
    end
  end
  writer:close()
  for _, v in ipairs(self.variants) do
    if v.lab then v.lab:close(); v.lab = nil end
  end
  if not o.quiet then
    io.stderr:write(string.format("%s: %d computed, %d already recorded, %d failed -> %s\n", self.name,
                                  result.computed, result.skipped, result.failed, writer.path))
  end
  return result
end

return experiment
